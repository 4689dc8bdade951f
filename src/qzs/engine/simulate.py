"""Fixed-step simulation of the isolator: :func:`simulate`, a run resolved then integrated.

>>> from qzs import simulate, Chirp
>>> result = simulate(Chirp(duration=20.0, f1=5.0), dt=1e-4, sample_rate=500.0)
>>> result.summary()  # doctest: +SKIP
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from qzs import defaults

if TYPE_CHECKING:
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.engine.result import SimulationResult
    from qzs.model.isolator import InitialState, IsolatorParameters

__all__ = ["simulate"]


def simulate(excitation: Excitation | None = None, isolator: IsolatorParameters | None = None,
             controller: ControllerParameters | None = None, *, duration: float | None = None,
             dt: float | None = None, tolerance: float | None = None,
             tolerance_state: float | None = None,
             sample_rate: float = defaults.SIMULATION["sample_rate"],
             solver: str = defaults.SIMULATION["solver"],
             initial_state: InitialState | None = None, progress: bool = False,
             interruptible: bool = False,
             sink: Callable[[Any, Any], Any] | None = None) -> SimulationResult:
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
    dt : float, optional
        A literal integration step [s] (the paper's: 1e-4, its 2e7 steps for 2000 s).
    tolerance : float, optional
        Choose the largest step whose transmissibility stays within this many [dB] of a
        finer one over the band the run covers (docs/model.md §7).
    tolerance_state : float, optional
        Choose the largest step whose relative position stays within this many [m] of a
        finer one. Give at most one of ``dt``, ``tolerance`` and ``tolerance_state``; given
        none, the paper's literal ``dt`` = 1e-4 s (``qzs simulate`` and the page choose
        the step for ``qzs.defaults.ACCURACY`` instead: ``tolerance=0.01`` here gives their
        step and numbers; :func:`qzs.engine.run_spec.resolve`); ``result.step`` says how.
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
    sink : callable, optional
        ``sink(data, flags)`` receives every output sample, chunk by chunk, in time order
        (``data`` of shape (n, N_CHANNELS) in the columns of
        :data:`~qzs.engine.channels.CHANNELS`, ``flags`` of shape (n, 2); both are reused
        buffers: consume or copy them). The result then keeps every sample if there are
        at most :data:`PREVIEW_SAMPLES`, else a preview for figures: per group of k
        consecutive samples (``result.run["preview_every"]``) one row of each channel's
        minimum and one of its maximum (the flags' all and any), so memory stays bounded
        however long the run and a plot shows the true envelope, never an aliased pick
        (:class:`qzs.engine.result_file.ResultWriter` is such a sink). The summary's
        statistics always come from every sample.

    Returns
    -------
    SimulationResult

    Raises
    ------
    ParameterError
        Invalid argument; ``StabilityError`` if ``dt`` exceeds the largest stable step;
        ``ResultTooLargeError`` if, without a ``sink``, the result would not fit in memory.
    SimulationError
        The state diverged or became non-finite (the message names time and state).
    """
    from qzs.engine.run_spec import resolve

    resolved = resolve(excitation, isolator, controller, duration=duration, dt=dt,
                       tolerance=tolerance, tolerance_state=tolerance_state,
                       sample_rate=sample_rate, solver=solver, initial_state=initial_state,
                       progress=progress)
    return resolved.simulate(progress=progress, interruptible=interruptible, sink=sink)
