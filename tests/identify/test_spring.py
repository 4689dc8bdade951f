"""MagSpring fit: round trips from known parameters, conventions, bad input."""
import numpy as np
import pytest

import qzs
from qzs.errors import DataError, ParameterError
from qzs.identify import fit_spring


def synthetic(a=60.84, b=78.10, noise=0.3, n=41, seed=1):
    rng = np.random.default_rng(seed)
    z = np.linspace(-0.1, 0.1, n)
    return z, -a * np.tanh(b * z) + rng.normal(0, noise, n)


@pytest.mark.parametrize("seed", range(5))
def test_round_trip_within_confidence_interval(seed, validation):
    z, f = synthetic(seed=seed)
    fit = fit_spring(z, f)
    assert fit.intervals["plateau"][0] <= 60.84 <= fit.intervals["plateau"][1]
    assert fit.intervals["shape"][0] <= 78.10 <= fit.intervals["shape"][1]
    assert fit.residual_rms == pytest.approx(0.3, rel=0.3)
    share = max(abs(value - truth) / (np.diff(interval)[0] / 2) for value, truth, interval in (
        (fit.spring_force, 60.84, fit.intervals["plateau"]),
        (fit.spring_shape, 78.10, fit.intervals["shape"])))
    validation(f"MagSpring fit round trip (seed {seed}, 0.3 N noise)",
               "a = 60.84 N, b = 78.10 1/m (Table 1, the paper's Fig. 5 fit) inside the 95 % "
               "intervals",
               share, 1.0, measure="largest |fit - truth| / 95 % half-width")


def test_test_machine_convention_reports_the_papers_sign():
    z, f = synthetic(noise=0.0)
    fit = fit_spring(-z, f, convention="test_machine")
    assert fit.spring_force == pytest.approx(60.84, rel=1e-6)
    assert fit.as_paper_reports()[0] == pytest.approx(-60.84, rel=1e-6)
    assert fit.convention == "test_machine"
    # the same data read in the model's convention gives the negative amplitude
    assert fit_spring(-z, f).spring_force == pytest.approx(-60.84, rel=1e-6)


def test_outlier_is_reported():
    z, f = synthetic(noise=0.1)
    f[7] += 15.0
    assert 7 in fit_spring(z, f).outliers


@pytest.mark.parametrize("z, f, error, match", [
    ([0, 1, 2], [0, 1, 2], DataError, "at least 4 points"),
    ([0, 1, 2, 3], [0, 1, 2], DataError, "same length"),
    ([0, 1, np.nan, 3], [0, 1, 2, 3], DataError, "1 force-displacement pairs are not finite"),
])
def test_bad_input(z, f, error, match):
    with pytest.raises(error, match=match):
        fit_spring(z, f)


def test_bad_convention():
    z, f = synthetic()
    with pytest.raises(ParameterError, match="`convention` must be one of"):
        fit_spring(z, f, convention="upside-down")


def test_fit_agrees_with_model_force_law():
    z, f = synthetic(noise=0.0)
    fit = fit_spring(z, f)
    iso = qzs.IsolatorParameters(spring_force=fit.spring_force, spring_shape=fit.spring_shape)
    np.testing.assert_allclose(qzs.spring_force(z, iso), f, atol=1e-6)


def test_fit_travels_as_the_paper_report_carries_it():
    """The paper's spring study keeps ``dataclasses.asdict(fit)`` in a case that a worker
    process pickles back: every law's fit must survive both."""
    import dataclasses
    import pickle

    z, f = synthetic()
    for law in ("tanh", "best"):
        fit = fit_spring(z, f, law=law)
        record = pickle.loads(pickle.dumps(dataclasses.asdict(fit)))
        assert record["spring_force"] == fit.spring_force
        assert record["law"] == {"plateau": fit.law.plateau, "shape": fit.law.shape}
        assert pickle.loads(pickle.dumps(fit)).law == fit.law
