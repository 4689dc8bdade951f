"""What active damping changes in a transmissibility curve: the two metrics, defined once.

The paper's claim "active damping did not help much" can be read off two curves, one
without damping (the reference) and one with, in two ways, and the two can disagree:

``largest_reduction_db``
    The largest per-bin reduction, ``max(-20 log10(T_damped / T_reference))`` [dB] over
    the bins of the band trusted in both curves: what damping does where it helps most
    (positive: a reduction).
``band_rms_change_db``
    The change of the band RMS, ``20 log10(rms_damped / rms_reference)`` [dB], where
    ``rms = sqrt(mean(T^2))`` (:func:`band_rms`, the cost ``qzs design`` minimises) over
    the same bins, those of the band trusted in both curves: what damping does to the band
    as a whole (negative: a reduction).

Both compare the curves bin by bin on one set of bins, so the band's reduction is never
larger than the largest per-bin one. (The ratio of two costs each read from its own
curve's trusted bins, which ``qzs design`` also shows as the change of its cost, can be:
bins the damped curve does not trust, where the reference is high, count only in the
reference's cost.)

``qzs paper`` decides the claim from both (:mod:`qzs.workflows.paper.report`) and ``qzs design``
shows both for every gain it tries (:mod:`qzs.workflows.design`), through
:func:`damping_change`, so the two reports cannot define them differently.

>>> f = np.array([1.0, 2.0, 3.0, 4.0])
>>> change = damping_change(f, np.ones(4), np.array([1.0, 1.0, 0.5, 1.0]), band=(1.0, 4.0))
>>> round(change.largest_reduction_db, 2), change.largest_reduction_frequency
(6.02, 3.0)
"""
import math
import warnings
from dataclasses import dataclass

import numpy as np

from qzs._format import decibels
from qzs.analysis.spectral import band_mask
from qzs.errors import DataWarning, ParameterError

__all__ = ["DampingChange", "band_rms", "damping_change", "DAMPING_METRICS"]

#: The two metrics of :class:`DampingChange`: name -> (unit, what it is).
DAMPING_METRICS = {
    "largest_reduction_db": ("dB", "largest per-bin reduction of T over the bins of the band "
                                   "trusted in both curves, -20 log10(T_damped/T_reference)"),
    "band_rms_change_db": ("dB", "change of the RMS of T over each curve's trusted bins of the "
                                 "band, 20 log10(rms_damped/rms_reference)"),
}


def _mask(frequency, band, trusted):
    """The bins of the band (:func:`qzs.analysis.spectral.band_mask`: closed, never DC)."""
    low, high = band
    if not low < high:
        raise ParameterError(f"`band` must be (low, high) with low < high [Hz], got {band!r}.")
    with warnings.catch_warnings():  # a band without a trusted bin is NaN here, said so
        warnings.simplefilter("ignore", DataWarning)
        return band_mask(frequency, low, high, trusted=trusted)


def band_rms(frequency, magnitude, band, *, trusted=None):
    """RMS of a transmissibility curve over the trusted bins of a band, ``sqrt(mean(T^2))``.

    Parameters
    ----------
    frequency : array_like
        Bin frequencies [Hz].
    magnitude : array_like
        Transmissibility, an amplitude ratio [-], at ``frequency``.
    band : tuple of float
        The band [Hz, Hz], both ends included, never the 0 Hz bin
        (:func:`qzs.analysis.spectral.band_mask`).
    trusted : array_like of bool, optional
        The bins that may be used; default all.

    Returns
    -------
    float
        The RMS [-]; NaN when no bin of the band is trusted.

    Raises
    ------
    ParameterError
        A band whose low end is not below its high end, or ``trusted`` of another shape.
    """
    keep = _mask(frequency, band, trusted)
    if not keep.any():
        return math.nan
    values = np.asarray(magnitude, dtype=float)[keep]
    return float(np.sqrt(np.mean(values ** 2)))


@dataclass(frozen=True, kw_only=True)
class DampingChange:
    """What damping changes in a curve, against the undamped reference (module docstring).

    Attributes
    ----------
    largest_reduction_db : float
        Largest per-bin reduction over the bins of the band trusted in both curves [dB];
        positive: a reduction; NaN without such a bin.
    largest_reduction_frequency : float
        The bin where it is [Hz]; NaN without one.
    band_rms_change_db : float
        Change of the band RMS over the bins trusted in both curves [dB]; negative: a
        reduction; NaN without such a bin.
    reference_rms, damped_rms : float
        The two band RMS values over those bins [-] (:func:`band_rms`).
    bins : int
        Bins of the band trusted in both curves.
    band : tuple of float
        The band [Hz, Hz].
    """

    largest_reduction_db: float
    largest_reduction_frequency: float
    band_rms_change_db: float
    reference_rms: float
    damped_rms: float
    bins: int
    band: tuple

    def to_dict(self):
        """The values as a flat dict (``band`` as ``band_low`` and ``band_high`` [Hz]).

        Returns
        -------
        dict
        """
        return {"largest_reduction_db": self.largest_reduction_db,
                "largest_reduction_frequency": self.largest_reduction_frequency,
                "band_rms_change_db": self.band_rms_change_db,
                "reference_rms": self.reference_rms, "damped_rms": self.damped_rms,
                "bins": self.bins, "band_low": self.band[0], "band_high": self.band[1]}


def damping_change(frequency, reference, damped, *, band, reference_trusted=None,
                   damped_trusted=None):
    """Both damping metrics of a damped curve against its undamped reference.

    Parameters
    ----------
    frequency : array_like
        Bin frequencies of both curves [Hz].
    reference : array_like
        Transmissibility without damping [-], at ``frequency``.
    damped : array_like
        Transmissibility with damping [-], at ``frequency``.
    band : tuple of float
        The band [Hz, Hz], both ends included.
    reference_trusted, damped_trusted : array_like of bool, optional
        The trusted bins of each curve; default all.

    Returns
    -------
    DampingChange

    Raises
    ------
    ParameterError
        Curves whose shapes differ from ``frequency``'s, or a bad ``band``.
    """
    frequency = np.asarray(frequency, dtype=float)
    reference = np.asarray(reference, dtype=float)
    damped = np.asarray(damped, dtype=float)
    for name, values in (("reference", reference), ("damped", damped)):
        if values.shape != frequency.shape:
            raise ParameterError(f"`{name}` must have the shape of `frequency` "
                                 f"{frequency.shape}, got {values.shape}.")
    band = (float(band[0]), float(band[1]))
    both = _mask(frequency, band, reference_trusted) & _mask(frequency, band, damped_trusted)
    both &= (reference > 0) & (damped > 0)
    reference_rms = band_rms(frequency, reference, band, trusted=both)
    damped_rms = band_rms(frequency, damped, band, trusted=both)
    if both.any():
        reduction = -decibels(damped[both] / reference[both])
        i = int(np.argmax(reduction))
        largest, at = float(reduction[i]) + 0.0, float(frequency[both][i])  # no -0
    else:
        largest = at = math.nan
    change = (decibels(damped_rms / reference_rms)
              if reference_rms > 0 and math.isfinite(damped_rms) and damped_rms > 0 else math.nan)
    return DampingChange(largest_reduction_db=largest, largest_reduction_frequency=at,
                         band_rms_change_db=float(change) + 0.0, reference_rms=reference_rms,
                         damped_rms=damped_rms, bins=int(both.sum()), band=band)
