"""The command line's contract, the same for every subcommand.

Exit codes (0 success, 1 a failed run, 2 bad input or usage, 130 Ctrl-C, 141 closed pipe,
143 SIGTERM), ``--json``, ``--force``, and output paths checked before the work starts:
each bad path fails at once and leaves the folder as it was.
"""
import json
import os
import signal
import subprocess
import sys
import time
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

from qzs.cli import HANDLERS, main
from qzs.cli.common import EXIT_CODES, emit, jsonable, run_handler
from qzs.errors import (CaseError, CompilerError, DataError, ExcitationError, FitError,
                        MissingDependencyError, OutputPathError, ParameterError,
                        SimulationError, StabilityError, Terminated, WriteError)

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "examples" / "data"
SRC = str(ROOT / "src")
#: Each bad output path must fail at least this fast [s] (generous: the machine is shared).
FAST = 5.0


def child_env(unbuffered=None):
    """This environment, with ``src`` on the path; stdout unbuffered (True), buffered (False)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")
    if unbuffered is not None:
        env.pop("PYTHONUNBUFFERED", None)
        if unbuffered:
            env["PYTHONUNBUFFERED"] = "1"
    return env


# ---------------------------------------------------------------- exit codes
@pytest.mark.parametrize("error, code", [
    (SimulationError("diverged at t = 1 s"), 1),
    (FitError("no convergence"), 1),
    (CompilerError("cc", "was not found on PATH"), 1),
    (CaseError(3, "`mass` must be positive"), 2),   # an invalid case, found before the batch runs
    (OSError(28, "No space left on device", "/full/run.nc"), 1),
    (WriteError("/full/run.nc", "the disk is full"), 1),  # a DataError, but the run ran
    (MemoryError(), 1),
    (ParameterError("`mass` must be positive"), 2),
    (ExcitationError("bad record"), 2),
    (StabilityError("largest stable step"), 2),
    (OutputPathError("--out", "x.xyz", "has extension '.xyz'"), 2),
    (DataError("missing channel"), 2),
    (MissingDependencyError("zarr", "cluster", "writing a sweep store"), 2),
    (KeyboardInterrupt(), 130),
    (Terminated(signal.SIGTERM), 143),
], ids=lambda v: type(v).__name__ if isinstance(v, BaseException) else str(v))
def test_run_handler_maps_each_error_class_to_its_code(capsys, error, code):
    def handler(args):
        raise error

    assert run_handler(handler, None) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert code in EXIT_CODES


def test_the_code_comes_from_the_class_not_the_message(capsys):
    def handler(args):  # a message that reads like bad input, from a failed run
        raise SimulationError("`mass` must be positive; bad input")

    assert run_handler(handler, None) == 1
    assert run_handler(lambda args: 0, None) == 0


def test_an_os_error_names_its_file(capsys):
    def handler(args):
        raise PermissionError(13, "Permission denied", "/data/run.nc")

    assert run_handler(handler, None) == 1
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and "'/data/run.nc'" in err and "Permission" in err


ARGV = {"simulate": ["simulate"], "params": ["params"], "paper": ["paper"],
        "study": ["study", "x.toml"], "experiment": ["experiment", "log.csv", "--map", "m.toml"],
        "sweep": ["sweep", "s.toml"], "sweep-plot": ["sweep-plot", "s.zarr"],
        "sweep-export": ["sweep-export", "s.zarr"],
        "hexapod": ["hexapod", "linear"], "response": ["response"],
        "design": ["design"], "app": ["app", "--no-browser"], "docs": ["docs"],
        "completion": ["completion", "bash"], "optimize": ["optimize", "p.toml"],
        "sensitivity": ["sensitivity", "p.toml"], "export": ["export", "controller"]}


def test_every_subcommand_has_the_same_exit_codes(monkeypatch, capsys):
    assert set(ARGV) == set(HANDLERS)
    for command, argv in ARGV.items():
        for error, code in ((SimulationError("x"), 1), (DataError("x"), 2),
                            (KeyboardInterrupt(), 130)):
            def handler(args, error=error):
                raise error

            monkeypatch.setitem(HANDLERS, command, handler)
            assert main(argv) == code, (command, error)
    capsys.readouterr()


@pytest.mark.parametrize("argv", [["simulate", "--no-such-option"], ["no-such-command"], [],
                                  ["experiment", "log.csv"]])
def test_usage_errors_are_2(capsys, argv):
    assert main(argv) == 2
    assert "usage: qzs" in capsys.readouterr().err


def test_version_and_help_are_0(capsys):
    from qzs._version import __version__

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"qzs {__version__}"
    assert main(["params", "--help"]) == 0
    out = capsys.readouterr().out
    assert "exit codes:" in out and "143" in out and "--overwrite" in out


def test_help_of_every_subcommand_documents_the_exit_codes(capsys):
    for command in HANDLERS:
        assert main([command, "--help"]) == 0, command
        assert "exit codes: 0 success, 1" in " ".join(capsys.readouterr().out.split()), command


# ---------------------------------------------------------------- SIGTERM
def test_sigterm_runs_the_cleanup_and_exits_143(monkeypatch, tmp_path, capsys):
    from qzs.iotools.files import atomic_path

    target = tmp_path / "out.nc"

    def handler(args):
        with atomic_path(target) as tmp:
            tmp.write_text("half a file")
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the signal arrives before this ends
        raise AssertionError("SIGTERM did not interrupt the handler")

    class NotCaught(Exception):
        pass

    def fallback(signum, frame):  # if main installs no handler, fail this test, not pytest
        raise NotCaught("main did not handle SIGTERM")

    original = signal.signal(signal.SIGTERM, fallback)
    try:
        monkeypatch.setitem(HANDLERS, "params", handler)
        began = time.perf_counter()
        assert main(["params"]) == 143
        assert time.perf_counter() - began < 4
        assert list(tmp_path.iterdir()) == []  # neither the target nor a temporary file
        assert signal.getsignal(signal.SIGTERM) is fallback  # main restored the handler
        assert "terminated by signal 15" in capsys.readouterr().err
    finally:
        signal.signal(signal.SIGTERM, original)


def test_sigterm_from_outside_ends_a_command_cleanly(tmp_path):
    """A real SIGTERM to a real process in the middle of an atomic write."""
    script = (
        "import sys, time\n"
        "from pathlib import Path\n"
        "import qzs.cli\n"
        "from qzs.iotools.files import atomic_path\n"
        "def slow(args):\n"
        f"    with atomic_path(Path({str(tmp_path)!r}) / 'out.toml') as tmp:\n"
        "        tmp.write_text('partial')\n"
        "        print('writing', flush=True)\n"
        "        time.sleep(60)\n"
        "    return 0\n"
        "qzs.cli.HANDLERS['params'] = slow\n"
        "sys.exit(qzs.cli.main(['params']))\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=child_env())
    try:
        assert child.stdout.readline().strip() == "writing"
        assert len(list(tmp_path.iterdir())) == 1  # the temporary file, while it writes
        child.send_signal(signal.SIGTERM)
        out, err = child.communicate(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 143, err
    assert "Traceback" not in err and "terminated" in err
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- a closed pipe
def _closed_pipe_run(argv, cwd, unbuffered):
    """Run ``python -m qzs argv`` with stdout a pipe whose reader has already gone."""
    read, write = os.pipe()
    os.close(read)
    try:
        done = subprocess.run([sys.executable, "-m", "qzs", *argv], stdout=write,
                              stderr=subprocess.PIPE, text=True, env=child_env(unbuffered),
                              cwd=cwd, timeout=300)
    finally:
        os.close(write)
    return done


@pytest.mark.parametrize("unbuffered", [False, True], ids=["buffered", "unbuffered"])
@pytest.mark.parametrize("argv, codes", [
    (["params"], (141,)),
    (["simulate", "--excitation", "sine", "--frequency", "3", "--amplitude", "0.001",
      "--duration", "0.5", "--sample-rate", "200", "--plot", "none", "--quiet"], (141,)),
    (["--help"], (0, 141)),  # argparse ignores a failed write of the help: 0 if unbuffered
], ids=["params", "simulate", "help"])
def test_a_closed_pipe_ends_quietly_with_141(tmp_path, argv, codes, unbuffered):
    done = _closed_pipe_run(argv, tmp_path, unbuffered)
    assert done.returncode in codes, done.stderr
    assert done.stderr == ""  # no BrokenPipeError, no "Exception ignored"


def test_head_reads_the_first_line(tmp_path):
    done = subprocess.run(f"{sys.executable} -m qzs params | head -1", shell=True,
                          capture_output=True, text=True, env=child_env(), cwd=tmp_path,
                          timeout=300)
    assert done.stdout.startswith("section") and done.stdout.count("\n") == 1
    assert done.stderr == ""


# ---------------------------------------------------------------- --json
def strict_json(text):
    def refuse(name):
        raise AssertionError(f"{name} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_jsonable_makes_strict_json():
    record = {"nan": float("nan"), "inf": np.inf, "ninf": -np.float32(np.inf),
              "np_float": np.float64(1.5), "np_int": np.int16(-3), "np_bool": np.bool_(True),
              "array": np.array([[1.0, np.nan], [np.inf, 2.0]]), "ints": np.arange(3),
              "path": Path("a/b.nc"), "tuple": (1, np.nan), "nested": {1: {"x": np.nan}}}
    text = json.dumps(jsonable(record), allow_nan=False)
    assert strict_json(text) == {
        "nan": None, "inf": None, "ninf": None, "np_float": 1.5, "np_int": -3,
        "np_bool": True, "array": [[1.0, None], [None, 2.0]], "ints": [0, 1, 2],
        "path": "a/b.nc", "tuple": [1, None], "nested": {"1": {"x": None}}}


def test_emit_prints_text_or_json(capsys):
    import argparse

    emit(argparse.Namespace(json=False), "the text", {"a": 1})
    assert capsys.readouterr().out == "the text\n"
    emit(argparse.Namespace(json=True), "the text", {"a": np.nan})
    assert strict_json(capsys.readouterr().out) == {"a": None}
    emit(argparse.Namespace(), "no --json option", {"a": 1})
    assert capsys.readouterr().out == "no --json option\n"


def test_experiment_json(tmp_path, capsys):
    assert main(["experiment", str(DATA / "experiment.csv"), "--map",
                 str(DATA / "experiment_map.toml"), "--no-simulation", "--fft-length", "8192",
                 "--averages", "29", "--out", str(tmp_path / "out"), "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1  # one record, nothing else on stdout
    record = strict_json(out)
    assert record["welch"] == {"fft_length": 8192, "n_averages": 29, "window": "hann"}
    assert record["log"]["sample_rate"] > 0 and record["chirp"]["inferred"] is True
    assert record["simulated_metrics"] is None and record["highpass_corner"] == 1.0
    assert Path(record["files"]["report"]).exists()


# ---------------------------------------------------------------- params --toml --overwrite
def test_params_toml_does_not_overwrite_without_overwrite(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text("# my edits\n")
    assert main(["params", "--toml", str(path), "--set", "mass=7"]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "--overwrite" in err
    assert path.read_text() == "# my edits\n"
    assert main(["params", "--toml", str(path), "--set", "mass=7", "--overwrite"]) == 0
    assert "mass = 7.0" in path.read_text()
    assert main(["params", "--toml", str(path), "--set", "mass=8", "--force"]) == 0  # old name
    assert "mass = 8.0" in path.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.toml"]


# ---------------------------------------------------------------- output paths checked first
@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    from qzs.workflows.sweeps import run_sweep

    store = tmp_path_factory.mktemp("store") / "tiny.zarr"
    run_sweep({"sweep": {"name": "tiny", "batch_size": 1}, "grid": {"pi_kp": [5.0]},
               "excitation": {"f1": 10.0},
               "analysis": {"fft_length": 1024, "n_averages": 4, "band": [0.0, 10.0]}},
              store, progress=False)
    return store


@pytest.fixture
def sweep_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("definition") / "tiny.toml"
    path.write_text('[sweep]\nname = "tiny"\nbatch_size = 1\n[grid]\npi_kp = [5.0]\n'
                    '[excitation]\nf1 = 10.0\n[analysis]\nfft_length = 1024\n'
                    'n_averages = 4\nband = [0.0, 10.0]\n')
    return path


def _fails_fast_and_leaves_nothing(argv, folder, capsys, *needles):
    before = sorted(os.listdir(folder))
    began = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - began
    err = capsys.readouterr().err
    assert code == 2, err
    assert elapsed < FAST, f"{argv} took {elapsed:.2f} s to fail"
    assert err.startswith("qzs: error:") and "Traceback" not in err
    for needle in needles:
        assert needle in err, (needle, err)
    assert sorted(os.listdir(folder)) == before


def test_bad_output_paths_fail_at_once_and_leave_nothing(tmp_path, capsys, small_store,
                                                         sweep_file):
    blocker = tmp_path / "a-file"
    blocker.write_text("in the way")
    store_blocker = tmp_path / "a-file.zarr"  # a file where the store's folder must go
    store_blocker.write_text("in the way")
    experiment = ["experiment", str(DATA / "experiment.csv"), "--map",
                  str(DATA / "experiment_map.toml")]
    cases = [
        (["params", "--toml", str(tmp_path / "p.yaml")], "--toml", ".toml"),
        (["params", "--toml", str(blocker / "p.toml")], "--toml", "is a file, not a folder"),
        ([*experiment, "--out", str(blocker)], "--out", "is a file, not a folder"),
        ([*experiment, "--out", str(blocker / "sub")], "--out", "is a file"),
        (["sweep", str(sweep_file), "--out", str(store_blocker)], "--out", "is a file"),
        (["sweep", str(sweep_file), "--out", str(tmp_path / "store.nc")], "--out", ".zarr"),
        (["sweep", str(sweep_file), "--out", str(small_store)], "--out", "--resume"),
        (["sweep-plot", str(small_store), "--out", str(tmp_path / "x.xyz")], "--out",
         "'.xyz'", ".png", ".svg", ".pdf"),
        (["sweep-plot", str(small_store), "--out", str(blocker / "x.png")], "--out",
         "is a file"),
    ]
    for argv, *needles in cases:
        _fails_fast_and_leaves_nothing(argv, tmp_path, capsys, *needles)


def test_read_only_folders_fail_at_once(read_only_folder, tmp_path, capsys, small_store,
                                        sweep_file):
    experiment = ["experiment", str(DATA / "experiment.csv"), "--map",
                  str(DATA / "experiment_map.toml")]
    for argv in (["params", "--toml", str(read_only_folder / "p.toml")],
                 [*experiment, "--out", str(read_only_folder / "report")],
                 ["sweep", str(sweep_file), "--out", str(read_only_folder / "s.zarr")],
                 ["sweep-plot", str(small_store), "--out", str(read_only_folder / "f.png")],
                 ["sweep-plot", str(small_store), "--out",
                  str(read_only_folder / "missing" / "deeper" / "f.png")]):
        _fails_fast_and_leaves_nothing(argv, read_only_folder, capsys, "read-only",
                                       str(read_only_folder))


def test_too_little_free_space_fails_at_once(monkeypatch, tmp_path, capsys, sweep_file):
    import qzs.iotools.paths

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(qzs.iotools.paths.shutil, "disk_usage",
                        lambda path: usage(10_000, 9_990, 10))
    _fails_fast_and_leaves_nothing(["sweep", str(sweep_file), "--out",
                                    str(tmp_path / "s.zarr")], tmp_path, capsys,
                                   "--out", "needs about", "only 10 B are free")
    _fails_fast_and_leaves_nothing(["params", "--toml", str(tmp_path / "p.toml")], tmp_path,
                                   capsys, "free")


def test_a_missing_folder_is_created(tmp_path, capsys):
    path = tmp_path / "new" / "deeper" / "p.toml"
    assert main(["params", "--toml", str(path)]) == 0
    assert path.exists()


def test_check_output_path_carries_its_data(tmp_path):
    from qzs.iotools.paths import check_output_path

    with pytest.raises(OutputPathError) as caught:
        check_output_path(tmp_path / "run.xyz", argument="out", suffixes=("nc", ".CSV"))
    error = caught.value
    assert isinstance(error, ParameterError)
    assert (error.argument, error.value) == ("out", str(tmp_path / "run.xyz"))
    assert ".nc or .csv" in error.reason
    assert check_output_path(tmp_path / "RUN.NC", argument="out", suffixes=(".nc",)) \
        == tmp_path / "RUN.NC"
    assert check_output_path(tmp_path, argument="out", suffixes=None, directory=True) \
        == tmp_path
    import pickle

    copy = pickle.loads(pickle.dumps(error))
    assert (copy.argument, copy.value, copy.reason) == (error.argument, error.value,
                                                        error.reason)
