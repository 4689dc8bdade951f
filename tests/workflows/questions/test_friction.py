"""The friction-compensation study: its table against single runs, fraction 0, the verdict."""
import math

import numpy as np
import pytest

import qzs
from qzs.analysis.damping import band_rms
from qzs.analysis.spectral import band_mask, transmissibility
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.workflows.questions import friction as fr
from qzs.workflows.questions.common import run_chirp_cases


def _short_plan():
    plan = fr.plan(quick=True)
    return fr.ChirpPlan(qzs.Chirp(amplitude=0.010, f0=0.2, f1=5.0, duration=20.0,
                                  fade_in=2.0), plan.sample_rate, 1024, plan.dt)


def test_the_batch_table_is_what_single_runs_give():
    """Each case's curve and stick events from the lanes equal those of qzs.simulate."""
    plan = _short_plan()
    isolator, controller = IsolatorParameters(), ControllerParameters()
    loops = [fr.compensated(controller, a) for a in (0.0, 1.25)]
    curves = run_chirp_cases(["a", "b"], [(isolator, c) for c in loops], plan, workers=2)
    for loop, curve in zip(loops, curves):
        run = qzs.simulate(plan.excitation, isolator, loop, dt=plan.dt,
                           sample_rate=plan.sample_rate)
        estimate = transmissibility(run.base_acceleration, run.payload_acceleration,
                                    plan.sample_rate, fft_length=plan.fft_length)
        keep = band_mask(estimate.frequency, 0.0, plan.excitation.f1)  # DC left out
        np.testing.assert_array_equal(curve.magnitude, estimate.magnitude[keep])
        assert curve.stats["stick_events"] == run.run["stick_events"]
        assert curve.stats["motor_force_rms"] == pytest.approx(
            float(np.sqrt(np.mean(run.motor_force ** 2))), rel=1e-9)


def test_fraction_zero_is_no_compensation_bit_for_bit():
    controller = ControllerParameters()
    assert fr.compensated(controller, 0.0) is controller
    plan = _short_plan()
    isolator = IsolatorParameters()
    zero = controller + qzs.FrictionCompensation(fraction=0.0)
    plain, blocked = run_chirp_cases(["plain", "a = 0 block"],
                                     [(isolator, controller), (isolator, zero)], plan, workers=2)
    np.testing.assert_array_equal(plain.magnitude, blocked.magnitude)
    assert plain.stats == blocked.stats


def _row(a, rms, onset=2.0, sticks=10.0, stops=0.0):
    return {"fraction": a, "band_rms": rms, "isolation_onset": onset, "stick_events": sticks,
            "motor_force_rms": 2.0 + a, "stop_contacts": stops}


def test_the_verdict_on_constructed_tables():
    reference = {"band_rms": 0.5, "isolation_onset": 1.0}
    boundary = {"predicted": 1.0, "simulated": 1.5}
    # removes 90 % of both penalties without hunting: yes
    table = [_row(0.0, 1.0, 2.0), _row(1.0, 0.55, 1.1)]
    answer = fr.friction_answer(table, reference, {0.0: False, 1.0: False}, boundary)
    assert answer.label == "yes" and "90%" in answer.answer
    # the same best case hunts: it does not count, the uncompensated one is the best left
    answer = fr.friction_answer(table, reference, {0.0: False, 1.0: True}, boundary)
    assert answer.label == "no" and "a = 0 " in answer.answer
    # the band's penalty removed, the onset's not: the least share decides (partly: 50 %)
    table = [_row(0.0, 1.0, 2.0), _row(1.0, 0.5, 1.5)]
    assert fr.friction_answer(table, reference, {}, boundary).label == "partly"
    # a case at the stops does not count either
    table = [_row(0.0, 1.0, 2.0), _row(1.0, 0.5, 1.0, stops=3.0)]
    assert fr.friction_answer(table, reference, {}, boundary).label == "no"
    # no penalty to remove, or none defined: not decidable, with the reason
    answer = fr.friction_answer([_row(0.0, 0.4)], reference, {}, boundary)
    assert answer.label == "not decidable" and "no penalty" in answer.evidence
    answer = fr.friction_answer([_row(0.0, math.nan)], reference, {}, boundary)
    assert answer.label == "not decidable"
    answer = fr.friction_answer([_row(0.5, 0.9)], reference, {}, boundary)
    assert answer.label == "not decidable" and "fraction 0" in answer.evidence


def test_the_hunting_boundary_is_where_the_net_law_over_compensates():
    """With the plant's own law compensated, the net law is (1 - a) f: negative past a = 1."""
    isolator, controller, options = fr.HUNTING_RIGS["paper loop"]
    boundary = fr.hunting_boundary(isolator, controller, tolerance=1e-3)
    assert 1.0 < boundary <= 1.0 + 1e-3


def test_the_measured_cycle_of_a_sine():
    t = np.linspace(0.0, 20.0, 20001)
    v = 0.03 * np.sin(2 * np.pi * 1.7 * t)
    cycle = fr.measure_cycle(t, v, v / (2 * np.pi * 1.7))
    assert cycle["velocity_amplitude"] == pytest.approx(0.03, rel=1e-3)
    assert cycle["frequency"] == pytest.approx(1.7, rel=1e-4)
    still = fr.measure_cycle(t, 0 * t, 0 * t)
    assert still["stroke"] == 0.0 and math.isnan(still["frequency"])


def test_the_quick_study_speaks_throughout_and_its_stiff_cycle_is_the_predicted_one(capsys):
    """With progress, the hunting runs after the chirps have a bar of their own (they were
    15 s of silence on a terminal), counted to the end."""
    result = fr.run_friction_study(quick=True, workers=2, progress=True)
    shown = capsys.readouterr().err
    total = len(result["hunting"]) + len(fr.HUNTING_RIGS)
    assert "hunting at rest" in shown and f"{total}/{total}" in shown
    assert [r["fraction"] for r in result["table"]] == list(fr.FRACTIONS[True])
    measured = [r for r in result["hunting"] if r["within_tolerance"] is not None]
    assert measured and all(r["within_tolerance"] for r in measured)
    # compensation cannot free a stuck payload: the onset stays far from the smooth guide's
    none = result["table"][0]
    assert none["isolation_onset"] > result["reference"]["isolation_onset"]
    assert result["answer"].label in ("no", "partly", "yes")
    assert none["band_rms"] == band_rms(result["curves"][0].frequency,
                                        result["curves"][0].magnitude, fr.BAND,
                                        trusted=result["curves"][0].trusted)
