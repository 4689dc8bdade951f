"""The figure drawn in a second process: the same figure and file as drawn in sequence, and
nothing left behind (no temporary file, no process) when a run stops early."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import qzs
from qzs.engine.result import SimulationResult
from qzs.engine.result_file import ResultWriter
from qzs.engine.run_spec import resolve
from qzs.workflows import figure_process, forked
from qzs.workflows.figure_process import figure_helper, simulate_with_figure

pytestmark = pytest.mark.skipif(not forked.available(),
                                reason="needs fork and two usable cores")

EXCITATION = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=30.0)


def _resolved():
    return resolve(EXCITATION, duration=30.0, dt=1e-3, sample_rate=1000.0)


_REFERENCES = ("DIMENSION_LIST", "REFERENCE_LIST")  # HDF5 object references: per file


def _file_data(path):
    """Every variable's values and every attribute but the wall-time ones."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, item):
            if isinstance(item, h5py.Dataset):
                out[name] = (item[()].tobytes(), str(item.dtype), item.shape)
            out[name + "@attrs"] = {k: repr(v) for k, v in item.attrs.items()
                                    if "elapsed" not in k and k not in _REFERENCES}
        f.visititems(visit)
        out["@global"] = {k: repr(v) for k, v in f.attrs.items()
                          if "elapsed" not in k and k != "history"}
    return out


def _writing(folder):
    """Whether a run is writing samples in ``folder`` (a temporary file past its header)."""
    try:
        return any(p.suffix == ".part" and p.stat().st_size > (2 << 20)
                   for p in folder.iterdir())
    except FileNotFoundError:  # renamed meanwhile
        return False


def _children_of(pid):
    """Processes whose parent is ``pid`` (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found


def test_the_helper_draws_the_figure_the_run_would_draw_itself(tmp_path, monkeypatch):
    """Parallel and sequential paths write the same figure (bytes) and the same file (every
    value and attribute); in the parallel path this process draws nothing (its
    ``plot`` raises) and never imports matplotlib's drawing into the run."""
    sequential = simulate_with_figure(_resolved(), out=tmp_path / "seq.nc",
                                      plot=tmp_path / "seq.png", parallel=False)

    def refuse(self, *args, **kwargs):
        raise AssertionError("the parent drew the figure")

    monkeypatch.setattr(SimulationResult, "plot", refuse)
    parallel = simulate_with_figure(_resolved(), out=tmp_path / "par.nc",
                                    plot=tmp_path / "par.png", parallel=True)
    assert (tmp_path / "par.png").read_bytes() == (tmp_path / "seq.png").read_bytes()
    assert (tmp_path / "par.png").stat().st_size > 10_000  # a figure, not an empty file
    assert _file_data(tmp_path / "par.nc") == _file_data(tmp_path / "seq.nc")
    assert parallel.summary().splitlines()[2:] == sequential.summary().splitlines()[2:]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["par.nc", "par.png", "seq.nc",
                                                           "seq.png"]


def test_the_default_is_parallel_with_a_file_and_sequential_without(tmp_path, monkeypatch):
    made = []

    def spy(suffix):
        made.append(suffix)
        return figure_helper(suffix)

    monkeypatch.setattr(figure_process, "figure_helper", spy)
    simulate_with_figure(_resolved(), plot=tmp_path / "memory.png")
    assert made == []  # a run in memory holds every sample: drawn here
    simulate_with_figure(_resolved(), out=tmp_path / "run.nc", plot=tmp_path / "run.svg")
    assert made == [".svg"]
    assert (tmp_path / "run.svg").read_bytes().lstrip().startswith(b"<?xml")


def test_a_helper_that_dies_leaves_the_figure_to_this_process(tmp_path, monkeypatch):
    """The helper killed before it draws: this process draws, the same bytes."""
    simulate_with_figure(_resolved(), out=tmp_path / "seq.nc", plot=tmp_path / "seq.png",
                         parallel=False)
    real_send = forked.Forked.send

    def kill_then_send(self, result):
        os.kill(self.pid, signal.SIGKILL)
        self._process.join()
        real_send(self, result)

    monkeypatch.setattr(forked.Forked, "send", kill_then_send)
    simulate_with_figure(_resolved(), out=tmp_path / "par.nc", plot=tmp_path / "par.png",
                         parallel=True)
    assert (tmp_path / "par.png").read_bytes() == (tmp_path / "seq.png").read_bytes()


def test_an_error_in_the_run_leaves_no_file_and_no_helper(tmp_path, monkeypatch):
    """KeyboardInterrupt (a non-interruptible run) while a chunk is written: no file, no
    temporary file, and the helper is gone (killed and waited for)."""
    helpers = []

    def spy(suffix):
        helper = figure_helper(suffix)
        helpers.append(helper.pid)
        return helper

    calls = []

    def interrupted(self, data, flags):
        calls.append(len(data))
        if len(calls) == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr(figure_process, "figure_helper", spy)
    monkeypatch.setattr(ResultWriter, "append", interrupted)
    with pytest.raises(KeyboardInterrupt):
        simulate_with_figure(_resolved(), out=tmp_path / "run.nc", plot=tmp_path / "run.png")
    assert list(tmp_path.iterdir()) == []
    assert len(helpers) == 1
    assert helpers[0] not in _children_of(os.getpid())
    with pytest.raises(ProcessLookupError):
        os.kill(helpers[0], 0)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_to_the_command_leaves_no_temporary_file_and_no_process(tmp_path, signum,
                                                                         code):
    """``qzs simulate --out`` with its figure, Ctrl-C (to the whole process group, as a
    terminal sends it) or SIGTERM while the helper is alive: Ctrl-C ends the run early, with
    the file and the interrupted run's figure (exit 130); SIGTERM ends it with neither (143).
    No temporary file either way, and no process of the command's session is left."""
    env = dict(os.environ, PYTHONPATH=str(Path(qzs.__file__).parents[1]))
    command = [sys.executable, "-m", "qzs", "simulate", "--duration", "600", "--dt", "1e-4",
               "--out", "run.nc", "--plot", "run.png", "--quiet"]
    proc = subprocess.Popen(command, cwd=tmp_path, env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while not _children_of(proc.pid) or not _writing(tmp_path):
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the helper and the file never appeared"
            time.sleep(0.02)
        helper = _children_of(proc.pid)
        if signum == signal.SIGINT:
            os.killpg(proc.pid, signum)  # what a terminal does: the whole group
        else:
            os.kill(proc.pid, signum)
        proc.wait(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert proc.returncode == code, proc.stderr.read().decode()
    if signum == signal.SIGINT:
        assert names == ["run.nc", "run.png"]
        with h5py.File(tmp_path / "run.nc", "r") as f:
            assert f["run"].attrs["completed"] == 0
    else:
        assert names == []
    for pid in helper:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


def test_the_helper_ignores_ctrl_c(tmp_path):
    """SIGINT reaches the whole process group: the helper must not die of it (the parent
    decides), nor print a traceback; it still draws."""
    helper = figure_helper(".png")
    try:
        time.sleep(0.2)
        os.kill(helper.pid, signal.SIGINT)
        time.sleep(0.2)
        assert helper.is_alive()
        result = qzs.simulate(EXCITATION, duration=2.0)
        helper.send(result)
        drawn = helper.result()
    finally:
        helper.close()
    assert drawn[:8] == b"\x89PNG\r\n\x1a\n"
    assert not helper.is_alive()


def test_warm_up_labels_are_those_of_the_run_figure():
    """The warm-up draws the texts whose glyphs and mathtext the run's figure needs."""
    import inspect

    from qzs.viz import simulation

    source = inspect.getsource(simulation.plot_simulation)
    for label in figure_process._WARM_UP_LABELS:
        assert label in source
    assert np.all([isinstance(label, str) for label in figure_process._WARM_UP_LABELS])


def test_a_warmed_up_helper_draws_the_same_bytes(tmp_path, monkeypatch):
    """The warm-up (a throw-away figure drawn while the run goes on) leaves no trace in the
    run's figure: the helper, warmed up before the run is sent, draws the bytes this process
    draws from scratch."""
    marker = tmp_path / "warmed"
    real = figure_process._warm_up

    def warm_up(suffix):  # runs in the forked helper
        real(suffix)
        marker.write_text("done")

    monkeypatch.setattr(figure_process, "_warm_up", warm_up)
    helper = figure_helper(".png")
    try:
        deadline = time.monotonic() + 120
        while not marker.exists():
            assert time.monotonic() < deadline, "the helper never warmed up"
            time.sleep(0.05)
        result = qzs.simulate(EXCITATION, duration=20.0)
        helper.send(result)
        drawn = helper.result()
    finally:
        helper.close()
    result.plot(path=tmp_path / "here.png")
    assert drawn == (tmp_path / "here.png").read_bytes()
