"""One single-axis run integrated at a given step: the engine's single run.

:func:`integrate` packs the run (:func:`~qzs.engine.prepare.prepare_run`), drives the kernel
(:class:`SingleAxis` under :mod:`qzs.engine.driver`) and gathers the result; :func:`qzs.simulate`
resolves the step first (:func:`qzs.engine.run_spec.resolve`) and integrates here.
"""
from __future__ import annotations

from qzs import defaults
from qzs.engine import driver
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.prepare import divergence_message, prepare_run
from qzs.engine.channels import channel_count, named_block, summary_statistics
from qzs.engine.result import SimulationResult
from qzs.errors import SimulationError

__all__ = ["integrate", "result_bytes", "SingleAxis"]

#: The flags of an output row (``locked``, ``contact``), one byte each in memory.
_FLAG_COUNT = 2


def integrate(excitation=None, isolator=None, controller=None, *, duration=None,
              dt=defaults.SIMULATION["dt"], sample_rate=defaults.SIMULATION["sample_rate"],
              solver=defaults.SIMULATION["solver"], initial_state=None, progress=False,
              interruptible=False, sink=None, step=None):
    """Integrate one single-axis run at a given step: the one single-axis run of the engine.

    :func:`qzs.simulate` resolves a run (:func:`qzs.engine.run_spec.resolve`) and integrates
    it here; the step search's probes integrate here too.

    Parameters
    ----------
    excitation, isolator, controller, solver, initial_state
        As for :func:`qzs.simulate`.
    duration : float, optional
        Simulated time [s]; default the excitation's length.
    dt : float
        The integration step [s].
    sample_rate : float
        Output rate [Hz].
    progress : bool
        Show a progress bar.
    interruptible : bool
        Ctrl-C ends the run early and returns what was simulated.
    sink : callable, optional
        As for :func:`qzs.simulate`.
    step : StepChoice, optional
        How ``dt`` was chosen (:mod:`qzs.engine.step_search`); default: given literally.

    Returns
    -------
    SimulationResult
        Its ``run`` holds the step record's entries (``step*``,
        :meth:`~qzs.engine.step_search.StepChoice.attributes`) and its ``step`` the record.
    """
    from qzs.engine.step_search import StepChoice

    run = prepare_run(excitation, isolator, controller, duration=duration, dt=dt,
                      sample_rate=sample_rate, solver=solver, initial_state=initial_state)
    if step is None:
        step = StepChoice.literal(run.dt, sample_rate=run.sample_rate, solver=solver)
    plan = driver.plan_run(run.duration, run.dt, run.decimation)
    p = run.params
    statistics = summary_statistics(run.controller, 0.5 * (p[K.P_Z_LOW] + p[K.P_Z_HIGH]),
                                    run.isolator.motor_force_max)
    recorder = driver.Recorder(plan, channel_count(run.controller), _FLAG_COUNT, sink=sink,
                               statistics=lambda data, flags: statistics.add(
                                   named_block(data, flags)),
                               duration=run.duration, sample_rate=run.sample_rate)
    stepper = SingleAxis(run, recorder.buffers)
    data, marks = recorder.buffers[0]
    K.evaluate(0.0, run.state, run.flags, p, K.kernel_model(run.model), *run.packed, data[0],
               marks[0])
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
    info.update(step.attributes())
    data, data_flags = recorder.result()
    result = SimulationResult(data, data_flags, isolator=run.isolator, controller=run.controller,
                              excitation=run.excitation, run=info, statistics=statistics.result())
    result.step = step
    return result


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
        self.status = K.STATUS_OK

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
        kernel = _lanes.single_kernel(run.model)
        status, written = kernel(run.solver_code, steps, run.decimation, run.state, run.flags,
                                 run.params, run.model, *run.packed, data, marks, row0)
        self.diverged = status != K.STATUS_OK
        self.status = status
        return written

    def divergence(self):
        """The :class:`~qzs.errors.SimulationError` of a diverged run (time and last state)."""
        run = self.run
        return SimulationError(divergence_message(run.state, run.flags[K.I_STEP],
                                                  run.params[K.P_DT], self.status, run.model))


def result_bytes(duration, sample_rate, controller=None):
    """Memory [bytes] a run's result takes: every channel and flag at every output sample.

    A float64 per channel (:func:`~qzs.engine.channels.channel_count`: the blocks' forces
    only with blocks) and a bool per flag.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    sample_rate : float
        Output sample rate [Hz].
    controller : ControllerParameters, optional
        The run's controller; default one without blocks.

    Returns
    -------
    int
    """
    samples = int(round(duration * sample_rate)) + 1
    return int(samples * (8 * channel_count(controller) + _FLAG_COUNT))
