"""The shared argument checks of :mod:`qzs._validation`: what they accept, return and say."""
import math
from fractions import Fraction

import numpy as np
import pytest

from qzs._validation import finite_real, integer, interval, optional, positive_real, real
from qzs.errors import DataError, ParameterError

NOT_NUMBERS = [True, np.True_, "1.0", None, [1.0], 1 + 2j]


@pytest.mark.parametrize("check", [real, finite_real, positive_real])
@pytest.mark.parametrize("value, expected", [(2, 2.0), (0.5, 0.5), (np.float32(0.25), 0.25),
                                             (np.int64(3), 3.0), (Fraction(1, 4), 0.25)])
def test_a_positive_real_number_comes_back_as_a_python_float(check, value, expected):
    number = check("x", value)
    assert type(number) is float and number == expected


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_real_refuses_what_is_not_a_real_number_naming_it_as_given(value):
    with pytest.raises(ParameterError) as info:
        real("gain", value, fix="; e.g. 2.0")
    assert str(info.value) == f"`gain` must be a number, got {value!r}; e.g. 2.0."


@pytest.mark.parametrize("value, minimum, strict, bound", [
    (math.nan, None, False, ""), (math.inf, None, False, ""), (-math.inf, 0.0, False, " >= 0"),
    (-0.5, 0.0, False, " >= 0"), (0.0, 0.0, True, " > 0"), (0.5, 1.0, True, " > 1"),
    (np.int64(-2), 0.0, False, " >= 0")])
def test_real_refuses_non_finite_values_and_values_out_of_bounds_naming_the_bound(
        value, minimum, strict, bound):
    with pytest.raises(ParameterError) as info:
        real("gain", value, minimum=minimum, strict=strict)
    assert str(info.value) == f"`gain` must be a finite number{bound}, got {float(value)!r}."


@pytest.mark.parametrize("value, minimum, strict", [(0.0, 0.0, False), (1.0, 1.0, False),
                                                    (1e-300, 0.0, True), (-5.0, None, False)])
def test_real_accepts_the_bound_itself_unless_strict(value, minimum, strict):
    assert real("gain", value, minimum=minimum, strict=strict) == value


@pytest.mark.parametrize("value", [*NOT_NUMBERS, math.nan, -math.inf, np.float64(math.inf)])
def test_finite_real_says_finite_number_with_the_value_as_given(value):
    with pytest.raises(ParameterError) as info:
        finite_real("dt", value, positive=True)
    assert str(info.value) == f"`dt` must be a finite number, got {value!r}."


@pytest.mark.parametrize("value", [0, -1, 0.0, -2.5, np.int64(0)])
def test_finite_real_positive_refuses_zero_and_below_with_the_value_as_given(value):
    assert finite_real("dt", value) == float(value)  # without `positive`, any finite number
    with pytest.raises(ParameterError) as info:
        finite_real("dt", value, positive=True)
    assert str(info.value) == f"`dt` must be positive, got {value!r}."


@pytest.mark.parametrize("value", [*NOT_NUMBERS, math.nan, math.inf, 0, -1.0, np.float64(-0.0)])
def test_positive_real_has_one_message_for_every_refusal(value):
    with pytest.raises(ParameterError) as info:
        positive_real("sample_rate", value)
    assert str(info.value) == f"`sample_rate` must be a positive finite number, got {value!r}."


def test_the_checks_raise_the_error_class_asked_for():
    for check in (lambda: real("x", "a", error=DataError),
                  lambda: finite_real("x", math.nan, error=DataError),
                  lambda: positive_real("x", 0.0, error=DataError)):
        with pytest.raises(DataError):
            check()


def test_optional_lets_none_through_and_checks_the_rest():
    assert optional(positive_real)("corner", None) is None
    assert optional(positive_real)("corner", 2) == 2.0
    with pytest.raises(ParameterError, match="`corner` must be a positive finite number"):
        optional(positive_real)("corner", -1.0)


@pytest.mark.parametrize("value", [True, 1.0, -1, "3"])
def test_integer_refuses_bools_floats_and_values_below_the_minimum(value):
    with pytest.raises(ParameterError) as info:
        integer("jitter_samples", value, 0)
    assert str(info.value) == f"`jitter_samples` must be an integer >= 0, got {value!r}."
    assert integer("jitter_samples", np.int64(4), 0) == 4


def test_an_interval_is_two_ordered_finite_numbers_above_its_minimum():
    assert interval("mass_range", (6, 6.5), "kg") == (6.0, 6.5)
    assert interval("mass_range", np.array([2.0, 2.0]), "kg") == (2.0, 2.0)
    for value in [(7.0, 6.0), (1.0,), (1.0, math.nan), "ab", (-1.0, 1.0), 3.0]:
        with pytest.raises(ParameterError, match="`mass_range`"):
            interval("mass_range", value, "kg")
    with pytest.raises(ParameterError) as info:
        interval("rate_range", (0.0, 10.0), "Hz", minimum=1e-9)
    assert str(info.value) == ("`rate_range` must satisfy 1e-09 <= low <= high (finite, in Hz), "
                               "got (0.0, 10.0); e.g. (1, 2) Hz.")
    with pytest.raises(ParameterError) as info:
        interval("band", "ab", "Hz", example="(1, 20)")
    assert str(info.value) == ("`band` must be two numbers (low, high) in Hz, got 'ab'; "
                               "e.g. (1, 20).")
