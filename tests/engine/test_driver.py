"""The one run driver (qzs.engine.driver): plan, chunks, memory guard, refusal, signals.

Each test states the property that fails if the driver is wrong; the drivers built on it
(single run, lockstep batch, six-leg platform) are checked to behave the same way.
"""
import math
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import qzs
from qzs.engine import driver
from qzs.engine import kernels as K
from qzs.errors import ParameterError, ResultTooLargeError, RunTooLongError


def test_phase_period_is_the_kernels():
    """The driver cuts chunks on the kernels' exact-phase grid (else chunking changes bits)."""
    assert driver.PHASE_PERIOD == K.PHASE_PERIOD


@pytest.mark.parametrize("decimation", [1, 7, 10, 256, 1000, 3 * 10 ** 5])
def test_chunks_hold_whole_samples_and_phase_periods(decimation):
    """A chunk is a multiple of lcm(decimation, 256) when that fits, within both bounds."""
    chunk = driver.chunk_steps(decimation, 2_000_000, 65_536)
    unit = math.lcm(decimation, 256)
    assert chunk % 256 == 0 and 0 < chunk <= 2_000_000
    if unit <= 2_000_000:  # a whole number of samples fits
        assert chunk % unit == 0
        assert chunk // decimation <= max(65_536, unit // decimation)
    else:
        assert chunk > 2_000_000 - 256


def test_chunks_are_bounded_in_steps_whatever_the_decimation():
    """With 1e10 steps per sample a chunk is still at most the affordable steps (the bug:
    one chunk of a whole sample ran for hours and ignored SIGTERM); and on the phase grid."""
    chunk = driver.chunk_steps(10 ** 10, 2_000_000, 65_536)
    assert chunk <= 2_000_000
    assert chunk % 256 == 0 and chunk > 0
    plan = driver.plan_run(10.0, 1e-9, 10 ** 9)
    assert plan.chunk <= driver.CHUNK_STEPS and plan.chunk % 256 == 0
    assert plan.samples == 11


def test_batch_chunks_shrink_with_the_cases_per_thread():
    """A thread stepping 128 lanes takes about as long per chunk as one case's chunk."""
    many = driver.plan_run(2000.0, 1e-4, 10, kernel="lanes", cases=256, workers=2,
                           max_samples=10 ** 9)
    ratio = (many.chunk * 128 * driver.BEST_STEP_SECONDS["lanes"]) / (
        driver.CHUNK_STEPS * driver.BEST_STEP_SECONDS["single"])
    assert 0.5 < ratio <= 1.0


def _hexapod(**options):
    from qzs.model.hexapod import PlatformParameters, cubic_geometry

    return qzs.simulate_hexapod(
        cubic_geometry(cube_edge=0.3, cube_center_height=0.3),
        PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5])),
        controller=qzs.ControllerParameters(pi_kp=2000.0, pi_ki=800.0), **options)


@pytest.mark.parametrize("run", [
    lambda: qzs.simulate(qzs.Sine(amplitude=0.01, frequency=1.0), duration=100.0, dt=1e-13,
                         sample_rate=1.0),
    lambda: _hexapod(excitation={"z": qzs.Sine(amplitude=0.01, frequency=1.0)},
                     duration=100.0, dt=1e-13, sample_rate=1.0),
    lambda: qzs.simulate_batch([(qzs.IsolatorParameters(), qzs.ControllerParameters())] * 2,
                               qzs.Sine(amplitude=0.01, frequency=1.0), duration=100.0,
                               dt=1e-13, sample_rate=1.0),
])
def test_absurd_runs_are_refused_before_they_start(run):
    """1e15 steps would take about a year: refused at once, naming dt, duration and the fix."""
    start = time.perf_counter()
    with pytest.raises(RunTooLongError) as caught:
        run()
    assert time.perf_counter() - start < 2.0
    error = caught.value
    assert isinstance(error, ParameterError)
    assert error.steps == 10 ** 15 and error.seconds > driver.LONGEST_RUN
    assert "`dt` = 1e-13 s" in str(error) and "larger `dt`" in str(error)


def test_a_long_but_possible_run_is_not_refused():
    """The refusal is a bound at the best speed: 1e9 steps (minutes) is allowed."""
    plan = driver.plan_run(1e5, 1e-4, 10)
    assert plan.steps == 10 ** 9


def _no_memory(monkeypatch):
    monkeypatch.setattr(driver, "available_memory", lambda: 10 * 2 ** 20)


def test_every_driver_raises_the_same_memory_error(monkeypatch):
    """Without a sink, a result over half the memory is refused before the run, with the
    same error class (and data) from the single run and the batch."""
    _no_memory(monkeypatch)
    chirp = qzs.Chirp(duration=200.0)
    errors = []
    for run in (lambda: qzs.simulate(chirp, sample_rate=1e4),
                lambda: _hexapod(excitation={"z": chirp}, sample_rate=1e4),
                lambda: qzs.simulate_batch([(qzs.IsolatorParameters(),
                                             qzs.ControllerParameters())] * 8, chirp,
                                           sample_rate=1e4, channels=("relative_position",
                                                                      "motor_force"))):
        start = time.perf_counter()
        with pytest.raises(ResultTooLargeError) as caught:
            run()
        assert time.perf_counter() - start < 2.0
        errors.append(caught.value)
    assert all(e.available == 10 * 2 ** 20 for e in errors)
    assert errors[0].needed == (2_000_001) * (8 * K.N_BASE_CHANNELS + 2)  # no blocks: 24
    assert "hexapod simulate --out" in errors[1].remedy
    assert errors[2].needed == 8 * 2_000_001 * 16
    assert "channels" in errors[2].remedy  # the batch's own advice, not --out


class _Counting(driver.Stepper):
    """A stepper of a fake kernel: the state is the step count; one sample every 3 steps."""

    def __init__(self, buffers, fail_at=None, flag=lambda step: step % 2 == 0):
        self.buffers, self.step, self.fail_at, self.calls = buffers, 0, fail_at, []
        self.flag = flag

    def advance(self, steps, buffer, row0):
        self.calls.append(steps)
        data, marks = self.buffers[buffer]
        row = row0
        for _ in range(steps):
            self.step += 1
            if self.fail_at is not None and self.step == self.fail_at:
                self.diverged = True
                return row - row0
            if self.step % 3 == 0:
                data[row] = self.step
                marks[row] = self.flag(self.step)
                row += 1
        return row - row0

    def divergence(self):
        return qzs.SimulationError(f"failed at {self.step}")


def _fake_run(steps, *, sink=None, chunk=256 * 3, fail_at=None, statistics=None, **stepper):
    plan = driver.RunPlan(steps=steps, decimation=3, samples=steps // 3 + 1, chunk=chunk)
    seen = []
    recorder = driver.Recorder(plan, 1, 1, statistics=statistics or (lambda d, f: seen.append(
        d.copy())), sink=sink)
    stepper = _Counting(recorder.buffers, fail_at, **stepper)
    recorder.buffers[0][0][0] = 0.0
    recorder.absorb(0, 0, 1)
    outcome = driver.drive(stepper, plan, recorder)
    return outcome, recorder, stepper, seen


def test_the_loop_keeps_every_sample_in_order():
    """In memory: sample k holds step 3k, whatever the chunks; statistics see each once."""
    outcome, recorder, stepper, seen = _fake_run(10_000)
    data, _ = recorder.result()
    np.testing.assert_array_equal(data[:, 0], 3 * np.arange(10_000 // 3 + 1))
    assert np.concatenate(seen).size == data.shape[0]
    assert stepper.calls[0] == 0  # the warm-up call, outside the clock
    assert sum(stepper.calls) == 10_000 and outcome.completed


def test_a_streamed_preview_is_the_min_max_envelope(monkeypatch):
    """A sink gets every sample in order; the preview holds each group's min and max."""
    monkeypatch.setattr(driver, "PREVIEW_SAMPLES", 100)
    streamed = []
    _, recorder, _, _ = _fake_run(30_000, sink=lambda d, f: streamed.append(d[:, 0].copy()))
    samples = np.concatenate(streamed)
    np.testing.assert_array_equal(samples, 3 * np.arange(10_001))
    preview, _ = recorder.result()
    every = recorder.every
    groups = [samples[i:i + every] for i in range(0, samples.size, every)]
    assert every > 1 and preview.shape[0] == 2 * len(groups) <= 100
    # one pair per group, also for the groups that chunk boundaries cut
    np.testing.assert_array_equal(preview[0::2, 0], [g.min() for g in groups])
    np.testing.assert_array_equal(preview[1::2, 0], [g.max() for g in groups])


def test_a_streamed_previews_flags_are_all_and_any_of_each_group(monkeypatch):
    """The preview's flag rows: the low row of a group is set where every sample of it is,
    the high row where any is, also for the groups that chunk boundaries cut (their first
    part merged with the rest). The flag is set over runs of 37 samples and clear over the
    next 37: a part of a group may be all set, or all clear, and the rest not."""
    monkeypatch.setattr(driver, "PREVIEW_SAMPLES", 100)
    streamed = []
    _, recorder, _, _ = _fake_run(30_000, sink=lambda d, f: streamed.append(f[:, 0].copy()),
                                  flag=lambda step: (step // 3) // 37 % 2 == 0)
    flags = np.concatenate(streamed)
    _, preview_flags = recorder.result()
    every = recorder.every
    groups = [flags[i:i + every] for i in range(0, flags.size, every)]
    assert 10_001 % every and 256 % every  # groups cut by chunks, and the last one short
    assert any(g.any() and not g.all() for g in groups)
    np.testing.assert_array_equal(preview_flags[0::2, 0], [g.all() for g in groups])
    np.testing.assert_array_equal(preview_flags[1::2, 0], [g.any() for g in groups])


def test_a_divergence_raises_the_steppers_error_after_keeping_the_rows():
    with pytest.raises(qzs.SimulationError, match="failed at 1000"):
        _fake_run(10_000, fail_at=1000)


def test_sigterm_ends_a_run_of_tiny_steps_within_seconds(tmp_path):
    """`qzs simulate` with 1e8 steps per output sample: SIGTERM ends it within a few seconds
    (a chunk is bounded in steps), exit 143, and nothing is left in the folder. (The output
    rate, 10 Hz, is above twice the sine's 1 Hz: a lower one is refused before the run.)"""
    out = tmp_path / "run.nc"
    process = subprocess.Popen(
        [sys.executable, "-m", "qzs", "simulate", "--excitation", "sine", "--dt", "1e-9",
         "--duration", "20", "--sample-rate", "10", "--out", str(out), "--plot", "none",
         "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not any(tmp_path.iterdir()) and time.monotonic() < deadline:  # the writer started
        time.sleep(0.05)
    time.sleep(1.0)
    sent = time.monotonic()
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert time.monotonic() - sent < 5.0
    assert process.returncode == 143, err
    assert list(tmp_path.iterdir()) == []


def _envelope_by_reduceat(data, flags, first, every):
    """The envelope by ``reduceat`` over the block's group starts (the former method)."""
    group = (first + np.arange(data.shape[0])) // every
    starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    rows = np.empty((2 * starts.size, data.shape[1]))
    rows[0::2] = np.minimum.reduceat(data, starts, axis=0)
    rows[1::2] = np.maximum.reduceat(data, starts, axis=0)
    marks = np.empty((2 * starts.size, flags.shape[1]), dtype=np.bool_)
    marks[0::2] = np.logical_and.reduceat(flags, starts, axis=0)
    marks[1::2] = np.logical_or.reduceat(flags, starts, axis=0)
    return rows, marks


@pytest.mark.parametrize("first, every, n", [(0, 20, 4000), (1, 20, 4001), (19, 20, 1),
                                             (0, 20, 20), (7, 3, 2), (5, 7, 1000),
                                             (0, 1, 50), (3, 1000, 999)])
def test_the_envelope_is_that_of_a_reduction_per_group_bit_for_bit(first, every, n):
    """Against reduceat over the group starts: the same bytes, with ties of +0 and -0 (which
    one wins depends on the order of comparison), NaN, and groups cut at both ends."""
    rng = np.random.default_rng(first + every + n)
    data = rng.choice([-1.5, -0.0, 0.0, 2.0, np.nan], size=(n, 5),
                      p=[0.2, 0.3, 0.3, 0.15, 0.05])
    data[:, 0] = np.arange(first, first + n) * 1e-3  # a time channel
    flags = rng.random((n, 2)) < 0.5
    rows, marks = driver.envelope_rows(data, flags, first, every)
    expected_rows, expected_marks = _envelope_by_reduceat(data, flags, first, every)
    assert rows.tobytes() == expected_rows.tobytes()
    assert marks.shape == expected_marks.shape and np.array_equal(marks, expected_marks)
    groups = len({(first + i) // every for i in range(n)})
    assert rows.shape == (2 * groups, 5)


# ---------------------------------------------------------------- the memory guard's threshold
_SINE = qzs.Sine(amplitude=0.01, frequency=1.0)
_PAIR = (qzs.IsolatorParameters(stiction_force=8.0), qzs.ControllerParameters())


def _single():
    result = qzs.simulate(_SINE, *_PAIR, duration=1.0, sample_rate=100.0)
    from qzs.engine.channels import CHANNELS, FLAGS

    held = sum(np.asarray(result[name]).nbytes for name in (*CHANNELS, *FLAGS))
    return held, result.relative_position


def _batch():
    result = qzs.simulate_batch([_PAIR] * 3, _SINE, duration=1.0, sample_rate=100.0,
                                channels=("relative_position", "motor_force", "locked"),
                                workers=1)
    return sum(a.nbytes for a in result.channels.values()), result.channels["relative_position"]


@pytest.mark.parametrize("run", [_single, _batch], ids=["single", "batch"])
def test_the_memory_guard_refuses_exactly_a_result_over_half_the_available_memory(run,
                                                                              monkeypatch):
    """As documented (:func:`qzs.engine.driver.check_memory`, ``MEMORY_SHARE``): a result of
    ``needed`` bytes is refused if and only if it is more than half the available memory.
    ``needed`` is what the finished result holds (the nbytes of every array it keeps), so the
    guard's byte count is checked too: at 2 * needed available the run goes (exactly half),
    at one byte less it is refused, as everywhere between half and all of the memory."""
    held, reference = run()  # the machine's real memory: a small run goes
    assert driver.MEMORY_SHARE == 0.5
    for available, refused in ((2 * held, False), (2 * held - 1, True), (4 * held, False),
                               ((3 * held) // 2, True), (held + 1, True), (held, True),
                               (held // 2, True), (None, False)):
        monkeypatch.setattr(driver, "available_memory", lambda a=available: a)
        if refused:
            with pytest.raises(ResultTooLargeError) as caught:
                run()
            assert (caught.value.needed, caught.value.available) == (held, available)
        else:
            again = run()
            assert again[0] == held and np.array_equal(again[1], reference), available
