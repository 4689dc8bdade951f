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


# ---------------------------------------------------------------- which part of the excitation
@pytest.mark.parametrize("excitation, duration, expected", [
    ("chirp", 200.0, "Chirp 0-20 Hz over 2000 s: first 200 s run (0-2 Hz)"),
    ("chirp", 2000.0, "Chirp 0-20 Hz over 2000 s: all 2000 s run"),
    ("log-chirp", 50.0, "Chirp 1-16 Hz (logarithmic) over 100 s: first 50 s run (1-4 Hz)"),
    ("sine", 10.0, "Sine 3 Hz: 10 s run"),
    ("random", 20.0, "Random 0.5-20 Hz over 100 s: first 20 s run"),
    ("random", 100.0, "Random 0.5-20 Hz over 100 s: all 100 s run"),
    ("record", 3.0, "Record of 6 s: first 3 s run"),
])
def test_a_summary_says_which_part_of_the_excitation_ran(excitation, duration, expected):
    """`qzs simulate --duration 200` was headed "Chirp: 200 s" while it ran the first tenth
    of the 2000 s chirp; the reached frequency is the sweep law's (linear: f0 + (f1 - f0)
    t / T; logarithmic: f0 (f1/f0)^(t/T))."""
    from qzs import Chirp, DisplacementRecord, RandomExcitation
    from qzs.analysis.summary import excitation_part

    made = {"chirp": lambda: Chirp(),
            "log-chirp": lambda: Chirp(f0=1.0, f1=16.0, duration=100.0, method="logarithmic"),
            "sine": lambda: Sine(frequency=3.0),
            "random": lambda: RandomExcitation(),
            "record": lambda: DisplacementRecord(time=np.linspace(0.0, 6.0, 61),
                                                 displacement=np.zeros(61))}[excitation]()
    assert excitation_part(made, duration) == expected


def test_the_summary_of_a_cut_run_is_headed_by_the_part_that_ran():
    text = summary_text(simulate(Sine(frequency=3.0, amplitude=0.002), duration=2.0,
                                 dt=1e-3, sample_rate=100.0))
    assert text.splitlines()[0].startswith("qzs simulation  Sine 3 Hz: 2 s run, ode3 dt = ")


def test_each_block_line_reports_its_own_cost():
    """Each block's RMS force stands by its own name, and the dither's cost line gives the
    payload's acceleration at the dither's frequency and the motor's whole RMS (not a block's)."""
    from qzs import Dither, FrictionCompensation, PIDamping
    from qzs.analysis.summary import block_lines

    controller = PIDamping(compensation=FrictionCompensation(fraction=0.5),
                           dither=Dither(amplitude=3.0, frequency=40.0))
    stats = {"compensation_force_rms": 1.25, "dither_force_rms": 2.5,
             "dither_payload_acceleration": 0.75, "motor_force_rms": 7.5}
    lines = block_lines(controller, stats)
    forces = next(line for line in lines if "block forces" in line)
    assert "compensation RMS 1.25 N" in forces and "dither RMS 2.5 N" in forces
    cost = next(line for line in lines if "dither cost" in line)
    assert "0.75 m/s^2 at 40 Hz" in cost and "motor RMS 7.5 N in all" in cost
