"""The argument checks the control-design modules share: numbers and (low, high) ranges."""
import math

import numpy as np
import pytest

from qzs import ParameterError
from qzs.analysis.control_design._arguments import _number, _range


def test_a_number_comes_back_as_a_float_and_a_bad_one_is_named():
    assert _number("delay", np.float32(0.5)) == 0.5 and type(_number("delay", 2)) is float
    assert _number("rate", 0.0) == 0.0  # >= 0 by default
    for value, words in [(True, "must be a number"), ("1", "must be a number"),
                         (math.nan, ">= 0"), (math.inf, ">= 0"), (-1e-9, ">= 0")]:
        with pytest.raises(ParameterError, match=f"`delay` {words}|`delay` must be a finite"):
            _number("delay", value)
    with pytest.raises(ParameterError, match=r"`rate` must be a finite number > 0, got 0\.0; "
                                             r"in Hz\."):
        _number("rate", 0.0, strict=True, fix="; in Hz")


def test_a_range_is_two_ordered_finite_numbers_above_its_minimum():
    assert _range("mass_range", (6, 6.5), "kg") == (6.0, 6.5)
    assert _range("mass_range", np.array([2.0, 2.0]), "kg") == (2.0, 2.0)
    for value in [(7.0, 6.0), (1.0,), (1.0, math.nan), "ab", (-1.0, 1.0)]:
        with pytest.raises(ParameterError, match="`mass_range`"):
            _range("mass_range", value, "kg")
    with pytest.raises(ParameterError, match="1e-09 <= low <= high"):
        _range("rate_range", (0.0, 10.0), "Hz", minimum=1e-9)
