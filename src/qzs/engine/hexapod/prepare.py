"""Validation and packing of a six-axis run: per-leg parameters, excitations, the stability
check, and the kernels' arrays with the preload at home.

Every argument of :func:`~qzs.engine.hexapod.simulate.simulate_hexapod` is checked here
before any integration; the packed arrays follow :mod:`qzs.engine.hexapod.layout`.
"""
from dataclasses import dataclass, replace

import numpy as np

from qzs import defaults
from qzs._validation import choice, known_keys, positive_real
from qzs.engine import driver
from qzs.engine import kernels as K
from qzs.engine.hexapod.dynamics import _advance_phases, _evaluate, _rest_frame
from qzs.engine.hexapod.layout import (
    AXES, LANES, LEG_COUNT, N_ODE, N_ODE_BLOCKS, N_PLAT, N_ROWS, N_WORK, PL_ACTIVE,
    PL_CENTRAL, PL_CKD, PL_CKI, PL_CKP, PL_CONTROL_STEPS, PL_CT, PL_G, PL_HOME, PL_IC, PL_ICINV,
    PL_JINV, PL_MASS, PL_ROTATING, S_C, S_INT, S_Q, S_X, V_A, V_B, V_BX, V_BY, V_BZ, V_CBC, V_CV,
    V_DIR, V_FC, V_FMAX, V_FS, V_HLI, V_HP, V_KD, V_KI, V_KP, V_L, V_LHOME, V_STOPC, V_STOPK,
    V_TX, V_TY, V_TZ, V_YDD, V_ZHIGH, V_ZLOW, V_ZREF)
from qzs.engine.prepare import (check_record, check_spring, linear_initial_state, linear_output,
                                pack_model, stack_models, steps_per_sample)
from qzs.engine.stability import SOLVERS, largest_stable_step, stability_test
from qzs.errors import ParameterError, StabilityError
from qzs.model.controller import ControllerParameters, refuse_blocks
from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine
from qzs.model.hexapod import (CartesianController, HexapodGeometry, PlatformParameters,
                               jacobian, static_leg_forces)
from qzs.model.isolator import IsolatorParameters, other_spring_law, spring_force

__all__ = ["hexapod_stability_test", "check_hexapod_run", "record_option", "has_blocks",
           "has_spring_laws"]

_EXCITATIONS = (Chirp, Sine, RandomExcitation, DisplacementRecord)


def _per_leg(name, value, kind):
    """One parameter object or a sequence of six (one per leg), as a tuple of six."""
    if isinstance(value, kind):
        return (value,) * LEG_COUNT
    if isinstance(value, (list, tuple)) and len(value) == LEG_COUNT \
            and all(isinstance(v, kind) for v in value):
        return tuple(value)
    raise ParameterError(f"`{name}` must be a {kind.__name__} or a sequence of six (one per "
                         f"leg), got {value!r}.")


def has_blocks(controller):
    """Whether a platform's controller has blocks beyond PI + damping on any leg.

    Parameters
    ----------
    controller : ControllerParameters, sequence of six, or None
        As :func:`~qzs.engine.hexapod.simulate.simulate_hexapod` takes it.

    Returns
    -------
    bool
    """
    legs = controller if isinstance(controller, (list, tuple)) else (controller,)
    return any(isinstance(c, ControllerParameters) and c.has_blocks for c in legs)


def has_spring_laws(isolators):
    """Whether a leg's spring is a law other than the MagSpring's tanh.

    Parameters
    ----------
    isolators : sequence of IsolatorParameters
        The six legs.

    Returns
    -------
    bool
    """
    return any(other_spring_law(iso) is not None for iso in isolators)


def _excitations(excitation):
    """The base excitation as ``{axis: excitation}`` of the axes that move."""
    if excitation is None:
        return {}
    if not isinstance(excitation, dict):
        raise ParameterError(
            f"`excitation` must be a dict from axis names {AXES} to excitations (Chirp, Sine, "
            f"RandomExcitation, DisplacementRecord) or None, got {type(excitation).__name__}; "
            "e.g. excitation={'z': Chirp(duration=20.0)}.")
    known_keys(excitation, AXES, "`excitation`", noun="axis name", options=("excitation",),
               fix="the axes are translations [m] and rotation angles [rad]")
    moving = {}
    for axis in AXES:
        value = excitation.get(axis)
        if value is None:
            continue
        if not isinstance(value, _EXCITATIONS):
            raise ParameterError(
                f"`excitation[{axis!r}]` must be a Chirp, Sine, RandomExcitation, "
                f"DisplacementRecord or None, got {type(value).__name__}.")
        moving[axis] = value
    return moving


def record_option(axis):
    """How a platform run's errors name the length of the excitation along ``axis``.

    Parameters
    ----------
    axis : str
        The base axis (``"z"``).

    Returns
    -------
    str
        ``excitation['z'].duration`` (an error's option, for a caller to spell its own way).
    """
    return f"excitation[{axis!r}].duration"


def _static_forces(geometry, platform):
    """The static leg forces of the weight [N]; the minimum-norm ones for redundant legs."""
    try:
        return static_leg_forces(geometry, platform)
    except np.linalg.LinAlgError:  # parallel legs: the geometry class refuses them, a test may not
        from qzs.model.hexapod import jacobian, weight_wrench

        return np.linalg.lstsq(jacobian(geometry).T, weight_wrench(platform), rcond=None)[0]


def hexapod_stability_test(geometry, platform, isolator=None, controller=None,
                           solver=defaults.SIMULATION["solver"]):
    """``stable(dt)``: does a step ``dt`` [s] integrate every leg stably (docs/hexapod.md §9.7)?

    Each leg's stiff modes (its stop contact, its loops) acting on the lightest mass the
    legs move, ``1/max eig(G M^-1 G^T)``, by the single axis's test
    (:func:`qzs.engine.stability.stability_test`); what
    :func:`~qzs.engine.hexapod.simulate.simulate_hexapod` checks.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass and inertia of the moving platform.
    isolator, controller : IsolatorParameters, ControllerParameters or sequences of six
        The legs; defaults if omitted.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.

    Returns
    -------
    callable
        ``stable(dt) -> bool``.
    """
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    mass = _effective_leg_mass(geometry, platform)
    tests = [stability_test(replace(iso, mass=mass), con, solver)
             for iso, con in zip(isolators, controllers)]
    return lambda dt: all(test(dt) for test in tests)


def _stability_limit(geometry, platform, isolators, controllers, solver):
    """The largest stable step [s]: the stiffest leg's on the lightest mass the legs move."""
    mass = _effective_leg_mass(geometry, platform)
    return min(largest_stable_step(replace(i, mass=mass), c, solver)
               for i, c in zip(isolators, controllers))


def _effective_leg_mass(geometry, platform):
    """``1/max eig(G M^-1 G^T)`` [kg]: the lightest mass a leg (or all legs at once) moves."""
    arms = geometry.top_joints - platform.center_of_mass
    vectors = geometry.top_joints + geometry.home_position - geometry.base_joints
    units = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    rows = np.hstack([units, np.cross(arms, units)])
    inverse = np.zeros((6, 6))
    inverse[:3, :3] = np.eye(3) / platform.mass
    inverse[3:, 3:] = np.linalg.inv(platform.inertia)
    return 1.0 / float(np.max(np.linalg.eigvalsh(rows @ inverse @ rows.T)))


def _start_blocks(controllers, models, needed, state, V):
    """Each leg's linear controller at t = 0, as the single axis's (docs/model.md §5.1).

    At equilibrium with the leg's sensors at home, locked (no error, the amplifier settled,
    both accelerometers reading the base joint's acceleration along the leg, row ``YDD``
    of the evaluation at t = 0), carrying the leg's static load ``needed`` [N] when its PI
    has no integral (:func:`qzs.engine.prepare.linear_initial_state`); a discrete one holds
    its output there. Returns each leg's blocks' output at t = 0 [N], shape (6,), which the
    PI's preload nets: the linear controller's ``C x0 + D u0`` (the compensation puts out
    nothing with the payload held, the dither nothing at t = 0).
    """
    outputs = np.zeros(LEG_COUNT)
    for i, (con, m) in enumerate(zip(controllers, models)):
        linear = con.linear
        if linear is None:
            continue
        sensors = np.array([0.0, 0.0, V[V_YDD + i], V[V_YDD + i], 0.0])
        x = state[S_X + i * K.N_X:S_X + i * K.N_X + K.NX_MAX]  # a view: written in place
        if linear.states:
            load = needed[i] if con.pi_ki == 0 else None
            x[:linear.states] = linear_initial_state(linear, sensors, load, needed[i])
        outputs[i] = linear_output(m, x, sensors)
        if linear.discrete:
            V[V_HLI + i] = outputs[i]
    return outputs


@dataclass
class _Prepared:
    geometry: HexapodGeometry
    platform: PlatformParameters
    isolators: tuple
    controllers: tuple
    excitation: dict
    duration: float
    dt: float
    sample_rate: float
    decimation: int
    solver: str
    solver_code: int
    V: np.ndarray
    plat: np.ndarray
    models: np.ndarray | None  # each leg's blocks and spring law, None without (layout.py)
    ex: np.ndarray
    tables: np.ndarray
    toff: np.ndarray
    state: np.ndarray
    cartesian: object = None


def check_hexapod_run(geometry, platform, isolator=None, controller=None, *, excitation=None,
                      duration=None, dt=defaults.SIMULATION["dt"],
                      sample_rate=defaults.SIMULATION["sample_rate"],
                      solver=defaults.SIMULATION["solver"], cartesian=None):
    """Check a six-axis run's arguments as :func:`~qzs.engine.hexapod.simulate.simulate_hexapod`
    does, without integrating (before long work that leads to the run, such as choosing its
    step).

    Parameters
    ----------
    geometry, platform, isolator, controller, excitation, solver, cartesian
        As :func:`~qzs.engine.hexapod.simulate.simulate_hexapod`'s.
    duration : float, optional
        Simulated time [s].
    dt : float
        Integration step [s].
    sample_rate : float
        Output rate [Hz].

    Raises
    ------
    ParameterError
        The first invalid argument, named with its value and the fix (``StabilityError``
        for a step beyond the stable one).
    """
    _prepare(geometry, platform, isolator, controller, excitation, duration, dt, sample_rate,
             solver, False, cartesian)


def _prepare(geometry, platform, isolator, controller, excitation, duration, dt, sample_rate,
             solver, progress, cartesian=None):
    """Validate every argument of :func:`~qzs.engine.hexapod.simulate.simulate_hexapod` and
    pack the kernels' arrays."""
    if not isinstance(geometry, HexapodGeometry):
        raise ParameterError(f"`geometry` must be a HexapodGeometry (e.g. from cubic_geometry or "
                             f"radial_geometry), got {type(geometry).__name__}.")
    if not isinstance(platform, PlatformParameters):
        raise ParameterError(f"`platform` must be a PlatformParameters, got "
                             f"{type(platform).__name__}.")
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    moving = _excitations(excitation)
    solver = choice("solver", solver, tuple(SOLVERS))
    solver_code = SOLVERS[solver][0]
    if not isinstance(progress, (bool, np.bool_)):
        raise ParameterError(f"`progress` must be True or False, got {progress!r}.")
    for leg, (iso, con) in enumerate(zip(isolators, controllers)):
        if iso.stop_model != "compliant":
            raise ParameterError(
                f"leg {leg + 1}: `stop_model` {iso.stop_model!r} is not supported by the hexapod "
                "(its stops are compliant contacts only); use stop_model='compliant'.")
        if getattr(iso, "friction_regularisation", 0.0) != 0.0:
            raise ParameterError(
                f"leg {leg + 1}: `friction_regularisation` ({iso.friction_regularisation!r} m/s) "
                "must be 0: the hexapod integrates the exact stick-slip model only.")
        if con.controller_rate != controllers[0].controller_rate:
            raise ParameterError(
                f"leg {leg + 1}: `controller_rate` ({con.controller_rate!r} Hz) differs from leg "
                f"1's ({controllers[0].controller_rate!r} Hz): the legs' loops run on one "
                "controller, sampled together; give every leg the same rate.")
        if iso.stroke_half != geometry.stroke_half:
            raise ParameterError(
                f"leg {leg + 1}: the isolator's `stroke_half` ({iso.stroke_half!r} m) differs "
                f"from the geometry's ({geometry.stroke_half!r} m); both describe the leg's guide, "
                "give them the same value.")
        center = con.position_setpoint if iso.stop_center is None else iso.stop_center
        if not center - iso.stroke_half <= con.position_setpoint <= center + iso.stroke_half:
            raise ParameterError(
                f"leg {leg + 1}: the `position_setpoint` ({con.position_setpoint!r} m), where the "
                f"leg starts at home, must lie between the stops [{center - iso.stroke_half:g}, "
                f"{center + iso.stroke_half:g}] m; move it or `stop_center`.")
    if duration is None:
        lengths = [e.duration for e in moving.values() if e.duration is not None]
        if not lengths:
            raise ParameterError(
                "`duration` is required when no excitation defines one (a Sine has no length; "
                "without excitation there is none); pass e.g. duration=10.0 [s].")
        duration = min(lengths)
    duration = positive_real("duration", duration)
    for axis, value in moving.items():
        if value.duration is not None and duration > value.duration * (1 + 1e-12):
            raise ParameterError(
                f"`duration` ({duration!r} s) exceeds the length of `excitation[{axis!r}]` "
                f"({value.duration!r} s); shorten the run or lengthen that excitation.")
        check_record(value, duration, name=record_option(axis))
    dt = positive_real("dt", dt)
    sample_rate = positive_real("sample_rate", sample_rate)
    if dt > duration:
        raise ParameterError(f"`dt` ({dt!r} s) must not exceed `duration` ({duration!r} s).")
    decimation = steps_per_sample(sample_rate, dt, "sample_rate")
    driver.plan_run(duration, dt, decimation, kernel="hexapod")  # absurd runs: before any kernel
    control_rate = controllers[0].controller_rate
    control_steps = 0 if control_rate == 0 else steps_per_sample(control_rate, dt,
                                                                 "controller_rate")
    if cartesian is not None and not isinstance(cartesian, CartesianController):
        raise ParameterError(
            f"`cartesian` must be a CartesianController (e.g. CartesianController.from_legs("
            f"geometry, controller)) or None for per-leg loops, got {type(cartesian).__name__}.")
    if cartesian is not None:  # the blocks are each leg's own, added to its own loop
        refuse_blocks(controllers, "centralised control (`cartesian`)",
                      "give the blocks to per-leg loops (cartesian=None)")
    models = []
    for leg, (iso, con) in enumerate(zip(isolators, controllers)):
        try:  # a discrete linear controller's period: a whole number of steps
            models.append(pack_model(iso, con, dt))  # the blocks, then the leg's spring law
        except ParameterError as error:
            raise ParameterError(f"leg {leg + 1}: {error}", error.options) from None
    blocks = has_blocks(controllers)
    laws = has_spring_laws(isolators)
    loads = _static_forces(geometry, platform)
    for leg, (iso, con) in enumerate(zip(isolators, controllers)):
        center = con.position_setpoint if iso.stop_center is None else iso.stop_center
        try:  # a law must hold the leg's static load inside its stroke, as the single axis's
            check_spring(iso, con, (center - iso.stroke_half, center + iso.stroke_half),
                         load=loads[leg])
        except ParameterError as error:
            raise ParameterError(f"leg {leg + 1}: {error}", error.options) from None
    if not hexapod_stability_test(geometry, platform, isolators, controllers, solver)(dt):
        mass = _effective_leg_mass(geometry, platform)
        limit = _stability_limit(geometry, platform, isolators, controllers, solver)
        raise StabilityError(
            f"`dt` ({dt!r} s) is too large for a stable {solver} integration of this hexapod "
            f"(stiffest mode: a leg's stop contact or loop acting on the {mass:.3g} kg the "
            f"legs move at least); the largest stable step is {limit:.3g} s. Reduce `dt`, "
            "or soften `stop_stiffness`.")

    V = np.zeros(N_ROWS * LANES)
    for i, (iso, con) in enumerate(zip(isolators, controllers)):
        center = con.position_setpoint if iso.stop_center is None else iso.stop_center
        values = {V_A: iso.spring_force, V_B: iso.spring_shape, V_FS: iso.stiction_force,
                  V_FC: iso.coulomb_force, V_CBC: iso.stribeck_decay, V_CV: iso.viscous_damping,
                  V_ZLOW: center - iso.stroke_half, V_ZHIGH: center + iso.stroke_half,
                  V_STOPK: iso.stop_stiffness, V_STOPC: iso.stop_damping,
                  V_FMAX: iso.motor_force_max, V_ZREF: con.position_setpoint, V_KP: con.pi_kp,
                  V_KI: con.pi_ki, V_KD: con.damping_gain,
                  V_HP: 2 * np.pi * con.velocity_highpass, V_DIR: 1.0}
        base = geometry.base_joints[i] - geometry.home_position
        top = geometry.top_joints[i] - platform.center_of_mass
        values.update({V_BX: base[0], V_BY: base[1], V_BZ: base[2], V_TX: top[0], V_TY: top[1],
                       V_TZ: top[2]})
        for offset, value in values.items():
            V[offset + i] = value
    rows = V.reshape(N_ROWS, LANES)
    rows[:, LEG_COUNT:] = rows[:, :1]  # the padding lanes copy leg 1
    plat = np.zeros(N_PLAT)
    plat[PL_MASS], plat[PL_G] = platform.mass, platform.gravity
    plat[PL_CT:PL_CT + 3] = platform.center_of_mass
    plat[PL_IC:PL_IC + 9] = np.asarray(platform.inertia).ravel()
    plat[PL_ICINV:PL_ICINV + 9] = np.linalg.inv(platform.inertia).ravel()
    plat[PL_HOME:PL_HOME + 3] = geometry.home_position
    plat[PL_CONTROL_STEPS] = control_steps
    if cartesian is not None:
        point = cartesian.point_in_top_frame(platform)
        inverse = np.linalg.inv(jacobian(geometry, point=point))
        plat[PL_CENTRAL] = 1.0
        plat[PL_JINV:PL_JINV + 36] = inverse.ravel()
        plat[PL_CKP:PL_CKP + 6] = cartesian.position_gain
        plat[PL_CKI:PL_CKI + 6] = cartesian.integral_gain
        plat[PL_CKD:PL_CKD + 6] = cartesian.damping_gain
    ex = np.zeros((6, 8))
    pieces, offsets = [], [0]
    for a, axis in enumerate(AXES):
        if axis in moving:
            scalars, table = moving[axis].pack()
            ex[a] = scalars
            plat[PL_ACTIVE + a] = 1.0
            pieces.append(np.asarray(table, dtype=float))
        else:
            pieces.append(np.zeros((5, 2)))
        offsets.append(offsets[-1] + pieces[-1].shape[1])
    plat[PL_ROTATING] = float(any(axis in moving for axis in AXES[3:]))
    tables = np.ascontiguousarray(np.concatenate(pieces, axis=1))
    toff = np.asarray(offsets, dtype=np.int64)
    # each leg's blocks and spring law, or None: the kernels compile their code only for a
    # run with blocks or a law other than the tanh (layout.py: models)
    packed = stack_models(models) if blocks or laws else None

    state = np.zeros(N_ODE_BLOCKS if blocks else N_ODE)
    state[S_C:S_C + 3] = platform.center_of_mass  # at home: c = o + R_r c_t, o = 0, R_r = I
    state[S_Q] = 1.0
    ww = np.zeros(N_WORK)
    _rest_frame(ww)
    if blocks:  # the base's motion at t = 0, for the legs' base accelerometers (row YDD)
        _advance_phases(0.0, True, plat, ex, ww)
    _evaluate(0.0, state, plat, packed, ex, tables, toff, ww, V, np.zeros((6, 6)),
              np.zeros(LEG_COUNT, dtype=np.int64), np.zeros((2, LEG_COUNT)),
              np.zeros(state.size), False)
    # the kernels' own arithmetic: z = z_ref exactly at home
    V[V_LHOME:V_LHOME + LANES] = V[V_L:V_L + LANES]
    # PI preload (docs/model.md §5 for each leg): the motor carries the static leg load the
    # spring does not (stops untouched at the setpoint), the base at rest, less the blocks'
    # output at t = 0 (the linear controller's states first); P and D put out nothing at home.
    needed = np.zeros(LEG_COUNT)
    for i, (iso, con) in enumerate(zip(isolators, controllers)):
        spring = spring_force(con.position_setpoint, iso)
        needed[i] = np.clip(loads[i] - spring, -iso.motor_force_max, iso.motor_force_max)
    started = np.zeros(LEG_COUNT)
    if blocks:  # refused with centralised control
        started = _start_blocks(controllers, models, needed, state, V)
    for i, con in enumerate(controllers):
        if cartesian is None and con.pi_ki > 0:
            state[S_INT + i] = (needed[i] - started[i]) / con.pi_ki
    if cartesian is not None:  # the same leg forces from the axes' integrals, J^-T Ki I = f
        wrench = jacobian(geometry, point=cartesian.point_in_top_frame(platform)).T @ needed
        held = cartesian.integral_gain > 0
        state[S_INT:S_INT + LEG_COUNT][held] = wrench[held] / cartesian.integral_gain[held]
    return _Prepared(geometry, platform, isolators, controllers, moving, duration, dt,
                     sample_rate, decimation, solver, solver_code, V, plat, packed, ex, tables,
                     toff, state, cartesian)
