"""How numbers are shown: in decibels (figures, reports, metrics).
"""
import math
import numbers

import numpy as np

__all__ = ["decibels"]


def decibels(ratio, floor=None):
    """An amplitude ratio in decibels, ``20 log10 |ratio|`` [dB].

    Parameters
    ----------
    ratio : float, complex or array_like
        Amplitude ratio [-], real or complex (a magnitude in some unit gives dB re 1 of
        that unit).
    floor : float, optional
        Smallest magnitude converted [-]: smaller ones, 0 included, give
        ``decibels(floor)`` (so that a figure can draw them). Without it 0 gives -inf.

    Returns
    -------
    float or ndarray
        A float for a number (:func:`math.log10`), an array of the shape of ``ratio``
        otherwise (:func:`numpy.log10`); NaN stays NaN.
    """
    if isinstance(ratio, numbers.Number):
        magnitude = abs(ratio)
        if floor is not None and magnitude < floor:
            magnitude = floor
        return 20 * math.log10(magnitude) if magnitude != 0 else -math.inf
    values = np.asarray(ratio)
    magnitude = np.abs(values if np.iscomplexobj(values) else values.astype(float, copy=False))
    with np.errstate(divide="ignore", invalid="ignore"):
        if floor is not None:
            magnitude = np.maximum(magnitude, floor)
        return 20 * np.log10(magnitude)
