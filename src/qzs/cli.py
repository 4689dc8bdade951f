"""The ``qzs`` command line: a thin layer over the public API.

    qzs simulate [--config FILE.toml] [--set NAME=VALUE ...] [--excitation chirp|sine|random|file]
                 [--amplitude M] [--f0 HZ] [--f1 HZ] [--frequency HZ] [--duration S]
                 [--dt S] [--sample-rate HZ] [--solver ode3|rk4|euler] [--out FILE.nc|FILE.csv]
    qzs params [--toml FILE]
    qzs study FILE.toml [--quick] [--out DIR] [--workers N]
    qzs paper [--quick] [--out DIR] [--workers N]
    qzs experiment LOG --map MAP.toml [--out DIR]
    qzs sweep FILE.toml [--resume] [--workers N | --scheduler ADDRESS]
    qzs sweep-plot STORE [--metric NAME] [--x PARAM] [--y PARAM]
"""
import argparse
import sys
from pathlib import Path

__all__ = ["main"]

DEFAULT_PLOT = "qzs-simulation.png"


def _build_parser():
    parser = argparse.ArgumentParser(
        prog="qzs", description="Semi-active quasi-zero-stiffness isolator toolkit.")
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser(
        "simulate", help="simulate the isolator under a base excitation",
        description="Simulate the isolator. With no options: the paper's default case "
                    "(10 mm chirp, 0-20 Hz, 2000 s, ode3, dt = 1e-4 s), summary and plot.")
    sim.add_argument("--config", metavar="FILE.toml", help="run configuration (see `qzs params --toml`)")
    sim.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                     help="override a parameter by its MODEL.md name (repeatable)")
    sim.add_argument("--excitation", choices=("chirp", "sine", "random", "file"),
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
    sim.add_argument("--sample-rate", type=float, metavar="HZ", help="output rate [Hz] (default 1000)")
    sim.add_argument("--solver", choices=("ode3", "rk4", "euler"), help="integrator (default ode3)")
    sim.add_argument("--out", metavar="FILE", help="write the time series (.nc or .csv)")
    sim.add_argument("--plot", metavar="FILE", default=DEFAULT_PLOT,
                     help=f"figure of the run (default {DEFAULT_PLOT}; 'none' to skip)")
    sim.add_argument("--quiet", action="store_true", help="no progress bar")

    for name, text in (("paper", "run every study of the paper, write figures, metrics and "
                                 "report.html"),
                       ("study", "run one study definition (a shipped name or a TOML file)")):
        cmd = sub.add_parser(name, help=text, description=text)
        if name == "study":
            cmd.add_argument("definition", metavar="FILE.toml",
                             help="study file, or a shipped study name (e.g. stiction)")
        cmd.add_argument("--quick", action="store_true",
                         help="shorter runs (fewer, shorter Welch segments)")
        cmd.add_argument("--out", metavar="DIR", default=f"results/{name}",
                         help=f"output folder (default results/{name})")
        cmd.add_argument("--workers", type=int, metavar="N",
                         help="worker processes (default: all cores)")
        cmd.add_argument("--quiet", action="store_true", help="no progress bar")

    from qzs import experiment, sweep

    experiment.add_parser(sub)
    sweep.add_parsers(sub)

    params = sub.add_parser("params", help="print the default parameters with units")
    params.add_argument("--toml", metavar="FILE", help="write them as a config file instead")
    params.add_argument("--config", metavar="FILE.toml", help="show the values of a config file")
    params.add_argument("--set", metavar="NAME=VALUE", action="append", default=[])
    return parser


def _settings(pairs):
    settings = {}
    for pair in pairs:
        if "=" not in pair:
            raise SystemExit(f"qzs: error: --set expects NAME=VALUE, got {pair!r}")
        name, value = pair.split("=", 1)
        settings[name.strip()] = value.strip()
    return settings


def _parameters(args):
    from qzs import ControllerParameters, IsolatorParameters
    from qzs.io import load_config, update_parameters

    config = {"isolator": IsolatorParameters(), "controller": ControllerParameters(),
              "excitation": {}, "simulation": {}}
    if args.config:
        config = load_config(args.config)
    config["isolator"], config["controller"] = update_parameters(
        config["isolator"], config["controller"], _settings(args.set))
    return config


def _excitation(args, table):
    from qzs import Chirp, DisplacementRecord, RandomExcitation, Sine

    options = dict(table)
    kind = args.excitation or options.pop("kind", "chirp")
    options.pop("kind", None)
    for key in ("amplitude", "f0", "f1", "frequency", "method", "seed", "duration", "record"):
        value = getattr(args, key)
        if value is not None:
            options[key] = value
    if kind == "chirp":
        keys = ("amplitude", "f0", "f1", "duration", "method")
        return Chirp(**{k: options[k] for k in keys if k in options})
    if kind == "sine":
        keys = ("amplitude", "frequency", "phase")
        return Sine(**{k: options[k] for k in keys if k in options})
    if kind == "random":
        mapping = {"amplitude": "amplitude", "f0": "f_low", "f1": "f_high",
                   "duration": "duration", "seed": "seed"}
        return RandomExcitation(**{mapping[k]: options[k] for k in mapping if k in options})
    if "record" not in options:
        raise SystemExit("qzs: error: --excitation file needs --record FILE.csv")
    return DisplacementRecord.from_file(options["record"])


def _simulate(args):
    from qzs import simulate

    config = _parameters(args)
    excitation = _excitation(args, config["excitation"])
    run = dict(config["simulation"])
    for key, attr in (("dt", "dt"), ("sample_rate", "sample_rate"), ("solver", "solver"),
                      ("duration", "duration")):
        value = getattr(args, attr)
        if value is not None:
            run[key] = value
    if "duration" not in run and config["excitation"].get("duration") is not None:
        run["duration"] = config["excitation"]["duration"]
    if excitation.duration is None and "duration" not in run:
        run["duration"] = 10.0
        print("qzs: no --duration given for the sine; simulating 10 s", file=sys.stderr)
    result = simulate(excitation, config["isolator"], config["controller"], **run,
                      progress=not args.quiet, interruptible=True)
    print(result.summary())
    if args.out:
        path = result.save(args.out)
        print(f"  wrote            {path}")
    if args.plot and args.plot.lower() != "none":
        import matplotlib

        matplotlib.use("Agg")
        from qzs.plotting import plot_simulation

        plot_simulation(result, path=args.plot)
        print(f"  wrote            {args.plot}")
    return 0 if result.completed else 130


def _params(args):
    from qzs.io import format_value, parameter_table, save_config

    config = _parameters(args)
    if args.toml:
        path = save_config(args.toml, config["isolator"], config["controller"])
        print(f"wrote {path}")
        return 0
    print(f"{'section':<11}{'name':<20}{'value':>12}  {'unit':<9}description")
    for section, name, value, unit, doc in parameter_table(config["isolator"],
                                                           config["controller"]):
        shown = format_value(value)
        if name == "stop_center" and value is None:
            shown = "setpoint"
        print(f"{section:<11}{name:<20}{shown:>12}  {unit:<9}{doc}")
    return 0


def _studies(args):
    import time

    from qzs.report import write_paper_outputs
    from qzs.studies import load_study, run_studies, shipped_studies

    if args.command == "paper":
        studies = [load_study(p) for p in shipped_studies()]
    else:
        studies = [load_study(args.definition)]
    if args.workers is not None and args.workers < 1:
        raise SystemExit(f"qzs: error: --workers must be >= 1, got {args.workers}")
    start = time.perf_counter()
    results = run_studies(studies, quick=args.quick, workers=args.workers,
                          progress=not args.quiet)
    wall = time.perf_counter() - start
    verdicts = write_paper_outputs(results, args.out, quick=args.quick, wall_seconds=wall)
    for result in results:
        print(f"{result.study.name:<12} {len(result.cases):>2} case(s) {result.seconds:7.1f} s")
    print(f"{'total':<12}    wall {wall:7.1f} s")
    for verdict in verdicts:
        print(f"  [{verdict.label}] {verdict.statement}\n      {verdict.evidence}")
    print(f"wrote {Path(args.out) / 'report.html'}, metrics.json, metrics.csv and figures")
    return 0


def main(argv=None):
    """Entry point of the ``qzs`` command; returns the process exit code."""
    from qzs.errors import DataError, ParameterError, SimulationError

    args = _build_parser().parse_args(argv)
    from qzs import experiment, sweep

    handlers = {"simulate": _simulate, "params": _params, "paper": _studies, "study": _studies,
                "experiment": experiment.run, "sweep": sweep.run_sweep_command,
                "sweep-plot": sweep.run_sweep_plot_command}
    try:
        return handlers[args.command](args)
    except (ParameterError, DataError, SimulationError) as error:
        print(f"qzs: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("qzs: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
