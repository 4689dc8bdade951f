"""The frequency-response curve (qzs.analysis.harmonic_balance.curve): folds where the tangent
turns, stability that changes only there, validity against the stops and the saturation the
smooth model leaves out, and its points as solutions and as JSON.

Where a fold and a change of stability are placed between two continuation points is checked
against an independent location: the softening curve re-solved by scipy.optimize at a fixed
phase of the fundamental (a parameter that runs monotonically through each fold), whose
frequency's extremum over that phase (scipy's bounded minimize_scalar) is the turning point.
Properties that fail if the code is wrong: each fold is placed between the two points that
straddle the turning point, no further from it than the linear interpolation of the tangent
on a parabola allows (``sqrt((F - f0)(F - f1))``, F the fold, f0, f1 the points); each
change of stability lies between the same two points, where the largest Floquet exponent of
the re-solved orbits crosses zero (bisection) at the fold's phase, and the monodromy matrix
integrated by scipy agrees on which side is stable.
"""
import dataclasses
import json
import warnings

import numpy as np
import pytest
from scipy import optimize

from qzs.analysis.harmonic_balance import (FrequencyResponseCurve, HarmonicBalanceSolution,
                                           floquet_exponents)
from qzs.analysis.harmonic_balance.curve import _curve
from qzs.analysis.harmonic_balance.fourier import _basis, _default_time_points
from qzs.analysis.harmonic_balance.residual import _residual


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


# ---------------------------------------------------------------- folds, independently
def fundamental_phase(coefficients):
    """Phase [rad] of z's fundamental ``a1 cos + b1 sin``: monotone along the softening
    curve (0.17 to 1.7 rad over its folds), where the frequency is not."""
    return np.arctan2(coefficients[..., 2], coefficients[..., 1])


def solve_at_phase(curve, phase, guess):
    """The periodic orbit whose fundamental has ``phase``: the balance plus
    ``a1 sin(phase) = b1 cos(phase)``, unknowns the coefficients and omega, by scipy's
    hybrid Powell method. Returns the coefficients and omega [rad/s]."""
    model, harmonics = curve.model, curve.harmonics
    basis = _basis(harmonics, _default_time_points(harmonics))
    force = model.mass * model.amplitude * guess[-1] ** 2

    def equations(x):
        balance = _residual(x[:-1], x[-1], model, basis, False)[0] / force
        return np.append(balance, (x[1] * np.sin(phase) - x[2] * np.cos(phase))
                         / model.amplitude)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # trial points far off the orbit
        x = optimize.root(equations, guess, method="hybr", options={"xtol": 1e-13}).x
    assert np.max(np.abs(equations(x))) < 1e-10
    return x


def independent_fold(curve, fold):
    """``(phase, frequency)`` of the turning point near ``fold`` [Hz]: the extremum of the
    re-solved orbits' frequency over the phase, bracketed by the curve's points 3 either
    side."""
    k = int(np.argmin(np.abs(curve.frequency - fold)))
    phases = fundamental_phase(curve.coefficients)
    guess = np.append(curve.coefficients[k], 2 * np.pi * curve.frequency[k])
    sign = 1.0 if curve.frequency[k] > curve.frequency[k - 3] else -1.0  # a maximum: +1
    found = optimize.minimize_scalar(
        lambda phase: -sign * solve_at_phase(curve, phase, guess)[-1],
        bounds=tuple(sorted((phases[k - 3], phases[k + 3]))), method="bounded",
        options={"xatol": 1e-12})
    return found.x, -sign * found.fun / (2 * np.pi)


@pytest.fixture(scope="module")
def softening_folds(softening_curve):
    """Each fold of the softening curve: ``(reported, phase, frequency, i)``, the turning
    point lying between points ``i`` and ``i + 1`` (by phase)."""
    phases = fundamental_phase(softening_curve.coefficients)
    folds = []
    for reported in softening_curve.folds:
        phase, frequency = independent_fold(softening_curve, reported)
        (i,) = np.flatnonzero((phases[:-1] - phase) * (phases[1:] - phase) < 0)
        folds.append((reported, phase, frequency, int(i)))
    return folds


def test_each_fold_is_placed_between_the_points_that_straddle_the_turning_point(
        softening_curve, softening_folds, validation):
    """The turning points are at 3.38923 and 4.06441 Hz; the curve places them between the
    right two points, within what a linear interpolation of the tangent's frequency
    component on a parabola leaves: ``sqrt((F - f0)(F - f1))`` (6e-5 and 1.5e-4 Hz here;
    the fold lies beyond both points, the interpolation between them)."""
    assert len(softening_folds) == 2
    f = softening_curve.frequency
    for reported, _, frequency, i in softening_folds:
        low, high = sorted((f[i], f[i + 1]))
        assert low <= reported <= high, (reported, low, high)
        bound = np.sqrt(abs(frequency - f[i]) * abs(frequency - f[i + 1]))
        assert abs(reported - frequency) <= 1.1 * bound, (reported, frequency, bound)
        assert abs(reported - frequency) < 2e-4
        validation(f"Fold of the softening curve near {frequency:.4f} Hz",
                   "turning point re-solved by scipy.optimize (extremum of frequency over "
                   "the fundamental's phase)", abs(reported - frequency), 2e-4,
                   measure="absolute error [Hz]")


def test_stability_changes_at_the_folds_between_the_same_two_points(softening_curve,
                                                                   softening_folds,
                                                                   monodromy):
    """A saddle-node: one real exponent crosses zero exactly at the turning point. The
    curve's stable flag changes between the points that straddle it, the largest exponent
    of orbits re-solved between them crosses zero at the fold's phase (bisection), and the
    monodromy matrix (scipy) agrees on which point is stable."""
    curve = softening_curve
    flips = np.flatnonzero(np.diff(curve.stable.astype(int)))
    assert sorted(int(j) for j in flips) == sorted(i for *_, i in softening_folds)
    phases = fundamental_phase(curve.coefficients)
    for _, phase, _, i in softening_folds:
        guess = np.append(curve.coefficients[i], 2 * np.pi * curve.frequency[i])

        def largest_exponent(at):
            x = solve_at_phase(curve, at, guess)
            orbit = dataclasses.replace(curve.solution(i), coefficients=x[:-1],
                                        frequency=x[-1] / (2 * np.pi))
            return floquet_exponents(orbit).real.max()

        crossing = optimize.brentq(largest_exponent, phases[i], phases[i + 1], xtol=1e-12)
        assert crossing == pytest.approx(phase, abs=1e-6)
        for j in (i, i + 1):
            _, _, phi = monodromy(curve.solution(j))
            largest = np.abs(np.linalg.eigvals(phi[:2, :2])).max()
            assert (largest < 1.0) == curve.stable[j], (j, largest)



def test_the_softening_curves_summary_dataset_and_figure(softening_curve, tmp_path):
    """The protocol on a curve that folds: the summary names the folds and the stable peak,
    the dataset keeps every point in arclength order with units, the figure marks the folds."""
    import matplotlib.pyplot as plt

    curve = softening_curve
    assert len(curve.folds) == 2
    text = curve.summary()
    assert all(f"{fold:.4g}" in text for fold in curve.folds)
    usable = curve.stable & curve.valid
    assert f"{np.max(curve.transmissibility[usable]):.4g}" in text
    data = curve.to_xarray()
    assert np.array_equal(data["frequency"].values, curve.frequency)  # folds go back: kept
    assert np.array_equal(data["stable"].values.astype(bool), curve.stable)
    assert np.array_equal(data["relative_max"].values, curve.relative_range[:, 1])
    assert data["largest_exponent"].attrs["units"] == "1/s"
    assert list(data.attrs["folds"]) == list(curve.folds)
    figure = curve.plot(tmp_path / "curve.png", frequency_scale="linear")
    try:
        folds = [line.get_xdata()[0] for line in figure.axes[0].lines
                 if line.get_linestyle() == "-."]
        assert folds == pytest.approx(list(curve.folds))
    finally:
        plt.close(figure)
