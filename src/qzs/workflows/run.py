"""One run written to a file as it is simulated: memory bounded by the chunk, not the duration.

>>> from qzs import Chirp
>>> from qzs.workflows.run import simulate_to_file
>>> result = simulate_to_file("run.nc", Chirp(duration=100.0, f1=5.0))  # doctest: +SKIP
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from qzs import defaults
from qzs.engine.result_file import ResultWriter, estimated_size
from qzs.engine.run_spec import ResolvedRun, resolve
from qzs.iotools.files import RESULT_SUFFIXES as _FORMATS
from qzs.iotools.paths import check_output_path

if TYPE_CHECKING:
    from qzs.engine.result import SimulationResult
    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import InitialState, IsolatorParameters

__all__ = ["simulate_to_file", "resolve_apart", "RESULT_SUFFIXES"]

#: File formats a run can be written to, by extension.
RESULT_SUFFIXES = tuple(_FORMATS)


def _resolve_job(arguments):
    """The forked helper's job: :func:`resolve` of ``(args, kwargs)``."""
    args, kwargs = arguments
    return resolve(*args, **kwargs)


def resolve_apart(*args: Any, **kwargs: Any) -> ResolvedRun:
    """:func:`qzs.engine.run_spec.resolve`, its step choice run by a forked helper.

    Choosing a step probes the run and estimates spectra: scipy.signal and the probe's
    samples, about 50 MB that a process keeps to its end (a module is never unloaded). A
    streamed run (:func:`simulate_to_file`, ``qzs simulate --out``) keeps its memory to its
    chunk buffers and preview (docs/model.md §8) by resolving in a copy of this process
    (:mod:`qzs.workflows.forked`), which ends with the choice; the answer (the
    :class:`~qzs.engine.run_spec.ResolvedRun` and the step cache entry) is the same. Resolved
    here instead when nothing is to choose (a literal ``dt``, or ``step="literal"`` with no
    tolerance), when no helper can fork, or when the run's kernels are still to compile (its
    compile notice and the compiled kernels belong to this process).

    Parameters
    ----------
    *args, **kwargs
        As :func:`~qzs.engine.run_spec.resolve` takes them.

    Returns
    -------
    ResolvedRun

    Raises
    ------
    ParameterError
        As :func:`~qzs.engine.run_spec.resolve` raises it (the helper's error raised here).
    """
    from qzs.engine.compiling import cold_kernels
    from qzs.workflows import forked

    literal = kwargs.get("dt") is not None or (
        kwargs.get("step", "literal") == "literal" and kwargs.get("tolerance") is None
        and kwargs.get("tolerance_state") is None)
    if literal or not forked.available() or cold_kernels(("single",)):
        return resolve(*args, **kwargs)
    if kwargs.get("progress"):
        # the helper's progress bar is this command speaking: a console's start notice
        # (qzs.cli.common.start_notice) watches this process's stderr, not the helper's;
        # a carriage return tells it so and shows nothing
        import sys

        sys.stderr.write("\r")
        sys.stderr.flush()
    with forked.start(_resolve_job, name="qzs-step-choice", grace=None) as helper:
        helper.send((args, kwargs))
        return helper.result()


def simulate_to_file(path: str | Path, excitation: Excitation | None = None,
                     isolator: IsolatorParameters | None = None,
                     controller: ControllerParameters | None = None, *,
                     duration: float | None = None, dt: float | None = None,
                     tolerance: float | None = None, tolerance_state: float | None = None,
                     sample_rate: float = defaults.SIMULATION["sample_rate"],
                     solver: str = defaults.SIMULATION["solver"],
                     initial_state: InitialState | None = None, progress: bool = False,
                     interruptible: bool = False, argument: str = "path",
                     resolved: ResolvedRun | None = None,
                     on_simulated: Callable[[SimulationResult], Any] | None = None
                     ) -> SimulationResult:
    """Simulate and stream every output sample to ``path`` (NetCDF, CSV or MATLAB).

    The path, its folder and the free space are checked before the run starts; samples are
    written chunk by chunk (:class:`~qzs.engine.result_file.ResultWriter`), so memory stays
    bounded however long the run; the file appears, complete, only when the run ends (an
    interrupted run, with ``interruptible``, writes what was simulated and says so in
    ``run.completed``); on an error nothing is left behind.

    Parameters
    ----------
    path : str or Path
        The file to write; ``.nc`` (CF-1.10 NetCDF), ``.csv`` or ``.mat`` (MATLAB, the
        layout of :mod:`qzs.iotools.matfile`).
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion; default the paper's chirp.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    duration : float, optional
        Simulated time [s]; default the excitation's length.
    dt, tolerance, tolerance_state : float, optional
        A literal step [s], or the tolerance [dB] or [m] it is chosen for, as for
        :func:`qzs.simulate` (none: the default accuracy).
    sample_rate : float
        Output sample rate [Hz].
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    initial_state : InitialState, optional
        Default: at rest at the setpoint.
    progress : bool
        Show a progress bar.
    interruptible : bool
        Ctrl-C ends the run early and writes what was simulated.
    argument : str
        How the caller names ``path`` in messages (``"--out"`` on the command line).
    resolved : ResolvedRun, optional
        The run already resolved (:func:`qzs.engine.run_spec.resolve`); then the run's
        other arguments are not given. Its step record goes into the file's ``run.step_*``
        attributes.
    on_simulated : callable, optional
        ``on_simulated(result)`` is called when the last sample is in, before the file is
        closed and renamed (:mod:`qzs.workflows.figure_process` starts the figure then).

    Returns
    -------
    SimulationResult
        The run, holding a preview of the samples (``run["preview_every"]``) and the
        statistics of all of them.

    Raises
    ------
    OutputPathError
        The path cannot be written (extension, folder, permissions, free space).
    """
    # the path first (its extension, folder and permissions), before the step is chosen
    check_output_path(path, argument=argument, suffixes=RESULT_SUFFIXES)
    if resolved is None:
        resolved = resolve_apart(excitation, isolator, controller, duration=duration, dt=dt,
                           tolerance=tolerance, tolerance_state=tolerance_state,
                           sample_rate=sample_rate, solver=solver, initial_state=initial_state,
                           progress=progress)
    size = None
    known = Path(path).suffix.lower() in RESULT_SUFFIXES  # else check_output_path names them
    if known:
        size = estimated_size(int(round(resolved.duration * resolved.sample_rate)) + 1,
                              Path(path).suffix)
    check_output_path(path, argument=argument, suffixes=RESULT_SUFFIXES, estimated_bytes=size)
    with ResultWriter(path, isolator=resolved.isolator, controller=resolved.controller,
                      excitation=resolved.excitation) as writer:
        result = resolved.simulate(progress=progress, interruptible=interruptible,
                                   sink=writer.append)
        if on_simulated is not None:
            on_simulated(result)
        # the file holds every sample: the in-memory preview's stride is no property of it
        writer.finish({k: v for k, v in result.run.items() if k != "preview_every"})
    return result
