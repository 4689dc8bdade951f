"""Batch engine: the same numbers as single runs, failures recorded, stats consistent."""
import numpy as np
import pytest
from helpers import linear_controller, linear_isolator

import qzs
from qzs.engine.batch import STATS, simulate_batch

EXCITATION = qzs.Chirp(duration=12.0, f1=8.0)
CASES = [(qzs.IsolatorParameters(stiction_force=fs), qzs.ControllerParameters(pi_kp=kp, pi_ki=ki))
         for fs in (2.0, 10.0) for kp, ki in ((5.0, 2.0), (50.0, 20.0))]


@pytest.fixture(scope="module")
def batch():
    return simulate_batch(CASES + [(qzs.IsolatorParameters(), qzs.ControllerParameters(
        pi_kp=0.0, pi_ki=0.0))], EXCITATION, sample_rate=500.0,
        channels=("payload_acceleration", "relative_position", "motor_force"), workers=2)


def test_batch_equals_single_runs_exactly(batch):
    for index, (isolator, controller) in enumerate(CASES):
        single = qzs.simulate(EXCITATION, isolator, controller, sample_rate=500.0)
        for name in ("payload_acceleration", "relative_position", "motor_force"):
            assert np.array_equal(batch.channels[name][index], single[name]), (index, name)
        assert batch.stats["stop_contacts"][index] == single.run["stop_contacts"]
        assert batch.stats["stick_events"][index] == single.run["stick_events"]
        assert batch.stats["z_min"][index] == single.relative_position.min()
        assert batch.stats["locked_fraction"][index] == pytest.approx(single.locked.mean())
        rms = np.sqrt(np.mean(single.motor_force ** 2))
        assert batch.stats["motor_force_rms"][index] == pytest.approx(rms, rel=1e-12)
    assert np.array_equal(batch.time, single.time)  # step * dt, as the kernel writes it


def test_stats_are_consistent(batch):
    assert set(batch.stats) == set(STATS)
    z = batch.channels["relative_position"]
    center = qzs.ControllerParameters().position_setpoint
    np.testing.assert_allclose(batch.stats["peak_stroke"], np.abs(z - center).max(axis=1))
    assert np.all(batch.stats["steps"] == 120_000)
    assert batch.stats["stop_contacts"][-1] == 0 or batch.stats["z_min"][-1] < -0.13
    assert batch.steps_per_second > 0


def test_one_thread_equals_many():
    one = simulate_batch(CASES[:3], EXCITATION, sample_rate=250.0, channels=("relative_position",),
                         workers=1)
    two = simulate_batch(CASES[:3], EXCITATION, sample_rate=250.0, channels=("relative_position",),
                         workers=2)
    assert np.array_equal(one.channels["relative_position"], two.channels["relative_position"])


def test_a_failing_case_is_recorded_and_the_others_go_on():
    plant = linear_isolator(stiffness=1e-9, damping=100.0, stroke_half=1.0, motor_force_max=1e12)
    unstable = linear_controller(pi_kp=1e6, controller_rate=100.0)
    result = simulate_batch([CASES[0], (plant, unstable), CASES[1]],
                            qzs.Sine(amplitude=0.01, frequency=1.0), duration=5.0,
                            sample_rate=100.0, channels=("relative_position",))
    assert list(result.status) == [0, 1, 0]
    assert result.messages[0] == result.messages[2] == ""
    assert "diverged at t = " in result.messages[1]
    assert np.all(np.isfinite(result.channels["relative_position"][[0, 2]]))
    assert result.stats["steps"][1] < result.stats["steps"][0]


@pytest.mark.parametrize("kwargs, match", [
    (dict(channels=("payload_jerk",)), r"unknown channel\(s\) \['payload_jerk'\]"),
    (dict(cases=[]), "at least one"),
    (dict(cases=[(qzs.IsolatorParameters(), "not a controller")]), "case 0: `controller` must be"),
    (dict(dt=0.5), "case 0: .*largest stable step"),
    (dict(workers=0), "`workers` must be an integer >= 1"),
])
def test_bad_arguments(kwargs, match):
    arguments = dict(cases=CASES[:1], excitation=EXCITATION, sample_rate=2.0)
    arguments.update(kwargs)
    with pytest.raises(qzs.ParameterError, match=match):
        simulate_batch(**arguments)


def test_chunking_changes_no_bit(monkeypatch):
    """Single runs and batches asked for different chunks give the same numbers to the last
    bit: calls are cut on multiples of lcm(decimation, PHASE_PERIOD) steps, where the
    excitation's sine and cosine are exact, and the holding margin carries across calls
    (docs/model.md §9). Stick-slip on a slow chirp crosses many of the boundaries."""
    from qzs.engine import batch as batch_module, driver as driver_module
    from qzs.engine.kernels import PHASE_PERIOD

    excitation = qzs.Chirp(duration=20.0, f0=0.5, f1=3.0)
    cases = [(qzs.IsolatorParameters(stiction_force=fs), qzs.ControllerParameters())
             for fs in (3.0, 8.0, 15.0)]
    runs = {}
    for label, steps in (("whole", 10 ** 7), ("short", 1_330), ("odd", 9_990)):  # asked for
        monkeypatch.setattr(driver_module, "CHUNK_STEPS", steps)
        runs[label] = [qzs.simulate(excitation, iso, ctrl, sample_rate=1000.0)
                       for iso, ctrl in cases]
    monkeypatch.setattr(batch_module, "_ROWS_PER_CHUNK", 3 * 777)  # 777 samples per case
    assert np.lcm(10, PHASE_PERIOD) == 1280  # what the calls are rounded to
    batch = simulate_batch(cases, excitation, sample_rate=1000.0,
                           channels=("payload_acceleration", "relative_position"))
    sticks = [r.run["stick_events"] for r in runs["whole"]]
    assert min(sticks) > 10
    for label in ("short", "odd"):
        for whole, cut in zip(runs["whole"], runs[label]):
            np.testing.assert_array_equal(cut.payload_acceleration, whole.payload_acceleration)
            assert cut.run["stick_events"] == whole.run["stick_events"]
    for c, whole in enumerate(runs["whole"]):
        np.testing.assert_array_equal(batch.channels["payload_acceleration"][c],
                                      whole.payload_acceleration)
        np.testing.assert_array_equal(batch.channels["relative_position"][c],
                                      whole.relative_position)


def _compensated(fraction, observer=0.0):
    return qzs.ControllerParameters(compensation=qzs.FrictionCompensation(
        fraction=fraction, observer_bandwidth=observer))


def test_a_block_channel_is_kept_and_equals_the_single_run():
    """A batch keeps a block's force (`compensation_force`, `friction_estimate`) as a
    single run records it, bit for bit, in one lane or in lockstep lanes."""
    cases = [(qzs.IsolatorParameters(), _compensated(fraction, observer))
             for fraction, observer in ((0.5, 0.0), (1.0, 20.0), (0.0, 5.0))]
    excitation = qzs.Chirp(duration=2.0, f0=0.5, f1=3.0)
    names = ("compensation_force", "payload_acceleration")
    for workers in (1, 3):
        batch = simulate_batch(cases, excitation, sample_rate=500.0, channels=names,
                               workers=workers)
        for index, (isolator, controller) in enumerate(cases):
            single = qzs.simulate(excitation, isolator, controller, sample_rate=500.0)
            for name in names:
                assert np.array_equal(batch.channels[name][index], single[name]), (
                    workers, index, name)
        assert np.any(batch.channels["compensation_force"][1] != 0.0)
        assert batch.to_xarray()["compensation_force"].attrs["units"] == "N"
    observed = simulate_batch(cases[1:], excitation, sample_rate=500.0,
                              channels=("friction_estimate",), workers=1)
    single = qzs.simulate(excitation, *cases[1], sample_rate=500.0)
    assert np.array_equal(observed.channels["friction_estimate"][0], single.friction_estimate)


def test_a_block_channel_of_a_case_without_the_block_is_refused_before_any_work():
    cases = [(qzs.IsolatorParameters(), _compensated(0.5)),
             (qzs.IsolatorParameters(), qzs.ControllerParameters())]
    with pytest.raises(qzs.ParameterError) as error:
        simulate_batch(cases, qzs.Chirp(duration=1e9), channels=("compensation_force",))
    message = str(error.value)
    assert "compensation_force" in message and "case 1" in message
    assert "channels" in error.value.options
    with pytest.raises(qzs.ParameterError) as error:  # no observer: no estimate
        simulate_batch(cases[:1], qzs.Chirp(duration=1e9), channels=("friction_estimate",))
    assert "observer_bandwidth" in str(error.value)
    with pytest.raises(qzs.ParameterError, match="dither_forse"):
        simulate_batch(cases[:1], qzs.Chirp(duration=1e9), channels=("dither_forse",))
