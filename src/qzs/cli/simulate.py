"""``qzs simulate``: one run, its summary, its figure and optionally its time series.

``--duration`` is the simulated time, as ``duration`` is in :func:`qzs.simulate`; the
excitation's own length (a chirp's sweep time, a random record's length) is
``--excitation-duration``. An option the chosen excitation does not use is an error.
"""
from qzs.analysis.summary import summary_record
from qzs.cli.common import (EPILOG, add_controller_option, add_output_options, add_set_option,
                             add_spring_option,
                             check_output, emit, figure_path, parameters)
from qzs.defaults import ACCURACY, EXCITATION, SIMULATION
from qzs.errors import ParameterError
from qzs.iotools.files import RESULT_SUFFIXES
from qzs.model.excitation import EXCITATION_KINDS, EXCITATION_OPTIONS, build_excitation

__all__ = ["add_parser", "run"]

DEFAULT_PLOT = "qzs-simulation.png"
#: Formats ``--plot`` writes (matplotlib chooses by the extension).
PLOT_SUFFIXES = (".png", ".svg", ".pdf")
#: Command-line flag -> the excitation option it sets (names of ``EXCITATION_OPTIONS``).
_FLAGS = {"--amplitude": "amplitude", "--f0": "f0", "--f1": "f1", "--frequency": "frequency",
          "--phase": "phase", "--method": "method", "--seed": "seed", "--record": "record",
          "--excitation-duration": "duration", "--fade-in": "fade_in"}


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
                    "(10 mm chirp, 0-20 Hz, 2000 s, ode3) at the largest step that keeps its "
                    "transmissibility within 0.01 dB (the paper's dt = 1e-4 s with --dt 1e-4), "
                    "summary and plot. "
                    "--duration is the simulated time (default: the whole excitation); "
                    "the excitation's own length is --excitation-duration, so "
                    "`--duration 60` simulates the first 60 s of the 2000 s chirp, as "
                    "qzs.simulate(Chirp(), duration=60) does.",
        epilog=EPILOG)
    sim.add_argument("--config", metavar="FILE.toml",
                     help="run configuration (see `qzs params --toml`)")
    add_controller_option(sim)
    add_spring_option(sim)
    add_set_option(sim)
    sim.add_argument("--excitation", choices=tuple(EXCITATION_KINDS),
                     help="base excitation (default chirp)")
    sim.add_argument("--amplitude", type=float, metavar="M",
                     help="displacement amplitude [m] (RMS for random; default "
                          f"{EXCITATION['amplitude']:.3f})")
    sim.add_argument("--f0", type=float, metavar="HZ", help="chirp start / random band low [Hz]")
    sim.add_argument("--f1", type=float, metavar="HZ", help="chirp end / random band high [Hz]")
    sim.add_argument("--frequency", type=float, metavar="HZ", help="sine frequency [Hz]")
    sim.add_argument("--phase", type=float, metavar="RAD", help="sine phase at t = 0 [rad]")
    sim.add_argument("--method", choices=("linear", "logarithmic"), help="chirp sweep law")
    sim.add_argument("--seed", type=int, help="random excitation seed (>= 0)")
    sim.add_argument("--record", metavar="FILE.csv",
                     help="displacement record for --excitation file (columns time, displacement)")
    sim.add_argument("--excitation-duration", type=float, metavar="S",
                     help="the excitation's length [s]: chirp sweep time (default 2000), "
                          "random record length (default 100)")
    sim.add_argument("--fade-in", type=float, metavar="S",
                     help="smooth fade-in of the excitation [s] (default 2 for sine, random "
                          "and file, a quarter of a shorter one; 0 for chirp; 0 starts at "
                          "full amplitude)")
    sim.add_argument("--duration", type=float, metavar="S",
                     help="simulated time [s] (default the excitation's length; 10 for a sine)")
    step = sim.add_mutually_exclusive_group()
    step.add_argument("--dt", type=float, metavar="S",
                      help="a literal integration step [s] (the paper's: 1e-4); default: the "
                           "largest step meeting --tolerance")
    step.add_argument("--tolerance", type=float, metavar="DB",
                      help="choose the largest step whose transmissibility stays within DB "
                           "[dB] of a finer one, on a short probe of the excitation "
                           f"(`qzs docs model` §7; default {ACCURACY['tolerance_db']:g}; a sine: "
                           "--tolerance-state)")
    step.add_argument("--tolerance-state", type=float, metavar="M",
                      help="choose the largest step whose relative position stays within M "
                           f"[m] of a finer one (default for a sine: "
                           f"{ACCURACY['tolerance_state']:g})")
    sim.add_argument("--sample-rate", type=float, metavar="HZ",
                     help="output rate [Hz] (default 1000)")
    sim.add_argument("--solver", choices=("ode3", "rk4", "euler"),
                     help="integrator (default ode3)")
    add_output_options(sim, out=dict(metavar="FILE", help="stream the time series to FILE (.nc, "
                                                         ".csv or .mat for MATLAB) while "
                                                         "simulating"),
                       plot=dict(default=DEFAULT_PLOT, help="figure of the run"))
    return sim


def _excitation(args, table, source):
    """The excitation: the config's ``[excitation]`` table, then the command line's flags."""
    options = dict(table)
    kind = args.excitation or options.get("kind", "chirp")
    options.pop("kind", None)
    names = {name: f"[excitation] {name}" for name in options}
    origin = {name: f"`{name}` in the [excitation] table of {source}" for name in options}
    for flag, name in _FLAGS.items():
        value = getattr(args, flag[2:].replace("-", "_"))
        if value is not None:
            options[name] = value
            names[name] = flag
            origin[name] = f"`{flag}`"
    unused = [origin[name] for name in options if name not in EXCITATION_OPTIONS[kind]]
    if unused:
        usable = [f"--{'excitation-duration' if o == 'duration' else o.replace('_', '-')}"
                  for o in EXCITATION_OPTIONS[kind]]
        raise ParameterError(
            f"{', '.join(unused)} is not used by a {kind} excitation (it takes "
            f"{', '.join(usable)}); drop it or choose the excitation that uses it "
            "(--excitation).")
    return build_excitation(kind, options, names=names)


def _spelling(args, settings, table):
    """How the command line names each argument of :func:`qzs.resolve`: its flag, or the
    config file's key where the value came from its ``[simulation]`` ``table`` (an error
    says it so); a default the command line put in (a sine's 10 s) is its flag's."""
    def origin(key, flag):
        if getattr(args, key, None) is None and key in table:
            return f"[simulation] {key} of {args.config}"
        return flag

    if "duration" in settings:  # --duration, or the config's [simulation] duration
        duration = origin("duration", "--duration")
    elif args.excitation_duration is not None:
        duration = "--excitation-duration"
    else:
        duration = f"[excitation] duration of {args.config}"
    record = ("--excitation-duration" if args.excitation_duration is not None
              else f"[excitation] duration of {args.config}")
    return {"duration": duration, "excitation.duration": record,
            "sample_rate": origin("sample_rate", "--sample-rate"),
            "dt": origin("dt", "--dt"), "solver": origin("solver", "--solver"),
            "tolerance": "--tolerance", "tolerance_state": "--tolerance-state",
            "frequency": "--frequency", "f1": "--f1", "f_high": "--f1",
            "sample_time": f"[controller.linear] sample_time of {args.controller or args.config}"}


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
    import sys

    from qzs.engine.run_spec import check_output_rate, resolve
    from qzs.workflows.run import resolve_apart
    from qzs.workflows.figure_process import simulate_with_figure

    config = parameters(args)
    excitation = _excitation(args, config["excitation"], args.config)
    settings = dict(config["simulation"])
    for key in ("dt", "sample_rate", "solver", "duration"):
        value = getattr(args, key)
        if value is not None:
            settings[key] = value
    if args.tolerance is not None or args.tolerance_state is not None:
        settings.pop("dt", None)  # a tolerance on the command line replaces the file's dt
    if excitation.duration is None and "duration" not in settings:
        settings["duration"] = 10.0
        print("qzs: no --duration given for the sine; simulating 10 s", file=sys.stderr)
    plot = figure_path(args)
    if plot is not None:
        check_output(args, "--plot", plot, suffixes=PLOT_SUFFIXES)
    if args.out:
        check_output(args, "--out", args.out, suffixes=RESULT_SUFFIXES)
    show = not args.quiet and not args.json
    try:  # resolve() checks the inputs; the command line only says them its own way
        check_output_rate(excitation, settings.get("duration", excitation.duration),
                          settings.get("sample_rate", SIMULATION["sample_rate"]))
        # a streamed run's step is chosen apart: its imports do not weigh on the run
        resolved = (resolve_apart if args.out else resolve)(
            excitation, config["isolator"], config["controller"], **settings,
            tolerance=args.tolerance, tolerance_state=args.tolerance_state, step="chosen",
            progress=show)
    except ParameterError as error:
        raise error.renamed(_spelling(args, settings, config["simulation"])) from None
    result = simulate_with_figure(resolved, out=args.out, plot=plot, progress=show,
                                  interruptible=True, argument="--out")
    files = {}
    if args.out:
        files["out"] = args.out
    if plot is not None:
        files["plot"] = plot
    step = resolved.step
    notes = "".join(f"\n                   note: {note}" for note in step.notes)
    text = (result.summary() + notes
            + "".join(f"\n  wrote            {p}" for p in files.values()))
    record = {**summary_record(result), "files": files, "step": step.to_dict()}
    emit(args, text, record)
    return 0 if result.completed else 130
