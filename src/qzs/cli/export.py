"""``qzs export``: the controller as one C file, and the isolator as an FMU (docs/fmu.md)."""
import sys

from qzs.cli.common import EPILOG, add_set_option, parameters
from qzs.defaults import SIMULATION

__all__ = ["add_parser", "run", "run_controller"]

#: The sample rate a continuous configuration's controller is exported at [Hz].
DEFAULT_CONTROLLER_RATE = 1000.0


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
        description="qzs outside Python: the sampled PI + active damping controller as one "
                    "dependency-free C file, and the isolator as an FMI co-simulation FMU "
                    "(`qzs docs fmu`).")
    sub = export.add_subparsers(dest="export_command", required=True)
    controller = sub.add_parser(
        "controller", help="the sampled controller as one C file",
        description="Write the sampled PI + active damping controller (high-passed velocity "
                    "from the charge amplifier, anti-windup, saturation) of a configuration as "
                    "one C99 file with an init and a step function: the very code the C model "
                    "and the closed-loop FMU call. A continuous controller (controller_rate = "
                    f"0) is exported at {DEFAULT_CONTROLLER_RATE:g} Hz.", epilog=EPILOG)
    controller.add_argument("--config", metavar="FILE.toml",
                            help="run configuration (see `qzs params --toml`)")
    add_set_option(controller)
    controller.add_argument("--dt", type=float, metavar="S",
                            help="integration step of the qzs run it reproduces [s] (default "
                                 f"the configuration's, else {SIMULATION['dt']:g}); the sample "
                                 "period is a whole number of it")
    controller.add_argument("--out", metavar="FILE.c", default="controller.c",
                            help="the C file to write (default controller.c)")
    controller.set_defaults(handler=run_controller)
    return export


def run(args):
    """Run the ``qzs export`` subcommand the arguments name; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments (``args.handler`` is the subcommand's).

    Returns
    -------
    int
        The subcommand's exit code.
    """
    return args.handler(args)


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
    from qzs.iotools.paths import check_output_path

    check_output_path(args.out, argument="--out", suffixes=(".c",))
    config = parameters(args)
    controller = config["controller"]
    if controller.controller_rate <= 0.0:
        controller = dataclasses.replace(controller, controller_rate=DEFAULT_CONTROLLER_RATE)
        print(f"qzs: the controller is continuous; exporting it sampled at "
              f"{DEFAULT_CONTROLLER_RATE:g} Hz (--set controller_rate=HZ to choose)",
              file=sys.stderr)
    dt = args.dt if args.dt is not None else config["simulation"].get("dt", SIMULATION["dt"])
    path = export_controller(args.out, controller, config["isolator"], dt=dt, argument="--out")
    print(f"wrote {path}")
    return 0
