"""One run written to a file as it is simulated: memory bounded by the chunk, not the duration.

>>> from qzs import Chirp
>>> from qzs.workflows.run import simulate_to_file
>>> result = simulate_to_file("run.nc", Chirp(duration=100.0, f1=5.0))  # doctest: +SKIP
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from qzs import defaults
from qzs.engine.prepare import run_inputs
from qzs.engine.result_file import ResultWriter, estimated_size
from qzs.engine.simulate import simulate
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
                     duration: float | None = None, dt: float = defaults.SIMULATION["dt"],
                     sample_rate: float = defaults.SIMULATION["sample_rate"],
                     solver: str = defaults.SIMULATION["solver"],
                     initial_state: InitialState | None = None, progress: bool = False,
                     interruptible: bool = False, argument: str = "path",
                     run_entries: Mapping[str, Any] | None = None) -> SimulationResult:
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
    dt : float
        Integration step [s].
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
    run_entries : dict, optional
        More entries of ``result.run`` (and of the file's ``run.*`` attributes), such as a
        chosen step's tolerance and error (:func:`qzs.engine.accuracy.step_run_entries`).

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
    excitation, isolator, controller = run_inputs(excitation, isolator, controller)
    length = duration if duration is not None else excitation.duration
    size = None
    known = Path(path).suffix.lower() in RESULT_SUFFIXES  # else check_output_path names them
    if known and length is not None and length > 0 and sample_rate > 0:
        size = estimated_size(int(round(length * sample_rate)) + 1, Path(path).suffix)
    check_output_path(path, argument=argument, suffixes=RESULT_SUFFIXES, estimated_bytes=size)
    with ResultWriter(path, isolator=isolator, controller=controller,
                      excitation=excitation) as writer:
        result = simulate(excitation, isolator, controller, duration=duration, dt=dt,
                          sample_rate=sample_rate, solver=solver, initial_state=initial_state,
                          progress=progress, interruptible=interruptible, sink=writer.append)
        result.run.update(run_entries or {})
        # the file holds every sample: the in-memory preview's stride is no property of it
        writer.finish({k: v for k, v in result.run.items() if k != "preview_every"})
    return result
