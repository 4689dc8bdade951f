"""Long runs: memory grows with what is kept, not with the duration (issue 10).

With a sink (``--out``) a run streams its samples chunk by chunk and keeps a preview;
without one, a result that would not fit in memory is refused before the run starts.
"""
import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import qzs
from qzs import Chirp, Sine, simulate
from qzs.engine import driver as driver_module, single as simulate_module, step_cache
from qzs.errors import ResultTooLargeError
from qzs.iotools import read_result
from qzs.workflows import forked
from qzs.workflows.run import simulate_to_file

EXCITATION = Sine(amplitude=0.004, frequency=3.0)


def test_streamed_statistics_equal_those_of_the_whole_run(monkeypatch):
    """Chunked statistics are the statistics of every sample: a run in 7 chunks whose result
    keeps every 4th sample reports what the same run held whole reports."""
    monkeypatch.setattr(driver_module, "CHUNK_STEPS", 1_500)  # cut to 1280: lcm(10, 256)
    monkeypatch.setattr(driver_module, "PREVIEW_SAMPLES", 250)
    whole = simulate(EXCITATION, duration=1.0, sample_rate=1000.0)
    blocks = []
    streamed = simulate(EXCITATION, duration=1.0, sample_rate=1000.0,
                        sink=lambda data, flags: blocks.append((data.copy(), flags.copy())))
    assert len(blocks) == 1 + 8  # t = 0, then ceil(10000 / 1280) chunks
    data = np.concatenate([b[0] for b in blocks])
    flags = np.concatenate([b[1] for b in blocks])
    np.testing.assert_array_equal(data, whole._data)
    np.testing.assert_array_equal(flags, whole._flags)
    assert streamed.run["preview_every"] == 9  # ceil(1001 / 125): two rows per group
    assert streamed.run["samples"] == len(whole) == 1001
    # the preview is the envelope: each group's min and max of every channel, flags all/any
    z = whole.relative_position
    groups = [slice(i, min(i + 9, 1001)) for i in range(0, 1001, 9)]
    preview_z = streamed.relative_position
    assert preview_z.min() == z.min() and preview_z.max() == z.max()
    lows, highs = preview_z[0::2], preview_z[1::2]
    chunk_groups = len(lows)  # a group a chunk boundary splits is split in two
    assert 112 <= chunk_groups <= 112 + 8
    for name in ("payload_acceleration", "motor_force", "time"):
        assert streamed[name].min() == whole[name].min()
        assert streamed[name].max() == whole[name].max()
    assert streamed.time[0] == 0.0 and streamed.time[-1] == whole.time[-1]
    assert np.all(np.diff(streamed.time) >= 0)
    np.testing.assert_array_equal(lows[0], min(z[groups[0]]))
    np.testing.assert_array_equal(highs[0], max(z[groups[0]]))
    assert streamed.locked.any() == whole.locked.any()
    for name, value in whole.statistics.items():
        assert streamed.statistics[name] == pytest.approx(value, rel=1e-12, abs=1e-15), name
    # the statistics are those of every sample, not of the preview
    assert streamed.statistics["z_min"] == whole.relative_position.min()


def test_simulate_to_file_writes_every_sample(tmp_path, monkeypatch):
    monkeypatch.setattr(driver_module, "CHUNK_STEPS", 2_000)
    monkeypatch.setattr(driver_module, "PREVIEW_SAMPLES", 100)
    path = tmp_path / "run.nc"
    result = simulate_to_file(path, EXCITATION, duration=1.0, sample_rate=500.0)
    data = read_result(path)
    whole = simulate(EXCITATION, duration=1.0, sample_rate=500.0)
    assert data.sizes["time"] == len(whole) == 501
    np.testing.assert_array_equal(data["relative_position"].values, whole.relative_position)
    assert len(result) < 501 and result.run["preview_every"] > 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_too_large_a_result_is_refused_before_the_run(monkeypatch):
    monkeypatch.setattr(driver_module, "available_memory", lambda: 100 * 2 ** 20)
    start = time.perf_counter()
    with pytest.raises(ResultTooLargeError, match="stream it to a file") as caught:
        simulate(Chirp(), duration=2000.0, sample_rate=1000.0)  # 2e6 samples, ~390 MB
    assert time.perf_counter() - start < 5.0
    error = caught.value
    assert error.needed == simulate_module.result_bytes(2000.0, 1000.0)
    assert error.available == 100 * 2 ** 20 and error.duration == 2000.0


#: ``qzs simulate --duration D --out FILE`` (its step chosen, its figure drawn by a forked
#: helper) in a fresh interpreter: prints the peak resident memory of this process and of its
#: helpers [bytes]. This process's is its image's high-water mark (VmHWM): its ``ru_maxrss``
#: would also hold the peak of the process it was started from (Linux keeps it across
#: ``exec``), here pytest's, 470 MB deep into the suite.
_PEAK = """
import json, resource, sys
from qzs.cli import main
duration = sys.argv[1]
code = main(["simulate", "--duration", duration, "--excitation-duration", duration,
             "--sample-rate", "1000", "--out", sys.argv[2], "--plot", sys.argv[3], "--quiet"])
assert code == 0, code
with open("/proc/self/status") as status:
    own = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
print(json.dumps([own * 1024, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024]))
"""
#: What a streamed run of any length may take at its peak [bytes] (issue 39: 301 MB at
#: 20000 s, 282 MB before; the numerical libraries alone hold about 200 MB).
PEAK_CEILING = 300 * 2 ** 20


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="ru_maxrss in KiB on Linux")
def test_peak_memory_of_a_streamed_run_does_not_grow_with_its_duration(tmp_path):
    """``qzs simulate --out`` of 2000 s and 20000 s at 1 kHz (2e6 and 2e7 samples, 390 MB and
    3.9 GB if kept, the file 10 times larger), each in a fresh process choosing its step on an
    empty step cache: the peak of the run and of its helpers (the step choice's, the
    figure's) stays under :data:`PEAK_CEILING`, and the longer's within 10 % of the
    shorter's (its chunk buffers and preview are sized once, not by the duration).

    The kernels are compiled first, by a short run: compiling is a first run's alone (LLVM's
    memory, once), and a suite whose other tests compile them concurrently would make this
    measure depend on the order the tests run in."""
    warm = subprocess.run([sys.executable, "-m", "qzs", "simulate", "--duration", "1",
                           "--dt", "1e-3", "--quiet"], capture_output=True, text=True,
                          timeout=900, cwd=tmp_path)
    assert warm.returncode == 0, warm.stderr
    peaks = {}
    for duration in (2000, 20000):
        out = tmp_path / f"run{duration}.nc"
        cache = tmp_path / f"cache{duration}"  # an empty step cache: the step is chosen
        run = subprocess.run([sys.executable, "-c", _PEAK, str(duration), str(out),
                              str(tmp_path / f"run{duration}.png")],
                             capture_output=True, text=True, timeout=900,
                             env={**os.environ, step_cache.CACHE_ENV: str(cache)})
        out.unlink(missing_ok=True)  # 3.9 GB: not left for pytest's kept folders
        assert run.returncode == 0, run.stderr
        assert list((cache / "steps").iterdir()), "no step was chosen"
        process, helper = json.loads(run.stdout.strip().splitlines()[-1])
        # the figure is drawn beside, by a forked helper (two cores), whose peak counts too
        assert helper > 0 or not forked.available()
        peaks[duration] = max(process, helper)
    assert max(peaks.values()) < PEAK_CEILING, {d: p / 2 ** 20 for d, p in peaks.items()}
    assert peaks[20000] < 1.10 * peaks[2000], {d: p / 2 ** 20 for d, p in peaks.items()}


_APART = """
import json, sys
from qzs import Chirp
from qzs.workflows.run import resolve_apart
resolved = resolve_apart(Chirp(duration=40.0, f1=5.0), step="chosen", progress=False)
print(json.dumps([resolved.dt, resolved.step.to_dict(), "scipy.signal" in sys.modules]))
"""


@pytest.mark.skipif(not forked.available(), reason="no fork or one core: resolved here")
def test_a_streamed_runs_step_is_chosen_apart_with_the_same_answer(tmp_path):
    """:func:`resolve_apart` chooses the step in a forked helper: the answer is
    :func:`resolve`'s, and the spectral estimate's imports never enter this process."""
    from qzs.engine.run_spec import resolve

    run = subprocess.run([sys.executable, "-c", _APART], capture_output=True, text=True,
                         timeout=900, env={**os.environ, step_cache.CACHE_ENV: str(tmp_path)})
    assert run.returncode == 0, run.stderr
    dt, record, imported = json.loads(run.stdout.strip().splitlines()[-1])
    assert not imported
    here = resolve(Chirp(duration=40.0, f1=5.0), step="chosen", cache=False)
    assert dt == here.dt and record["chosen"]
    assert record == json.loads(json.dumps(here.step.to_dict()))


def test_resolve_apart_raises_resolves_error_with_its_arguments():
    """A bad input chosen apart is the same :class:`ParameterError`, naming its argument."""
    from qzs.errors import ParameterError
    from qzs.workflows.run import resolve_apart

    with pytest.raises(ParameterError, match="tolerance") as caught:
        resolve_apart(Sine(amplitude=0.004, frequency=3.0), duration=2.0, tolerance=0.01,
                      step="chosen")
    assert "tolerance" in caught.value.options


def test_ctrl_c_while_a_chunk_is_written_keeps_every_chunk_whole(tmp_path, monkeypatch):
    """SIGINT arriving inside the sink (the main thread writing a chunk) stops the run after
    the chunk under way: the file holds whole chunks, in order, and says it is incomplete."""
    import signal

    from qzs.engine.result_file import ResultWriter

    monkeypatch.setattr(driver_module, "CHUNK_SAMPLES", 100)  # cut to 128 samples
    # from Python's own handler, whatever the shell gave: a background job starts with SIGINT
    # ignored, and raise_signal would then do nothing
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        path = tmp_path / "run.nc"
        calls = []
        with ResultWriter(path, isolator=qzs.IsolatorParameters(),
                          controller=qzs.ControllerParameters(), excitation=EXCITATION) as writer:
            def sink(data, flags):
                calls.append(len(data))
                if len(calls) == 3:
                    signal.raise_signal(signal.SIGINT)  # Ctrl-C in the middle of writing
                writer.append(data, flags)

            result = simulate(EXCITATION, duration=10.0, sample_rate=1000.0, sink=sink,
                              interruptible=True)
            writer.finish(result.run)
        assert not result.completed
        assert calls == [1, 128, 128, 128]  # t = 0, the chunk being written, the one under way
        data = read_result(path)
        assert data.sizes["time"] == result.run["samples"] == 1 + 3 * 128
        np.testing.assert_allclose(np.diff(data.time.values), 1e-3, rtol=1e-9)
        assert data.attrs["run.completed"] == 0
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # given back
    finally:
        signal.signal(signal.SIGINT, before)


def test_sigterm_during_an_interruptible_run_is_raised_between_chunks(monkeypatch):
    """Where SIGTERM is turned into Terminated (the CLI), an interruptible run defers it to the
    next chunk boundary and raises it there, in the run's own code: raised at an arbitrary
    point it may land in a weakref callback, where Python only prints it and goes on (the
    run then finished and wrote its file). With the default action nothing is taken over."""
    import os
    import signal

    import qzs
    from qzs.errors import Terminated

    def raising(signum, frame):  # what the CLI installs
        raise Terminated(signum)

    previous = signal.signal(signal.SIGTERM, raising)
    sent = []

    def sink(block, flags):
        if len(block) > 1 and not sent:  # a chunk of the run (the first call is row 0)
            sent.append("signal")
            os.kill(os.getpid(), signal.SIGTERM)
            sent.append("chunk written whole")  # not cut off inside the sink

    try:
        with pytest.raises(Terminated):
            qzs.simulate(qzs.Chirp(duration=60.0), interruptible=True, sink=sink)
        assert sent == ["signal", "chunk written whole"]
        assert signal.getsignal(signal.SIGTERM) is raising  # given back
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert signal.getsignal(signal.SIGTERM) is previous
