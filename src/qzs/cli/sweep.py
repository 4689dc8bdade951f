"""``qzs sweep``, ``qzs sweep-plot`` and ``qzs sweep-export``: parameter sweeps into a Zarr
store, their figures, and the store as a MATLAB file."""
from pathlib import Path

from qzs.cli.common import (EPILOG, add_execution_options, add_output_options, check_output, emit,
                             output_name, stopped)
from qzs.errors import Terminated
from qzs.viz.sweeps import FIGURE_BYTES, REDUCTIONS, figure_suffixes

__all__ = ["add_parsers", "run_sweep_command", "run_plot_command", "run_export_command"]


def add_parsers(subparsers):
    """Add ``sweep``, ``sweep-plot`` and ``sweep-export`` to a sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``sweep`` parser.
    """
    cmd = subparsers.add_parser(
        "sweep", help="run a parameter sweep or Monte Carlo study into a Zarr store",
        description="Run every case of a sweep file (grid, random or Latin-hypercube "
                    "sampling) and store per-case metrics, statistics and transmissibility "
                    "in a Zarr store, batch by batch; Ctrl-C and --resume continue it.",
        epilog="The sweep is checked before any case runs: every case's values (the invalid "
               "ones are named), at most 1,000,000 cases, the store's name (.zarr), its folder "
               "(writable, room for its uncompressed size); an existing store you named needs "
               "--resume or --overwrite (one of the default name: a new store is named anew), "
               "--resume a store. Ctrl-C (130) and SIGTERM (143) keep the batches "
               "already stored. "
               + EPILOG)
    cmd.add_argument("definition", metavar="FILE.toml",
                     help="sweep file, or a shipped sweep name (e.g. pi_vs_stiction)")
    cmd.add_argument("--resume", action="store_true",
                     help="continue an interrupted sweep in --out (same sweep file)")
    cmd.add_argument("--dry-run", action="store_true",
                     help="print the cases and the work, run nothing")
    add_execution_options(cmd)
    add_output_options(cmd, out=dict(metavar="STORE.zarr", unnamed="rename",
                                     help="the Zarr store, a folder whose name ends in .zarr "
                                          "(default NAME.zarr, NAME the sweep's)"))

    plot = subparsers.add_parser(
        "sweep-plot", help="figures of a sweep store",
        description="Plot a per-case output against one parameter (--metric NAME --x: line) "
                    "or two (--x and --y: heat map), or the transmissibility band (median and "
                    "5/95 percentiles; the default, one band per level of --x if given).",
        epilog="The figure's format follows the extension of --out (.png, .svg, .pdf, ...), "
               "checked before the store is read. " + EPILOG)
    plot.add_argument("store", metavar="STORE.zarr", help="sweep store written by `qzs sweep`")
    plot.add_argument("--x", metavar="PARAM", help="parameter on the horizontal axis")
    plot.add_argument("--y", metavar="PARAM", help="parameter on the vertical axis (heat map)")
    plot.add_argument("--metric", metavar="NAME",
                      help="per-case output (e.g. peak_stroke), or 'transmissibility' (the "
                           "default without --y: the band, one per --x level)")
    plot.add_argument("--reduce", choices=REDUCTIONS, default="median",
                      help="combine the cases at one grid point (default median; max = worst)")
    add_output_options(plot, out=dict(metavar="FILE", unnamed="replace",
                                      help="figure file, format from its extension (default "
                                           "<sweep>-<...>.png)"))

    export = subparsers.add_parser(
        "sweep-export", help="write a sweep store to a MATLAB file (.mat)",
        description="Write every variable of a sweep store (per-case outputs, varied "
                    "parameters, transmissibility, kept time series) to a MATLAB file, with "
                    "their units and the sweep's settings in structs (MAT 5; MAT 7.3 if a "
                    "variable exceeds 2 GiB).",
        epilog="The file's name is checked before the store is read. " + EPILOG)
    export.add_argument("store", metavar="STORE.zarr", help="sweep store written by `qzs sweep`")
    add_output_options(export, out=dict(metavar="FILE.mat", unnamed="replace",
                                        help="the MATLAB file (default the store's name with "
                                             ".mat)"))
    return cmd


def run_sweep_command(args):
    """Run ``qzs sweep`` from parsed arguments; returns the exit code (130 if interrupted).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs sweep`` arguments.

    Returns
    -------
    int
        The exit code: 0, or 130 if Ctrl-C interrupted the sweep, 143 if SIGTERM ended it
        (its stored cases stay either way).
    """
    from qzs.workflows.sweeps import load_sweep, open_sweep, plan_text, stored_count
    from qzs.workflows.sweeps.runner import execute
    from qzs.workflows.sweeps.store_checks import check_store_path
    from qzs.workflows.sweeps.store import summary_text

    definition = load_sweep(args.definition)
    if args.dry_run:
        print(plan_text(definition))
        return 0
    store, overwrite = output_name(args, "--out", args.out or f"{definition.name}.zarr",
                                   directory=True, resume=args.resume)
    check_store_path(definition, store, argument="--out", resume=args.resume,
                     overwrite=overwrite)
    try:
        report = execute(definition, store, resume=args.resume, overwrite=overwrite,
                         scheduler=args.scheduler, workers=args.workers, threads=args.threads,
                         progress=not args.quiet and not args.json)
    except (KeyboardInterrupt, Terminated) as stop:
        return stopped(stop, f"{stored_count(store)} of {definition.n_cases} cases are stored "
                             f"in {store}. Continue with: qzs sweep {args.definition} --out "
                             f"{store} --resume")
    emit(args, summary_text(open_sweep(store), report) + f"\n  wrote            {store}",
         {"sweep": definition.name, "cases": definition.n_cases, "report": report,
          "files": {"out": str(store)}})
    return 0


def run_plot_command(args):
    """Run ``qzs sweep-plot`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs sweep-plot`` arguments.

    Returns
    -------
    int
        The exit code, 0.
    """
    from qzs.workflows.sweeps import plot_sweep

    if args.out is not None:
        check_output(args, "--out", args.out, suffixes=figure_suffixes(),
                     estimated_bytes=FIGURE_BYTES)
    out = plot_sweep(args.store, metric=args.metric, x=args.x, y=args.y, reduce=args.reduce,
                     out=args.out)
    emit(args, f"wrote {out}", {"files": {"out": str(out)}})
    return 0


def run_export_command(args):
    """Run ``qzs sweep-export`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs sweep-export`` arguments.

    Returns
    -------
    int
        The exit code, 0.
    """
    from qzs.workflows.sweeps import export_sweep

    out = Path(args.out) if args.out else Path(args.store).with_suffix(".mat")
    check_output(args, "--out", out, suffixes=(".mat",))
    out = export_sweep(args.store, out, argument="--out")
    emit(args, f"wrote {out}", {"files": {"out": str(out)}})
    return 0
