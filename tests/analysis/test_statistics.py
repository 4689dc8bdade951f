"""Run statistics (qzs.analysis.statistics): closed forms of a sampled sine, and blocks added
in any cut and any order of cases give the statistics of the whole run."""
import numpy as np
import pytest

from qzs.analysis.statistics import RunStatistics, SummaryStatistics, run_statistics


def test_statistics_of_a_sine_are_its_closed_forms():
    """One period of z = c + A sin, force F sin, locked a quarter of the time."""
    t = np.arange(1000) / 1000.0
    center, amplitude, force = -0.06, 0.01, 3.0
    stats = run_statistics(center + amplitude * np.sin(2 * np.pi * t),
                           force * np.sin(2 * np.pi * t), t < 0.25, center)
    assert stats["z_min"] == pytest.approx(center - amplitude, abs=1e-15)
    assert stats["z_max"] == pytest.approx(center + amplitude, abs=1e-15)
    assert stats["peak_stroke"] == pytest.approx(amplitude, rel=1e-12)
    assert stats["motor_force_rms"] == pytest.approx(force / np.sqrt(2), rel=1e-12)
    assert stats["locked_fraction"] == 0.25


def test_blocks_of_cases_give_the_statistics_of_the_whole_run():
    rng = np.random.default_rng(3)
    z, force = rng.normal(size=(3, 500)), rng.normal(size=(3, 500))
    locked = rng.random((3, 500)) < 0.3
    centers = np.array([0.0, 0.5, -0.5])
    statistics = RunStatistics(centers)
    for cases in (slice(0, 2), slice(2, 3)):       # the cases in two groups ...
        for cut in (slice(0, 123), slice(123, 500)):  # ... each in two blocks
            statistics.add(z[cases, cut], force[cases, cut], locked[cases, cut], cases)
    result = statistics.result()
    np.testing.assert_array_equal(result["z_min"], z.min(axis=1))
    np.testing.assert_array_equal(result["z_max"], z.max(axis=1))
    np.testing.assert_array_equal(result["peak_stroke"],
                                  np.abs(z - centers[:, None]).max(axis=1))
    np.testing.assert_allclose(result["motor_force_rms"], np.sqrt((force ** 2).mean(axis=1)),
                               rtol=1e-14)
    np.testing.assert_array_equal(result["locked_fraction"], locked.mean(axis=1))


def test_the_summary_measures_the_ledger_residual_and_saturation():
    """A ledger that closes but for a 2 mJ drift, and loops asking for the limit 1/4 of the time."""
    n = 400
    t = np.arange(n) / 100.0
    base_work = 0.05 * np.sin(t)
    drift = 0.002 * t / t[-1]
    block = {"time": t, "relative_position": np.zeros(n), "motor_force": np.zeros(n),
             "pi_force": np.where(np.arange(n) % 4 == 0, 12.0, 1.0), "damping_force": np.zeros(n),
             "locked": np.zeros(n, bool), "stop_contact": np.zeros(n, bool),
             "mechanical_energy": 1.0 + base_work + drift, "base_work": base_work,
             "motor_work": np.zeros(n), "friction_dissipation": np.zeros(n),
             "stop_dissipation": np.zeros(n)}
    summary = SummaryStatistics(stop_center=0.0, motor_force_max=12.0)
    for cut in (slice(0, 150), slice(150, n)):
        summary.add({name: values[cut] for name, values in block.items()})
    result = summary.result()
    assert result["energy_residual_max"] == pytest.approx(0.002, rel=1e-12)
    assert result["base_work_max"] == pytest.approx(np.abs(base_work).max(), rel=1e-15)
    assert result["saturated_fraction"] == 0.25
    assert result["samples"] == n and (result["time_first"], result["time_last"]) == (0.0, t[-1])
