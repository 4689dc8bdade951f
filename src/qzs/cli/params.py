"""``qzs params``: every parameter with its default (or configured) value and unit."""
from qzs.cli.common import (EPILOG, NamedOutput, add_controller_option, add_set_option,
                             check_output, parameters)
from qzs.iotools.config import config_text, save_config
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
    params = subparsers.add_parser(
        "params", help="print the default parameters with units",
        description="Print every parameter with its value (the defaults, or --config's, with "
                    "--set applied), unit and description; or write them as a config file.",
        epilog="--toml FILE never replaces a file without --overwrite; --toml alone prints "
               "the file to stdout (`qzs params --toml > my.toml`). " + EPILOG)
    params.add_argument("--toml", metavar="FILE.toml", nargs="?", const="-", action=NamedOutput,
                        help="write them as a config file instead (to stdout without FILE, "
                             "or with -)")
    params.add_argument("--overwrite", "--force", dest="overwrite", action="store_true",
                        help="let --toml replace an existing file (--force: the old name)")
    params.add_argument("--config", metavar="FILE.toml", help="show the values of a config file")
    add_controller_option(params)
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

    Raises
    ------
    OutputPathError
        ``--toml`` names an existing file without ``--overwrite``, or a path that cannot be
        written (checked before anything is written).
    """
    to_file = args.toml is not None and args.toml != "-"
    if to_file:
        check_output(args, "--toml", args.toml, suffixes=(".toml",),
                     estimated_bytes=64 * 1024)
    config = parameters(args)
    if args.toml == "-":  # only the file's text: `qzs params --toml > my.toml`
        print(config_text(config["isolator"], config["controller"]), end="")
        return 0
    if to_file:
        path = save_config(args.toml, config["isolator"], config["controller"])
        print(f"wrote {path}")
        return 0
    rows = parameter_table(config["isolator"], config["controller"])
    width = max(20, 1 + max(len(row[1]) for row in rows))
    print(f"{'section':<11}{'name':<{width}}{'value':>12}  {'unit':<9}description")
    for section, name, value, unit, doc in rows:
        shown = format_value(value)
        if name == "stop_center" and value is None:
            shown = "setpoint"
        print(f"{section:<11}{name:<{width}}{shown:>12}  {unit:<9}{doc}")
    return 0
