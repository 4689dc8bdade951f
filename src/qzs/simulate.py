"""Fixed-step simulation of the isolator: validated entry point around the kernels.

>>> from qzs import simulate, Chirp
>>> result = simulate(Chirp(duration=20.0, f1=5.0), dt=1e-4, sample_rate=500.0)
>>> result.summary()  # doctest: +SKIP
"""
import time as _time
from dataclasses import dataclass

import numpy as np

from qzs import _kernels as K
from qzs import _lanes
from qzs._validation import as_float, choice, positive
from qzs.control import ControllerParameters
from qzs.errors import ParameterError, SimulationError, StabilityError
from qzs.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine, base_motion_series
from qzs.model import InitialState, IsolatorParameters
from qzs.results import SimulationResult

__all__ = ["simulate", "prepare_run", "largest_stable_step", "SOLVERS"]

#: Fixed-step integrators and their orders of accuracy.
SOLVERS = {"euler": (K.SOLVER_EULER, 1), "ode3": (K.SOLVER_ODE3, 3), "rk4": (K.SOLVER_RK4, 4)}
_STABILITY_POLYNOMIALS = {  # |R(h*lambda)| <= 1 is linear stability (Taylor coefficients)
    "euler": [1, 1], "ode3": [1, 1, 1 / 2, 1 / 6], "rk4": [1, 1, 1 / 2, 1 / 6, 1 / 24]}
_EXCITATIONS = (Chirp, Sine, RandomExcitation, DisplacementRecord)
_CHUNK_SECONDS = 0.25  # aim for progress updates (and Ctrl-C checks) about 4 times a second


def _stiff_modes(isolator, controller):
    """Eigenvalues [1/s] of the fastest linear modes: free, and pressed on a compliant stop."""
    m = isolator.mass
    stiffness = isolator.spring_force * isolator.spring_shape + controller.pi_kp
    damping = isolator.viscous_damping + controller.damping_gain
    cases = [(stiffness, damping)]
    if isolator.stop_model == "compliant":
        cases.append((stiffness + isolator.stop_stiffness, damping + isolator.stop_damping))
    eigenvalues = [-2 * np.pi * controller.velocity_highpass]
    for k, c in cases:
        eigenvalues.extend(np.roots([m, c, k]))
    return np.asarray(eigenvalues, dtype=complex)


def _stability_test(isolator, controller, solver):
    """``stable(h)``: does a step ``h`` [s] keep every stiff mode's growth below 0.1 %/s?"""
    choice("solver", solver, tuple(SOLVERS))
    coefficients = np.array(_STABILITY_POLYNOMIALS[solver][::-1])
    eigenvalues = _stiff_modes(isolator, controller)

    def stable(h):
        growth = np.log(np.abs(np.polyval(coefficients, h * eigenvalues)))
        return bool(np.all(growth <= 1e-3 * h))

    return stable


def largest_stable_step(isolator=None, controller=None, solver="ode3"):
    """Largest time step [s] for which the explicit integrator stays stable.

    Linear stability of the stiffest modes (the payload on its spring, PI gain
    and dampers, and pressed against a compliant hard stop): the step ``h``
    must keep the solver's amplification ``|R(h*lambda)|`` from growing faster
    than 0.1 % per second for every eigenvalue ``lambda``.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
    controller : ControllerParameters, optional
    solver : {"ode3", "rk4", "euler"}

    Returns
    -------
    float
        The largest stable step [s].
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    stable = _stability_test(isolator, controller, solver)
    low, high = 0.0, 1.0
    while stable(high) and high < 1e3:
        low, high = high, high * 2
    if stable(high):
        return float(high)
    for _ in range(200):  # bisection on a log scale to relative precision ~1e-6
        mid = np.sqrt(low * high) if low > 0 else high / 2
        if stable(mid):
            low = mid
        else:
            high = mid
        if low > 0 and high / low < 1 + 1e-6:
            break
    return float(low)


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
    return p


def _steps_per(rate, dt, name):
    """Integer number of grid steps per period of ``rate`` [Hz], or a clear error."""
    ratio = 1.0 / (rate * dt)
    steps = int(round(ratio))
    if steps < 1 or abs(ratio - steps) > 1e-6 * ratio:
        hint = 1.0 / (max(steps, 1) * dt)
        raise ParameterError(
            f"`{name}` ({rate!r} Hz) must divide the integration rate 1/dt = {1 / dt:g} Hz into "
            f"a whole number of steps; got {ratio:g} steps. Use e.g. {name}={hint:g}.")
    return steps


def _initial_state(initial, isolator, controller, p, excitation, packed_excitation):
    """State vector and flags at t = 0 (at rest at the setpoint by default)."""
    s = np.zeros(K.N_STATE)
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
    force = K.hold_force(0.0, s, p, *packed_excitation)
    if initial.pi_integral is not None:
        s[K.S_INT] = initial.pi_integral
    elif controller.pi_ki > 0:  # preload: the motor carries what the spring and stops do not
        without_motor = force[K.F_HOLD] + force[K.F_MOTOR]
        needed = np.clip(without_motor, -isolator.motor_force_max, isolator.motor_force_max)
        f_pi, f_damp = K.controller_output(K.params_tuple(p), z0, force[K.F_V_MEASURED], 0.0)[:2]
        s[K.S_INT] = (needed - f_pi - f_damp) / controller.pi_ki
    held = K.controller_output(K.params_tuple(p), z0, force[K.F_V_MEASURED], s[K.S_INT])
    s[K.A_F_PI], s[K.A_F_DAMP], s[K.A_F_MOTOR] = held[:3]
    force = K.hold_force(0.0, s, p, *packed_excitation)
    f_hold = force[K.F_HOLD]
    locked = initial.locked
    if locked is None:
        locked = initial.relative_velocity == 0.0 and abs(f_hold) <= isolator.stiction_force
    flags[K.I_MODE] = K.MODE_STICK if locked else K.MODE_SLIP
    if initial.relative_velocity != 0.0:
        flags[K.I_DIRECTION] = 1 if initial.relative_velocity > 0 else -1
    else:
        flags[K.I_DIRECTION] = -1 if f_hold > 0 else 1
    return s, flags


@dataclass
class PreparedRun:
    """Everything the kernels need for one run, validated (see :func:`prepare_run`)."""

    excitation: object
    isolator: IsolatorParameters
    controller: ControllerParameters
    params: np.ndarray
    packed: tuple
    state: np.ndarray
    flags: np.ndarray
    duration: float
    decimation: int
    solver_code: int
    dt: float
    sample_rate: float


def prepare_run(excitation=None, isolator=None, controller=None, *, duration=None, dt=1e-4,
                sample_rate=1000.0, solver="ode3", initial_state=None):
    """Validate a run's inputs and pack them for the kernels (shared by single and batch runs).

    Parameters and exceptions as in :func:`simulate`.

    Returns
    -------
    PreparedRun
    """
    excitation = Chirp() if excitation is None else excitation
    isolator = IsolatorParameters() if isolator is None else isolator
    controller = ControllerParameters() if controller is None else controller
    initial_state = InitialState() if initial_state is None else initial_state
    for name, value, kinds in (("excitation", excitation, _EXCITATIONS),
                               ("isolator", isolator, (IsolatorParameters,)),
                               ("controller", controller, (ControllerParameters,)),
                               ("initial_state", initial_state, (InitialState,))):
        if not isinstance(value, kinds):
            names = " or ".join(k.__name__ for k in kinds)
            raise ParameterError(f"`{name}` must be a {names}, got {type(value).__name__}.")
    solver_code, _ = SOLVERS[choice("solver", solver, tuple(SOLVERS))]
    dt = positive("dt", dt)
    sample_rate = positive("sample_rate", sample_rate)
    if duration is None:
        if excitation.duration is None:
            raise ParameterError("`duration` is required for a sine excitation, got None.")
        duration = excitation.duration
    duration = positive("duration", duration)
    if excitation.duration is not None and duration > excitation.duration * (1 + 1e-12):
        raise ParameterError(
            f"`duration` ({duration!r} s) exceeds the excitation's length "
            f"({excitation.duration!r} s); shorten the run or lengthen the excitation.")
    if dt > duration:
        raise ParameterError(f"`dt` ({dt!r} s) must not exceed `duration` ({duration!r} s).")
    if not _stability_test(isolator, controller, solver)(dt):
        limit = largest_stable_step(isolator, controller, solver)  # only for the message
        raise StabilityError(
            f"`dt` ({dt!r} s) is too large for a stable {solver} integration of this model "
            f"(stiffest mode: the hard-stop contact or the spring/PI/damping loop); the largest "
            f"stable step is {limit:.3g} s. Reduce `dt`, or soften `stop_stiffness`.")
    decimation = _steps_per(sample_rate, dt, "sample_rate")
    control_steps = 0
    if controller.controller_rate > 0:
        control_steps = _steps_per(controller.controller_rate, dt, "controller_rate")

    p = _pack_parameters(isolator, controller, dt, control_steps)
    packed = excitation.pack()
    s, flags = _initial_state(initial_state, isolator, controller, p, excitation, packed)
    return PreparedRun(excitation, isolator, controller, p, packed, s, flags, duration,
                       decimation, solver_code, dt, sample_rate)


def simulate(excitation=None, isolator=None, controller=None, *, duration=None, dt=1e-4,
             sample_rate=1000.0, solver="ode3", initial_state=None, progress=False,
             interruptible=False):
    """Simulate the isolator under a base excitation with a fixed-step integrator.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's 10 mm, 0-20 Hz, 2000 s chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; MODEL.md defaults if omitted.
    duration : float, optional
        Simulated time [s]; default the excitation's length (required for a sine).
    dt : float
        Integration step [s]; default 1e-4 (the paper's 2e7 steps for 2000 s).
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it. Output
        is decimated while integrating, so memory grows with the output only.
    solver : {"ode3", "rk4", "euler"}
        Bogacki-Shampine 3rd order (Simulink ode3, default), classic RK4, or explicit Euler.
    initial_state : InitialState, optional
        Default: at rest at the setpoint, stuck if friction can hold the payload.
    progress : bool
        Show a progress bar.
    interruptible : bool
        If True, Ctrl-C ends the run early and returns what was simulated
        (``result.completed`` is False) instead of raising ``KeyboardInterrupt``.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ParameterError
        Invalid argument; ``StabilityError`` if ``dt`` exceeds the largest stable step.
    SimulationError
        The state diverged or became non-finite (the message names time and state).
    """
    run = prepare_run(excitation, isolator, controller, duration=duration, dt=dt,
                      sample_rate=sample_rate, solver=solver, initial_state=initial_state)
    excitation, isolator, controller = run.excitation, run.isolator, run.controller
    p, packed, s, flags = run.params, run.packed, run.state, run.flags
    duration, decimation, solver_code = run.duration, run.decimation, run.solver_code
    dt, sample_rate = run.dt, run.sample_rate
    n_steps = int(round(duration / dt))
    n_out = n_steps // decimation + 1
    out = np.empty((n_out, K.N_CHANNELS))
    out_flags = np.zeros((n_out, 2), dtype=np.bool_)
    K.evaluate(0.0, s, flags, p, *packed, out[0], out_flags[0])

    rows, done, completed = 1, 0, True
    chunk = max(decimation, int(2e6 // decimation) * decimation)
    bar = _progress_bar(n_steps, progress)
    start = _time.perf_counter()
    try:
        while done < n_steps:
            n = min(chunk, n_steps - done)
            status, written = _lanes.run_single(solver_code, n, decimation, s, flags, p, *packed,
                                                out, out_flags, rows)
            rows += written
            if status != K.STATUS_OK:
                _raise_diverged(s, flags, p)
            done += n
            if bar is not None:
                bar.update(n)
    except KeyboardInterrupt:
        if not interruptible:
            raise
        completed = False
        done = int(flags[K.I_STEP])
    finally:
        if bar is not None:
            bar.close()
    elapsed = _time.perf_counter() - start
    run = dict(solver=solver, dt=dt, sample_rate=sample_rate, duration=duration,
               steps=int(flags[K.I_STEP]), elapsed=elapsed, completed=completed,
               stop_contacts=int(flags[K.I_N_CONTACTS]), stick_events=int(flags[K.I_N_STICKS]),
               stop_low=float(p[K.P_Z_LOW]), stop_high=float(p[K.P_Z_HIGH]))
    return SimulationResult(out[:rows], out_flags[:rows], isolator=isolator,
                            controller=controller, excitation=excitation, run=run)


def _progress_bar(total, enabled):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, unit="step", unit_scale=True, desc="simulating", leave=False)


def divergence_message(state, step, dt):
    """What a diverged run reports: the time [s] of the failing step and the last finite state."""
    return (f"the simulation diverged at t = {step * dt:.6g} s (last finite state: relative "
            f"position z = {state[K.S_Z]:.6g} m, relative velocity v = {state[K.S_V]:.6g} m/s, "
            f"PI integral {state[K.S_INT]:.6g} m*s); check the gains and parameters, or reduce "
            "`dt`.")


def _raise_diverged(s, flags, p):
    raise SimulationError(divergence_message(s, flags[K.I_STEP], p[K.P_DT]))
