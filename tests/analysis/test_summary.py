"""The summary of a run (qzs.analysis.summary): its warnings at their closed-form thresholds,
and its numbers those of the run's samples."""
import numpy as np
import pytest

from qzs import Sine, simulate
from qzs.analysis.summary import WARNING_LIMITS, run_warnings, summary_record, summary_text


@pytest.fixture(scope="module")
def coarse_run():
    """A 3 Hz sine sampled at 10 Hz (3.3 samples per period) with 3333 steps per period."""
    return simulate(Sine(amplitude=0.004, frequency=3.0), duration=1.0, dt=1e-4,
                    sample_rate=10.0)


def test_an_output_rate_under_five_samples_per_period_is_flagged(coarse_run):
    codes = dict(run_warnings(coarse_run))
    assert "samples per period" in codes["output_rate_low"]
    assert f"{10.0 / 3.0:.1f} samples per period" in codes["output_rate_low"]
    assert 1 / (3.0 * 1e-4) > WARNING_LIMITS["steps_per_period"]
    assert "few_steps_per_period" not in codes


def test_too_few_steps_per_period_name_the_step_that_suffices():
    """60 Hz at dt = 1 ms: 16.7 steps per period, under 20: dt below 1/(20*60 Hz)."""
    run = simulate(Sine(amplitude=1e-4, frequency=60.0), duration=0.2, dt=1e-3,
                   sample_rate=1000.0)
    message = dict(run_warnings(run))["few_steps_per_period"]
    assert f"only {1 / (60.0 * 1e-3):.1f} integration steps per period" in message
    assert f"below {1 / (20 * 60.0):.3g} s" in message


def test_the_text_and_the_record_report_the_runs_own_samples(coarse_run):
    z = coarse_run.relative_position
    text = summary_text(coarse_run)
    assert f"z in [{z.min() * 1e3:.2f}, {z.max() * 1e3:.2f}] mm" in text
    assert f"final z = {z[-1] * 1e3:.2f} mm" in text
    record = summary_record(coarse_run)
    assert record["statistics"]["z_min"] == z.min() and record["statistics"]["samples"] == z.size
    assert [w["code"] for w in record["warnings"]] == [c for c, _ in run_warnings(coarse_run)]
