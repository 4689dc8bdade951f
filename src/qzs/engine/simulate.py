"""Fixed-step simulation of the isolator: validated entry point around the kernels.

>>> from qzs import simulate, Chirp
>>> result = simulate(Chirp(duration=20.0, f1=5.0), dt=1e-4, sample_rate=500.0)
>>> result.summary()  # doctest: +SKIP
"""
import time as _time

import numpy as np

from qzs import defaults
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.prepare import divergence_message, prepare_run
from qzs.engine.results import SimulationResult
from qzs.errors import SimulationError

__all__ = ["simulate"]


def simulate(excitation=None, isolator=None, controller=None, *, duration=None,
             dt=defaults.SIMULATION["dt"], sample_rate=defaults.SIMULATION["sample_rate"],
             solver=defaults.SIMULATION["solver"], initial_state=None, progress=False,
             interruptible=False):
    """Simulate the isolator under a base excitation with a fixed-step integrator.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's 10 mm, 0-20 Hz, 2000 s chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults of docs/model.md §11 if omitted.
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


def _raise_diverged(s, flags, p):
    raise SimulationError(divergence_message(s, flags[K.I_STEP], p[K.P_DT]))
