"""The ``qzs`` command line: argparse only, one module per subcommand; it computes nothing.

    qzs simulate [--config FILE.toml] [--set NAME=VALUE ...] [--excitation chirp|sine|random|file]
                 [--amplitude M] [--f0 HZ] [--f1 HZ] [--frequency HZ] [--duration S]
                 [--dt S] [--sample-rate HZ] [--solver ode3|rk4|euler] [--out FILE.nc|FILE.csv]
    qzs params [--toml FILE]
    qzs study FILE.toml [--quick] [--out DIR] [--workers N]
    qzs paper [--quick] [--out DIR] [--workers N]
    qzs experiment LOG --map MAP.toml [--out DIR]
    qzs sweep FILE.toml [--resume] [--workers N | --scheduler ADDRESS]
    qzs sweep-plot STORE [--metric NAME] [--x PARAM] [--y PARAM]

Every subcommand hands its parsed arguments to a function of the layers below;
bad input ends with one line on stderr and exit code 2, Ctrl-C with 130.
"""
import argparse
import sys

from qzs._version import __version__
from qzs.cli import experiment, params, simulate, studies, sweep
from qzs.cli.common import run_handler

__all__ = ["main", "build_parser"]

HANDLERS = {"simulate": simulate.run, "params": params.run, "paper": studies.run,
            "study": studies.run, "experiment": experiment.run,
            "sweep": sweep.run_sweep_command, "sweep-plot": sweep.run_plot_command}


def build_parser():
    """The ``qzs`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="qzs", description="Semi-active quasi-zero-stiffness isolator toolkit.",
        epilog="The model, its signs, defaults and every modelling decision: docs/model.md "
               "(in the qzs repository). Parameter names and units: `qzs params`.")
    parser.add_argument("--version", action="version", version=f"qzs {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    simulate.add_parser(sub)
    studies.add_parsers(sub)
    experiment.add_parser(sub)
    sweep.add_parsers(sub)
    params.add_parser(sub)
    return parser


def main(argv=None):
    """Entry point of the ``qzs`` command; returns the process exit code.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``qzs``; default ``sys.argv[1:]``.

    Returns
    -------
    int
        0 on success, 2 for bad input, 130 when interrupted.
    """
    args = build_parser().parse_args(argv)
    return run_handler(HANDLERS[args.command], args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
