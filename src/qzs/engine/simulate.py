"""Fixed-step simulation of the isolator: validated entry point around the kernels.

>>> from qzs import simulate, Chirp
>>> result = simulate(Chirp(duration=20.0, f1=5.0), dt=1e-4, sample_rate=500.0)
>>> result.summary()  # doctest: +SKIP
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from qzs import defaults
from qzs.analysis.statistics import SummaryStatistics
from qzs.engine import driver
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.prepare import divergence_message, prepare_run
from qzs.engine.result import SimulationResult
from qzs.engine.channels import named_block
from qzs.errors import SimulationError

if TYPE_CHECKING:
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import InitialState, IsolatorParameters

__all__ = ["simulate", "result_bytes", "SingleAxis"]

#: Bytes one output sample takes in memory: every channel as float64, the flags as bool.
BYTES_PER_SAMPLE = 8 * K.N_CHANNELS + 2


def simulate(excitation: Excitation | None = None, isolator: IsolatorParameters | None = None,
             controller: ControllerParameters | None = None, *, duration: float | None = None,
             dt: float = defaults.SIMULATION["dt"],
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
    run = prepare_run(excitation, isolator, controller, duration=duration, dt=dt,
                      sample_rate=sample_rate, solver=solver, initial_state=initial_state)
    plan = driver.plan_run(run.duration, run.dt, run.decimation)
    p = run.params
    statistics = SummaryStatistics(0.5 * (p[K.P_Z_LOW] + p[K.P_Z_HIGH]),
                                   run.isolator.motor_force_max)
    recorder = driver.Recorder(plan, K.N_CHANNELS, 2, sink=sink,
                               statistics=lambda data, flags: statistics.add(
                                   named_block(data, flags)),
                               duration=run.duration, sample_rate=run.sample_rate)
    stepper = SingleAxis(run, recorder.buffers)
    data, marks = recorder.buffers[0]
    K.evaluate(0.0, run.state, run.flags, p, *run.packed, data[0], marks[0])
    recorder.absorb(0, 0, 1)
    outcome = driver.drive(stepper, plan, recorder, progress="simulating" if progress else None,
                           interruptible=interruptible)
    flags = run.flags
    info = dict(solver=solver, dt=run.dt, sample_rate=run.sample_rate,
                duration=run.duration, steps=int(flags[K.I_STEP]), elapsed=outcome.elapsed,
                completed=outcome.completed, stop_contacts=int(flags[K.I_N_CONTACTS]),
                stick_events=int(flags[K.I_N_STICKS]), stop_low=float(p[K.P_Z_LOW]),
                stop_high=float(p[K.P_Z_HIGH]), samples=recorder.rows,
                preview_every=recorder.every)
    data, data_flags = recorder.result()
    return SimulationResult(data, data_flags, isolator=run.isolator, controller=run.controller,
                            excitation=run.excitation, run=info, statistics=statistics.result())


class SingleAxis(driver.Stepper):
    """The single-axis kernel (:func:`qzs.engine.lanes.run_single`) as the driver's stepper.

    Parameters
    ----------
    run : PreparedRun
        The packed run (:func:`qzs.engine.prepare.prepare_run`); its ``state`` and ``flags``
        carry the run between calls.
    buffers : list of (ndarray, ndarray)
        The output buffers ``(data, flags)`` the kernel writes, by index.
    """

    def __init__(self, run, buffers):
        self.run = run
        self.buffers = buffers
        self.diverged = False

    def advance(self, steps, buffer, row0):
        """Advance the kernel, recording the samples that fall in the steps.

        Parameters
        ----------
        steps : int
            Integration steps [-].
        buffer : int
            Index of the buffer the kernel writes.
        row0 : int
            First row to write.

        Returns
        -------
        int
            Rows written [-].
        """
        run = self.run
        data, marks = self.buffers[buffer]
        status, written = _lanes.run_single(run.solver_code, steps, run.decimation, run.state,
                                            run.flags, run.params, *run.packed, data, marks,
                                            row0)
        self.diverged = status != K.STATUS_OK
        return written

    def divergence(self):
        """The :class:`~qzs.errors.SimulationError` of a diverged run (time and last state)."""
        run = self.run
        return SimulationError(divergence_message(run.state, run.flags[K.I_STEP],
                                                  run.params[K.P_DT]))


def result_bytes(duration, sample_rate):
    """Memory [bytes] a run's result takes: every channel and flag at every output sample.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    sample_rate : float
        Output sample rate [Hz].

    Returns
    -------
    int
    """
    return int((int(round(duration * sample_rate)) + 1) * BYTES_PER_SAMPLE)
