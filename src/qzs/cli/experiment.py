"""``qzs experiment``: an experiment log beside the matching simulation.

``qzs experiment --write-map FILE.toml`` writes a commented channel map template instead and
ends the command, as ``--help`` does (LOG and ``--map`` are not needed then).
"""
import argparse
from pathlib import Path

from qzs.cli.common import (EPILOG, add_frequency_axis_option, add_output_options,
                             check_output, emit, integer_at_least, run_handler)
from qzs.errors import OutputPathError
from qzs.iotools.paths import check_output_path

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Add ``experiment`` to an ``argparse`` sub-parser collection; returns the parser.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``experiment`` parser.
    """
    parser = subparsers.add_parser(
        "experiment", help="process an experiment log: transmissibility beside the simulation",
        description="Read a test-rig log with a channel map, estimate the transmissibility, "
                    "simulate the same chirp, and write a figure, a table and report.md.",
        epilog="A log whose time base is not uniform needs --resample (or resample = true in "
               "the map's [options]). " + EPILOG)
    parser.add_argument("log", metavar="LOG", help="log file (.csv, .mat, .mf4, .nc)")
    parser.add_argument("--map", required=True, metavar="MAP.toml",
                        help="channel map: each signal's source channel and unit (layout: "
                             "`qzs docs identification`; a template: --write-map)")
    parser.add_argument("--write-map", metavar="FILE.toml", action=WriteMap,
                        help="write a commented channel map template (every key the map "
                             "reader accepts) to FILE.toml and exit; never replaces a file")
    parser.add_argument("--no-simulation", action="store_true",
                        help="do not simulate the matching run")
    parser.add_argument("--fft-length", type=integer_at_least(8), metavar="N",
                        help="Welch segment length [samples], >= 8 (default the map's "
                             "[experiment] fft_length, else 32768)")
    parser.add_argument("--averages", type=integer_at_least(1), metavar="N",
                        help="Welch averages, >= 1 (default the map's [experiment] "
                             "n_averages, else 29; fewer if the log is short)")
    parser.add_argument("--config", metavar="PARAMS.toml",
                        help="model parameters for the simulation (see `qzs params --toml`)")
    parser.add_argument("--resample", action="store_true",
                        help="resample a non-uniform time base onto a uniform grid")
    add_frequency_axis_option(parser)
    add_output_options(parser, out=dict(metavar="DIR", default="qzs-experiment",
                                        unnamed="replace",
                                        help="output folder (default qzs-experiment)"))
    return parser


class WriteMap(argparse.Action):
    """``--write-map FILE.toml``: write the channel map template, then end the command.

    Like ``--help``, it acts while the arguments are parsed, so that LOG and ``--map`` stay
    required for a run. Its errors end as every command's do (:func:`run_handler`): one line
    ``qzs: error: ...`` and exit code 2 for a bad path or an existing file.
    """

    def __call__(self, parser, namespace, values, option_string=None):
        parser.exit(run_handler(_write_map, argparse.Namespace(write_map=values,
                                                               option=option_string)))


def _write_map(args):
    check_output_path(args.write_map, argument=args.option, suffixes=(".toml",),
                      estimated_bytes=16 * 1024)
    if Path(args.write_map).exists():
        raise OutputPathError(args.option, args.write_map, "exists; choose another name (a map "
                              "someone filled in is never replaced)")
    from qzs.workflows.experiment.map_template import PLACEHOLDER, write_channel_map_template

    path = write_channel_map_template(args.write_map)
    print(f'wrote {path}: replace each source = "{PLACEHOLDER}" with the signal\'s name in '
          f"your log, then: qzs experiment LOG --map {path}")
    return 0


def run(args):
    """Run ``qzs experiment`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs experiment`` arguments.

    Returns
    -------
    int
        The exit code, 0.
    """
    check_output(args, "--out", args.out, suffixes=None, directory=True)
    from qzs.workflows.experiment.process import run_experiment  # scipy and the engine: after the check

    result, paths = run_experiment(args.log, args.map, out=args.out, fft_length=args.fft_length,
                                   n_averages=args.averages, config=args.config,
                                   resample=args.resample,
                                   simulate_match=not args.no_simulation,
                                   frequency_scale=args.frequency_axis)
    text = (f"{result.summary()}\nwrote {paths['report']}, {paths['figure'].name} (+ .svg) "
            f"and {paths['table'].name}")
    emit(args, text, {**result.to_record(),
                      "files": {name: str(path) for name, path in paths.items()}})
    return 0
