"""The shared ways of showing numbers (:mod:`qzs._format`), against independent references."""
import cmath
import math

import numpy as np
import pytest

from qzs._format import decibels


@pytest.mark.parametrize("ratio, expected", [(10, 20.0), (0.1, -20.0), (1.0, 0.0), (100.0, 40.0),
                                             (math.sqrt(2), 3.0103), (-10.0, 20.0),
                                             (3 + 4j, 20 * math.log10(5)),
                                             (np.float64(0.01), -40.0)])
def test_decibels_of_a_number_is_20_log10_of_its_magnitude(ratio, expected):
    value = decibels(ratio)
    assert type(value) is float
    assert value == pytest.approx(expected, abs=1e-4)


def test_decibels_of_a_number_is_computed_as_math_log10_gives_it():
    for ratio in np.random.default_rng(1).uniform(1e-6, 1e3, 200):
        assert decibels(float(ratio)) == 20 * math.log10(ratio)


def test_decibels_of_an_array_keeps_its_shape_and_matches_numpy_to_the_bit():
    ratio = np.random.default_rng(2).uniform(1e-6, 1e3, (7, 6, 6))
    db = decibels(ratio)
    assert db.shape == ratio.shape
    assert np.array_equal(db, 20 * np.log10(ratio))
    assert np.array_equal(decibels(ratio.tolist()), db)


def test_decibels_of_a_complex_array_is_that_of_its_magnitude():
    rng = np.random.default_rng(3)
    response = rng.normal(size=40) + 1j * rng.normal(size=40)
    expected = [20 * math.log10(abs(z)) for z in response]
    assert decibels(response) == pytest.approx(expected, rel=1e-13)
    assert decibels(response)[5] == pytest.approx(decibels(complex(response[5])), rel=1e-13)
    assert cmath.isclose(10 ** (decibels(response[0]) / 20), abs(response[0]))


def test_zero_is_minus_infinity_without_a_warning_and_nan_stays_nan():
    with np.errstate(all="raise"):
        db = decibels(np.array([0.0, np.nan, np.inf]))
    assert db[0] == -np.inf and np.isnan(db[1]) and db[2] == np.inf
    assert decibels(0.0) == -math.inf and math.isnan(decibels(math.nan))


def test_a_floor_replaces_what_lies_below_it_and_leaves_nan():
    floor = 1e-12
    db = decibels(np.array([0.0, 1e-15, 1e-3, np.nan]), floor)
    assert db[0] == db[1] == pytest.approx(-240.0)
    assert db[2] == pytest.approx(-60.0) and np.isnan(db[3])
    assert decibels(0.0, floor) == pytest.approx(-240.0) and decibels(0.5, floor) == decibels(0.5)
