"""Validation and packing of a run's inputs for the kernels, shared by single and batch runs."""
from dataclasses import dataclass

import numpy as np

from qzs import defaults
from qzs._validation import choice, positive_real
from qzs.engine import kernels as K
from qzs.engine.base_motion import base_motion_series
from qzs.engine.stability import SOLVERS, largest_stable_step, stability_test
from qzs.errors import ParameterError, StabilityError, UnresolvedExcitationError
from qzs.model.controller import SENSORS as K_SENSORS
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import (Chirp, DisplacementRecord, RandomExcitation, Sine,
                                  highest_frequency)
from qzs.model.isolator import InitialState, IsolatorParameters, other_spring_law
from qzs.model.springs import TABLE_COUNT, TABLE_POSITIONS, check_equilibrium
from qzs.model.registry import model_inputs

__all__ = ["PreparedRun", "prepare_run", "pack_model", "stack_models", "check_spring",
           "linear_initial_state", "linear_output",
           "run_inputs", "run_duration", "steps_per_sample",
           "divides",
           "divergence_message", "table_exit_message",
           "check_resolution", "resolving_step", "MIN_STEPS_PER_PERIOD",
           "check_record", "RECORD_BYTES_PER_POINT"]

#: Fewest integration steps per period of the excitation's highest frequency a run is
#: started with [-]: below, the fixed-step integrator does not follow the base motion (at
#: 2.5 steps per period the energy ledger is 15 % off; far below, the run diverges). The
#: summary warns below 20 (:data:`qzs.analysis.summary.WARNING_LIMITS`).
MIN_STEPS_PER_PERIOD = 10

_EXCITATIONS = (Chirp, Sine, RandomExcitation, DisplacementRecord)
# A base at rest, for the static load of the PI preload.
_AT_REST = Sine(amplitude=0.0, fade_in=0.0).pack()


def _pack_parameters(isolator, controller, dt, control_steps):
    center = controller.position_setpoint if isolator.stop_center is None else isolator.stop_center
    p = np.zeros(K.N_PARAMS)
    p[K.P_MASS] = isolator.mass
    p[K.P_GRAVITY] = isolator.gravity
    p[K.P_SPRING_A] = isolator.spring_force
    p[K.P_SPRING_B] = isolator.spring_shape
    p[K.P_FS] = isolator.stiction_force
    p[K.P_FC] = isolator.coulomb_force
    p[K.P_CBC] = isolator.stribeck_decay
    p[K.P_CV] = isolator.viscous_damping
    p[K.P_Z_LOW] = center - isolator.stroke_half
    p[K.P_Z_HIGH] = center + isolator.stroke_half
    p[K.P_STOP_K] = isolator.stop_stiffness
    p[K.P_STOP_C] = isolator.stop_damping
    p[K.P_PLASTIC] = 1.0 if isolator.stop_model == "plastic" else 0.0
    p[K.P_FMAX] = isolator.motor_force_max
    p[K.P_ZREF] = controller.position_setpoint
    p[K.P_KP] = controller.pi_kp
    p[K.P_KI] = controller.pi_ki
    p[K.P_KD] = controller.damping_gain
    p[K.P_HP_OMEGA] = 2 * np.pi * controller.velocity_highpass
    p[K.P_CONTROL_STEPS] = control_steps
    p[K.P_DT] = dt
    p[K.P_VREG] = isolator.friction_regularisation
    return p


def pack_model(isolator, controller, dt):
    """The controller's blocks beyond PI + damping and the spring law packed for the kernels
    (``K.M_*``).

    The blocks all zeros for PI + damping alone, the spring the tanh ``[0, a, b]`` by default
    (the kernels then take exactly the operations of PI + damping with the tanh); after the
    blocks (``K.M_SPRING``) the law's :meth:`~qzs.model.springs.SpringLaw.pack`, so a row is
    as wide as its law needs. Checks what needs the step: a discrete linear controller's
    sample time must be a whole number of integration steps.

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant (the compensator's friction law where it sets none).
    controller : ControllerParameters
        The controller.
    dt : float
        Integration step [s].

    Returns
    -------
    ndarray, shape (M_SPRING + the packed law's size,)

    Raises
    ------
    ParameterError
        A discrete linear controller's sample time that is not a whole number of steps.
    """
    law = isolator.spring_law.pack()
    m = np.zeros(K.M_SPRING + law.size)
    m[K.M_SPRING:] = law
    if not controller.has_blocks:
        return m
    m[K.M_BLOCKS] = 1.0
    compensation = controller.compensation
    if compensation is not None:
        m[K.M_COMP_FRACTION] = compensation.fraction
        (m[K.M_COMP_FS], m[K.M_COMP_FC], m[K.M_COMP_CBC],
         m[K.M_COMP_CV]) = compensation.law(isolator)
        m[K.M_COMP_DEADBAND] = compensation.deadband
        m[K.M_OBSERVER_RATE] = 2 * np.pi * compensation.observer_bandwidth
    if controller.dither is not None:
        m[K.M_DITHER_AMPLITUDE] = controller.dither.amplitude
        m[K.M_DITHER_OMEGA] = 2 * np.pi * controller.dither.frequency
    linear = controller.linear
    if linear is not None:
        n = linear.states
        m[K.M_LINEAR] = 1.0
        m[K.M_LINEAR_STATES] = n
        if linear.discrete:
            steps = linear.sample_time / dt
            if abs(steps - round(steps)) > 1e-6 * steps or round(steps) < 1:
                near = max(round(steps), 1)
                raise ParameterError(
                    f"`sample_time` of the LinearController ({linear.sample_time!r} s) must "
                    f"be a whole number of integration steps (dt = {dt!r} s), got {steps:g} "
                    f"steps; use sample_time={near * dt:g} s, or a dt that divides it.",
                    ("sample_time",))
            m[K.M_LINEAR_STEPS] = round(steps)
        a, b, c, d = linear.matrices()
        columns = [list(K_SENSORS).index(name) for name in linear.inputs]
        for i in range(n):
            m[K.M_A + i * K.NX_MAX:K.M_A + i * K.NX_MAX + n] = a[i]
            for j, column in enumerate(columns):
                m[K.M_B + i * K.N_SENSORS + column] = b[i, j]
            m[K.M_C + i] = c[0, i]
        for j, column in enumerate(columns):
            m[K.M_D + column] = d[0, j]
        m[K.M_ANTIWINDUP:K.M_ANTIWINDUP + n] = linear.antiwindup_gain()
    return m


def steps_per_sample(rate, dt, name="sample_rate", *, rounding="exact"):
    """Grid steps per period of ``rate`` [-]: the one place this arithmetic is done.

    Parameters
    ----------
    rate : float
        Sample or controller rate [Hz].
    dt : float
        Integration step [s].
    name : str
        Argument name for the message.
    rounding : {"exact", "up", "down"}
        ``exact``: ``1/(rate*dt)`` must be a whole number (else :class:`ParameterError`
        with a rate that works); ``up``: the fewest steps whose length is at most
        ``dt``; ``down``: the most steps of at least ``dt`` (at least 1).

    Returns
    -------
    int
    """
    ratio = 1.0 / (rate * dt)
    if rounding == "up":
        return max(1, int(np.ceil(ratio - 1e-9)))
    if rounding == "down":
        return max(1, int(np.floor(ratio + 1e-9)))
    steps = int(round(ratio))
    if steps < 1 or abs(ratio - steps) > 1e-6 * ratio:
        hint = 1.0 / (max(steps, 1) * dt)
        raise ParameterError(
            f"`{name}` ({rate!r} Hz) must divide the integration rate 1/dt = {1 / dt:g} Hz into "
            f"a whole number of steps; got {ratio:g} steps. Use e.g. {name}={hint:g}.")
    return steps


def divides(rate, dt):
    """Whether a period of ``rate`` [Hz] is a whole number of steps ``dt`` [s]
    (:func:`steps_per_sample`'s arithmetic, as a test).

    Parameters
    ----------
    rate : float
        Sample or controller rate [Hz].
    dt : float
        Integration step [s].

    Returns
    -------
    bool
    """
    try:
        steps_per_sample(rate, dt)
    except ParameterError:
        return False
    return True


def resolving_step(excitation, duration=None):
    """The largest step [s] that resolves the excitation (:func:`check_resolution`).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base motion the step must follow.
    duration : float, optional
        The run's simulated time [s] (a chirp cut short ends lower); default its length.

    Returns
    -------
    float
        ``1/(MIN_STEPS_PER_PERIOD * f_max)`` [s]; inf for a record or a base at rest.
    """
    if isinstance(excitation, DisplacementRecord):
        return np.inf
    top = highest_frequency(excitation, duration)
    return np.inf if top <= 0 else 1.0 / (MIN_STEPS_PER_PERIOD * top)


def check_resolution(excitation, dt, duration=None):
    """Refuse a step too coarse for the excitation: fewer than :data:`MIN_STEPS_PER_PERIOD`
    per period of its highest frequency within the run.

    A record is not checked: its samples' Nyquist frequency bounds its content from above
    only (a measured record sampled fast is common and usually slow in content).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base motion.
    dt : float
        Integration step [s].
    duration : float, optional
        Simulated time [s] (a chirp cut short reaches only the frequency of its end).

    Raises
    ------
    UnresolvedExcitationError
        The step gives fewer than :data:`MIN_STEPS_PER_PERIOD` steps per period.
    """
    if dt > resolving_step(excitation, duration) * (1.0 + 1e-9):
        top = highest_frequency(excitation, duration)
        name = ("frequency" if isinstance(excitation, Sine) else "f1" if (
            isinstance(excitation, RandomExcitation) or excitation.f1 >= excitation.f0) else "f0")
        raise UnresolvedExcitationError(frequency=top, dt=dt, minimum=MIN_STEPS_PER_PERIOD,
                                        name=name)


def run_inputs(excitation=None, isolator=None, controller=None):
    """A run's excitation, isolator and controller, the defaults put in for None.

    The one place these defaults are chosen: the paper's chirp, Table 1's isolator and
    the default loops (docs/model.md §11).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default :class:`~qzs.model.excitation.Chirp`.
    isolator : IsolatorParameters, optional
        Plant parameters; default Table 1.
    controller : ControllerParameters, optional
        PI and damping loops; default the defaults.

    Returns
    -------
    excitation, isolator, controller

    Raises
    ------
    ParameterError
        An argument of another type.
    """
    excitation = Chirp() if excitation is None else excitation
    _check_type("excitation", excitation, _EXCITATIONS)
    return (excitation, *model_inputs(isolator, controller))


def stack_models(models):
    """The packed models of a batch's cases as one array, each row zero-padded to the widest.

    Parameters
    ----------
    models : sequence of ndarray
        :func:`pack_model`'s rows.

    Returns
    -------
    ndarray, shape (len(models), widest)
    """
    width = max(m.size for m in models)
    out = np.zeros((len(models), width))
    for i, m in enumerate(models):
        out[i, :m.size] = m
    return out


def check_spring(isolator, controller, stroke, load=None):
    """Refuse a spring law with no stable equilibrium inside the stroke for the payload.

    The MagSpring's tanh (the default, or a TanhSpring) is not checked: on the paper's rig
    it alone falls short of the weight and the PI integral carries the rest, or the payload
    rests on its lower stop (docs/model.md §3). Another law must hold the payload's weight
    ``m g`` in the stroke with a positive (or quasi-zero) stiffness, the motor adding what the
    PI's bumpless preload holds where the controller has an integral: the setpoint is then the
    equilibrium when the motor can carry ``m g - F(z_ref)``, else the saturated motor's
    ``+-F_max`` is the hold (docs/model.md §3.1).

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant, its ``spring``.
    controller : ControllerParameters
        The controller (its setpoint and integral gain).
    stroke : tuple of float
        The stops ``(low, high)`` [m] (a single run's ``K.P_Z_LOW``, ``K.P_Z_HIGH``).
    load : float, optional
        The static force the spring and the motor carry [N] (a platform's leg: its share of
        the platform's weight along the leg); default the payload's weight ``m g``.

    Raises
    ------
    ParameterError
        No stable equilibrium (``qzs.model.springs.check_equilibrium``'s message), naming
        ``spring``.
    """
    law = other_spring_law(isolator)
    if law is None:
        return
    weight = isolator.mass * isolator.gravity if load is None else float(load)
    hold = 0.0
    first, last = law.domain
    if controller.pi_ki > 0.0 and first <= controller.position_setpoint <= last:
        needed = weight - float(law.force(controller.position_setpoint))
        if abs(needed) <= isolator.motor_force_max:
            return  # the PI's integral holds the payload at the setpoint
        hold = float(np.clip(needed, -isolator.motor_force_max, isolator.motor_force_max))
    try:  # a load pulling on the spring (< 0) is a hold the other way: the same net force
        check_equilibrium(law, max(weight, 0.0), (float(stroke[0]), float(stroke[1])),
                          hold=hold - min(weight, 0.0))
    except ParameterError as error:
        carried = "the weight m g" if load is None else "the static load along the leg"
        raise ParameterError(f"`spring`: {error} (the stroke from the stops, {carried}, the "
                             f"hold the PI's integral preload)",
                             ("spring", *error.options)) from None


def _check_type(name, value, kinds):
    if not isinstance(value, kinds):
        names = " or ".join(k.__name__ for k in kinds)
        raise ParameterError(f"`{name}` must be a {names}, got {type(value).__name__}.")


def _initial_state(initial, isolator, controller, p, m, excitation, packed_excitation):
    """State vector and flags at t = 0 (at rest at the setpoint by default).

    The PI's integral (or, without one, a linear controller's integrator) carries the static
    load, worked out with the base at rest, less every other term of the motor's command as
    it stands at the run's own t = 0 (:func:`_at_start`): the motor starts at the static load
    (docs/model.md §5, §5.1).
    """
    s = np.zeros(K.N_STATE)
    s[K.A_MARGIN] = np.nan  # not known yet: the first step works it out
    flags = np.zeros(K.N_FLAGS, dtype=np.int64)
    z0 = controller.position_setpoint if initial.relative_position is None else initial.relative_position
    if not p[K.P_Z_LOW] <= z0 <= p[K.P_Z_HIGH]:
        raise ParameterError(
            f"the initial `relative_position` ({z0!r} m) must lie between the stops "
            f"[{p[K.P_Z_LOW]:g}, {p[K.P_Z_HIGH]:g}] m; move it or the stops (`stop_center`).")
    s[K.S_Z] = z0
    s[K.S_V] = initial.relative_velocity
    yd0 = base_motion_series(excitation, [0.0])[1][0]
    s[K.S_HP] = yd0 + initial.relative_velocity  # the amplifier's high-pass has settled
    model = K.kernel_model(m)  # None on the default path: its kernels only
    measured = _at_start(s, p, model, packed_excitation)[0][K.F_V_MEASURED]
    preload = initial.pi_integral is None
    needed = None
    if not preload:
        s[K.S_INT] = initial.pi_integral
    elif controller.pi_ki > 0 or controller.linear is not None:
        # The static load the motor carries: what the spring and stops do not, nothing more.
        # Evaluated with the base at rest: the base's acceleration at t = 0 is no load the
        # integrator should hold (docs/model.md §5).
        force = K.hold_force(0.0, s, p, model, *_AT_REST)
        without_motor = force[K.F_HOLD] + force[K.F_MOTOR]
        needed = np.clip(without_motor, -isolator.motor_force_max, isolator.motor_force_max)
    if controller.linear is not None:  # its states first: its output at t = 0 is netted below
        _preload_linear(s, p, m, controller, packed_excitation,
                        needed if controller.pi_ki == 0 else None)
    if preload and controller.pi_ki > 0:
        # the rest of the command at the run's own t = 0: the motor starts at `needed`
        f_pi, f_damp = K.controller_output(K.params_tuple(p), z0, measured, 0.0)[:2]
        if controller.has_blocks:
            f_comp, f_dither, f_linear = _blocks_at_start(s, p, m, packed_excitation)
            blocks = f_comp + f_dither + f_linear
            s[K.S_INT] = (needed - f_pi - f_damp - blocks) / controller.pi_ki
        else:
            s[K.S_INT] = (needed - f_pi - f_damp) / controller.pi_ki
    held = K.controller_output(K.params_tuple(p), z0, measured, s[K.S_INT])
    s[K.A_F_PI], s[K.A_F_DAMP], s[K.A_F_MOTOR] = held[:3]
    if controller.has_blocks:
        _hold_blocks(s, p, m, packed_excitation)
    force = K.hold_force(0.0, s, p, model, *packed_excitation)
    f_hold = force[K.F_HOLD]
    locked = initial.locked
    regularised = isolator.friction_regularisation > 0.0
    if locked and regularised:
        raise ParameterError(
            "`locked` must not be True with `friction_regularisation` > 0 "
            f"({isolator.friction_regularisation!r} m/s): the regularised friction model never "
            "locks the payload. Leave `locked` as None or False, or set "
            "`friction_regularisation=0` (exact stick-slip).")
    if locked is None:
        locked = (not regularised and initial.relative_velocity == 0.0
                  and abs(f_hold) <= isolator.stiction_force)
    flags[K.I_MODE] = K.MODE_STICK if locked else K.MODE_SLIP
    if initial.relative_velocity != 0.0:
        flags[K.I_DIRECTION] = 1 if initial.relative_velocity > 0 else -1
    else:
        flags[K.I_DIRECTION] = -1 if f_hold > 0 else 1
    return s, flags


def _at_start(s, p, model, packed_excitation):
    """The forces (``F_*``) and the five sensors (``K.U_*``) at the run's own t = 0.

    State ``s`` on the real base motion, slipping if it starts with a relative velocity
    (``S_V`` != 0, in its direction) else held (the payload's acceleration the base's), each
    block by its law (a sampled one's output at the initial state, not the value it held
    before it: none); the PI's integral as ``s`` holds it.
    """
    laws = p.copy()
    laws[K.P_CONTROL_STEPS] = 0.0
    if s[K.S_V] == 0.0:
        force = K.hold_force(0.0, s, laws, model, *packed_excitation)
    else:
        ex, table = packed_excitation
        force = K.rhs_at(0.0, K.state_tuple(s), K.blocks_tuple(s), np.int64(K.MODE_SLIP),
                         float(np.sign(s[K.S_V])), K.held_tuple(s), K.params_tuple(laws), model,
                         K.excitation_tuple(ex), table)[1]
    sensors = np.array([p[K.P_ZREF] - s[K.S_Z], force[K.F_V_MEASURED], force[K.F_XDD],
                        force[K.F_YDD], s[K.S_V]])
    return force, sensors


def _blocks_at_start(s, p, m, packed_excitation):
    """What the blocks put out at the run's own t = 0 (:func:`_at_start`) [N].

    Returns ``(compensation, dither, linear)``: the compensation with the observer's
    estimate at 0, the dither at t = 0, the linear controller's ``C x0 + D u0`` with its
    states as ``s`` holds them (a continuous one's without the payload's acceleration, which
    it reads through ``B`` only).
    """
    force, sensors = _at_start(s, p, m, packed_excitation)
    f_linear = force[K.F_LINEAR]
    if m[K.M_LINEAR_STEPS] > 0:  # a discrete controller's output at x(0): C x + D u
        f_linear = linear_output(m, s[K.A_X0:K.A_X0 + K.NX_MAX], sensors)
    return force[K.F_COMPENSATION], force[K.F_DITHER], f_linear


def _preload_linear(s, p, m, controller, packed_excitation, needed):
    """A linear controller's state at t = 0: at equilibrium with its sensors' values there.

    ``x0`` solves ``A x0 + B u0 = 0`` (least squares), ``u0`` the sensors at the run's own
    t = 0 (:func:`_at_start`); with the static load ``needed`` [N] (the PI has no integral,
    ``pi_ki = 0``, and its integral is not given; else None), it also carries what the rest
    of the command does not there, ``C x0 + D u0 = needed - F_pi - F_damp - F_comp -
    F_dither``, if its states can (an integrator): the same bumpless preload as the PI's
    (docs/model.md §5.1). Discrete: ``x0 = A x0 + B u0``.
    """
    linear = controller.linear
    n = linear.states
    if n == 0:
        return
    force, sensors = _at_start(s, p, m, packed_excitation)
    load = None
    if needed is not None:
        f_pi, f_damp = K.controller_output(K.params_tuple(p), s[K.S_Z],
                                           force[K.F_V_MEASURED], s[K.S_INT])[:2]
        load = needed - f_pi - f_damp - force[K.F_COMPENSATION] - force[K.F_DITHER]
    s[K.A_X0:K.A_X0 + n] = linear_initial_state(linear, sensors, load,
                                                0.0 if needed is None else needed)


def linear_initial_state(linear, sensors, load=None, needed=0.0):
    """A linear controller's state at t = 0, at equilibrium with its sensors (docs/model.md §5.1).

    ``x0`` solves ``A x0 + B u0 = 0`` (discrete: ``x0 = A x0 + B u0``), least squares; with
    ``load``, also ``C x0 + D u0 = load``, if its states can carry it (an integrator), else
    the equilibrium alone. For every driver: the single axis, each leg of the hexapod.

    Parameters
    ----------
    linear : LinearController
        The controller (at least one state).
    sensors : array_like, shape (5,)
        The five sensors at t = 0 [SI], in the kernels' order (``K.U_*``).
    load : float, optional
        The static load its output should carry besides the PI and damping [N] (the PI has
        no integral); None: none.
    needed : float
        The static load the motor carries [N] (the scale of the tolerance on ``load``).

    Returns
    -------
    ndarray, shape (linear.states,)
    """
    n = linear.states
    a, b, c, d = linear.matrices()
    u0 = np.asarray(sensors)[[list(K_SENSORS).index(name) for name in linear.inputs]]
    system = a - np.eye(n) if linear.discrete else a
    rows, rhs = [system], [-(b @ u0)]
    if load is not None:
        loaded = np.vstack([system, c])
        target = np.concatenate([-(b @ u0), [load - float(d[0] @ u0)]])
        x0 = np.linalg.lstsq(loaded, target, rcond=None)[0]
        if np.allclose(loaded @ x0, target, rtol=1e-9, atol=1e-12 * max(1.0, abs(needed))):
            return x0
    return np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]


def linear_output(m, x, sensors):
    """A linear controller's output ``C x + D u`` [N]: what a discrete one holds at t = 0.

    Parameters
    ----------
    m : ndarray, shape (N_MODEL,)
        The packed blocks (``K.M_*``, :func:`pack_model`).
    x : array_like, shape (NX_MAX,)
        Its states, zero-padded.
    sensors : array_like, shape (5,)
        The five sensors [SI] (``K.U_*``).

    Returns
    -------
    float
        The output [N].
    """
    return (float(np.dot(m[K.M_C:K.M_C + K.NX_MAX], x))
            + float(np.dot(m[K.M_D:K.M_D + K.N_SENSORS], sensors)))


def _hold_blocks(s, p, m, packed_excitation):
    """The held outputs of sampled blocks at t = 0: what they put out at the initial state
    (:func:`_blocks_at_start`, the values the PI's preload netted).

    The kernels sample at step 0 before the first step, so these only matter for the
    first record and the holding force at t = 0; a continuous block's held value is unused.
    """
    f_comp, f_dither, f_linear = _blocks_at_start(s, p, m, packed_excitation)
    s[K.A_F_COMPENSATION] = f_comp
    s[K.A_F_DITHER] = f_dither
    if m[K.M_LINEAR_STEPS] > 0:
        s[K.A_F_LINEAR] = f_linear


@dataclass
class PreparedRun:
    """Everything the kernels need for one run, validated (see :func:`prepare_run`).

    Attributes
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base excitation.
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    params : ndarray, shape (N_PARAMS,)
        The packed parameters of the kernels (:mod:`qzs.engine.kernels` ``P_*``).
    model : ndarray, shape (N_MODEL,)
        The controller's blocks packed for the kernels (``M_*``, :func:`pack_model`).
    packed : tuple
        The excitation's kernel form ``(scalars, table)`` (its ``pack()``).
    state : ndarray, shape (N_STATE,)
        State at t = 0 (``S_*``, then the held controller outputs).
    flags : ndarray of int64, shape (N_FLAGS,)
        Integer flags at t = 0 (``I_*``: stick/slip mode, direction, counters).
    duration : float
        Simulated time [s].
    decimation : int
        Integration steps per output sample.
    solver_code : int
        The integrator's kernel code (:data:`qzs.engine.stability.SOLVERS`).
    dt : float
        Integration step [s].
    sample_rate : float
        Output sample rate [Hz].
    """

    excitation: object
    isolator: IsolatorParameters
    controller: ControllerParameters
    params: np.ndarray
    model: np.ndarray
    packed: tuple
    state: np.ndarray
    flags: np.ndarray
    duration: float
    decimation: int
    solver_code: int
    dt: float
    sample_rate: float


def run_duration(excitation, duration):
    """A run's simulated time [s], checked: the one place it is worked out.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.
    duration : float or None
        The time asked for [s]; None: the excitation's length (required for a sine).

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        No duration for a sine, not a positive finite number, or longer than the excitation.
    """
    if duration is None:
        if excitation.duration is None:
            raise ParameterError("`duration` is required for a sine excitation, got None.",
                                 ("duration",))
        duration = excitation.duration
    duration = positive_real("duration", duration)
    if excitation.duration is not None and duration > excitation.duration * (1 + 1e-12):
        raise ParameterError(
            f"`duration` ({duration!r} s) exceeds the excitation's length "
            f"({excitation.duration!r} s); shorten the run or lengthen the excitation.",
            ("duration",))
    check_record(excitation, duration)
    return duration


#: Memory a random excitation's record takes while it is made, per point of its table
#: [bytes] (the phases, the inverse FFT, the spline's coefficients and the packed table:
#: 157 measured at its peak).
RECORD_BYTES_PER_POINT = 160


def check_record(excitation, duration, name="excitation.duration"):
    """Refuse a random excitation whose record would not fit in memory, before it is made.

    A :class:`~qzs.model.excitation.RandomExcitation` tabulates its whole record
    (:attr:`~qzs.model.excitation.RandomExcitation.record_points`) whatever part of it a run
    uses; one of 1e12 s asks for petabytes. Other excitations hold no record to make.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The run's excitation.
    duration : float
        The run's simulated time [s] (the fix the message gives).
    name : str
        How the caller names the excitation's length (the message's first option).

    Raises
    ------
    ParameterError
        The record would take more than :data:`qzs.engine.driver.MEMORY_SHARE` of the
        memory available; its ``options`` are ``(name, "duration")``.
    """
    from qzs.engine import driver
    from qzs._format import format_bytes
    from qzs.model.excitation import RandomExcitation

    if not isinstance(excitation, RandomExcitation):
        return
    needed = excitation.record_points * RECORD_BYTES_PER_POINT
    available = driver.available_memory()
    if available is None or needed <= driver.MEMORY_SHARE * available:
        return
    raise ParameterError(
        f"`{name}` = {excitation.duration:g} s makes the random excitation's record "
        f"{excitation.record_points:.3g} points (20 a period of its {excitation.f_high:g} Hz), "
        f"{format_bytes(needed)} while it is made, more than half the "
        f"{format_bytes(available)} of memory available; the record need not be longer than "
        f"the run (`duration` = {duration:g} s): give it that length, or one that fits.",
        (name, "duration"))


def prepare_run(excitation=None, isolator=None, controller=None, *, duration=None,
                dt=defaults.SIMULATION["dt"], sample_rate=defaults.SIMULATION["sample_rate"],
                solver=defaults.SIMULATION["solver"], initial_state=None):
    """Validate a run's inputs and pack them for the kernels (shared by single and batch runs).

    Exceptions as in :func:`qzs.simulate`.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    duration : float, optional
        Simulated time [s]; default the excitation's length (required for a sine).
    dt : float
        Integration step [s].
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    initial_state : InitialState, optional
        Default: at rest at the setpoint, stuck if friction can hold the payload.

    Returns
    -------
    PreparedRun
    """
    excitation, isolator, controller = run_inputs(excitation, isolator, controller)
    initial_state = InitialState() if initial_state is None else initial_state
    _check_type("initial_state", initial_state, (InitialState,))
    solver_code, _ = SOLVERS[choice("solver", solver, tuple(SOLVERS))]
    dt = positive_real("dt", dt)
    sample_rate = positive_real("sample_rate", sample_rate)
    duration = run_duration(excitation, duration)
    if dt > duration:
        raise ParameterError(f"`dt` ({dt!r} s) must not exceed `duration` ({duration!r} s).",
                             ("dt", "duration"))
    if not stability_test(isolator, controller, solver)(dt):
        limit = largest_stable_step(isolator, controller, solver)  # only for the message
        mode, remedy = "the hard-stop contact or the spring/PI/damping loop", "`stop_stiffness`"
        if isolator.friction_regularisation > 0:
            mode += ", with the regularised friction's slope Fs/v_reg at v = 0"
            remedy += " or raise `friction_regularisation`"
        raise StabilityError(
            f"`dt` ({dt!r} s) is too large for a stable {solver} integration of this model "
            f"(stiffest mode: {mode}); the largest stable step is {limit:.3g} s. Reduce `dt`, "
            f"or soften {remedy}.")
    check_resolution(excitation, dt, duration)
    decimation = steps_per_sample(sample_rate, dt, "sample_rate")
    control_steps = 0
    if controller.controller_rate > 0:
        control_steps = steps_per_sample(controller.controller_rate, dt, "controller_rate")

    p = _pack_parameters(isolator, controller, dt, control_steps)
    check_spring(isolator, controller, (p[K.P_Z_LOW], p[K.P_Z_HIGH]))
    m = pack_model(isolator, controller, dt)
    packed = excitation.pack()
    s, flags = _initial_state(initial_state, isolator, controller, p, m, excitation, packed)
    return PreparedRun(excitation, isolator, controller, p, m, packed, s, flags, duration,
                       decimation, solver_code, dt, sample_rate)


def table_exit_message(model, z, v, t, who="the payload", at="last position inside"):
    """What a run that left a refusing spring table reports (a SimulationError's message).

    Parameters
    ----------
    model : ndarray
        The packed model row (``K.M_*``) of the table's leg or case.
    z, v : float
        A position [m] and the velocity [m/s] there, as ``at`` describes them.
    t : float
        Time of the failing step [s].
    who : str
        What left the table (``"the payload"``, ``"leg 3"``).
    at : str
        Which position ``z`` is: the last one inside the table (a single axis's last finite
        state), or the one reached outside it (``"reached"``: a platform's leg).

    Returns
    -------
    str
    """
    n = int(model[K.M_SPRING + TABLE_COUNT])
    first = float(model[K.M_SPRING + TABLE_POSITIONS])
    last = float(model[K.M_SPRING + TABLE_POSITIONS + n - 1])
    end = last if v > 0 or z > 0.5 * (first + last) else first
    return (f"the run stopped at t = {t:.6g} s: {who} left the spring table "
            f"[{first:.6g}, {last:.6g}] m past its end at {end:.6g} m ({at} z = {z:.6g} m, "
            f"moving at v = {v:.6g} m/s), and the TabulatedSpring "
            "refuses positions outside it (outside='refuse'); measure the curve over the "
            "whole stroke and a margin for the stops' penetration, or build it with "
            "outside='extend' (linear beyond the ends).")


def divergence_message(state, step, dt, status=K.STATUS_DIVERGED, model=None):
    """What a stopped run reports: the time [s] of the failing step and the last finite state.

    Parameters
    ----------
    state : ndarray, shape (N_STATE,)
        The last finite state.
    step : int
        Index of the failing step.
    dt : float
        Integration step [s].
    status : int
        The kernel's status: ``K.STATUS_DIVERGED``, or ``K.STATUS_OUTSIDE`` (the payload
        left a spring table that refuses positions outside it; ``model`` then needed).
    model : ndarray, optional
        The case's packed model (``K.M_*``), its spring table.

    Returns
    -------
    str
        The message of the :class:`~qzs.errors.SimulationError`.
    """
    if status == K.STATUS_OUTSIDE:
        return table_exit_message(model, float(state[K.S_Z]), float(state[K.S_V]), step * dt)
    controller = ""
    blocks = np.abs(state[K.A_X0:K.A_X0 + K.N_X])
    if np.any(blocks):
        controller = (f", the controller blocks' largest state {np.max(blocks):.6g}; a linear "
                      "controller whose states grow is unstable in the loop: check its poles "
                      "and qzs.loop_margins")
    return (f"the simulation diverged at t = {step * dt:.6g} s (last finite state: relative "
            f"position z = {state[K.S_Z]:.6g} m, relative velocity v = {state[K.S_V]:.6g} m/s, "
            f"PI integral {state[K.S_INT]:.6g} m*s{controller}); check the gains and "
            "parameters, or reduce `dt`.")
