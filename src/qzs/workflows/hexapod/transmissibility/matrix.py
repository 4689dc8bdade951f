"""The entry point: the runs in parallel processes, assembled into the 6x6 matrix."""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from qzs._validation import worker_count
from qzs.defaults import AXES
from qzs.workflows.hexapod.transmissibility.plan import _dry_run, _plan
from qzs.workflows.hexapod.transmissibility.result import HexapodTransmissibility
from qzs.workflows.hexapod.transmissibility.runs import run_axis
from qzs.workflows.hexapod.transmissibility.settings import CHIRP, FLOOR_DB, _scale

if TYPE_CHECKING:
    from qzs.workflows.hexapod.setups import HexapodSetup


# ---------------------------------------------------------------- the matrix
def hexapod_transmissibility(setup: HexapodSetup, *, axes: Sequence[str] | str = AXES,
                             amplitude: float | Mapping[str, float] | None = None,
                             f0: float = CHIRP["f0"], f1: float = CHIRP["f1"],
                             duration: float = CHIRP["duration"], dt: float | None = None,
                             tolerance: float | None = None,
                             sample_rate: float | None = None, solver: str | None = None,
                             fft_length: int | None = None, estimator: str = "h1",
                             floor_db: float = FLOOR_DB, workers: int | None = None,
                             progress: bool = True,
                             tolerance_db: float | None = None) -> HexapodTransmissibility:
    """Simulate one chirp per base axis and estimate the 6x6 transmissibility matrix.

    Each axis of ``axes`` is one run of :func:`qzs.engine.hexapod.simulate_hexapod` with
    the base moving along that axis alone (a linear chirp of constant displacement
    amplitude from ``f0`` to ``f1``); column ``j`` of the matrix is the single-axis Welch
    estimate from ``base_velocity[:, j]`` to ``platform_twist[:, i]`` for every platform
    axis ``i``, with its coherence and trusted bins (see the module docstring for the
    numerical floor). The runs go in parallel processes, one per axis. Every argument is
    checked before any run; then one integration step of the first run lets the engine
    check the set-up itself.

    Parameters
    ----------
    setup : HexapodSetup
        The platform (:func:`qzs.workflows.hexapod.setups.load_hexapod`, ``hexapod_setup``).
    axes : sequence of str or str
        Base axes to excite (``"x", "y", "z"`` [m], ``"rx", "ry", "rz"`` [rad]), or one
        comma-separated string (``"z,x"``); each is one run. Default all six.
    amplitude : float or mapping, optional
        Chirp displacement amplitude: one number for every excited axis (all translations
        [m] or all rotations [rad]), or ``{axis: amplitude}``. Default per axis
        :data:`AMPLITUDE`: 0.002 m in translation, 0.01 rad in rotation.
    f0, f1 : float
        Chirp start and end frequency [Hz], ``0 <= f0 < f1`` below the Nyquist frequency;
        default 0 and 20 (the paper's band).
    duration : float
        Sweep time and run length [s]; default 200.
    dt : float, optional
        A literal integration step [s] for every run. Default: accuracy-driven per run
        (module docstring), falling back to the set-up's ``[simulation] dt`` (1e-4 s if it
        gives none); each run's record says which, with the estimated error.
    tolerance : float, optional
        Tolerance [dB] of the accuracy-driven step on each run's column of the matrix;
        default ``qzs.defaults.ACCURACY["tolerance_db"]`` (0.01). Not with ``dt``.
    sample_rate : float, optional
        Output rate [Hz]; default the set-up's, else 1000.
    solver : {"ode3", "rk4", "euler"}, optional
        Integrator; default the set-up's, else ode3.
    fft_length : int, optional
        Welch segment length [samples]; default the power of two giving at least 8
        half-overlapping segments, at most 16384 (bins of 0.061 Hz at 1 kHz).
    estimator : {"h1", "h2"}
        ``H1 = S_bp/S_bb`` (default; unbiased by noise on the platform's motion) or
        ``H2 = S_pp/S_pb``.
    floor_db : float
        Numerical floor [dB] below which an entry is untrusted whatever its coherence
        (negative; default -100).
    workers : int, optional
        Processes running the axes at once; default the machine's cores. 1 runs them
        one after another in this process.
    progress : bool
        Show a progress bar over the runs.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    HexapodTransmissibility

    Raises
    ------
    ParameterError
        An invalid argument (named, with its value and the fix), before any run; the
        engine's own errors for the set-up after one step.
    StabilityError
        ``dt`` (or the set-up's) beyond the largest stable step.
    SimulationError
        A run diverged.
    """
    from qzs._validation import renamed_keyword

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)
    axes, amplitudes, common, runs, workers = _plan(
        setup, axes, amplitude, f0, f1, duration, dt, sample_rate, solver, fft_length,
        estimator, floor_db, workers, progress, tolerance)
    from qzs.engine.progress import progress_bar

    _dry_run(runs[0])
    workers = worker_count(workers, len(runs))
    columns = {}
    bar = progress_bar(total=len(runs), unit="run", desc="hexapod chirps", disable=not progress)
    try:
        if workers == 1:
            for run in runs:
                columns[run.axis] = run_axis(run)
                bar.update()
        else:
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(max_workers=workers) as pool:
                futures = [pool.submit(run_axis, run) for run in runs]
                try:
                    for future in as_completed(futures):
                        column = future.result()
                        columns[column["axis"]] = column
                        bar.update()
                except BaseException:
                    for future in futures:
                        future.cancel()
                    raise
    finally:
        bar.close()
    return _assemble(setup, axes, amplitudes, common, columns)


def _assemble(setup, axes, amplitudes, common, columns):
    """The result object from the columns of the runs."""
    from qzs.analysis.hexapod_linear import hexapod_linearize

    frequency = columns[axes[0]]["frequency"]
    keep = frequency <= common["f1"]  # above the sweep the base put no power
    frequency = frequency[keep]
    n = frequency.size
    response = np.full((n, 6, 6), np.nan + 0j)
    coherence = np.full((n, 6, 6), np.nan)
    trusted = np.zeros((n, 6, 6), dtype=bool)
    for axis, column in columns.items():
        j = AXES.index(axis)
        response[:, :, j] = column["response"].T[keep]
        coherence[:, :, j] = column["coherence"].T[keep]
        trusted[:, :, j] = column["trusted"].T[keep]
    floor = 10 ** (common["floor_db"] / 20)
    with np.errstate(invalid="ignore"):
        below = (np.abs(response) * _scale(common["platform_size"])[None] < floor) & np.isfinite(
            np.abs(response))
    trusted &= ~below
    trusted &= (frequency >= common["trusted_from"])[:, None, None]
    cartesian = getattr(setup, "cartesian", None)
    model = hexapod_linearize(setup.geometry, setup.platform, setup.isolator,
                              getattr(setup, "controllers", setup.controller),
                              frame="origin",
                              **({} if cartesian is None else {"cartesian": cartesian}))
    linear = np.full((n, 6, 6), np.nan + 0j)
    positive_bins = frequency > 0
    linear[positive_bins] = model.transmissibility(frequency[positive_bins])
    runs = {axis: MappingProxyType(columns[axis]["record"]) for axis in axes}
    residual = {axis: columns[axis]["record"]["energy_residual"]
                / max(columns[axis]["record"]["base_work_max"], 1e-300) for axis in axes}
    for array in (frequency, response, coherence, trusted, below, linear):
        array.setflags(write=False)
    return HexapodTransmissibility(
        frequency=frequency, response=response, coherence=coherence, trusted=trusted,
        below_floor=below, linear_response=linear, linear_stable=bool(model.stable),
        linear_natural_frequencies=np.asarray(model.natural_frequencies, dtype=float),
        linear_notes=tuple(model.notes), excited_axes=axes,
        amplitude=MappingProxyType(dict(amplitudes)),
        energy_residual=MappingProxyType(residual), runs=MappingProxyType(runs),
        settings=MappingProxyType(dict(common)), setup=setup)
