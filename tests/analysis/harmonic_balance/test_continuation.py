"""Continuation in frequency (qzs.analysis.harmonic_balance.continuation): the closed-form
transmissibility of a linear model over the whole range, and the stepped-sine simulation where
the response is smooth (a frictionless MagSpring driven into its softening bend, with folds,
an unstable branch and jumps), and the same curve whatever frequency the continuation started
from (followed down and up from a start above the bottom: the same folds, no fold at the
start, the points in arclength order)."""
import numpy as np
import pytest

from qzs import ParameterError
from qzs.analysis.harmonic_balance import (SmoothModel, frequency_response_curve,
                                           periodic_response)
from qzs.analysis.harmonic_balance import continuation
from qzs.workflows.response import steady_state_response


def test_the_linear_limit_follows_the_closed_form_over_the_range(linear_curve,
                                                                linear_transmissibility,
                                                                validation):
    curve = linear_curve
    exact = linear_transmissibility(curve.frequency, curve.model)
    error = np.abs(curve.transmissibility / np.abs(exact) - 1).max()
    assert error < 1e-9
    np.testing.assert_allclose(curve.phase, np.angle(exact), atol=1e-9)
    # from the bottom of the range to its top, rising, no fold, stable, nothing to note
    assert curve.frequency[0] == pytest.approx(0.3, rel=1e-12) and curve.frequency[-1] >= 8.0
    assert np.all(np.diff(curve.frequency) > 0)
    assert np.max(np.diff(curve.frequency)) <= (1 - 0.3 / 8.0) / 150 * 8.0 * (1 + 1e-9)
    assert curve.folds == () and curve.stable.all() and curve.notes == ()
    validation("Continuation of a linear model, 0.3-8 Hz",
               "closed-form transmissibility of the linear closed loop", error, 1e-9)


def test_the_curve_stops_at_max_points_and_says_so(linear_model):
    curve = frequency_response_curve(linear_model(), (0.3, 8.0), harmonics=3, max_points=12)
    assert curve.frequency.size == 12
    assert curve.notes == ("stopped after 12 points (`max_points`)",)


def test_harmonic_balance_is_the_stepped_sine_where_the_response_is_smooth(softening_curve,
                                                                          softening,
                                                                          validation):
    """Every stepped-sine point lies on a stable branch of the harmonic balance (solved at
    its frequency from the nearest point of that branch); the sweeps jump where the
    harmonic balance folds: up just after the upper fold, down just below the lower one."""
    frequencies = np.round(np.arange(3.0, 4.61, 0.1), 10)
    response = steady_state_response(frequencies, softening["amplitude"],
                                     **softening["parameters"], dt=1e-3,
                                     harmonic_balance=False, workers=2)
    curve = softening_curve
    worst = 0.0
    for direction in ("up", "down"):
        branch = response.branch(direction)
        for f, t in zip(branch["frequency"], branch["transmissibility"]):
            candidates = np.flatnonzero(curve.stable & (np.abs(curve.frequency - f) < 0.05))
            nearest = candidates[np.argmin(np.abs(curve.transmissibility[candidates] - t))]
            exact = periodic_response(f, curve.model, harmonics=softening["harmonics"],
                                      initial_guess=curve.solution(nearest))
            assert exact.converged
            assert t == pytest.approx(exact.transmissibility, rel=3e-4), (direction, f)
            worst = max(worst, abs(t / exact.transmissibility - 1))
    # each sweep leaves its branch at the fold where the branch ends, or a step before it:
    # close to a fold the branch's basin shrinks below what a 0.1 Hz step disturbs
    lower, upper = min(curve.folds), max(curve.folds)
    jumps = response.jumps()
    ((up_from, up_to),) = jumps["up"]
    ((down_from, down_to),) = jumps["down"]
    assert up_from < upper < up_to + 1e-9
    assert lower < down_from and down_to < lower + 0.1 + 1e-9
    band = response.hysteresis()
    assert band.min() > lower and band.max() < upper
    validation("Stepped sine up and down a folding softening resonance, 3-4.6 Hz",
               "harmonic balance (20 harmonics) on the stable branch",
               worst, 3e-4)


def test_a_curve_started_above_the_bottom_is_the_same_curve(softening_curve, softening,
                                                           monkeypatch):
    """Newton made to fail below 3.3 Hz: the continuation starts at the fourth geometric
    frequency (3.371 Hz) and is followed down to 3 Hz and up from there. The part below,
    reversed (points and tangents), joins the rest without a fold at the start; the folds
    are the curve's from the bottom (to the placement's interpolation error, 5e-4 Hz) and
    the fundamental's phase rises along the whole curve."""
    newton = continuation._newton

    def failing_below(q, omega, *args):
        if omega < 2 * np.pi * 3.3:
            return q, False, 1, 1.0
        return newton(q, omega, *args)

    monkeypatch.setattr(continuation, "_newton", failing_below)
    curve = frequency_response_curve(softening_curve.model, (3.0, 4.6),
                                     harmonics=softening["harmonics"])
    assert curve.notes == ("the continuation started at 3.371 Hz (Newton failed below) and "
                           "went both ways from there",)
    assert curve.frequency[0] <= 3.0 < 3.3 < curve.frequency[np.argmax(curve.frequency > 3.3)]
    phase = np.unwrap(np.arctan2(curve.coefficients[:, 2], curve.coefficients[:, 1]))
    assert np.all(np.diff(phase) > 0)
    assert len(curve.folds) == 2
    assert sorted(curve.folds) == pytest.approx(sorted(softening_curve.folds), abs=5e-4)
    assert np.count_nonzero(np.diff(curve.stable.astype(int))) == 2


@pytest.mark.parametrize("call, name", [
    (lambda m: frequency_response_curve(m, (5.0, 1.0)), "frequency_range"),
    (lambda m: frequency_response_curve(m, (0.0, 1.0)), "frequency_range"),
    (lambda m: frequency_response_curve(m, 5.0), "frequency_range"),
    (lambda m: frequency_response_curve("model", (1.0, 5.0)), "model"),
    (lambda m: frequency_response_curve(m, (1.0, 5.0), max_points=1), "max_points"),
    (lambda m: frequency_response_curve(m, (1.0, 5.0), step=-0.1), "step"),
])
def test_bad_input_is_refused(call, name):
    model = SmoothModel.from_parameters(amplitude=0.01)
    with pytest.raises(ParameterError, match=name):
        call(model)
