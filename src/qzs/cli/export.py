"""``qzs export``: the controller as one C file, and the isolator as an FMU (docs/fmu.md)."""
import sys

from qzs.cli.common import (EPILOG, add_output_options, add_set_option, add_spring_option,
                             check_output, emit, parameters)
from qzs.defaults import SIMULATION

__all__ = ["add_parser", "run_controller", "run_fmu"]

#: The internal excitation's options: flag, type, metavar, help (as ``qzs simulate`` has them).
_EXCITATION_FLAGS = (
    ("--amplitude", float, "M", "displacement amplitude [m]"),
    ("--f0", float, "HZ", "chirp start frequency [Hz]"),
    ("--f1", float, "HZ", "chirp end frequency [Hz]"),
    ("--frequency", float, "HZ", "sine frequency [Hz]"),
    ("--phase", float, "RAD", "sine phase at t = 0 [rad]"),
    ("--method", str, "linear|logarithmic", "chirp sweep law"),
    ("--excitation-duration", float, "S", "the chirp's sweep time [s]"),
    ("--fade-in", float, "S", "smooth fade-in of the excitation [s]"),
)
#: The sample rate a continuous configuration's controller is exported at [Hz].
DEFAULT_CONTROLLER_RATE = 1000.0
#: How ``qzs export fmu`` names the arguments of :func:`qzs.export_fmu` (and of what it
#: resolves) in its messages: by their flags.
_FMU_SPELLING = {"communication_step": "--step", "1/communication_step": "1/--step",
                 "duration": "--duration", "dt": "--dt", "tolerance": "--tolerance",
                 "tolerance_db": "--tolerance", "tolerance_state": "--tolerance-state",
                 "solver": "--solver", "frequency": "--frequency", "f1": "--f1", "f0": "--f0",
                 "fmi_version": "--fmi", "mode": "--mode", "base_motion": "--base-motion"}


def add_parser(subparsers):
    """Add ``export`` and its subcommands to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``export`` parser.
    """
    export = subparsers.add_parser(
        "export", help="the controller as C, the isolator as an FMU",
        description="qzs outside Python: the sampled controller (PI + active damping and its "
                    "blocks) as one C file, and the isolator as an FMI co-simulation FMU "
                    "(`qzs docs fmu`).")
    sub = export.add_subparsers(dest="export_command", required=True)
    controller = sub.add_parser(
        "controller", help="the sampled controller as one C file",
        description="Write the sampled controller of a configuration (PI + active damping on "
                    "the charge amplifier's high-passed velocity, anti-windup, saturation, and "
                    "its blocks: friction compensation and observer, dither, a discrete linear "
                    "controller) as one C99 file with an init and a step function: the very "
                    "laws the C model and the closed-loop FMU call (`qzs docs fmu` §8). A "
                    "continuous controller (controller_rate = 0) is exported at "
                    f"{DEFAULT_CONTROLLER_RATE:g} Hz; a continuous linear controller is "
                    "refused (discretise it).", epilog=EPILOG)
    controller.add_argument("--config", metavar="FILE.toml",
                            help="run configuration (see `qzs params --toml`)")
    add_set_option(controller)
    controller.add_argument("--dt", type=float, metavar="S",
                            help="integration step of the qzs run it reproduces [s] (default "
                                 f"the configuration's, else {SIMULATION['dt']:g}); the sample "
                                 "period is a whole number of it")
    add_output_options(controller, out={"metavar": "FILE.c", "default": "controller.c",
                                        "unnamed": "replace", "help": "the C file to write (default controller.c)"})
    controller.set_defaults(handler=run_controller)
    fmu = sub.add_parser(
        "fmu", help="the isolator as an FMI co-simulation FMU",
        description="Write the single-axis isolator as an FMI 3.0 (default) or 2.0 "
                    "co-simulation FMU: qzs's C model (no Python inside) in sources/ and "
                    "compiled for this platform, every parameter with its SI unit, the "
                    "recorded channels as outputs. Closed loop (PI and damping inside) or plant "
                    "(the motor force an input); the chirp or sine of the configuration inside, "
                    "or the base motion as inputs (`qzs docs fmu`). Needs a C compiler and "
                    "FMPy's FMI headers (pip install \"qzs[fmu]\").", epilog=EPILOG)
    add_output_options(fmu, out={"metavar": "FILE.fmu", "default": "isolator.fmu",
                                 "unnamed": "replace", "help": "the FMU to write (default isolator.fmu)"})
    fmu.add_argument("--fmi", type=int, choices=(3, 2), default=3,
                     help="FMI version (default 3)")
    fmu.add_argument("--mode", choices=("closed-loop", "plant"), default="closed-loop",
                     help="closed-loop: the PI and damping inside (default); plant: the motor "
                          "force is an input")
    fmu.add_argument("--base-motion", choices=("internal", "input"), default="internal",
                     help="internal: the chirp or sine as FMU parameters (default); input: base "
                          "displacement, velocity and acceleration as inputs")
    fmu.add_argument("--config", metavar="FILE.toml",
                     help="run configuration (see `qzs params --toml`)")
    add_spring_option(fmu)
    add_set_option(fmu)
    fmu.add_argument("--excitation", choices=("chirp", "sine"),
                     help="the internal excitation (default the configuration's, else chirp)")
    for flag, kind, metavar, text in _EXCITATION_FLAGS:
        fmu.add_argument(flag, type=kind, metavar=metavar, help=text)
    step = fmu.add_mutually_exclusive_group()
    step.add_argument("--dt", type=float, metavar="S",
                      help="a literal internal integration step [s] (default the "
                           "configuration's, else the step `qzs simulate` chooses; "
                           "`qzs.export_fmu` in Python takes 1e-4 s literally)")
    step.add_argument("--tolerance", type=float, metavar="DB",
                      help="choose the internal step as `qzs simulate --tolerance` does [dB] "
                           "(default 0.01; a sine: --tolerance-state)")
    step.add_argument("--tolerance-state", type=float, metavar="M",
                      help="choose the internal step for the relative position within M [m]")
    fmu.add_argument("--solver", choices=("ode3", "rk4", "euler"),
                     help="integrator (default ode3)")
    fmu.add_argument("--duration", type=float, metavar="S",
                     help="the default experiment's stop time [s] (default the excitation's "
                          "length, 10 for a sine or inputs)")
    fmu.add_argument("--step", type=float, metavar="S",
                     help="the default experiment's communication step [s] (default 0.001); "
                          "the FMU takes any positive step")
    fmu.set_defaults(handler=run_fmu)
    return export


def run_controller(args):
    """``qzs export controller``: write the controller's C file.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    import dataclasses

    from qzs.export.controller import export_controller

    check_output(args, "--out", args.out, suffixes=(".c",))
    config = parameters(args)
    controller = config["controller"]
    if controller.controller_rate <= 0.0:
        controller = dataclasses.replace(controller, controller_rate=DEFAULT_CONTROLLER_RATE)
        print(f"qzs: the controller is continuous; exporting it sampled at "
              f"{DEFAULT_CONTROLLER_RATE:g} Hz (--set controller_rate=HZ to choose)",
              file=sys.stderr)
    dt = args.dt if args.dt is not None else config["simulation"].get("dt", SIMULATION["dt"])
    path = export_controller(args.out, controller, config["isolator"], dt=dt, argument="--out")
    emit(args, f"wrote {path}", {"files": {"out": str(path)},
                                 "controller_rate": controller.controller_rate, "dt": dt})
    return 0


def _fmu_spelling(args, settings):
    """:data:`_FMU_SPELLING`, with a value the configuration file gave named as its key there
    (the ``[simulation]`` table's ``dt``, ``duration`` or ``solver``)."""
    spelling = dict(_FMU_SPELLING)
    for key, flag in (("dt", "--dt"), ("duration", "--duration"), ("solver", "--solver")):
        if getattr(args, key, None) is None and key in settings:
            spelling[key] = f"[simulation] {key} of {args.config}"
    if args.excitation_duration is not None and args.duration is None \
            and "duration" not in settings:
        spelling["duration"] = "--excitation-duration"
    return spelling


def run_fmu(args):
    """``qzs export fmu``: write the FMU.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    from qzs.cli.simulate import _excitation
    from qzs.errors import ParameterError
    from qzs.export.fmu import export_fmu

    check_output(args, "--out", args.out, suffixes=(".fmu",))
    config = parameters(args)
    settings = dict(config["simulation"])
    excitation = None
    if args.base_motion == "internal":
        args.seed = args.record = None  # not options of an FMU: its excitation is a chirp or sine
        excitation = _excitation(args, config["excitation"], args.config)
    elif args.excitation or any(getattr(args, flag[2:].replace("-", "_")) is not None
                                for flag, *_ in _EXCITATION_FLAGS):
        raise ParameterError("--excitation and its options are not used with --base-motion "
                             "input (the base motion comes from the FMU's inputs); drop them.")
    try:  # export_fmu checks the inputs; the command line only says them its own way
        path = export_fmu(args.out, excitation, config["isolator"], config["controller"],
                          fmi_version=args.fmi, mode=args.mode, base_motion=args.base_motion,
                          dt=args.dt if args.dt is not None else (
                              None if args.tolerance is not None
                              or args.tolerance_state is not None else settings.get("dt")),
                          tolerance=args.tolerance, tolerance_state=args.tolerance_state,
                          step="chosen",
                          solver=args.solver or settings.get("solver", SIMULATION["solver"]),
                          duration=args.duration if args.duration is not None
                          else settings.get("duration"),
                          communication_step=args.step, argument="--out")
    except ParameterError as error:
        raise error.renamed(_fmu_spelling(args, settings)) from None
    emit(args, f"wrote {path} (FMI {args.fmi}.0 co-simulation, {args.mode}, base motion "
               f"{args.base_motion}); `qzs docs fmu` shows how to use it",
         {"files": {"out": str(path)}, "fmi": args.fmi, "mode": args.mode,
          "base_motion": args.base_motion})
    return 0
