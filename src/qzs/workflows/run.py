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

__all__ = ["simulate_to_file", "RESULT_SUFFIXES"]

#: File formats a run can be written to, by extension.
RESULT_SUFFIXES = tuple(_FORMATS)


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
        resolved = resolve(excitation, isolator, controller, duration=duration, dt=dt,
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
