"""Argument checks shared by the modules of :mod:`qzs.analysis.control_design`."""
import math

import numpy as np

from qzs.errors import ParameterError


def _number(name, value, *, minimum=0.0, strict=False, fix=""):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"`{name}` must be a number, got {value!r}{fix}.")
    value = float(value)
    if not math.isfinite(value) or value < minimum or (strict and value == minimum):
        bound = f"> {minimum:g}" if strict else f">= {minimum:g}"
        raise ParameterError(f"`{name}` must be a finite number {bound}, got {value!r}{fix}.")
    return value


def _range(name, values, unit, *, minimum=0.0):
    try:
        low, high = (float(v) for v in values)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be two numbers (low, high) in {unit}, got "
                             f"{values!r}.") from None
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise ParameterError(f"`{name}` must satisfy {minimum:g} <= low <= high (finite, {unit}), "
                             f"got {values!r}; give e.g. ({max(minimum, 1.0):g}, 2) {unit}.")
    return low, high
