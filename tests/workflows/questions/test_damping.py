"""The damping-design study: the linear responses, the verdict's logic, the quick study."""
import dataclasses
import math
import time

import numpy as np
import pytest

from qzs.analysis.linear import linearize
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.workflows.questions import damping as dm


def test_the_linear_transmissibility_is_linearize_s():
    isolator = IsolatorParameters()
    controller = dataclasses.replace(ControllerParameters(), damping_gain=50.0)
    f = np.array([0.5, 2.0, 7.0, 15.0])
    t, force, stable = dm.linear_responses(isolator, controller, f)
    assert stable
    np.testing.assert_allclose(np.abs(t), linearize(isolator, controller).transmissibility(f),
                               rtol=1e-9)
    # the force is the PI's on -z plus the damping's on the high-passed payload velocity:
    # z = (T - 1) y''/s^2, v_meas = s/(s + w_h) T y''/s
    s = 2j * np.pi * f
    w_h = 2 * np.pi * controller.velocity_highpass
    expected = (-(controller.pi_kp + controller.pi_ki / s) * (t - 1) / s ** 2
                - controller.damping_gain * t / (s + w_h))
    np.testing.assert_allclose(force, expected, rtol=1e-9)


def test_a_shaped_skyhook_of_gain_k_is_kd_k_in_the_band():
    """Well below its 40 Hz roll-off the shaped skyhook is the Kd loop of the same gain."""
    isolator, controller = IsolatorParameters(), ControllerParameters()
    f = np.array([2.0, 3.0])
    shaped, _, _ = dm.linear_responses(isolator, controller + dm.shaped_skyhook(100.0), f)
    plain, _, _ = dm.linear_responses(
        isolator, dataclasses.replace(controller, damping_gain=100.0), f)
    np.testing.assert_allclose(np.abs(shaped), np.abs(plain), rtol=0.02)


def _row(label, kind, largest, rms, stops=0.0):
    return {"label": label, "kind": kind, "largest_reduction_db": largest,
            "band_rms_change_db": rms, "stop_contacts": stops, "saturated_fraction": 0.0}


def test_the_verdict_on_constructed_rows():
    paper = [_row("Kd 50", "paper", 2.0, -1.0), _row("Kd 250", "paper", 8.0, -5.0)]
    # better on one metric only: no
    answer = dm.damping_answer(paper + [_row("d", "design", 9.0, -4.0)])
    assert answer.label == "no" and "Kd 250" in answer.answer
    # better on both by more than the margin: yes, naming it
    answer = dm.damping_answer(paper + [_row("d", "design", 9.0, -6.0)])
    assert answer.label == "yes" and answer.answer.startswith("d beats")
    # better, but at the stops: no
    assert dm.damping_answer(paper + [_row("d", "design", 9, -6, stops=2)]).label == "no"
    # within the margin: no
    assert dm.damping_answer(paper + [_row("d", "design", 8.4, -5.4)]).label == "no"
    # nothing defined: not decidable
    answer = dm.damping_answer([_row("Kd", "paper", math.nan, math.nan),
                                _row("d", "design", 1.0, -1.0)])
    assert answer.label == "not decidable"


def test_the_quick_study_runs_in_seconds_and_its_designs_keep_their_limits():
    dm.run_damping_study(quick=True, workers=2)  # compile whatever is not cached
    start = time.perf_counter()
    result = dm.run_damping_study(quick=True, workers=2)
    assert time.perf_counter() - start < 30.0
    isolator = IsolatorParameters()
    for key in ("shaped", "cancellation"):
        assert result["designs"][key]["peak_force"] <= dm.FORCE_SHARE * isolator.motor_force_max
    labels = [r["label"] for r in result["rows"]]
    assert labels[:3] == [f"Kd = {g:g} N*s/m" for g in dm.PAPER_GAINS]
    # more damping, more reduction: the paper's gains in order on both metrics
    paper = [r for r in result["rows"] if r["kind"] == "paper"]
    assert np.all(np.diff([r["band_rms_change_db"] for r in paper]) < 0)
    assert result["answer"].label in ("yes", "no")


def test_the_peak_motor_force_of_a_slow_chirp_is_the_payloads_inertia():
    """Far below the loop's corners the PI holds the payload on the base (T -> 1, the
    integral takes the error to 0): the motor then carries the payload's inertia alone, and
    the linear peak force at f is ``m * A * (2 pi f)^2`` for a chirp of displacement
    amplitude A (the base's acceleration amplitude), within 1e-3 at 1 mHz."""
    import qzs

    isolator, controller = IsolatorParameters(), ControllerParameters()
    chirp = qzs.Chirp(amplitude=0.002, f0=0.1, f1=10.0, duration=100.0)
    for f in (1e-3, 5e-4):
        inertia = isolator.mass * chirp.amplitude * (2 * np.pi * f) ** 2
        assert dm._peak_force(isolator, controller, chirp, np.array([f])) == \
            pytest.approx(inertia, rel=1e-3), f
