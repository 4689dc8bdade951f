"""The `qzs` command (qzs.cli.main): it only parses, calls the API and reports; bad input
is one clear line and exit code 2."""
import numpy as np
import pytest

from qzs.cli import main
from qzs.iotools import read_result, save_config


def test_simulate_writes_outputs_and_summary(tmp_path, capsys):
    out, plot = tmp_path / "run.csv", tmp_path / "run.png"
    code = main(["simulate", "--excitation", "sine", "--frequency", "3", "--amplitude", "0.004",
                 "--duration", "2", "--sample-rate", "200", "--set", "pi_kp=20",
                 "--out", str(out), "--plot", str(plot), "--quiet"])
    assert code == 0
    text = capsys.readouterr().out
    for key in ("operating point", "stroke used", "stop contacts", "locked", "M steps/s",
                "PI integral must carry"):
        assert key in text
    data = read_result(out)
    assert data.attrs["controller.pi_kp"] == 20.0
    assert data.sizes["time"] == 401
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"


def test_simulate_config_and_set_override(tmp_path):
    config = save_config(tmp_path / "c.toml", excitation={"kind": "sine", "frequency": 2.0,
                                                          "amplitude": 0.002},
                         simulation={"duration": 1.0, "sample_rate": 100.0})
    out = tmp_path / "r.nc"
    assert main(["simulate", "--config", str(config), "--set", "viscous_damping=50",
                 "--out", str(out), "--plot", "none", "--quiet"]) == 0
    data = read_result(out)
    assert data.attrs["isolator.viscous_damping"] == 50.0
    assert data.attrs["excitation.frequency"] == 2.0
    assert np.isclose(float(data.time[-1]), 1.0)


def test_simulate_file_excitation(tmp_path):
    t = np.linspace(0, 1, 1001)
    record = tmp_path / "base.csv"
    record.write_text("time,displacement\n" + "\n".join(
        f"{a},{0.003 * np.sin(2 * np.pi * 2 * a)}" for a in t))
    out = tmp_path / "r.nc"
    assert main(["simulate", "--excitation", "file", "--record", str(record), "--out", str(out),
                 "--fade-in", "0", "--plot", "none", "--quiet"]) == 0
    data = read_result(out)
    np.testing.assert_allclose(data.base_displacement.values[::100],
                               0.003 * np.sin(2 * np.pi * 2 * data.time.values[::100]),
                               atol=1e-6)


@pytest.mark.parametrize("argv, message", [
    (["simulate", "--set", "mass=-2"], "`mass` must be positive, got -2.0"),
    (["simulate", "--set", "masss=2"], "unknown parameter 'masss'"),
    (["simulate", "--dt", "0.5", "--duration", "10", "--excitation", "sine"],
     "largest stable step"),
    (["simulate", "--excitation", "file", "--record", "/nonexistent.csv"],
     "displacement record not found"),
])
def test_errors_are_one_clear_line(capsys, argv, message):
    assert main(argv + ["--plot", "none", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and message in err
    assert "Traceback" not in err


def test_a_sigterm_landing_in_a_weakref_callback_is_not_lost():
    """Python ignores an exception raised inside a weakref callback or ``__del__`` (it only
    prints "Exception ignored in"): a SIGTERM whose handler ran there was lost, and the run
    went on to exit 0 with its file written (seen once in a fresh clone's
    test_sigterm_leaves_no_file_behind). The signal is delivered again outside it."""
    import os
    import signal
    import sys
    import time
    import weakref

    from qzs.cli import _catch_sigterm, _restore_sigterm
    from qzs.errors import Terminated

    class Payload:
        pass

    def callback(_):  # the handler runs inside this callback, where a raise is ignored
        os.kill(os.getpid(), signal.SIGTERM)
        for _ in range(1000):
            pass

    hook = sys.unraisablehook
    previous = _catch_sigterm()
    try:
        payload = Payload()
        ref = weakref.ref(payload, callback)
        with pytest.raises(Terminated) as caught:
            del payload
            deadline = time.monotonic() + 5.0
            while time.monotonic() < deadline:  # the signal delivered again lands here
                pass
        assert caught.value.exit_code == 143 and ref() is None
    finally:
        _restore_sigterm(previous)
    assert sys.unraisablehook is hook
    assert signal.getsignal(signal.SIGTERM) == previous


EMPTY_ARGUMENTS = [
    (["simulate", "--out", ""], "--out"), (["simulate", "--config", ""], "--config"),
    (["hexapod", "simulate", "--out", ""], "--out"),
    (["hexapod", "simulate", "--config", ""], "--config"), (["params", "--toml", ""], "--toml"),
    (["sweep-export", ""], "STORE"), (["optimize", ""], "FILE"), (["sweep", ""], "FILE"),
    (["experiment", "log.csv", "--map", ""], "--map"), (["simulate", "--plot", ""], "--plot"),
    (["response", "--out", ""], "--out"), (["design", "--out", ""], "--out"),
    (["docs", ""], "TOPIC"), (["simulate", "--set", ""], "--set"),
    # blank is empty too: a path of spaces is no name either
    (["simulate", "--out", " "], "--out"), (["optimize", "  "], "FILE"),
    (["params", "--toml", "\t"], "--toml"),
]


@pytest.mark.parametrize("argv, flag", EMPTY_ARGUMENTS)
def test_an_empty_argument_is_refused_by_name_before_any_work(argv, flag, tmp_path,
                                                               monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and flag in err and "empty" in err
    assert "'.'" not in err
    assert list(tmp_path.iterdir()) == []  # nothing written, not even a default output


def test_text_the_console_cannot_encode_is_transliterated_not_a_traceback(monkeypatch, capsys):
    import io
    import sys

    raw = io.BytesIO()
    console = io.TextIOWrapper(raw, encoding="cp1252")  # a Windows console
    monkeypatch.setattr(sys, "stdout", console)
    assert main(["docs", "hexapod", "2"]) == 0
    console.flush()
    text = raw.getvalue().decode("cp1252")
    from qzs.iotools.docs import read_topic

    page = read_topic("hexapod", 2)
    assert "\u2212" in page  # the page has the minus sign the console cannot show
    assert text.count("?") == page.count("?")  # every character spelled, none lost
    assert text.splitlines()[0] == page.splitlines()[0].replace("\u2212", "-")
    minus_line = next(line for line in page.splitlines() if "\u2212" in line
                      and line.encode("cp1252", "replace").count(b"?") == line.count("\u2212"))
    assert minus_line.replace("\u2212", "-") in text


_ENDING = r"""
import atexit, sys, threading, time
class Teardown:
    def __del__(self):
        sys.stdout.write("torn down\n")
kept = Teardown()  # freed only by the interpreter's teardown of this module
atexit.register(lambda: sys.stdout.write("exit handler ran"))  # no newline: no line flush
import qzs.cli
if "--thread" in sys.argv:  # a thread still running when the command has returned
    sys.argv.remove("--thread")
    returned, command = threading.Event(), qzs.cli.main
    def main(*args, **kwargs):
        try:
            return command(*args, **kwargs)
        finally:
            qzs.cli.main = command  # nothing of this script's kept by qzs past here
            returned.set()
    qzs.cli.main = main
    threading.Thread(target=lambda: (returned.wait(), time.sleep(0.3),
                                     sys.stdout.write("thread joined\n"))).start()
from qzs.cli import console
sys.argv[0] = "qzs"
console()
"""


@pytest.mark.parametrize("argv, code", [(["params"], 0), (["params", "--set", "mass=-1"], 2),
                                        (["docs", "model"], 0)])
def test_the_console_script_ends_without_the_interpreter_teardown_but_loses_nothing(argv, code):
    """console(): exit handlers run, the exit code and every byte of stdout (piped, so
    block-buffered) arrive, and the modules are not torn down (0.45 s after qzs optimize)."""
    import os
    import subprocess
    import sys

    from qzs.cli import main

    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}  # buffered
    done = subprocess.run([sys.executable, "-c", _ENDING, *argv], capture_output=True,
                          text=True, timeout=120, env=env)
    assert done.returncode == code, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1] == "exit handler ran"
    assert "torn down" not in lines
    if code == 0:  # the command's whole output, in order, before the exit handler's line
        import contextlib
        import io

        with contextlib.redirect_stdout(io.StringIO()) as expected:
            main(argv)
        assert done.stdout == expected.getvalue() + "exit handler ran"


def test_the_console_script_joins_a_running_thread_the_ordinary_way():
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", _ENDING, "params", "--thread"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    tail = done.stdout.splitlines()[-2:]
    assert tail == ["thread joined", "exit handler rantorn down"]


def test_under_a_profiler_the_console_script_ends_the_ordinary_way_and_its_record_is_written(
        tmp_path):
    """``python -m cProfile -o FILE -m qzs ...`` writes FILE after the command returns: the
    quick end (os._exit) would lose it."""
    import pstats
    import subprocess
    import sys

    record = tmp_path / "qzs.prof"
    done = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(record), "-m", "qzs",
                           "params"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert any("console" in function for _, _, function in pstats.Stats(str(record)).stats)
