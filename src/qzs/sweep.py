"""Parameter sweeps and Monte Carlo runs: thousands of isolator simulations from one TOML file.

A sweep file names what varies and what to keep::

    [sweep]
    name = "gains"
    method = "grid"          # "grid" (default), "random" or "lhs" (Latin hypercube)
    samples = 64             # random/lhs: draws, crossed with every [grid] point
    seed = 1                 # random/lhs: the same seed gives the same cases
    batch_size = 32          # cases per batch: one task, one Zarr chunk

    [parameters]             # MODEL.md names held fixed for every case
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
through :func:`qzs.batch.simulate_batch`, locally or on a Dask cluster, and
writes each finished batch to a Zarr store (:mod:`qzs.sweep_store`) that an
interrupted run resumes. Shipped examples: ``qzs/sweep_files/*.toml``; the guide
is ``docs/sweeps.md``.

Modules: :mod:`qzs.sweep_definition` (files, grids, sampling),
:mod:`qzs.sweep_backends` (the batch task, local and Dask backends),
:mod:`qzs.sweep_store` (the Zarr store), :mod:`qzs.sweep_plots` (figures).
"""
from pathlib import Path

from qzs.errors import ParameterError
from qzs.sweep_definition import (  # noqa: F401 - re-exported
    DISTRIBUTIONS,
    EXCITATION_PARAMETERS,
    METHODS,
    SweepDefinition,
    draw_samples,
    load_sweep,
    plan_text,
    sample_cases,
    shipped_sweeps,
)

__all__ = ["run_sweep", "open_sweep", "load_sweep", "sample_cases", "draw_samples",
           "shipped_sweeps", "plan_text", "SweepDefinition", "add_parsers",
           "run_sweep_command", "run_sweep_plot_command", "METHODS", "DISTRIBUTIONS",
           "EXCITATION_PARAMETERS"]


# ---------------------------------------------------------------- running
def run_sweep(definition, store=None, *, resume=False, overwrite=False, scheduler=None,
              workers=None, threads=None, progress=True):
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
        Invalid definition, an existing store without `resume`/`overwrite`, or a
        store written by a different definition.
    KeyboardInterrupt
        On Ctrl-C, after the batches that finished have been stored.
    """
    from qzs.sweep_backends import execute

    if not isinstance(definition, SweepDefinition):
        definition = load_sweep(definition)
    store = Path(store) if store is not None else Path(f"{definition.name}.zarr")
    execute(definition, store, resume=resume, overwrite=overwrite, scheduler=scheduler,
            workers=workers, threads=threads, progress=progress)
    return open_sweep(store)


def open_sweep(store):
    """Open a sweep store as an ``xarray.Dataset`` (lazy; ``.load()`` to read it all)."""
    from qzs.sweep_store import open_store

    return open_store(store)


# ---------------------------------------------------------------- command line
def add_parsers(subparsers):
    """Add ``sweep`` and ``sweep-plot`` to an ``argparse`` sub-parser collection."""
    from qzs.sweep_plots import add_plot_parser

    cmd = subparsers.add_parser(
        "sweep", help="run a parameter sweep or Monte Carlo study into a Zarr store",
        description="Run every case of a sweep file (grid, random or Latin-hypercube "
                    "sampling) and store per-case metrics, statistics and transmissibility "
                    "in a Zarr store, batch by batch; Ctrl-C and --resume continue it.")
    cmd.add_argument("definition", metavar="FILE.toml",
                     help="sweep file, or a shipped sweep name (e.g. pi_vs_stiction)")
    cmd.add_argument("--out", metavar="STORE.zarr", help="store (default NAME.zarr)")
    cmd.add_argument("--resume", action="store_true",
                     help="continue an interrupted sweep in --out (same sweep file)")
    cmd.add_argument("--overwrite", action="store_true", help="replace an existing store")
    where = cmd.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on an existing Dask cluster (e.g. tcp://host:8786)")
    where.add_argument("--workers", type=int, metavar="N",
                       help="start a local Dask cluster of N worker processes")
    cmd.add_argument("--threads", type=int, metavar="N",
                     help="threads per batch (default: all cores locally, 1 on Dask)")
    cmd.add_argument("--dry-run", action="store_true",
                     help="print the cases and the work, run nothing")
    cmd.add_argument("--quiet", action="store_true", help="no progress bar")
    add_plot_parser(subparsers)
    return cmd


def run_sweep_command(args):
    """Run ``qzs sweep`` from parsed arguments; returns the exit code (130 if interrupted)."""
    import sys

    from qzs.sweep_store import summary_text

    definition = load_sweep(args.definition)
    store = Path(args.out) if args.out else Path(f"{definition.name}.zarr")
    for option in ("workers", "threads"):
        value = getattr(args, option)
        if value is not None and value < 1:
            raise ParameterError(f"`--{option}` must be >= 1, got {value}.")
    if args.dry_run:
        print(plan_text(definition))
        return 0
    from qzs.sweep_backends import execute

    try:
        report = execute(definition, store, resume=args.resume, overwrite=args.overwrite,
                         scheduler=args.scheduler, workers=args.workers, threads=args.threads,
                         progress=not args.quiet)
    except KeyboardInterrupt:
        done = _done_count(store)
        print(f"qzs: interrupted; {done} of {definition.n_cases} cases are stored in "
              f"{store}. Continue with: qzs sweep {args.definition} --out {store} --resume",
              file=sys.stderr)
        return 130
    print(summary_text(open_sweep(store), report))
    print(f"  wrote            {store}")
    return 0


def _done_count(store):
    try:
        return int(open_sweep(store)["done"].sum())
    except Exception:  # noqa: BLE001 - the store may not exist yet
        return 0


def run_sweep_plot_command(args):
    """Run ``qzs sweep-plot`` from parsed arguments; returns the exit code."""
    from qzs.sweep_plots import run_plot

    return run_plot(args)
