"""Parameter sweeps and Monte Carlo runs: thousands of isolator simulations from one TOML file.

A sweep file names what varies and what to keep::

    [sweep]
    name = "gains"
    method = "grid"          # "grid" (default), "random" or "lhs" (Latin hypercube)
    samples = 64             # random/lhs: draws, crossed with every [grid] point
    seed = 1                 # random/lhs: the same seed gives the same cases
    batch_size = 32          # cases per batch: one task, one Zarr chunk

    [parameters]             # parameter names (qzs params) held fixed for every case
    damping_gain = 0.0

    [excitation]             # kind (chirp, sine, random) and fixed values
    kind = "chirp"
    amplitude = 0.010

    [grid]                   # full factorial: a list, or a range table
    pi_kp = [5.0, 20.0, 50.0]
    stiction_force = { start = 5.0, stop = 15.0, num = 5 }    # scale = "log" optional
    "excitation.f1" = [10.0, 20.0]

    [distributions]          # random/lhs only
    viscous_damping = { distribution = "normal", mean = 100.0, std = 10.0 }

    [simulation]             # dt [s], solver
    [analysis]               # sample_rate [Hz], fft_length, n_averages or duration [s],
                             # overlap, band [Hz], at_frequencies [Hz]
    [outputs]                # stats, metrics, transmissibility, coherence, time_series,
                             # bands = { low = [0.2, 1.0] }  (mean T in a band [Hz])

Cases are the product of the grid points (excitation parameters vary slowest,
so that batches share one excitation) and the samples (the same draws at every
grid point: common random numbers). :func:`run_sweep` runs them batch by batch
through :func:`qzs.engine.batch.simulate_batch`, locally or on a Dask cluster, and
writes each finished batch to a Zarr store (:mod:`qzs.workflows.sweeps.store`) that an
interrupted run resumes. Shipped examples: ``qzs/workflows/sweeps/sweep_files/*.toml``; the
guide is ``docs/sweeps.md``.

:func:`run_sweep`, :func:`open_sweep`, :func:`plot_sweep`, :func:`export_sweep` (a store
to a MATLAB file) and :func:`stored_count` are here; figures in :mod:`qzs.viz.sweeps`. The modules:

================  =================================================================
``definition``    sweep files: validation, grids, random and Latin-hypercube sampling
``cases``         each case's parameters and excitation, invalid cases refused early
``step``          the integration step chosen for the tolerance on a few cases
``batch``         the batch task, run in this process or on a Dask cluster
``reduction``     a case's transmissibility curve, band means and metrics
``cluster``       the Dask client: given, by address, or a local cluster
``store``         the Zarr store: layout, creation, batch writes, resume checks
``store_checks``  the store's name, folder, room and resume, checked before any run
``runner``        :func:`execute`: a sweep run end to end, batch by batch into the store
================  =================================================================
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from qzs.errors import ParameterError
from qzs.workflows.sweeps.definition import (DISTRIBUTIONS, EXCITATION_PARAMETERS, METHODS,
                                             SweepDefinition, draw_samples, load_sweep,
                                             plan_text, sample_cases, shipped_sweeps)

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["run_sweep", "open_sweep", "plot_sweep", "export_sweep", "stored_count", "load_sweep",
           "sample_cases", "draw_samples", "shipped_sweeps", "plan_text", "SweepDefinition",
           "METHODS", "DISTRIBUTIONS", "EXCITATION_PARAMETERS"]


# ---------------------------------------------------------------- running
def run_sweep(definition: SweepDefinition | str | Path | Mapping[str, Any],
              store: str | Path | None = None, *, resume: bool = False,
              overwrite: bool = False, scheduler: Any = None, workers: int | None = None,
              threads: int | None = None, progress: bool = True) -> xr.Dataset:
    """Run a sweep and write every finished batch to a Zarr store.

    Parameters
    ----------
    definition : SweepDefinition, str, Path or dict
        The sweep, a TOML file, the name of a shipped sweep, or a parsed document.
    store : str or Path, optional
        The Zarr store (a directory); default ``<name>.zarr`` in the working directory.
    resume : bool
        Continue an interrupted sweep in ``store``: batches already stored are kept,
        the others are run. The store must have been written by the same definition.
    overwrite : bool
        Replace an existing ``store``.
    scheduler : str or distributed.Client, optional
        Run on this Dask cluster (scheduler address or client).
    workers : int, optional
        Start a local Dask cluster of this many single-threaded worker processes.
        Without `scheduler` and `workers` the batches run in this process, each in
        parallel over `threads` threads (cases sharing an excitation in one batch
        call, several cases per vector instruction; cases with an excitation of
        their own side by side).
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a Dask cluster.
    progress : bool
        Show a progress bar (cases done, failures, time left).

    Returns
    -------
    xarray.Dataset
        The store, opened lazily (:func:`open_sweep`).

    Raises
    ------
    ParameterError
        Invalid definition (more than :data:`~qzs.workflows.sweeps.definition.MAX_CASES`
        cases: :class:`~qzs.errors.CountLimitError`), invalid cases
        (:class:`~qzs.errors.InvalidCasesError`, naming each), an existing store without
        `resume`/`overwrite`, both of them, `resume` of no store, a store written by a
        different definition, a store not named ``*.zarr`` or that cannot be written (a
        read-only folder, less free space than its uncompressed size), a scheduler that
        does not answer (:class:`~qzs.errors.SchedulerError`), all before any case runs.
    KeyboardInterrupt
        On Ctrl-C, after the batches that finished have been stored.
    """
    from qzs.workflows.sweeps.runner import execute

    if not isinstance(definition, SweepDefinition):
        definition = load_sweep(definition)
    store = Path(store) if store is not None else Path(f"{definition.name}.zarr")
    execute(definition, store, resume=resume, overwrite=overwrite, scheduler=scheduler,
            workers=workers, threads=threads, progress=progress)
    return open_sweep(store)


def open_sweep(store: str | Path) -> xr.Dataset:
    """Open a sweep store as an ``xarray.Dataset`` (lazy; ``.load()`` to read it all).

    Parameters
    ----------
    store : str or Path
        The Zarr store (a directory) written by :func:`run_sweep`.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ParameterError
        There is no store at ``store``, or it is not a sweep store.
    """
    from qzs.workflows.sweeps.store import open_store

    return open_store(store)


def export_sweep(store: str | Path, out: str | Path | None = None, *,
                 argument: str = "out") -> Path:
    """Write a sweep store to a MATLAB file (``.mat``), one variable in memory at a time.

    The store's variables and coordinates under their own names (a varied excitation
    parameter such as ``excitation.f1`` becomes ``excitation_f1``, listed in
    ``netcdf_names``), their units and the sweep's settings in structs: the layout of
    :mod:`qzs.iotools.matfile`. MAT 5, or MAT 7.3 if a variable (kept time series) holds
    more than 2 GiB.

    Parameters
    ----------
    store : str or Path
        The Zarr store written by :func:`run_sweep`.
    out : str or Path, optional
        The ``.mat`` file; default the store's name with ``.mat`` (``gains.zarr`` ->
        ``gains.mat``).
    argument : str
        How the caller names ``out`` in messages (``"--out"`` on the command line).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    OutputPathError
        ``out`` does not end in ``.mat`` or cannot be written (checked before the store
        is read).
    ParameterError
        ``store`` is not a sweep store.
    """
    from qzs.iotools.matfile import write_mat
    from qzs.iotools.paths import check_output_path

    out = Path(out) if out is not None else Path(store).with_suffix(".mat")
    check_output_path(out, argument=argument, suffixes=(".mat",))
    dataset = open_sweep(store)
    title = (f"qzs sweep {dataset.attrs.get('sweep_name', Path(store).stem)}: "
             f"{dataset.attrs.get('sweep_title', '')}").rstrip(": ")
    return write_mat(dataset.assign_attrs(title=title), out)


def plot_sweep(store: str | Path, *, metric: str | None = None, x: str | None = None,
               y: str | None = None, reduce: str = "median",
               out: str | Path | None = None) -> str | Path:
    """Draw a sweep store's figure, choosing what the arguments leave open; returns the path.

    Parameters
    ----------
    store : str or Path
        The Zarr store.
    metric : str, optional
        A per-case output (e.g. ``peak_stroke``) or ``transmissibility`` (the band);
        default the band without ``y`` if the store keeps it, else ``peak_stroke``.
    x, y : str, optional
        Parameters on the horizontal and vertical axis (``y``: a heat map).
    reduce : {"median", "mean", "min", "max"}
        How cases at one grid point combine.
    out : str or Path, optional
        Figure file; its extension chooses the format (:func:`qzs.viz.sweeps.figure_suffixes`);
        default ``<sweep>-<metric>-<x>[-<y>].png``.

    Returns
    -------
    str or Path
        The figure file written.

    Raises
    ------
    ParameterError
        ``y`` without ``x`` or equal to it, ``out`` cannot be written (both checked before
        the store is read), ``store`` is not a sweep store, an unknown metric or parameter.
    """
    from qzs.iotools.paths import check_output_path
    from qzs.viz.sweeps import (FIGURE_BYTES, figure_suffixes, plot_metric,
                                plot_transmissibility_band, scalar_outputs, varied_parameters)

    if y is not None and x is None:
        raise ParameterError(f"`y` (--y) {y!r} needs `x` (--x): a heat map draws the metric "
                             "over two parameters; add --x PARAM, or leave out --y for a line.")
    if y is not None and y == x:
        raise ParameterError(f"`x` (--x) and `y` (--y) are both {x!r}: a heat map needs two "
                             "different parameters; choose another for one of them.")
    if out is not None:
        check_output_path(out, argument="out", suffixes=figure_suffixes(),
                          estimated_bytes=FIGURE_BYTES)
    dataset = open_sweep(store)
    name = dataset.attrs.get("sweep_name", Path(store).stem)
    if metric is None:
        scalars = scalar_outputs(dataset)
        metric = ("transmissibility" if y is None and "transmissibility" in dataset
                  else "peak_stroke" if "peak_stroke" in scalars else scalars[0])
    if metric == "transmissibility":
        if y is not None:
            raise ParameterError("the transmissibility band takes --x (one band per level), "
                                 "not --y; choose a --metric for a heat map.")
        out = out or f"{name}-transmissibility{'-' + x if x else ''}.png"
        plot_transmissibility_band(dataset, by=x, path=out)
    else:
        x = x or varied_parameters(dataset)[0]
        parts = [name, metric, x] + ([y] if y else [])
        out = out or "-".join(parts) + ".png"
        plot_metric(dataset, metric, x, y, reduce=reduce, path=out)
    return out


def stored_count(store: str | Path) -> int:
    """Cases already stored in ``store`` [-] (0 if there is no store yet).

    Parameters
    ----------
    store : str or Path
        The Zarr store (a directory).

    Returns
    -------
    int
    """
    try:
        return int(open_sweep(store)["done"].sum())
    except Exception:  # noqa: BLE001 - the store may not exist yet
        return 0
