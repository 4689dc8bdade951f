"""Friction fit: round trips from the model's force laws, sign conventions, bad input."""
from pathlib import Path

import numpy as np
import pytest

import qzs
from qzs.errors import DataError, ParameterError
from qzs.errors import FitError
from qzs.identify import fit_friction
from qzs.viz.identify import plot_friction_fit

from helpers import instron_test

TRUTH = qzs.IsolatorParameters()
NAMES = ("stiction_force", "coulomb_force", "stribeck_decay", "viscous_damping")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "data"


@pytest.mark.parametrize("seed", range(4))
def test_round_trip_within_confidence_intervals(seed, validation):
    time, z, force = instron_test(seed)
    fit = fit_friction(time, z, force, spring=TRUTH, mass=TRUTH.mass)
    for name in NAMES:
        low, high = fit.intervals[name]
        assert low <= getattr(TRUTH, name) <= high, (name, getattr(fit, name), (low, high))
        assert high - low < 0.1 * getattr(TRUTH, name)  # and the intervals are informative
    assert fit.intervals["offset"][0] <= 3.0 <= fit.intervals["offset"][1]
    assert fit.force_sign == "applied"
    assert fit.n_used + fit.n_excluded == time.size and 0 < fit.n_excluded < 0.05 * time.size
    assert np.all(np.abs(fit.velocity[fit.used]) >= 2e-3)
    assert fit.residual_rms == pytest.approx(0.2, rel=0.5)
    share = max(abs(getattr(fit, name) - getattr(TRUTH, name))
                / (np.diff(fit.intervals[name])[0] / 2) for name in NAMES)
    validation(f"Friction fit round trip (seed {seed}, 0.2 N noise)",
               "Table 1's Fs, Fc, Cbc, Cv (paper eq. 3) inside the 95 % intervals", share, 1.0,
               measure="largest |fit - truth| / 95 % half-width")


def test_interval_coverage_is_close_to_nominal():
    """Over 40 noise draws the 95 % intervals hold the truth at least 85 % of the time."""
    hits = dict.fromkeys(NAMES, 0)
    for seed in range(40):
        fit = fit_friction(*instron_test(100 + seed, cycles=2), spring=TRUTH, mass=TRUTH.mass)
        for name in NAMES:
            hits[name] += fit.intervals[name][0] <= getattr(TRUTH, name) <= fit.intervals[name][1]
    assert min(hits.values()) >= 34, hits


def test_either_sign_convention_gives_the_same_friction():
    time, z, force = instron_test(1)
    reference = fit_friction(time, z, force, spring=(60.84, 78.10), mass=6.4)
    reaction = fit_friction(time, z, -force, spring=(60.84, 78.10), mass=6.4)
    flipped = fit_friction(time, -z, -force, spring=(60.84, 78.10), mass=6.4)  # both reversed
    assert reaction.force_sign == "reaction" and flipped.force_sign == "applied"
    for fit in (reaction, flipped):
        for name in NAMES:
            assert getattr(fit, name) == pytest.approx(getattr(reference, name), rel=1e-6)
    assert flipped.offset == pytest.approx(-reference.offset, rel=1e-6)
    forced = fit_friction(time, z, force, spring=TRUTH, mass=6.4, force_sign="applied")
    assert forced.stiction_force == pytest.approx(reference.stiction_force, rel=1e-9)


def test_fit_feeds_the_model():
    time, z, force = instron_test(2, offset=0.0)
    fit = fit_friction(time, z, force, spring=TRUTH, mass=TRUTH.mass, fit_offset=False)
    assert fit.offset == 0.0 and fit.intervals["offset"] == (0.0, 0.0)
    isolator = fit.to_isolator(qzs.IsolatorParameters(mass=5.0))
    assert isolator.mass == 5.0 and isolator.stiction_force == pytest.approx(10.0, rel=0.02)
    v = np.array([-0.05, 0.01, 0.1])
    np.testing.assert_allclose(fit.friction_force(v), qzs.friction_force(v, TRUTH), rtol=0.02)


def test_example_data_recovers_table_1():
    data = np.loadtxt(EXAMPLES / "friction_test.csv", delimiter=",", skiprows=3)
    fit = fit_friction(data[:, 0], data[:, 1] * 1e-3, data[:, 2], spring=TRUTH, mass=TRUTH.mass)
    assert fit.force_sign == "reaction"
    for name in NAMES:
        assert fit.intervals[name][0] <= getattr(TRUTH, name) <= fit.intervals[name][1]
    assert fit.offset == pytest.approx(TRUTH.mass * TRUTH.gravity, abs=0.1)


def test_residual_plot(tmp_path):
    import matplotlib.pyplot as plt

    fit = fit_friction(*instron_test(3), spring=TRUTH, mass=TRUTH.mass)
    fig = plot_friction_fit(fit, path=tmp_path / "friction.png")
    assert (tmp_path / "friction.png").stat().st_size > 0 and (tmp_path / "friction.svg").exists()
    assert len(fig.axes) == 2
    plt.close(fig)


def test_bad_input():
    time, z, force = instron_test(0)
    with pytest.raises(DataError, match="same length"):
        fit_friction(time, z[:-1], force)
    bad = force.copy()
    bad[[3, 4]] = np.nan
    with pytest.raises(DataError, match="`force` has 2 non-finite"):
        fit_friction(time, z, bad)
    with pytest.raises(DataError, match="at least 20 samples"):
        fit_friction(time[:10], z[:10], force[:10])
    with pytest.raises(DataError, match="only .* samples move faster"):
        fit_friction(time, z, force, exclude_below_velocity=1.0)
    uneven = time.copy()
    uneven[500:] += 3e-4
    with pytest.raises(DataError, match="not uniformly sampled"):
        fit_friction(uneven, z, force)
    backwards = time.copy()
    backwards[[5, 6]] = backwards[[6, 5]]
    with pytest.raises(DataError, match="strictly increasing"):
        fit_friction(backwards, z, force)
    with pytest.raises(ParameterError, match="`force_sign` must be one of"):
        fit_friction(time, z, force, force_sign="up")
    with pytest.raises(ParameterError, match="`spring` must be"):
        fit_friction(time, z, force, spring="magspring")


@pytest.mark.parametrize("options, message", [
    (dict(smoothing_window=0.0), "`smoothing_window` must be positive, got 0.0; a window in s"),
    (dict(smoothing_window="0.02"), "`smoothing_window` must be a number, got '0.02'"),
    (dict(mass=-1.0), "`mass` must be positive, got -1.0; in kg, or None"),
    (dict(exclude_below_velocity=float("nan")), "`exclude_below_velocity` must be finite"),
    (dict(exclude_below_velocity=-1e-3), "`exclude_below_velocity` must be non-negative"),
    (dict(polyorder=2.0), "`polyorder` must be an integer >= 2, got 2.0")])
def test_bad_settings_get_the_shared_checks_messages(options, message):
    """Hand-written checks before (text such as "0.02" was taken through float())."""
    time, z, force = instron_test(0)
    with pytest.raises(ParameterError) as info:
        fit_friction(time, z, force, **options)
    assert str(info.value).startswith(message)


def test_one_direction_cannot_separate_offset():
    time = np.arange(0, 2, 1e-3)
    z = 0.05 * time ** 2  # always moving up
    force = 5.0 + 100.0 * 0.1 * time + np.random.default_rng(0).normal(0, 0.1, time.size)
    with pytest.raises(DataError, match="one direction only"):
        fit_friction(time, z, force)


def test_non_convergence_is_an_error(monkeypatch):
    from scipy import optimize

    real = optimize.least_squares

    def capped(*args, **kwargs):
        kwargs["max_nfev"] = 1
        return real(*args, **kwargs)

    monkeypatch.setattr(optimize, "least_squares", capped)
    with pytest.raises(FitError, match="did not converge"):
        fit_friction(*instron_test(0), spring=TRUTH, mass=TRUTH.mass)
