"""What every subcommand shares: ``--set`` pairs, parameter loading, the error contract."""
import sys

from qzs.errors import DataError, MissingDependencyError, ParameterError, SimulationError
from qzs.iotools.config import load_config
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters

__all__ = ["settings", "parameters", "add_set_option", "run_handler"]


def add_set_option(parser):
    """Add the repeatable ``--set NAME=VALUE`` option to ``parser``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    """
    parser.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                        help="override a parameter by its name (see `qzs params`; repeatable)")


def settings(pairs):
    """``NAME=VALUE`` strings as a dict (values stay strings; the registry parses them).

    Parameters
    ----------
    pairs : iterable of str
        The ``--set`` values, each ``NAME=VALUE``.

    Returns
    -------
    dict
        Name -> value, both stripped of surrounding blanks.

    Raises
    ------
    ParameterError
        A pair without ``=``.
    """
    result = {}
    for pair in pairs:
        if "=" not in pair:
            raise ParameterError(f"--set expects NAME=VALUE, got {pair!r}.")
        name, value = pair.split("=", 1)
        result[name.strip()] = value.strip()
    return result


def parameters(args):
    """The run configuration of ``--config`` (or the defaults) with ``--set`` applied.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``set`` and, optionally, ``config``.

    Returns
    -------
    dict
        ``isolator``, ``controller``, ``excitation`` and ``simulation``, as
        :func:`qzs.iotools.config.load_config` gives them.
    """
    config = {"isolator": IsolatorParameters(), "controller": ControllerParameters(),
              "excitation": {}, "simulation": {}}
    if getattr(args, "config", None):
        config = load_config(args.config)
    config["isolator"], config["controller"] = update_parameters(
        config["isolator"], config["controller"], settings(args.set))
    return config


def run_handler(handler, args):
    """Run a subcommand's handler; bad input is one line on stderr and exit code 2.

    Parameters
    ----------
    handler : callable
        The subcommand's ``run(args)``, returning its exit code.
    args : argparse.Namespace
        The parsed arguments, handed to ``handler``.

    Returns
    -------
    int
        The handler's exit code; 2 after a :class:`ParameterError`, :class:`DataError`,
        :class:`SimulationError` or :class:`MissingDependencyError`; 130 after Ctrl-C.
    """
    try:
        return handler(args)
    except (ParameterError, DataError, SimulationError, MissingDependencyError) as error:
        print(f"qzs: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("qzs: interrupted", file=sys.stderr)
        return 130
