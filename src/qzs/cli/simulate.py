"""``qzs simulate``: one run, its summary, its figure and optionally its time series."""
import sys

from qzs.cli.common import add_set_option, parameters
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, build_excitation

__all__ = ["add_parser", "run"]

DEFAULT_PLOT = "qzs-simulation.png"
# Options read from the command line into the excitation (those the kind takes).
_OPTIONS = ("amplitude", "f0", "f1", "frequency", "method", "seed", "duration", "record")


def add_parser(subparsers):
    """Add ``simulate`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``simulate`` parser.
    """
    sim = subparsers.add_parser(
        "simulate", help="simulate the isolator under a base excitation",
        description="Simulate the isolator. With no options: the paper's default case "
                    "(10 mm chirp, 0-20 Hz, 2000 s, ode3, dt = 1e-4 s), summary and plot.")
    sim.add_argument("--config", metavar="FILE.toml",
                     help="run configuration (see `qzs params --toml`)")
    add_set_option(sim)
    sim.add_argument("--excitation", choices=tuple(EXCITATION_KINDS),
                     help="base excitation (default chirp)")
    sim.add_argument("--amplitude", type=float, metavar="M",
                     help="displacement amplitude [m] (RMS for random; default 0.010)")
    sim.add_argument("--f0", type=float, metavar="HZ", help="chirp start / random band low [Hz]")
    sim.add_argument("--f1", type=float, metavar="HZ", help="chirp end / random band high [Hz]")
    sim.add_argument("--frequency", type=float, metavar="HZ", help="sine frequency [Hz]")
    sim.add_argument("--method", choices=("linear", "logarithmic"), help="chirp sweep law")
    sim.add_argument("--seed", type=int, help="random excitation seed")
    sim.add_argument("--record", metavar="FILE.csv",
                     help="displacement record for --excitation file (columns time, displacement)")
    sim.add_argument("--duration", type=float, metavar="S", help="simulated time [s]")
    sim.add_argument("--dt", type=float, metavar="S", help="integration step [s] (default 1e-4)")
    sim.add_argument("--sample-rate", type=float, metavar="HZ",
                     help="output rate [Hz] (default 1000)")
    sim.add_argument("--solver", choices=("ode3", "rk4", "euler"),
                     help="integrator (default ode3)")
    sim.add_argument("--out", metavar="FILE", help="write the time series (.nc or .csv)")
    sim.add_argument("--plot", metavar="FILE", default=DEFAULT_PLOT,
                     help=f"figure of the run (default {DEFAULT_PLOT}; 'none' to skip)")
    sim.add_argument("--quiet", action="store_true", help="no progress bar")
    return sim


def _excitation(args, table):
    options = dict(table)
    kind = args.excitation or options.pop("kind", "chirp")
    options.pop("kind", None)
    for key in _OPTIONS:
        value = getattr(args, key)
        if value is not None:
            options[key] = value
    return build_excitation(kind, {k: v for k, v in options.items()
                                   if k in EXCITATION_OPTIONS[kind]})


def run(args):
    """Run ``qzs simulate`` from parsed arguments; returns the exit code (130 if interrupted).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs simulate`` arguments.

    Returns
    -------
    int
        The exit code: 0, or 130 if Ctrl-C ended the run early.
    """
    from qzs.engine.simulate import simulate

    config = parameters(args)
    excitation = _excitation(args, config["excitation"])
    settings = dict(config["simulation"])
    for key in ("dt", "sample_rate", "solver", "duration"):
        value = getattr(args, key)
        if value is not None:
            settings[key] = value
    if "duration" not in settings and config["excitation"].get("duration") is not None:
        settings["duration"] = config["excitation"]["duration"]
    if excitation.duration is None and "duration" not in settings:
        settings["duration"] = 10.0
        print("qzs: no --duration given for the sine; simulating 10 s", file=sys.stderr)
    result = simulate(excitation, config["isolator"], config["controller"], **settings,
                      progress=not args.quiet, interruptible=True)
    print(result.summary())
    if args.out:
        path = result.save(args.out)
        print(f"  wrote            {path}")
    if args.plot and args.plot.lower() != "none":
        result.plot(path=args.plot)
        print(f"  wrote            {args.plot}")
    return 0 if result.completed else 130
