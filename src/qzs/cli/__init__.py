"""The ``qzs`` command line: argparse only, one module per subcommand; it computes nothing.

    qzs simulate [--config FILE.toml] [--set NAME=VALUE ...] [--excitation chirp|sine|random|file]
                 [--amplitude M] [--f0 HZ] [--f1 HZ] [--frequency HZ] [--duration S]
                 [--dt S] [--sample-rate HZ] [--solver ode3|rk4|euler] [--out FILE.nc|.csv|.mat]
    qzs params [--toml FILE]
    qzs study FILE.toml [--quick] [--out DIR] [--workers N]
    qzs paper [--quick] [--out DIR] [--workers N]
    qzs experiment LOG --map MAP.toml [--out DIR]
    qzs sweep FILE.toml [--resume] [--workers N | --scheduler ADDRESS]
    qzs sweep-plot STORE [--metric NAME] [--x PARAM] [--y PARAM]
    qzs sweep-export STORE [--out FILE.mat]
    qzs response [--frequencies F1,F2,... | --range F0,F1,N] [--direction up|down|both] [--json]
    qzs design [--config FILE.toml] [--set NAME=VALUE] [--stiction-range LOW,HIGH] [--quick]
    qzs optimize FILE.toml [--out DIR] [--resume] [--workers N | --scheduler ADDRESS]
    qzs sensitivity FILE.toml [--method sobol|morris] [--samples N] [--out DIR]
    qzs app [--port N] [--host ADDRESS] [--no-browser]
    qzs export controller [--config FILE.toml] [--set NAME=VALUE ...] [--dt S] [--out FILE.c]
    qzs export fmu [--out FILE.fmu] [--fmi 3|2] [--mode closed-loop|plant]
                   [--base-motion internal|input] [--config FILE.toml] [--set NAME=VALUE ...]
    qzs docs [TOPIC [SECTION]]
    qzs completion bash|zsh

Every subcommand hands its parsed arguments to a function of the layers below; one module
per subcommand (or pair of subcommands), and what they share:

================  =======================================================================
``common``        ``--set`` pairs, parameter loading, ``--json``, the exit codes
``simulate``      ``qzs simulate``: one run, its summary, figure and time series
``params``        ``qzs params``: every parameter with its value and unit
``studies``       ``qzs paper`` and ``qzs study``: the paper's studies and report
``experiment``    ``qzs experiment``: an experiment log beside the matching simulation
``sweep``         ``qzs sweep``, ``sweep-plot``, ``sweep-export``: Zarr store, figures, .mat
``response``      ``qzs response``: the steady-state response by stepped-sine simulation
``design``        ``qzs design``: PI and damping gains from the isolator and its disturbance
``design_space``  ``qzs optimize``, ``qzs sensitivity``: Pareto search and Sobol/Morris indices
``hexapod``       ``qzs hexapod``: the six-axis platform of six isolator legs
``app``           ``qzs app``: the interactive tuning page in the browser
``export``        ``qzs export``: the controller as one C file, the isolator as an FMU
``docs``          ``qzs docs``: the model and workflow pages shipped inside the package
``completion``    ``qzs completion``: bash and zsh completion scripts from the parser
================  =======================================================================

Exit codes, the same for every subcommand (:data:`qzs.cli.common.EXIT_CODES`): 0 success,
1 a failed run, 2 bad input or usage (one line on stderr, never a traceback), 130 Ctrl-C,
141 the output pipe was closed by its reader (``qzs params | head -1`` ends quietly),
143 SIGTERM (converted into :class:`qzs.errors.Terminated`, so that cleanup runs and no
temporary file stays behind).

An empty argument (``--out ''``, ``qzs sweep ''``) is refused by name before any work,
never read as if the option were absent or as the current folder. On a console whose
encoding cannot show a character (cp1252 on Windows has no U+2212 minus), the character
is spelled in ASCII (``-``, ``<=``, ``phi``) instead of failing: one error handler,
:data:`CONSOLE_ERRORS`, set on stdout and stderr here.
"""
import argparse
import atexit
import codecs
import os
import re
import signal
import sys
import threading
import unicodedata

from qzs._version import __version__
from qzs.cli import (app, completion, design, design_space, docs, experiment, export, hexapod,
                     params, response, simulate, studies, sweep)
from qzs.cli.common import EPILOG, run_handler, run_subcommand
from qzs.errors import Terminated

__all__ = ["main", "console", "build_parser", "CONSOLE_ERRORS"]

#: Name of the codec error handler that spells a character the console cannot encode.
CONSOLE_ERRORS = "qzs-transliterate"
#: ASCII spellings of the symbols the pages and messages use; other characters are
#: decomposed (x-dot -> x, superscript 4 -> 4) or named (Greek phi -> phi), else ``?``.
_ASCII = {"\u2212": "-", "\u2013": "-", "\u2014": "--", "\u2192": "->", "\u2190": "<-",
          "\u21d2": "=>", "\u2264": "<=", "\u2265": ">=", "\u2248": "~", "\u2260": "!=",
          "\u221e": "inf", "\u221a": "sqrt", "\u00d7": "x", "\u00b7": "*", "\u1d40": "^T",
          "\u2213": "-+", "\u00b1": "+-", "\u221d": "~", "\u2207": "grad", "\u03a3": "Sum",
          "\u2026": "...", "\u2018": "'", "\u2019": "'", "\u201c": '"', "\u201d": '"'}

HANDLERS = {"simulate": simulate.run, "params": params.run, "paper": studies.run,
            "study": studies.run, "experiment": experiment.run,
            "sweep": sweep.run_sweep_command, "sweep-plot": sweep.run_plot_command,
            "sweep-export": sweep.run_export_command,
            "hexapod": run_subcommand, "response": response.run,
            "design": design.run, "optimize": design_space.run_optimize_command,
            "sensitivity": design_space.run_sensitivity_command,
            "app": app.run, "export": run_subcommand, "docs": docs.run,
            "completion": completion.run}


class Parser(argparse.ArgumentParser):
    """argparse's parser that reads every negative number as a value, as Python 3.13's does.

    Python 3.11's argparse takes only ``-1`` and ``-1.5`` for numbers: ``--dt -1e-4``,
    ``--frequencies -1,2`` or ``--mass-range -1,6.4`` stopped at "expected one argument"
    before the option's check could say what is wrong with the value. No option of qzs
    looks like a number, so an argument that starts with ``-`` and a digit (or ``-.`` and
    a digit) is always a value; the subparsers inherit the class.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")


def build_parser():
    """The ``qzs`` argument parser with every subcommand."""
    parser = Parser(
        prog="qzs", description="Semi-active quasi-zero-stiffness isolator toolkit.",
        epilog="The model, its signs, defaults and every modelling decision: `qzs docs model` "
               "(`qzs docs` lists every page). Parameter names and units: `qzs params`. "
               "Shell completion: `qzs completion bash|zsh`. " + EPILOG)
    parser.add_argument("--version", action="version", version=f"qzs {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    simulate.add_parser(sub)
    studies.add_parsers(sub)
    experiment.add_parser(sub)
    sweep.add_parsers(sub)
    design_space.add_parsers(sub)
    params.add_parser(sub)
    hexapod.add_parser(sub)
    design.add_parser(sub)
    response.add_parser(sub)
    app.add_parser(sub)
    export.add_parser(sub)
    docs.add_parser(sub)
    completion.add_parser(sub, parser)
    for command in sub.choices.values():  # every subcommand's help ends with the exit codes
        if EPILOG not in (command.epilog or ""):
            command.epilog = f"{command.epilog} {EPILOG}" if command.epilog else EPILOG
    return parser


def main(argv=None):
    """Entry point of the ``qzs`` command; returns the process exit code.

    While it runs, SIGTERM raises :class:`qzs.errors.Terminated` in the main thread
    (so ``finally`` blocks and atomic writers clean up) and the previous handler is
    restored afterwards. A reader that closes the output pipe early ends the command
    quietly: the rest of stdout goes to ``os.devnull`` and the exit code is 141.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``qzs``; default ``sys.argv[1:]``.

    Returns
    -------
    int
        0 success, 1 a failed run, 2 bad input or usage, 130 interrupted (Ctrl-C),
        141 output pipe closed, 143 terminated (SIGTERM); see
        :data:`qzs.cli.common.EXIT_CODES`.
    """
    previous = _catch_sigterm()
    _console_safe()
    try:
        try:
            parser = build_parser()
            args = parser.parse_args(argv)
        except SystemExit as exit_:  # --help, --version, usage errors (2)
            _flush_stdout()
            return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None
                                                                   else 2)
        empty = _empty_argument(parser, args)
        if empty is not None:
            print(f"qzs: error: {empty}", file=sys.stderr)
            return 2
        code = run_handler(HANDLERS[args.command], args)
        _flush_stdout()  # a closed pipe shows here, not as "Exception ignored" at exit
        return code
    except BrokenPipeError:
        _silence_stdout()
        return 141
    except Terminated as error:  # outside a handler: while parsing or flushing
        return error.exit_code
    except KeyboardInterrupt:
        return 130
    finally:
        _restore_sigterm(previous)


def console():
    """The ``qzs`` console script and ``python -m qzs``: :func:`main`, then the process ends.

    Once the command is done (its files closed, its output flushed, its helper processes
    and threads joined), Python's exit handlers (:mod:`atexit`) run, both streams are
    flushed and the process ends at once (:func:`os._exit`), without the interpreter's
    teardown of every loaded module: freeing numba's, scipy's, xarray's and zarr's objects
    one by one took 0.25 s after ``qzs simulate`` and 0.45 s after ``qzs optimize`` on the
    2-core test machine, after the answer was already written. If a thread other than the
    main one is still running and is not a daemon, the ordinary exit joins it instead; so
    it does under a profiler or a tracer (``python -m cProfile -m qzs``, a debugger), which
    writes its record after the command returns.
    An exception that escapes :func:`main` (a bug) ends the process the ordinary way, with
    its traceback.
    """
    code = main()
    if sys.getprofile() is not None or sys.gettrace() is not None or any(
            thread.is_alive() and not thread.daemon and thread is not threading.main_thread()
            for thread in threading.enumerate()):
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing left to say
            pass
    os._exit(code)


def _empty_argument(parser, args):
    """The message for the first argument given as an empty string, or None.

    An empty path would otherwise run on as if the option were absent (``--out ''``) or
    read as the current folder (``Path('')`` is ``'.'``); no option of qzs takes an
    empty value.
    """
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            chosen = action.choices.get(getattr(args, action.dest, None))
            found = None if chosen is None else _empty_argument(chosen, args)
            if found is not None:
                return found
            continue
        value = getattr(args, action.dest, None)
        values = value if isinstance(value, list) else [value]
        if not any(isinstance(item, str) and not item.strip() for item in values):
            continue
        if action.option_strings:
            flag = max(action.option_strings, key=len)
            shown = f" {action.metavar}" if isinstance(action.metavar, str) else ""
            fix = "" if action.required else f", or leave {flag} out for its default"
            return f"`{flag}` is empty ({value!r}); give{shown or ' a value'} after {flag}{fix}"
        name = action.metavar if isinstance(action.metavar, str) else action.dest.upper()
        return f"{name} is empty ({value!r}); give a non-empty {name}"
    return None


def _transliterate(error):
    """Codec error handler: the unencodable characters of ``error`` spelled in ASCII."""
    if not isinstance(error, UnicodeEncodeError):
        raise error
    spelled = []
    for char in error.object[error.start:error.end]:
        ascii_ = _ASCII.get(char)
        if ascii_ is None:
            decomposed = unicodedata.normalize("NFKD", char).encode("ascii", "ignore").decode()
            if decomposed:
                ascii_ = decomposed
            else:
                name = unicodedata.name(char, "")
                ascii_ = (name.split(" LETTER ")[-1].lower() if "GREEK" in name
                          and " LETTER " in name else "?")
                if "CAPITAL" in name and ascii_ != "?":
                    ascii_ = ascii_.capitalize()
        spelled.append(ascii_)
    return "".join(spelled), error.end


def _console_safe():
    """Let stdout and stderr spell in ASCII what their encoding cannot show."""
    try:
        codecs.lookup_error(CONSOLE_ERRORS)
    except LookupError:
        codecs.register_error(CONSOLE_ERRORS, _transliterate)
    for stream in (sys.stdout, sys.stderr):
        encoding = (getattr(stream, "encoding", None) or "utf-8").lower().replace("_", "-")
        if encoding in ("utf-8", "utf8") or not hasattr(stream, "reconfigure"):
            continue
        try:
            stream.reconfigure(errors=CONSOLE_ERRORS)
        except (ValueError, OSError):  # pragma: no cover - a stream that cannot change
            pass


def _flush_stdout():
    if sys.stdout is not None:
        sys.stdout.flush()


def _silence_stdout():
    """Point stdout at os.devnull, so that the interpreter's last flush cannot fail."""
    try:
        fileno = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file (captured, closed)
        fileno = None
    devnull = os.open(os.devnull, os.O_WRONLY)
    if fileno is not None:
        os.dup2(devnull, fileno)
        os.close(devnull)
    else:
        sys.stdout = os.fdopen(devnull, "w")


def _catch_sigterm():
    """Make SIGTERM raise :class:`Terminated` in this process; returns the old handler.

    Only the main thread can set a handler (None is returned elsewhere). The first
    SIGTERM raises; a second one, while the cleanup runs, ends the process at once (the
    default action). Child processes forked later (worker pools) inherit the handler;
    there it restores the default action and re-sends the signal, so that a pool can
    still stop its workers.

    A handler that runs inside a weakref callback or a ``__del__`` raises where Python
    ignores exceptions (it prints "Exception ignored in" and goes on): the
    :func:`sys.unraisablehook` installed here sees that :class:`Terminated`, arms the
    handler again and sends the signal once more, so that it raises at the next
    instruction outside (the run would otherwise finish and exit 0).
    """
    pid = os.getpid()

    def handler(signum, frame):
        signal.signal(signum, signal.SIG_DFL)
        if os.getpid() != pid:
            os.kill(os.getpid(), signum)
            return
        inside = frame
        while inside is not None:  # still in the hook: a raise would be ignored again
            if inside.f_code is redeliver.__code__:
                _send_later(signum)
                return
            inside = inside.f_back
        raise Terminated(signum)

    def _send_later(signum):
        """Arm the handler and send the signal again in 10 ms, after the hook returned."""
        signal.signal(signum, handler)
        timer = threading.Timer(0.01, os.kill, args=(pid, signum))
        timer.daemon = True
        redeliver.timers.append(timer)
        timer.start()

    def redeliver(unraisable):
        error = unraisable.exc_value
        if isinstance(error, Terminated) and os.getpid() == pid:
            _send_later(error.signum)
            return
        chained(unraisable)

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread
        return None
    chained = sys.unraisablehook
    redeliver.chained, redeliver.timers = chained, []
    sys.unraisablehook = redeliver
    return previous


def _restore_sigterm(previous):
    """Undo :func:`_catch_sigterm`: its SIGTERM handler and its unraisable hook.

    Parameters
    ----------
    previous : handler or None
        What :func:`_catch_sigterm` returned (None: it set nothing).
    """
    if previous is None:
        return
    signal.signal(signal.SIGTERM, previous)
    chained = getattr(sys.unraisablehook, "chained", None)
    if chained is not None:
        for timer in sys.unraisablehook.timers:  # a signal not yet sent again stays unsent
            timer.cancel()
        sys.unraisablehook = chained


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
