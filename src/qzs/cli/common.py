"""What every subcommand shares: ``--set`` pairs, parameter loading, ``--json``, the exit codes.

Exit codes (:data:`EXIT_CODES`), the same for every subcommand:

- 0: success.
- 1: the run started and failed (:class:`~qzs.errors.SimulationError`,
  :class:`~qzs.errors.FitError`, an I/O error while writing such as a full disk
  (:class:`~qzs.errors.WriteError`), out of memory, no working C compiler for an export
  (:class:`~qzs.errors.CompilerError`), a C model that is not the Python side's
  (:class:`~qzs.errors.CModelMismatchError`)).
- 2: bad input or usage (:class:`~qzs.errors.ParameterError` and its subclasses, such as
  :class:`~qzs.errors.CaseError` for an invalid case of a batch, found before the batch
  runs; :class:`~qzs.errors.DataError`, :class:`~qzs.errors.MissingDependencyError`;
  argparse's usage errors are 2 as well).
- 130: interrupted by Ctrl-C (SIGINT).
- 141: the reader of the output went away (a closed pipe, ``qzs params | head -1``):
  the command stops quietly, as a program killed by SIGPIPE would (128 + 13).
- 143: terminated by SIGTERM (128 + 15), after the cleanup ran (no temporary file stays).
"""
import argparse
import contextlib
import dataclasses
import json
import sys
import threading
import warnings
from pathlib import Path

from qzs._format import json_ready
from qzs.defaults import FIGURES, FREQUENCY_SCALES
from qzs.engine.progress import show_warning
from qzs.errors import (CModelMismatchError, CompilerError, DataError, FitError,
                        MissingDependencyError, ParameterError, SimulationError, Terminated,
                        WriteError)
from qzs.iotools.config import load_config, load_controller, load_spring
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters

__all__ = ["settings", "parameters", "add_set_option", "add_controller_option",
           "add_spring_option", "add_json_option",
           "add_execution_options", "add_output_options", "figure_path", "check_output",
           "OUTPUT_OPTIONS", "NO_FIGURE", "UNNAMED", "NamedOutput", "named", "output_name",
           "stopped",
           "add_frequency_axis_option", "emit", "jsonable",
           "integer_at_least", "run_handler", "memory_hint", "EXIT_CODES", "EPILOG",
           "MEMORY_HINTS", "MEMORY_HINT", "KERNEL_FAMILIES", "kernel_families",
           "start_notice", "START_NOTICE_DELAY", "run_subcommand"]

#: The output options every subcommand that writes takes (:func:`add_output_options`):
#: ``--out`` and/or ``--plot`` (what it writes), then all of ``--json``, ``--quiet`` and
#: ``--overwrite``.
OUTPUT_OPTIONS = ("--out", "--plot", "--json", "--quiet", "--overwrite")
#: The value of ``--plot`` that draws no figure.
NO_FIGURE = "none"
#: What becomes of an output the user did not name (``--out``/``--plot`` left at its default)
#: when one of that name exists, by policy: a figure, a report or an export is made again
#: from the run and replaced; a store (a sweep's, a search's) holds work that may have taken
#: hours, so it is kept and the new one named anew (``NAME-2.zarr``). The help of each such
#: option says which (:func:`add_output_options`); an output the user named is never
#: replaced without ``--overwrite``.
UNNAMED = {"replace": "a default one that exists is replaced",
           "rename": "a default one that exists is kept and the next free name taken (NAME-2, "
                     "NAME-3, ...)"}
#: Exit code -> meaning, for every subcommand.
EXIT_CODES = {0: "success", 1: "the run started and failed", 2: "bad input or usage",
              130: "interrupted (Ctrl-C)", 141: "output pipe closed by its reader",
              143: "terminated (SIGTERM), after cleanup"}
#: What to do after running out of memory, per subcommand (``hexapod <sub>`` for the
#: six-axis ones): the options that apply to it, never another command's.
MEMORY_HINTS = {
    "simulate": "choose a shorter run (--duration), a lower --sample-rate, or stream it to a "
                "file with --out",
    "hexapod simulate": "choose a shorter run (--duration), a lower --sample-rate, or stream "
                        "it to a file with --out",
    "hexapod transmissibility": "choose fewer --workers (each holds one run), a shorter "
                                "--duration or a lower --sample-rate",
    "hexapod study": "choose fewer --workers, or --quick",
    "sweep": "choose a smaller batch_size in [sweep] (cases held at once), keep fewer "
             "[outputs] time_series, or run fewer --threads",
    "response": "give fewer frequencies (--range F0,F1,N), or fewer --workers",
    "paper": "choose fewer --workers, or --quick",
    "study": "choose fewer --workers, or --quick",
    "design": "choose fewer --workers, or --quick",
}
#: The kernel families (:data:`qzs.engine.compiling.ENTRY_KERNELS`) each subcommand runs
#: (``hexapod <sub>`` for the six-axis ones): a first run on an empty kernel cache says that
#: they compile, and about how long it takes. A subcommand not listed runs no kernel.
KERNEL_FAMILIES = {
    "simulate": ("single",), "experiment": ("single",), "response": ("single",),
    "app": ("single",), "sweep": ("single", "batch"), "design": ("single", "batch"),
    "optimize": ("single", "batch"), "sensitivity": ("single", "batch"),
    "paper": ("single", "batch"), "study": ("single", "batch"),
    "hexapod simulate": ("hexapod",), "hexapod transmissibility": ("hexapod",),
    "hexapod study": ("hexapod",),
}
#: What to do after running out of memory in any other subcommand.
MEMORY_HINT = "close other programs, or ask for less (a shorter run, fewer cases)"
#: The exit codes as a help epilog.
EPILOG = "exit codes: " + ", ".join(f"{code} {text}" for code, text in EXIT_CODES.items()) + "."


def add_set_option(parser):
    """Add the repeatable ``--set NAME=VALUE`` option to ``parser``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    """
    parser.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                        help="override a parameter by its name (see `qzs params`; repeatable)")


def add_controller_option(parser):
    """Add ``--controller FILE.toml`` to ``parser``: a controller file
    (:func:`qzs.iotools.config.load_controller`) that replaces ``--config``'s controller;
    ``--set`` applies after it.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    """
    parser.add_argument("--controller", metavar="FILE.toml",
                        help="controller file: a [controller] table with its blocks' tables "
                             "([controller.compensation], [controller.dither], "
                             "[controller.linear]); replaces --config's controller")


def add_spring_option(parser, config=True):
    """Add ``--spring FILE.toml`` to ``parser``: a spring file
    (:func:`qzs.iotools.config.load_spring`, a ``[spring]`` table) whose law replaces
    ``--config``'s; ``--set`` applies after it.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    config : bool
        Whether the subcommand takes ``--config`` too (its help then says which wins).
    """
    parser.add_argument("--spring", metavar="FILE.toml",
                        help="spring file: a [spring] table (law = \"tanh\", \"oblique\", "
                             "\"polynomial\" or \"table\" and its parameters, a table's "
                             "curve as csv = \"FILE.csv\")"
                             + ("; replaces --config's spring" if config else
                                "; default the MagSpring's tanh"))


def add_json_option(parser, help_text=None):
    """Add ``--json`` to ``parser``: print the summary as one JSON object instead of text.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser; its handler then prints through :func:`emit`.
    help_text : str, optional
        The option's help, where the record is not one object.
    """
    parser.add_argument("--json", action="store_true",
                        help=help_text or "print the summary as one JSON object (NaN and inf "
                                          "as null) instead of text")


def add_frequency_axis_option(parser):
    """Add ``--frequency-axis {log,linear}`` to ``parser``: the scale of its figures'
    frequency axes (``args.frequency_axis``; None: ``qzs.defaults.FIGURES``, log).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser; its handler passes ``frequency_scale=args.frequency_axis``.
    """
    parser.add_argument("--frequency-axis", choices=FREQUENCY_SCALES, default=None,
                        help=f"frequency axis of the figures (default "
                             f"{FIGURES['frequency_scale']}: the features below 2.5 Hz and "
                             f"the roll-off to 20 Hz span decades)")


class NamedOutput(argparse.Action):
    """Store an output option's value and remember that the user named it (:func:`named`)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        setattr(namespace, "named_outputs",
                {*getattr(namespace, "named_outputs", ()), self.option_strings[0]})


def named(args, option):
    """Did the user give ``option`` (``"--out"``), rather than leave it at its default?

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.
    option : str
        An output option declared with :class:`NamedOutput` (:func:`add_output_options`,
        ``qzs params --toml``).

    Returns
    -------
    bool
    """
    return option in getattr(args, "named_outputs", ())


def add_output_options(parser, *, out=None, plot=None, json_help=None):
    """Add the output options of a subcommand that writes: ``--out`` and/or ``--plot``, then
    ``--json``, ``--quiet`` and ``--overwrite`` (:data:`OUTPUT_OPTIONS`).

    One policy for every subcommand: an output the user named that exists (a file, or a
    folder holding anything) is refused before any work, the message naming the path and
    ``--overwrite``; with ``--overwrite`` it is replaced, atomically (:func:`check_output`).
    An output left at its default name is replaced or named anew, as its help says
    (:data:`UNNAMED`). ``--plot none`` draws no figure (:func:`figure_path`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    out : dict, optional
        ``--out``'s ``metavar``, ``help``, (optional) ``default`` and, where there is a
        default (given here, or made by the command from its input), ``unnamed``: a key of
        :data:`UNNAMED`, what becomes of an existing output of that name; None: no ``--out``.
    plot : dict, optional
        ``--plot``'s ``help`` and (optional) ``default`` (None: no figure unless asked; a
        default figure is replaced); None: no ``--plot``.
    json_help : str, optional
        ``--json``'s help, where the record is not one object (:func:`add_json_option`).
    """
    policies = {}
    if out is not None:
        text = out["help"]
        if "unnamed" in out:
            policies["--out"] = out["unnamed"]
            text = f"{text}; {UNNAMED[out['unnamed']]}"
        elif out.get("default") is not None:
            raise ValueError("an --out with a default needs `unnamed` (qzs.cli.common.UNNAMED)")
        parser.add_argument("--out", metavar=out["metavar"], default=out.get("default"),
                            action=NamedOutput, help=text)
    if plot is not None:
        default = plot.get("default")
        if default:
            policies["--plot"] = "replace"
        shown = f"default {default}, replaced if it exists" if default else "default none"
        parser.add_argument("--plot", metavar="FILE", default=default, action=NamedOutput,
                            help=f"{plot['help']} (.png, .svg or .pdf; {shown}; "
                                 f"'{NO_FIGURE}' for no figure)")
    parser.set_defaults(unnamed_outputs=policies)
    add_json_option(parser, json_help)
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bar (nor the seconds of a first compilation)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace an existing output that you named (without it, one is "
                             "refused before any work); one left at its default name is "
                             "replaced or named anew, as its option says")


def figure_path(args):
    """``--plot``'s file, or None for no figure (not given, or ``--plot none``).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``plot``.

    Returns
    -------
    str or None
    """
    plot = getattr(args, "plot", None)
    return None if plot is None or plot.lower() == NO_FIGURE else plot


def check_output(args, option, path, *, suffixes, directory=False, estimated_bytes=None):
    """Check an output path before any work (:func:`qzs.iotools.paths.check_output_path`)
    under the command line's policy: an existing output the user named needs
    ``--overwrite``; one left at its default name is replaced, or named anew, as the
    subcommand declared (:data:`UNNAMED`, :func:`add_output_options`).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments; ``args.overwrite`` (absent: False) allows replacing.
    option : str
        The option that names the path (``"--out"``), for the message and to tell whether
        the user gave it (:func:`named`).
    path : str or Path
        The file or folder: the option's value, or the default the command made.
    suffixes : iterable of str or None
        Allowed extensions (None: any).
    directory : bool
        ``path`` is a folder to write into.
    estimated_bytes : float, optional
        Expected size [bytes].

    Returns
    -------
    Path
        Where to write: ``path``, or the free name taken in its place (said on stderr).
    """
    from qzs.iotools.paths import check_output_path

    path, overwrite = output_name(args, option, path, directory=directory)
    return check_output_path(path, argument=option, suffixes=suffixes, directory=directory,
                             estimated_bytes=estimated_bytes, overwrite=overwrite)


def output_name(args, option, path, *, directory=False, resume=False):
    """Where an output goes, and whether one that exists there may be replaced, under the
    command line's policy (:func:`check_output`, which checks the path too; a store's own
    checks take the answer instead).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (``overwrite``, and which outputs the user named).
    option : str
        The option that names the path (``"--out"``).
    path : str or Path
        The option's value, or the default the command made.
    directory : bool
        ``path`` is a folder (an empty one is free).
    resume : bool
        The command continues what is there (``--resume``): never named anew (nor with
        ``--overwrite``, which asks for the default to be replaced).

    Returns
    -------
    path : Path
        ``path``, or the free name taken in its place (said on stderr).
    overwrite : bool
        An existing output at ``path`` may be replaced: ``--overwrite`` given, or a default
        whose policy is ``"replace"``.
    """
    from qzs.iotools.paths import free_name

    policy = None if named(args, option) else getattr(args, "unnamed_outputs", {}).get(option)
    overwrite = getattr(args, "overwrite", False) or policy == "replace"
    path = Path(path)
    if policy == "rename" and not resume and not overwrite:
        free = free_name(path, directory=directory)
        if free != path:
            print(f"qzs: {path} exists; writing {free} ({option} names another)",
                  file=sys.stderr)
        path = free
    return path, overwrite


def add_execution_options(parser, verb="run"):
    """Add ``--scheduler`` | ``--workers`` and ``--threads`` (Dask or local).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser.
    verb : str
        What the cases do there (``run``, ``evaluate``), for the help texts.
    """
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help=f"{verb} on an existing Dask cluster (e.g. tcp://host:8786)")
    where.add_argument("--workers", type=integer_at_least(1), metavar="N",
                       help="start a local Dask cluster of N worker processes")
    parser.add_argument("--threads", type=integer_at_least(1), metavar="N",
                        help="threads per batch (default: all cores locally, 1 on Dask)")


def stopped(stop, what_is_kept):
    """Say on stderr what an interrupted or terminated run kept; return its exit code.

    Parameters
    ----------
    stop : KeyboardInterrupt or Terminated
        What ended the run.
    what_is_kept : str
        What stays and how to continue.

    Returns
    -------
    int
        130 for Ctrl-C, the signal's code (143) for SIGTERM.
    """
    import sys

    from qzs.errors import Terminated

    what, code = (("terminated", stop.exit_code) if isinstance(stop, Terminated)
                  else ("interrupted", 130))
    print(f"qzs: {what}; {what_is_kept}", file=sys.stderr)
    return code


def emit(args, text, record):
    """Print ``text``, or with ``--json`` the ``record`` as one line of strict JSON.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments; ``args.json`` (absent: False) chooses the output.
    text : str
        The human-readable summary.
    record : dict
        The same summary as data; made JSON-safe by :func:`jsonable` (NaN and inf become
        null, numpy scalars and arrays become numbers and lists).
    """
    if getattr(args, "json", False):
        print(json.dumps(jsonable(record), allow_nan=False))
    else:
        print(text)


def jsonable(value):
    """``value`` as plain JSON types: NaN and inf -> None, numpy -> Python, Path -> str.

    What :func:`qzs._format.json_ready` converts (mappings, lists, tuples and sets item by
    item, numbers, arrays, paths), and beyond it: numpy's other scalars (bytes decoded,
    dates), anything with ``items()``, a dataclass or an object with ``to_dict()``
    through its fields; anything else unknown becomes its ``str``.

    Parameters
    ----------
    value : object
        What to convert.

    Returns
    -------
    object
        None, bool, int, float (finite), str, list or dict.
    """
    return json_ready(value, _jsonable_other)


def _jsonable_other(value):
    """What :func:`jsonable` makes of what ``json_ready`` leaves."""
    import numpy as np

    if isinstance(value, np.generic):
        value = value.item()
        return value.decode() if isinstance(value, bytes) else jsonable(value)
    if hasattr(value, "items") and callable(value.items):
        return {str(k): jsonable(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)
                if not (f.metadata.get("block") and getattr(value, f.name) is None)}
    if callable(getattr(value, "to_dict", None)):
        return jsonable(value.to_dict())
    return str(value)


def integer_at_least(minimum):
    """An argparse ``type``: an integer >= ``minimum``, else a usage error (exit code 2).

    Parameters
    ----------
    minimum : int
        The smallest value allowed.

    Returns
    -------
    callable
        ``text -> int``, raising ``argparse.ArgumentTypeError`` with the value and the bound.
    """
    import argparse

    from qzs._validation import Structured, integer

    usage = Structured(build=lambda name, value, reason:
                       argparse.ArgumentTypeError(f"{reason}, got {value!r}"))

    def parse(text):
        try:
            value = int(text)
        except ValueError:
            value = text
        return integer("N", value, minimum, usage)

    parse.__name__ = f"integer >= {minimum}"
    return parse


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
    """The run configuration of ``--config`` (or the defaults), its controller replaced by
    ``--controller``'s file where given, with ``--set`` applied.

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
    if getattr(args, "controller", None):
        config["controller"] = load_controller(args.controller)
    if getattr(args, "spring", None):
        config["isolator"] = dataclasses.replace(config["isolator"],
                                                 spring=load_spring(args.spring))
    config["isolator"], config["controller"] = update_parameters(
        config["isolator"], config["controller"], settings(args.set))
    return config


def run_handler(handler, args):
    """Run a subcommand's handler and map its outcome to the exit code (:data:`EXIT_CODES`).

    Every error ends as one line ``qzs: error: ...`` on stderr, never a traceback;
    which exit code follows from the error's class, never from its message. Every warning
    raised while it runs (ours, numpy's, xarray's, ...) is one line ``qzs: warning: ...``
    (:func:`qzs.engine.progress.show_warning`), never Python's text with its source file
    and line. When the handler compiles kernels (a first run on an empty cache), a notice
    on stderr says so at once and the seconds follow while they compile (:func:`qzs.engine.compiling.compile_notice`;
    with ``--quiet`` or ``--json`` the notice alone).

    Parameters
    ----------
    handler : callable
        The subcommand's ``run(args)``, returning its exit code.
    args : argparse.Namespace
        The parsed arguments, handed to ``handler``.

    Returns
    -------
    int
        The handler's exit code; 1 after a failed run (:class:`SimulationError`,
        :class:`FitError`, :class:`WriteError`, :class:`CompilerError`,
        :class:`CModelMismatchError`, an ``OSError`` or
        ``MemoryError``); 2 after
        bad input (:class:`ParameterError` and subclasses such as :class:`CaseError`,
        :class:`DataError`, :class:`MissingDependencyError`); 130 after Ctrl-C; 143 after SIGTERM
        (:class:`~qzs.errors.Terminated`, raised by :func:`qzs.cli.main`'s handler).
        ``BrokenPipeError`` is left to :func:`qzs.cli.main` (141).
    """
    quiet = getattr(args, "quiet", False) or getattr(args, "json", False)
    try:
        with warnings.catch_warnings(), start_notice(_command(args), quiet=quiet):
            warnings.showwarning = show_warning  # restored by catch_warnings afterwards
            families = kernel_families(args)
            if not families:
                return handler(args)
            from qzs.engine.compiling import compile_notice

            with compile_notice(families, ticking=not quiet):
                return handler(args)
    except (SimulationError, FitError, WriteError, CompilerError,
            CModelMismatchError) as error:  # before DataError
        return _fail(error, 1)
    except (ParameterError, DataError, MissingDependencyError) as error:
        return _fail(error, 2)
    except KeyboardInterrupt:
        print("qzs: interrupted", file=sys.stderr)
        return 130
    except Terminated as error:
        print(f"qzs: terminated by signal {error.signum}", file=sys.stderr)
        return error.exit_code
    except BrokenPipeError:
        raise
    except OSError as error:  # writing: disk full, permission denied, ...
        where = f" {str(error.filename)!r}" if error.filename else ""
        return _fail(f"cannot access{where}: {error.strerror or error}", 1)
    except MemoryError as error:
        return _fail(f"out of memory{': ' + str(error) if str(error) else ''}; "
                     f"{memory_hint(args)}", 1)


#: Seconds a command may say nothing before :func:`start_notice` says it has started.
START_NOTICE_DELAY = 1.0


class _Watched:
    """A stream that notes (``written``) when anything is written to it; the rest delegated."""

    def __init__(self, stream, written):
        self._stream = stream
        self._written = written

    def write(self, text):
        if text:
            self._written.set()
        return self._stream.write(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextlib.contextmanager
def start_notice(command, *, quiet=False, delay=None):
    """One line on stderr if a command has said nothing ``delay`` seconds after it started.

    Loading numpy, scipy and numba and reading a command's inputs can take a few seconds
    before its first line of progress (more on a busy machine); a console silent that long
    looks hung (issue 32). While the block runs, ``sys.stdout`` and ``sys.stderr`` note
    any writing; if there was none after ``delay`` [s], ``qzs <command>: starting ...`` is
    written on stderr, once. A command that speaks first, or ends first, prints no notice;
    ``quiet`` (``--quiet``, ``--json``) none at all.

    Parameters
    ----------
    command : str or None
        The command's name, as the user typed it (``optimize``, ``hexapod study``).
    quiet : bool
        Say nothing.
    delay : float, optional
        Seconds of silence before the notice [s]; default :data:`START_NOTICE_DELAY`.
    """
    delay = START_NOTICE_DELAY if delay is None else delay
    if quiet or not command:
        yield
        return
    written = threading.Event()
    out, err = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Watched(out, written), _Watched(err, written)

    def speak():
        if not written.is_set():
            err.write(f"qzs {command}: starting (loading the numerical libraries and the "
                      "inputs) ...\n")
            err.flush()

    timer = threading.Timer(delay, speak)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        sys.stdout, sys.stderr = out, err


def run_subcommand(args):
    """Run the subcommand of a command group (``qzs hexapod``, ``qzs export``) the arguments
    name: ``args.handler``, set by the subcommand's parser; returns its exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        The subcommand's exit code.
    """
    return args.handler(args)


def _command(args):
    """``args.command``, or ``hexapod <sub>`` for the six-axis subcommands."""
    command = getattr(args, "command", None)
    if command == "hexapod":
        command = f"hexapod {getattr(args, 'hexapod_command', '')}"
    return command


def kernel_families(args):
    """The kernel families the command ``args`` describe runs (:data:`KERNEL_FAMILIES`).

    Parameters
    ----------
    args : argparse.Namespace or None
        The parsed arguments (``command``, and ``hexapod_command`` for ``qzs hexapod``).

    Returns
    -------
    tuple of str
        Keys of :data:`qzs.engine.compiling.ENTRY_KERNELS`; empty for a command that runs
        no kernel.
    """
    families = KERNEL_FAMILIES.get(_command(args), ())
    if "single" in families and (_has_blocks(args) or _spring_law(args)):
        # the general kernel (lanes.run_single_blocks)
        families = tuple("single_blocks" if f == "single" else f for f in families)
    return families


def _spring_law(args):
    """Whether the command's spring is a law other than the tanh: ``--spring``'s or
    ``--config``'s ``[spring]`` table (read only for that, as :func:`_has_blocks`)."""
    import tomllib

    path = getattr(args, "spring", None) or getattr(args, "config", None)
    if not path:
        return False
    try:
        with open(path, "rb") as handle:
            table = tomllib.load(handle).get("spring", {})
    except (OSError, ValueError):
        return False
    return isinstance(table, dict) and table.get("law", "tanh") != "tanh"


def _has_blocks(args):
    """Whether the command's controller has blocks beyond PI + damping: a ``--set`` of a
    block's parameter, or a block's table in ``--controller``'s or ``--config``'s file (read
    only for that; a file that cannot be read says nothing here: its command refuses it)."""
    import tomllib

    from qzs.model.controller import BLOCKS

    if any(str(pair).partition("=")[0].strip().partition(".")[0] in BLOCKS
           for pair in getattr(args, "set", None) or ()):
        return True
    path = getattr(args, "controller", None) or getattr(args, "config", None)
    if path:  # --controller replaces --config's controller
        try:
            with open(path, "rb") as handle:
                table = tomllib.load(handle).get("controller", {})
        except (OSError, ValueError):
            return False
        return isinstance(table, dict) and any(table.get(name) for name in BLOCKS)
    return False


def memory_hint(args):
    """What to do after running out of memory in the command ``args`` describe.

    Parameters
    ----------
    args : argparse.Namespace or None
        The parsed arguments (``command``, and ``hexapod_command`` for ``qzs hexapod``).

    Returns
    -------
    str
        The options of that command that make it take less memory (:data:`MEMORY_HINTS`),
        else :data:`MEMORY_HINT`.
    """
    return MEMORY_HINTS.get(_command(args), MEMORY_HINT)


def _fail(error, code):
    print(f"qzs: error: {error}", file=sys.stderr)
    return code
