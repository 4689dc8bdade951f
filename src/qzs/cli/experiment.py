"""``qzs experiment``: an experiment log beside the matching simulation."""

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
                    "simulate the same chirp, and write a figure, a table and report.md.")
    parser.add_argument("log", metavar="LOG", help="log file (.csv, .mat, .mf4, .nc)")
    parser.add_argument("--map", required=True, metavar="MAP.toml",
                        help="channel map (see qzs.iotools.readers)")
    parser.add_argument("--out", metavar="DIR", default="qzs-experiment",
                        help="output folder (default qzs-experiment)")
    parser.add_argument("--no-simulation", action="store_true",
                        help="do not simulate the matching run")
    parser.add_argument("--fft-length", type=int, metavar="N",
                        help="Welch segment length [samples] (default 32768)")
    parser.add_argument("--averages", type=int, metavar="N",
                        help="Welch averages (default 29; fewer if the log is short)")
    parser.add_argument("--config", metavar="PARAMS.toml",
                        help="model parameters for the simulation (see `qzs params --toml`)")
    parser.add_argument("--resample", action="store_true",
                        help="resample a non-uniform time base onto a uniform grid")
    return parser


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
    from qzs.workflows.experiment import run_experiment

    result, paths = run_experiment(args.log, args.map, out=args.out, fft_length=args.fft_length,
                                   n_averages=args.averages, config=args.config,
                                   resample=args.resample,
                                   simulate_match=not args.no_simulation)
    print(result.summary())
    print(f"wrote {paths['report']}, {paths['figure'].name} (+ .svg) and {paths['table'].name}")
    return 0
