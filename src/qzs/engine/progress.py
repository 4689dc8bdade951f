"""Progress bars that always show: a tqdm bar, or plain lines where a bar cannot be drawn.

Every progress bar of qzs comes from :func:`progress_bar`. On a terminal it is tqdm's bar.
A console that reports a size of 0 columns or 0 rows (some CI and IDE consoles; also
``COLUMNS=0`` or ``LINES=0`` in the environment) cannot hold one: tqdm reads the size as -1
and draws nothing at all, so a long run would be silent. There the bar is
:class:`PlainProgress`: one full line per update, at most one every :data:`PLAIN_INTERVAL`
seconds, with no carriage return and no cursor movement. ::

    studies:  40%| 2/5 [00:03<00:04,  1.2case/s]

A step of work can take many seconds (a figure, a loop analysis at a long delay); a bar
not drawn for :data:`HEARTBEAT` seconds is drawn again, its elapsed time moving on, so
that a console is never silent for longer while a bar is open (:class:`Heartbeat`).

A warning meant for the user is one line ``qzs: warning: ...`` above the bars
(:func:`show_warning`, which the command line puts in place of
:func:`warnings.showwarning` while a command runs, and :func:`install_warning_lines` in the
worker processes of a local Dask cluster). In Python, while a bar is open, whatever shows
warnings (Python's own display, a notebook's, the command line's) writes through the bar
(:class:`WarningsThroughBar`): the bar is cleared, the warning written on lines of its own,
the bar drawn again.
"""
import os
import sys
import threading
import time
import warnings

from tqdm.std import tqdm as std_tqdm

__all__ = ["PLAIN_INTERVAL", "HEARTBEAT", "terminal_size", "plain_terminal", "PlainProgress",
           "Heartbeat", "WarningsThroughBar", "progress_bar", "show_warning",
           "install_warning_lines"]

#: Seconds between two plain progress lines (a 0-column console).
PLAIN_INTERVAL = 1.0
#: Seconds after which a bar not drawn is drawn again.
HEARTBEAT = 1.0


def _bar_class():
    """tqdm's bar for where this runs: tqdm.auto's (a notebook widget) in a Jupyter kernel,
    else tqdm.std's, imported without tqdm.auto's asyncio and ssl (5 MB more of every
    command's memory)."""
    if "ipykernel" in sys.modules:
        from tqdm.auto import tqdm

        return tqdm
    return std_tqdm


def terminal_size(stream):
    """The ``(columns, rows)`` the console of ``stream`` reports, or None when it reports none.

    ``COLUMNS`` and ``LINES`` in the environment take precedence, as for
    :func:`shutil.get_terminal_size`; a stream that is not a terminal reports nothing.

    Parameters
    ----------
    stream : file
        The stream the progress is written on.

    Returns
    -------
    tuple of (int or None, int or None)
        Columns and rows; None where neither the environment nor the console says.
    """
    try:
        size = os.get_terminal_size(stream.fileno())
        columns, rows = size.columns, size.lines
    except (AttributeError, ValueError, OSError):  # not a terminal (a file, a pipe, pytest)
        columns = rows = None
    for name, index in (("COLUMNS", 0), ("LINES", 1)):
        text = os.environ.get(name, "").strip()
        if text.lstrip("-").isdigit():
            columns, rows = (int(text), rows) if index == 0 else (columns, int(text))
    return columns, rows


def plain_terminal(stream):
    """Whether ``stream``'s console reports 0 (or fewer) columns or rows: no bar fits there.

    Parameters
    ----------
    stream : file
        The stream the progress is written on.

    Returns
    -------
    bool
    """
    columns, rows = terminal_size(stream)
    return (columns is not None and columns <= 0) or (rows is not None and rows <= 0)


class PlainProgress(std_tqdm):
    """A tqdm bar written as plain lines: each display a whole line ending in a newline.

    No carriage return, no cursor movement, no bar (``ncols=0``: the counts and rates
    only), at most one line per :data:`PLAIN_INTERVAL` seconds.
    """

    def __init__(self, *arguments, **options):
        super().__init__(*arguments, **options)
        self.fp = _Lines(self.fp)

    @staticmethod
    def status_printer(file):
        """What tqdm displays with: each text a whole line on ``file``, an empty one nothing.

        Parameters
        ----------
        file : file
            The stream of the bar.

        Returns
        -------
        callable
            Writes one text.
        """
        def print_line(text):
            text = str(text).strip()
            if text:
                file.write(text + "\n")
                getattr(file, "flush", lambda: None)()
        return print_line

    def moveto(self, n):
        """No cursor movement on a plain console.

        Parameters
        ----------
        n : int
            Lines tqdm would move by; ignored.
        """

    def clear(self, nolock=False):
        """Nothing to clear: the lines written stay.

        Parameters
        ----------
        nolock : bool
            tqdm's; ignored.
        """


class _Lines:
    """A stream that drops what tqdm writes to end or wipe a bar (a lone ``\\r`` or ``\\n``)."""

    def __init__(self, stream):
        self._wrapped = getattr(stream, "_wrapped", stream)

    def write(self, text):
        if str(text).strip():
            self._wrapped.write(text)

    def flush(self):
        getattr(self._wrapped, "flush", lambda: None)()

    def __getattr__(self, name):
        return getattr(self._wrapped, name)


class Heartbeat:
    """Draws ``bar`` again whenever it has not been drawn for ``interval`` seconds, until the
    bar is closed (a daemon thread; tqdm's lock keeps it from drawing over an update).

    Parameters
    ----------
    bar : tqdm.tqdm
        An open bar, not disabled.
    interval : float
        Seconds [s].
    """

    def __init__(self, bar, interval):
        self.bar, self.interval = bar, interval
        self.thread = threading.Thread(target=self.run, name="qzs-progress-heartbeat",
                                       daemon=True)
        self.thread.start()

    def run(self):
        """Until the bar is closed (tqdm disables it then): redraw it when it went quiet."""
        bar, drawn = self.bar, 0.0
        while True:
            now = time.time()  # tqdm's clock
            drawn = max(drawn, getattr(bar, "last_print_t", now),
                        getattr(bar, "start_t", now) + getattr(bar, "delay", 0.0))
            if now - drawn < self.interval:
                time.sleep(self.interval - (now - drawn))
                continue
            if bar.disable:
                return
            try:
                bar.refresh()
            except (OSError, ValueError):  # a closed stream: nothing to draw on
                return
            drawn = time.time()


class WarningsThroughBar:
    """While ``bar`` is open, show warnings through it: its stream's bars cleared, the
    warning shown by whatever showed it before (so a recorder or a notebook keeps it), the
    bars drawn again; at ``bar.close()`` the display before it is put back.

    Parameters
    ----------
    bar : tqdm.tqdm
        An open bar.
    stream : file
        The stream the bar is drawn on.
    """

    def __init__(self, bar, stream):
        self.stream, self.shown, self.bars = stream, warnings.showwarning, type(bar)
        show = warnings.showwarning = self.show   # one bound method, to know it again
        close = bar.close

        def closed(*arguments, **options):
            try:
                return close(*arguments, **options)
            finally:
                if warnings.showwarning is show:  # not if another took its place since
                    warnings.showwarning = self.shown

        bar.close = closed

    def show(self, message, category, filename, lineno, file=None, line=None):
        """Show a warning with the bars cleared, then draw them again.

        Parameters
        ----------
        message : Warning or str
            The warning.
        category, filename, lineno, file, line
            As for :func:`warnings.showwarning`, passed on to the display it replaced.
        """
        try:
            with self.bars.external_write_mode(file=self.stream):
                self.shown(message, category, filename, lineno, file, line)
        except (OSError, ValueError):  # a closed stream: shown as it would have been
            self.shown(message, category, filename, lineno, file, line)


def progress_bar(*, total=None, desc=None, unit="it", disable=False, leave=True, file=None,
                 **options):
    """A progress bar on ``file`` (default stderr): tqdm's, or plain lines on a 0-column console.

    Parameters
    ----------
    total : int or float, optional
        Units of work in all.
    desc : str, optional
        What is under way, before the counts.
    unit : str
        The unit of work.
    disable : bool
        Show nothing.
    leave : bool
        Keep the bar once closed (tqdm's ``leave``).
    file : file, optional
        Where to write (default ``sys.stderr``).
    **options
        Further tqdm options (``unit_scale``, ``initial``, ``delay``, ...).

    Returns
    -------
    tqdm.tqdm
        The bar; a :class:`PlainProgress` where :func:`plain_terminal` holds.
    """
    stream = sys.stderr if file is None else file
    tqdm = _bar_class()
    if disable:
        return tqdm(total=total, desc=desc, unit=unit, disable=True, file=file, **options)
    if plain_terminal(stream):
        options.update(ncols=0, nrows=10 ** 6, mininterval=PLAIN_INTERVAL, dynamic_ncols=False)
        bar = PlainProgress(total=total, desc=desc, unit=unit, leave=leave, file=stream,
                            **options)
    else:
        bar = tqdm(total=total, desc=desc, unit=unit, leave=leave, file=file, **options)
    Heartbeat(bar, HEARTBEAT)
    WarningsThroughBar(bar, stream)
    return bar


def show_warning(message, category, filename, lineno, file=None, line=None):
    """Show a warning as one line ``qzs: warning: ...`` on stderr, above any progress bar.

    Takes the place of :func:`warnings.showwarning`: the message alone, its lines joined,
    without the category, source file or line. Python's filters still decide which
    warnings come, and how often.

    Parameters
    ----------
    message : Warning or str
        The warning.
    category, filename, lineno, line
        As for :func:`warnings.showwarning`; not shown.
    file : file, optional
        Where to write (default ``sys.stderr``).
    """
    text = " ".join(str(message).split())
    stream = sys.stderr if file is None else file
    try:
        _bar_class().write(f"qzs: warning: {text}", file=stream)  # clears the bars, writes, redraws
    except (OSError, ValueError):  # a closed stderr: nothing to say it on
        pass


def install_warning_lines():
    """Show every warning of this process as :func:`show_warning` does, from now on.

    For worker processes (``distributed.Client.run``), whose stderr is the user's console.
    """
    warnings.showwarning = show_warning
