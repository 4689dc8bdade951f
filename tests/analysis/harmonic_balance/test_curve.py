"""The frequency-response curve (qzs.analysis.harmonic_balance.curve): folds where the tangent
turns, stability that changes only there, validity against the stops and the saturation the
smooth model leaves out, and its points as solutions and as JSON."""
import dataclasses
import json

import numpy as np
import pytest

from qzs.analysis.harmonic_balance import FrequencyResponseCurve, HarmonicBalanceSolution
from qzs.analysis.harmonic_balance.curve import _curve


def points_of(curve, indices):
    return [curve.solution(i) for i in indices]


def test_the_softening_resonance_folds_and_is_unstable_between_its_folds(softening_curve):
    curve = softening_curve
    assert len(curve.folds) == 2
    upper, lower = max(curve.folds), min(curve.folds)
    assert 3.3 < lower < 3.5 and 4.0 < upper < 4.1
    # stability changes only at the folds: the middle branch, between them, is unstable
    flips = np.flatnonzero(np.diff(curve.stable.astype(int)))
    assert flips.size == 2
    for i in flips:
        assert min(abs(curve.frequency[i] - f) for f in curve.folds) < 2e-3
    middle = ~curve.stable
    assert np.all(curve.largest_exponent[middle] > 0)
    inside = (curve.frequency > lower - 1e-3) & (curve.frequency < upper + 1e-3)
    assert np.all(inside[middle])
    assert curve.valid.all()


def test_a_fold_is_where_the_tangents_frequency_component_changes_sign(linear_curve):
    """Rebuilt from four of its points with tangents ``(1, 1, -3, -3)``: one fold, a quarter
    of the way from the second point to the third (linear in the tangent)."""
    indices = [10, 11, 12, 13]
    curve = _curve(points_of(linear_curve, indices), [1.0, 1.0, -3.0, -3.0],
                   linear_curve.model, linear_curve.harmonics, [])
    f = linear_curve.frequency[indices]
    assert curve.folds == pytest.approx((f[1] + 0.25 * (f[2] - f[1]),), rel=1e-15)
    np.testing.assert_array_equal(curve.transmissibility,
                                  linear_curve.transmissibility[indices])


def test_valid_marks_the_points_inside_the_stops_and_below_the_saturation(linear_curve):
    model = linear_curve.model
    n = linear_curve.frequency.size
    points = points_of(linear_curve, range(n))
    top = np.median(linear_curve.relative_range[:, 1])
    narrow = _curve(points, [1.0] * n, dataclasses.replace(model, stop_high=top),
                    linear_curve.harmonics, [])
    np.testing.assert_array_equal(narrow.valid, linear_curve.relative_range[:, 1] <= top)
    assert narrow.valid.any() and not narrow.valid.all()
    limit = np.median(linear_curve.motor_force_peak)
    weak = _curve(points, [1.0] * n, dataclasses.replace(model, motor_force_max=limit),
                  linear_curve.harmonics, [])
    np.testing.assert_array_equal(weak.valid, linear_curve.motor_force_peak <= limit)
    assert linear_curve.valid.all()


def test_a_point_is_a_solution_and_the_curve_plain_lists(linear_curve):
    curve = linear_curve
    assert isinstance(curve, FrequencyResponseCurve)
    solution = curve.solution(7)
    assert isinstance(solution, HarmonicBalanceSolution)
    assert solution.frequency == curve.frequency[7]
    assert solution.transmissibility == curve.transmissibility[7]
    assert solution.integral_mean == curve.integral_mean[7]
    series = solution.time_series()
    assert np.max(np.abs(series["motor_force"])) == curve.motor_force_peak[7]
    data = json.loads(json.dumps(curve.to_dict()))
    assert data["frequency"] == curve.frequency.tolist()
    assert len(data["stable"]) == curve.frequency.size and data["harmonics"] == 3
    assert data["folds"] == [] and data["notes"] == []
    assert data["friction_velocity"] == curve.model.friction_velocity
