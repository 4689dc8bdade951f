"""``qzs params``: every parameter with its default (or configured) value and unit."""
from qzs.cli.common import add_set_option, parameters
from qzs.iotools.config import save_config
from qzs.model.registry import format_value, parameter_table

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Add ``params`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``params`` parser.
    """
    params = subparsers.add_parser("params", help="print the default parameters with units")
    params.add_argument("--toml", metavar="FILE", help="write them as a config file instead")
    params.add_argument("--config", metavar="FILE.toml", help="show the values of a config file")
    add_set_option(params)
    return params


def run(args):
    """Run ``qzs params`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs params`` arguments.

    Returns
    -------
    int
        The exit code, 0.
    """
    config = parameters(args)
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
