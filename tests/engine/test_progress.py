"""Progress bars that always show: plain lines on a console of 0 columns (qzs.engine.progress)."""
import fcntl
import io
import os
import pty
import struct
import sys
import termios

import pytest

from qzs.engine import progress


def _console(columns, rows):
    """A pseudo-terminal reporting ``columns`` x ``rows``: (reader fd, writer file)."""
    main, secondary = pty.openpty()
    fcntl.ioctl(secondary, termios.TIOCSWINSZ, struct.pack("HHHH", rows, columns, 0, 0))
    attributes = termios.tcgetattr(secondary)
    attributes[1] &= ~termios.OPOST  # no output processing: bytes as written
    termios.tcsetattr(secondary, termios.TCSANOW, attributes)
    return main, os.fdopen(secondary, "w", buffering=1)


def _read(fd):
    chunks = []
    os.set_blocking(fd, False)
    while True:
        try:
            chunk = os.read(fd, 65536)
        except (BlockingIOError, OSError):
            break
        if not chunk:
            break
        chunks.append(chunk)
    return b"".join(chunks).decode()


def _run(bar, steps=4):
    for _ in range(steps):
        bar.update()
    bar.close()


@pytest.fixture
def no_size_environment(monkeypatch):
    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.delenv("LINES", raising=False)
    monkeypatch.setattr(progress, "PLAIN_INTERVAL", 0.0)


def test_tqdm_alone_draws_nothing_on_a_console_of_zero_columns(no_size_environment, monkeypatch):
    """The reason for the module: tqdm reads a 0x0 console as -1 and writes no text at all."""
    from tqdm.std import tqdm

    reader, console = _console(0, 0)
    monkeypatch.setattr(sys, "stderr", console)  # tqdm reads the size of stderr alone
    _run(tqdm(total=4, desc="work", mininterval=0))
    assert "work" not in _read(reader)


@pytest.mark.parametrize("columns, rows", [(0, 0), (0, 24), (80, 0)])
def test_a_zero_size_console_gets_plain_lines(no_size_environment, monkeypatch, columns, rows):
    """Each update a whole line with the description and counts; no carriage return."""
    reader, console = _console(columns, rows)
    monkeypatch.setattr(sys, "stderr", console)
    assert progress.plain_terminal(console)
    bar = progress.progress_bar(total=4, desc="work", unit="case", leave=False)
    assert isinstance(bar, progress.PlainProgress)
    _run(bar)
    text = _read(reader)
    assert "\r" not in text and "\x1b" not in text
    lines = text.splitlines()
    assert [line for line in lines if line.startswith("work:")] == lines
    assert any(" 4/4 " in line for line in lines) and any(" 1/4 " in line for line in lines)


def test_a_console_with_a_size_keeps_tqdms_bar(no_size_environment, monkeypatch):
    reader, console = _console(80, 24)
    monkeypatch.setattr(sys, "stderr", console)
    assert not progress.plain_terminal(console)
    bar = progress.progress_bar(total=4, desc="work", mininterval=0)
    assert not isinstance(bar, progress.PlainProgress)
    _run(bar)
    assert "\rwork: 100%" in _read(reader)


def test_columns_zero_in_the_environment_means_plain_lines_even_off_a_console(monkeypatch):
    """``COLUMNS=0`` (how a CI console says it) on a pipe or file: plain lines, not nothing."""
    monkeypatch.setattr(progress, "PLAIN_INTERVAL", 0.0)
    monkeypatch.setenv("COLUMNS", "0")
    stream = io.StringIO()
    bar = progress.progress_bar(total=3, desc="figures", file=stream)
    _run(bar, 3)
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue()
    assert lines and all(line.startswith("figures:") for line in lines)
    assert " 3/3 " in lines[-1]
    monkeypatch.setenv("COLUMNS", "120")
    assert not progress.plain_terminal(stream)


def test_plain_lines_come_at_most_once_per_interval(monkeypatch):
    monkeypatch.setenv("COLUMNS", "0")
    monkeypatch.setattr(progress, "PLAIN_INTERVAL", 3600.0)
    stream = io.StringIO()
    bar = progress.progress_bar(total=100, desc="many", file=stream, leave=False)
    _run(bar, 100)
    assert len(stream.getvalue().splitlines()) <= 2  # the first display, none within the hour


def test_a_disabled_bar_writes_nothing_even_on_a_plain_console(monkeypatch):
    monkeypatch.setenv("COLUMNS", "0")
    stream = io.StringIO()
    _run(progress.progress_bar(total=3, desc="quiet", file=stream, disable=True))
    assert stream.getvalue() == ""


@pytest.mark.parametrize("columns", ["0", "120"])
def test_a_bar_without_updates_is_drawn_again_every_heartbeat_until_closed(monkeypatch, columns):
    """A step taking seconds: the elapsed time moves on, a sign of life each interval."""
    import time

    monkeypatch.setenv("COLUMNS", columns)
    monkeypatch.setattr(progress, "HEARTBEAT", 0.1)
    monkeypatch.setattr(progress, "PLAIN_INTERVAL", 0.1)
    stream = io.StringIO()
    bar = progress.progress_bar(total=2, desc="slow", file=stream, leave=False)
    time.sleep(0.75)
    drawn = stream.getvalue().replace("\r", "\n").count("slow:")
    assert 5 <= drawn <= 10  # about one per interval, not a busy loop
    bar.close()
    after = stream.getvalue()
    time.sleep(0.3)
    assert stream.getvalue() == after  # closed: the heartbeat stops


def test_a_bar_updated_often_gets_no_extra_drawing(monkeypatch):
    import time

    monkeypatch.setenv("COLUMNS", "0")
    monkeypatch.setattr(progress, "HEARTBEAT", 0.2)
    monkeypatch.setattr(progress, "PLAIN_INTERVAL", 0.0)
    stream = io.StringIO()
    bar = progress.progress_bar(total=20, desc="busy", file=stream, leave=False)
    for _ in range(20):
        time.sleep(0.03)
        bar.update()
    bar.close()
    assert len(stream.getvalue().splitlines()) <= 21  # the first drawing and one per update


def test_a_warning_comes_above_a_progress_bar_not_inside_it(monkeypatch):
    """The bar is cleared, the line written whole, the bar drawn again below it."""
    import io
    import warnings

    from qzs.engine.progress import progress_bar, show_warning

    monkeypatch.delenv("COLUMNS", raising=False)
    stream = io.StringIO()
    bar = progress_bar(total=4, desc="cases", file=stream, mininterval=0)
    bar.update()
    show_warning(warnings.WarningMessage("a step note", UserWarning, "x.py", 1).message,
                 UserWarning, "x.py", 1, file=stream)
    bar.close()
    text = stream.getvalue()
    assert "\nqzs: warning: a step note\n" in text.replace("\r", "\n")
    before, _, after = text.partition("qzs: warning: a step note\n")
    assert before.endswith("\r") and "1/4" in after  # cleared first, drawn again after


def test_a_python_warning_during_a_bar_lands_on_its_own_line(monkeypatch):
    """In Python (no command line to put show_warning in place) a warning raised while a bar
    is drawn, such as a DataWarning of a sweep's batch, goes through the bar's write: the
    bar is cleared, the warning written whole, the bar drawn again; after the bar, warnings
    are Python's own again, and a recorder (catch_warnings) still records."""
    import io
    import warnings

    from qzs.engine.progress import progress_bar
    from qzs.errors import DataWarning

    monkeypatch.delenv("COLUMNS", raising=False)
    stream = io.StringIO()
    original = warnings.showwarning

    def python_default(message, category, filename, lineno, file=None, line=None):
        stream.write(warnings.formatwarning(message, category, filename, lineno, line))

    monkeypatch.setattr(warnings, "showwarning", python_default)
    bar = progress_bar(total=4, desc="cases", file=stream, mininterval=0)
    bar.update()
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.warn("no trusted bin in the band [1, 3] Hz", DataWarning)
    bar.update()
    bar.close()
    text = stream.getvalue()
    before, found, after = text.partition("DataWarning: no trusted bin in the band [1, 3] Hz")
    assert found, text
    line_start = before.rsplit("\n", 1)[-1].rsplit("\r", 1)[-1]
    assert "1/4" not in line_start and before.endswith(line_start)   # the bar was cleared
    assert before.rstrip(" ").endswith(("\r", "\n")) or "cases" not in line_start
    assert "2/4" in after or "1/4" in after                          # drawn again after it
    assert warnings.showwarning is python_default                    # put back at the close
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with progress_bar(total=1, file=stream) as recorded_bar:
            warnings.warn("kept", DataWarning)
            recorded_bar.update()
    assert [str(w.message) for w in caught] == ["kept"]
    monkeypatch.setattr(warnings, "showwarning", original)
