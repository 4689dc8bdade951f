"""Transmissibility estimation and metrics for a base-excited isolator.

Pure numpy/scipy.signal: Welch spectra of base and payload acceleration, their ratio
(the paper's 'transmissibility', Section 4), which of its bins can be trusted, and
scalar metrics read off the trusted bins only (docs/model.md §10).
Segments follow scipy's rule: ``step = fft_length - round(overlap * fft_length)`` and
``n_averages = (n_samples - noverlap) // step``.

A bin is *trusted* when it is above 0 Hz, its magnitude-squared coherence is at least
``ANALYSIS["coherence_min"]``, it holds at least ``ANALYSIS["base_share_min"]`` of the
base's own power (DC excluded), and it lies at or above ``ANALYSIS["highpass_factor"]``
times a measurement high-pass corner. Every metric comes from trusted bins, or is NaN
with the reason in :attr:`TransmissibilityMetrics.reasons`.
"""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass, field
from collections.abc import Callable, Sequence
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal, Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs._format import UndefinedValue, decibels
from qzs._validation import finite_rows, finite_series, integer, optional, positive_real
from qzs.analysis.estimate_views import EstimateProtocol
from qzs.analysis.welch import transmissibility_arrays
from qzs.defaults import ANALYSIS, REPORTED_FREQUENCIES
from qzs.errors import DataError, DataWarning, ParameterError
from qzs.iotools.schema import Schema, Variable, to_dataset

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["TransmissibilityEstimate", "TransmissibilityMetrics", "UndefinedValue",
           "amplitude_spectrum", "band_mask",
           "rolloff_slope", "highpass", "required_duration", "required_samples", "transmissibility",
           "transmissibility_batch",
           "transmissibility_at", "transmissibility_metrics", "trusted_bins",
           "welch_average_count", "estimate_schema", "METRIC_UNITS", "metric_unit"]

ESTIMATORS = ("psd_ratio", "h1", "h2")
_MAGNITUDE_NAMES = {"psd_ratio": "amplitude ratio sqrt(S_payload / S_base)",
                    "h1": "|H1| = |S_base,payload| / S_base", "h2": "|H2| = S_payload / |S_payload,base|"}


# ---------------------------------------------------------------- validation
def _noverlap(fft_length, overlap):
    if isinstance(overlap, bool) or not isinstance(overlap, numbers.Real) or not 0 <= overlap < 1:
        raise ParameterError(f"`overlap` must be a fraction in [0, 1), got {overlap!r}.")
    noverlap = int(round(overlap * fft_length))
    if noverlap >= fft_length:
        raise ParameterError(f"`overlap`={overlap} leaves no step between segments of "
                             f"{fft_length} samples; use a smaller `overlap`.")
    return noverlap


def _signal(name, values):
    return finite_series(name, values, DataError,
                         "interpolate or trim them before estimating spectra")


def highpass(values, corner, sample_rate):
    """First-order high-pass ``s/(s + 2*pi*corner)`` (bilinear), as a charge amplifier's.

    Parameters
    ----------
    values : array_like
        Signal sampled at ``sample_rate`` [Hz].
    corner : float
        Corner frequency [Hz]; 0 or None returns the signal unchanged.
    sample_rate : float
        Sample rate of ``values`` [Hz].

    Returns
    -------
    ndarray
        The filtered signal, in the unit of ``values``.
    """
    if not corner:
        return np.asarray(values, dtype=float)
    from scipy import signal  # on first use: importing scipy.signal takes about 0.9 s

    b, a = signal.bilinear([1.0, 0.0], [1.0, 2 * np.pi * corner], fs=sample_rate)
    return signal.lfilter(b, a, values)


def band_mask(frequency, low, high, trusted=None):
    """Bins of ``frequency`` in the closed band ``[low, high]`` [Hz], never the DC bin.

    The one rule every band in qzs follows (curves kept, band means, fits, figures):
    both edges included, and the 0 Hz bin excluded, since a Welch ratio there
    compares the segments' means, not a vibration.

    Parameters
    ----------
    frequency : array_like
        Bin frequencies [Hz].
    low, high : float
        Band edges [Hz].
    trusted : array_like of bool, optional
        Keep only these bins too (:attr:`TransmissibilityEstimate.trusted`); a band
        left with no trusted bin raises a :class:`~qzs.errors.DataWarning`.

    Returns
    -------
    ndarray of bool
    """
    f = np.asarray(frequency, dtype=float)
    mask = (f > 0) & (f >= low) & (f <= high)
    if trusted is not None:
        trusted = np.asarray(trusted, dtype=bool)
        if trusted.shape != f.shape:
            raise ParameterError(f"`trusted` must have the shape of `frequency` {f.shape}, "
                                 f"got {trusted.shape}.")
        mask &= trusted
        if not mask.any():
            warnings.warn(f"no trusted bin in the band [{low:g}, {high:g}] Hz: a mean, maximum "
                          "or fit over it is undefined (NaN)", DataWarning, stacklevel=2)
    return mask


def trusted_bins(frequency, coherence, base_share, *, coherence_min=ANALYSIS["coherence_min"],
                 base_share_min=ANALYSIS["base_share_min"], highpass_corner=None,
                 highpass_factor=ANALYSIS["highpass_factor"], magnitude=None):
    """The bins of a transmissibility estimate that can be trusted (docs/model.md §10).

    A bin is trusted when all hold: it is above 0 Hz; its magnitude-squared coherence
    is at least ``coherence_min`` (the payload's power there is explained by the base's;
    the PSD ratio then exceeds the coherent response ``|H1|`` by at most
    ``1/sqrt(coherence_min)``); it holds at least ``base_share_min`` of the base's power
    (the base excited it at all); it lies at or above ``highpass_factor * highpass_corner``;
    and its magnitude, if given, is finite.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Bin frequencies [Hz].
    coherence : array_like, shape (n,)
        Magnitude-squared coherence of base and payload [-], 0..1.
    base_share : array_like, shape (n,)
        Each bin's share of the base's power, DC excluded [-].
    coherence_min : float
        Least coherence of a trusted bin [-], in (0, 1].
    base_share_min : float
        Least share of the base's power of a trusted bin [-], >= 0.
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz]; bins below
        ``highpass_factor * highpass_corner`` are untrusted.
    highpass_factor : float
        Multiple of the corner below which bins are untrusted [-].
    magnitude : array_like, shape (n,), optional
        The transmissibility [-]; non-finite bins are untrusted.

    Returns
    -------
    ndarray of bool, shape (n,)
    """
    f = np.asarray(frequency, dtype=float)
    if isinstance(coherence_min, bool) or not isinstance(coherence_min, numbers.Real) \
            or not 0 < coherence_min <= 1:
        raise ParameterError(f"`coherence_min` must be in (0, 1], got {coherence_min!r}.")
    if isinstance(base_share_min, bool) or not isinstance(base_share_min, numbers.Real) \
            or not 0 <= base_share_min < 1:
        raise ParameterError(f"`base_share_min` must be in [0, 1), got {base_share_min!r}.")
    corner = optional(positive_real)("highpass_corner", highpass_corner)
    factor = positive_real("highpass_factor", highpass_factor)
    with np.errstate(invalid="ignore"):
        mask = ((f > 0) & (np.asarray(coherence, dtype=float) >= coherence_min)
                & (np.asarray(base_share, dtype=float) >= base_share_min))
    if corner is not None:
        mask &= f >= factor * corner
    if magnitude is not None:
        mask &= np.isfinite(np.asarray(magnitude, dtype=float))
    return mask


# ---------------------------------------------------------------- run sizing
def welch_average_count(n_samples, fft_length, overlap=0.5):
    """Number of segments scipy.signal.welch averages over `n_samples` [samples].

    Segments are `fft_length` [samples] long and share the fraction `overlap` in [0, 1);
    the count is ``(n_samples - noverlap) // step``, 0 if the record is shorter than one segment.

    Parameters
    ----------
    n_samples : int
        Length of the record [samples], >= 0.
    fft_length : int
        Segment length [samples], >= 8.
    overlap : float
        Fraction of a segment shared with the next [-], in [0, 1).

    Returns
    -------
    int
        Number of segments averaged.
    """
    n_samples = integer("n_samples", n_samples, 0)
    fft_length = integer("fft_length", fft_length, 8)
    noverlap = _noverlap(fft_length, overlap)
    return 0 if n_samples < fft_length else (n_samples - noverlap) // (fft_length - noverlap)


def required_samples(fft_length, n_averages, overlap=0.5):
    """Shortest record giving `n_averages` Welch segments: ``fft_length + (n_averages - 1) * step``.

    Parameters
    ----------
    fft_length : int
        Segment length [samples], >= 8.
    n_averages : int
        Number of segments wanted, >= 1.
    overlap : float
        Fraction of a segment shared with the next [-], in [0, 1).

    Returns
    -------
    int
        Record length [samples].
    """
    fft_length = integer("fft_length", fft_length, 8)
    n_averages = integer("n_averages", n_averages, 1)
    return fft_length + (n_averages - 1) * (fft_length - _noverlap(fft_length, overlap))


def required_duration(fft_length, n_averages, sample_rate, overlap=0.5):
    """Shortest record duration [s] giving `n_averages` segments at `sample_rate` [Hz].

    The paper's 32768-point FFT with 122 averages at 1 kHz needs 2015.232 s.

    Parameters
    ----------
    fft_length : int
        Segment length [samples], >= 8.
    n_averages : int
        Number of segments wanted, >= 1.
    sample_rate : float
        Sample rate [Hz].
    overlap : float
        Fraction of a segment shared with the next [-], in [0, 1).

    Returns
    -------
    float
        Record duration [s]: :func:`required_samples` divided by ``sample_rate``.
    """
    return (required_samples(fft_length, n_averages, overlap)
            / positive_real("sample_rate", sample_rate))


# ---------------------------------------------------------------- estimation
@dataclass(frozen=True, eq=False)
class TransmissibilityEstimate(EstimateProtocol):
    """Transmissibility from base to payload acceleration, one value per frequency bin.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Bin frequencies [Hz], from 0 to the Nyquist frequency.
    magnitude : ndarray, shape (n,)
        Amplitude ratio [-]; for ``psd_ratio`` it is ``sqrt(S_payload / S_base)``.
    phase : ndarray, shape (n,)
        Phase of payload relative to base [rad]: the phase of the cross spectrum
        ``S_bp``, which H1 and H2 share (``S_bb`` and ``S_pp`` are real); every estimator
        has it.
    coherence : ndarray, shape (n,)
        Magnitude-squared coherence [-], 0..1.
    base_share : ndarray, shape (n,)
        Each bin's share of the base's power [-], ``S_base / sum(S_base)`` over the bins
        above 0 Hz (0 at DC).
    trusted : ndarray of bool, shape (n,)
        The bins metrics may use (:func:`trusted_bins`): never DC, coherence at least
        ``coherence_min``, base share at least ``base_share_min``, at or above
        ``highpass_factor * highpass_corner``, finite magnitude.
    estimator : str
        ``"psd_ratio"``, ``"h1"`` or ``"h2"``.
    fft_length, n_averages : int
        Segment length [samples] and number of segments averaged.
    sample_rate : float
        Sample rate [Hz].
    highpass_corner : float or None
        Corner of a high-pass filter in the measurement chain [Hz], if any.
    coherence_min, base_share_min : float
        The thresholds ``trusted`` was drawn with [-].
    highpass_factor : float
        Multiple of ``highpass_corner`` below which bins are untrusted [-].
    """

    frequency: np.ndarray
    magnitude: np.ndarray
    phase: np.ndarray
    coherence: np.ndarray
    base_share: np.ndarray
    trusted: np.ndarray
    estimator: str
    fft_length: int
    n_averages: int
    sample_rate: float
    highpass_corner: float | None = None
    coherence_min: float = ANALYSIS["coherence_min"]
    base_share_min: float = ANALYSIS["base_share_min"]
    highpass_factor: float = ANALYSIS["highpass_factor"]

    @property
    def untrusted_below(self) -> float:
        """Upper edge of the high-pass's untrusted band [Hz]: ``highpass_factor * highpass_corner``, or 0."""
        return 0.0 if self.highpass_corner is None else self.highpass_factor * self.highpass_corner

    def magnitude_db(self) -> NDArray[np.float64]:
        """Magnitude in decibels, ``20 * log10(magnitude)`` [dB] (-inf where it is 0)."""
        return decibels(self.magnitude)

    def metrics(self, **options: Any) -> TransmissibilityMetrics:
        """Scalar metrics of this curve's trusted bins (:func:`transmissibility_metrics`).

        Parameters
        ----------
        **options
            Keywords of :func:`transmissibility_metrics`; ``trusted``,
            ``highpass_corner`` and ``untrusted_factor`` default to this estimate's.

        Returns
        -------
        TransmissibilityMetrics
        """
        options.setdefault("trusted", self.trusted)
        options.setdefault("highpass_corner", self.highpass_corner)
        options.setdefault("untrusted_factor", self.highpass_factor)
        return transmissibility_metrics(self.frequency, self.magnitude, **options)

    def to_xarray(self) -> xr.Dataset:
        """Repackage as an ``xarray.Dataset`` on coordinate ``frequency`` [Hz], with units attrs
        (:func:`estimate_schema`)."""
        attrs = {"estimator": self.estimator, "fft_length": self.fft_length,
                 "n_averages": self.n_averages, "sample_rate": self.sample_rate,
                 "coherence_min": self.coherence_min, "base_share_min": self.base_share_min,
                 "highpass_factor": self.highpass_factor}
        if self.highpass_corner is not None:
            attrs["highpass_corner"] = self.highpass_corner
        values = {"frequency": self.frequency, "magnitude": self.magnitude, "phase": self.phase,
                  "coherence": self.coherence, "base_share": self.base_share,
                  "trusted": self.trusted}
        return to_dataset(estimate_schema(self.estimator), values, attrs)


def estimate_schema(estimator="h1"):
    """The CF-1.10 layout of a :class:`TransmissibilityEstimate`'s dataset.

    Coordinate ``frequency`` [Hz]; ``magnitude`` [-], ``phase`` [rad], ``coherence`` [-],
    ``base_share`` [-] and the ``trusted`` flag (int8), each with ``units`` and
    ``long_name``.

    Parameters
    ----------
    estimator : {"psd_ratio", "h1", "h2"}
        The estimator, named in the magnitude's ``long_name``.

    Returns
    -------
    Schema
    """
    on = ("frequency",)
    variables = (
        Variable(name="magnitude", dims=on, units="1",
                 long_name=f"transmissibility, {_MAGNITUDE_NAMES[estimator]}"),
        Variable(name="phase", dims=on, units="rad", long_name="phase of payload relative to base"),
        Variable(name="coherence", dims=on, units="1", long_name="magnitude-squared coherence"),
        Variable(name="base_share", dims=on, units="1", long_name="share of the base's power"),
        Variable(name="trusted", dims=on, units="1", dtype="int8",
                 long_name="1 where the bin is trusted (docs/model.md section 10)",
                 flag_meanings="untrusted trusted"))
    return Schema(kind="a transmissibility estimate", dimensions={"frequency": None},
                  coordinates=(Variable(name="frequency", dims=on, units="Hz",
                                        long_name="frequency"),),
                  variables=variables)


def transmissibility(base: ArrayLike, payload: ArrayLike, sample_rate: float, *,
                     fft_length: int = ANALYSIS["fft_length"],
                     overlap: float = ANALYSIS["overlap"],
                     window: str | tuple[Any, ...] | ArrayLike = "hann",
                     n_averages: int | None = None, estimator: str = "psd_ratio",
                     detrend: str | Callable[..., Any] | Literal[False] = "constant",
                     highpass_corner: float | None = None,
                     coherence_min: float = ANALYSIS["coherence_min"],
                     base_share_min: float = ANALYSIS["base_share_min"],
                     highpass_factor: float = ANALYSIS["highpass_factor"],
                     ) -> TransmissibilityEstimate:
    """Estimate the transmissibility from base to payload acceleration by Welch averaging.

    Parameters
    ----------
    base, payload : array_like, shape (n,)
        Base and payload acceleration [m/s^2] (any common unit), sampled together.
    sample_rate : float
        Sample rate [Hz].
    fft_length : int
        Segment and FFT length [samples], >= 8. The paper uses 32768.
    overlap : float
        Segment overlap fraction in [0, 1).
    window : str, tuple or array_like
        Window, as for ``scipy.signal.get_window``; Hann in the paper.
    n_averages : int, optional
        Average exactly this many segments, using only the start of the record.
        Default: as many as fit.
    estimator : {"psd_ratio", "h1", "h2"}
        ``psd_ratio``: ``sqrt(S_pp / S_bb)`` (the paper's definition; its phase is that of
        ``S_bp``, as for H1 and H2);
        ``h1``: ``S_bp / S_bb`` (unbiased by payload noise);
        ``h2``: ``S_pp / S_pb`` (unbiased by base noise).
    detrend : str, callable or False
        Per-segment detrending, as in ``scipy.signal.welch``.
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz]: bins below
        ``highpass_factor * highpass_corner`` are untrusted.
    coherence_min : float
        Least magnitude-squared coherence of a trusted bin [-] (:func:`trusted_bins`).
    base_share_min : float
        Least share of the base's power of a trusted bin [-] (:func:`trusted_bins`).
    highpass_factor : float
        Multiple of ``highpass_corner`` below which bins are untrusted [-].

    Returns
    -------
    TransmissibilityEstimate
        With ``trusted``, the bins metrics may use, and the ``coherence`` and
        ``base_share`` arrays that define it.

    Raises
    ------
    ParameterError
        Invalid option.
    DataError
        Signals not 1-D, of different lengths, non-finite, or too short.
    """
    base, payload = _signal("base", base), _signal("payload", payload)
    if base.size != payload.size:
        raise DataError(f"`base` and `payload` must have the same length, "
                        f"got {base.size} and {payload.size}.")
    # one case of a population: the same operations, the same bits (qzs.analysis.welch)
    return transmissibility_batch(
        base[np.newaxis], payload[np.newaxis], sample_rate, fft_length=fft_length,
        overlap=overlap, window=window, n_averages=n_averages, estimator=estimator,
        detrend=detrend, highpass_corner=highpass_corner, coherence_min=coherence_min,
        base_share_min=base_share_min, highpass_factor=highpass_factor)[0]


def transmissibility_batch(base: ArrayLike, payload: ArrayLike, sample_rate: float, *,
                           fft_length: int = ANALYSIS["fft_length"],
                           overlap: float = ANALYSIS["overlap"],
                           window: str | tuple[Any, ...] | ArrayLike = "hann",
                           n_averages: int | None = None, estimator: str = "psd_ratio",
                           detrend: str | Callable[..., Any] | Literal[False] = "constant",
                           highpass_corner: float | None = None,
                           coherence_min: float = ANALYSIS["coherence_min"],
                           base_share_min: float = ANALYSIS["base_share_min"],
                           highpass_factor: float = ANALYSIS["highpass_factor"],
                           ) -> tuple[TransmissibilityEstimate, ...]:
    """The transmissibility of every case of a population, from one batched Welch estimate.

    :func:`transmissibility` of each row of ``base`` and ``payload``, the same numbers
    (the same operations along the rows, :mod:`qzs.analysis.welch`), but every case's
    segments in one :class:`scipy.signal.ShortTimeFFT` call: the window, its PSD scale and
    the transform are set up once for the population rather than once per case.

    Parameters
    ----------
    base, payload : array_like, shape (n_cases, n)
        Base and payload acceleration of each case [m/s^2] (any common unit), one case per
        row, all sampled together at ``sample_rate``.
    sample_rate : float
        Sample rate [Hz].
    fft_length : int
        Segment and FFT length [samples], >= 8.
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz].
    overlap, window, n_averages, estimator, detrend, coherence_min, base_share_min, \
highpass_factor
        As for :func:`transmissibility`, the same for every case.

    Returns
    -------
    tuple of TransmissibilityEstimate
        One per row, in order (none for no row); they share their ``frequency`` array.

    Raises
    ------
    ParameterError
        Invalid option.
    DataError
        Signals not 2-D, of different shapes, non-finite (the cases are named), or too short.
    """
    sample_rate = positive_real("sample_rate", sample_rate)
    fft_length = integer("fft_length", fft_length, 8)
    noverlap = _noverlap(fft_length, overlap)
    highpass_corner = optional(positive_real)("highpass_corner", highpass_corner)
    if estimator not in ESTIMATORS:
        raise ParameterError(f"`estimator` must be one of {ESTIMATORS}, got {estimator!r}.")
    fix = "estimate those cases apart, or interpolate or trim them before estimating spectra"
    base, payload = (finite_rows(name, values, DataError, fix)
                     for name, values in (("base", base), ("payload", payload)))
    if base.shape != payload.shape:
        raise DataError(f"`base` and `payload` must have the same shape, got {base.shape} and "
                        f"{payload.shape}.")
    if n_averages is None:
        needed, what = fft_length, f"fft_length={fft_length}"
    else:
        needed = required_samples(fft_length, n_averages, overlap)
        what = f"n_averages={n_averages} with fft_length={fft_length} and overlap={overlap}"
    size = base.shape[-1]
    if size < needed:
        raise DataError(f"{what} needs at least {needed} samples ({needed / sample_rate:g} s at "
                        f"{sample_rate:g} Hz), got {size} ({size / sample_rate:g} s); "
                        f"record longer or reduce `fft_length`/`n_averages`.")
    if n_averages is not None:  # contiguous rows: the FFTs of strided rows are other bits
        base, payload = (np.ascontiguousarray(x[:, :needed]) for x in (base, payload))
    if base.shape[0] == 0:
        return ()
    arrays = transmissibility_arrays(base, payload, sample_rate, window=window,
                                     fft_length=fft_length, noverlap=noverlap,
                                     detrend=detrend, estimator=estimator)
    return _estimates(arrays, estimator=estimator, fft_length=fft_length,
                      n_averages=welch_average_count(base.shape[-1], fft_length, overlap),
                      sample_rate=sample_rate, highpass_corner=highpass_corner,
                      coherence_min=coherence_min, base_share_min=base_share_min,
                      highpass_factor=highpass_factor)


def _estimates(arrays, *, coherence_min, base_share_min, highpass_corner, highpass_factor,
               **fields):
    """One :class:`TransmissibilityEstimate` per case (row) of ``arrays``, read-only."""
    frequency, magnitude, phase, coherence, base_share = arrays
    trusted = trusted_bins(frequency, coherence, base_share, coherence_min=coherence_min,
                           base_share_min=base_share_min, highpass_corner=highpass_corner,
                           highpass_factor=highpass_factor, magnitude=magnitude)
    rows = [np.atleast_2d(np.asarray(a, dtype=float))
            for a in (magnitude, phase, coherence, base_share)] + [np.atleast_2d(trusted)]
    frequency = np.asarray(frequency, dtype=float)
    for array in [frequency, *rows]:
        array.setflags(write=False)
    return tuple(TransmissibilityEstimate(
        frequency, *(array[i] for array in rows), **fields,
        highpass_corner=highpass_corner, coherence_min=float(coherence_min),
        base_share_min=float(base_share_min), highpass_factor=float(highpass_factor))
        for i in range(rows[0].shape[0]))


def amplitude_spectrum(signal_values, sample_rate, fft_length=ANALYSIS["fft_length"], window="hann",
                       overlap=ANALYSIS["overlap"]):
    """Welch-averaged RMS amplitude per frequency bin (``sqrt`` of ``welch(scaling="spectrum")``).

    A sine of peak amplitude ``A`` centred on a bin shows ``A / sqrt(2)`` there (its RMS);
    multiply by ``sqrt(2)`` for peak amplitude. Between bins the window's scalloping applies.

    Parameters
    ----------
    signal_values : array_like, shape (n,)
        Time series (any unit ``u``), sampled at `sample_rate` [Hz].
    sample_rate : float
        Sample rate [Hz].
    fft_length : int
        Segment and FFT length [samples], >= 8, as in :func:`transmissibility`.
    window : str, tuple or array_like
        Window, as in :func:`transmissibility`.
    overlap : float
        Segment overlap fraction [-] in [0, 1), as in :func:`transmissibility`.

    Returns
    -------
    frequency : ndarray
        Bin frequencies [Hz].
    rms_amplitude : ndarray
        RMS amplitude per bin [u].
    """
    sample_rate = positive_real("sample_rate", sample_rate)
    fft_length = integer("fft_length", fft_length, 8)
    noverlap = _noverlap(fft_length, overlap)
    values = _signal("signal_values", signal_values)
    if values.size < fft_length:
        raise DataError(f"fft_length={fft_length} needs at least {fft_length} samples "
                        f"({fft_length / sample_rate:g} s at {sample_rate:g} Hz), got {values.size}.")
    from scipy import signal  # on first use, as above

    frequency, power = signal.welch(values, fs=sample_rate, window=window, nperseg=fft_length,
                                    noverlap=noverlap, scaling="spectrum")
    return frequency, np.sqrt(power)


# ---------------------------------------------------------------- metrics
#: The scalar metrics, in the order of :meth:`TransmissibilityMetrics.to_dict`.
METRIC_NAMES = ("resonance_frequency", "resonance_peak", "isolation_onset", "minus_3db_frequency",
                "rolloff_db_per_decade", "untrusted_below")
#: The unit of each metric (of :meth:`TransmissibilityMetrics.to_dict`, and the trusted range
#: ``trusted_from``/``trusted_to`` beside it); a spot value ``transmissibility_at_<f>_hz`` is
#: an amplitude ratio, "1" (:func:`metric_unit`).
METRIC_UNITS = MappingProxyType({
    "resonance_frequency": "Hz", "resonance_peak": "1", "isolation_onset": "Hz",
    "minus_3db_frequency": "Hz", "rolloff_db_per_decade": "dB/decade", "untrusted_below": "Hz",
    "trusted_from": "Hz", "trusted_to": "Hz"})


def metric_unit(name):
    """The unit of a transmissibility metric (a key of :meth:`TransmissibilityMetrics.to_dict`).

    Parameters
    ----------
    name : str
        The metric's name: one of :data:`METRIC_UNITS` or ``transmissibility_at_<f>_hz``.

    Returns
    -------
    str or None
        Its unit ("1" for an amplitude ratio); None for a name that is not a metric.
    """
    if name.startswith("transmissibility_at_") and name.endswith("_hz"):
        return "1"
    return METRIC_UNITS.get(name)


def rolloff_slope(frequency, magnitude):
    """Least-squares slope of ``20 log10 T`` against ``log10 f`` [dB/decade].

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz] of the bins to fit, all > 0 (at least two distinct ones).
    magnitude : array_like
        Transmissibility at them, an amplitude ratio [-], all > 0.

    Returns
    -------
    float
        The slope [dB/decade]: -40 for a curve falling as ``1/f^2``.
    """
    return float(np.polyfit(np.log10(frequency), decibels(magnitude), 1)[0])


def _spot_key(frequency):
    return f"transmissibility_at_{frequency:g}_hz"


@dataclass(frozen=True)
class TransmissibilityMetrics:
    """Scalar metrics of a transmissibility curve's trusted bins; frequencies [Hz], ratios [-].

    NaN marks a metric the trusted bins do not define; ``reasons`` says why.

    Attributes
    ----------
    resonance_frequency : float
        Frequency of the resonance peak over the trusted bins [Hz].
    resonance_peak : float
        Transmissibility at that peak, an amplitude ratio [-].
    isolation_onset : float
        Frequency above which the transmissibility stays below 1 [Hz].
    minus_3db_frequency : float
        First frequency above resonance where the curve falls to ``peak / sqrt(2)`` [Hz].
    at : Mapping[float, float]
        Each requested frequency [Hz] -> the interpolated transmissibility [-].
    rolloff_db_per_decade : float
        Least-squares slope of ``20 log10 T`` against ``log10 f`` [dB/decade].
    untrusted_below : float
        Frequency below which a measurement high-pass makes the curve untrusted [Hz];
        0 without one.
    reasons : Mapping[str, str]
        For each metric that is NaN (keys of :meth:`to_dict`), why it is undefined.
    trusted_range : (float, float)
        Lowest and highest trusted bin [Hz, Hz]; NaN, NaN if no bin is trusted.
    """

    resonance_frequency: float
    resonance_peak: float
    isolation_onset: float
    minus_3db_frequency: float
    at: Mapping[float, float]
    rolloff_db_per_decade: float
    untrusted_below: float
    reasons: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    trusted_range: tuple = (float("nan"), float("nan"))

    def to_dict(self) -> dict[str, float]:
        """Flat dict of the values; ``at`` becomes keys ``transmissibility_at_<f>_hz``.

        A NaN is an :class:`UndefinedValue`: a float NaN that carries its reason (shown
        when the dict is printed; ``str`` and number formats give ``nan`` as before).
        """
        out = {name: getattr(self, name) for name in METRIC_NAMES}
        out.update({_spot_key(f): value for f, value in self.at.items()})
        return {name: UndefinedValue(self.reason(name) or "undefined")
                if isinstance(value, float) and math.isnan(value) else value
                for name, value in out.items()}

    def reason(self, name: str) -> str:
        """Why metric ``name`` (a key of :meth:`to_dict`) is NaN; ``""`` if it is defined.

        Parameters
        ----------
        name : str
            A key of :meth:`to_dict`.

        Returns
        -------
        str
        """
        return self.reasons.get(name, "")


def _crossing(frequency, magnitude, j, level):
    """Frequency where bins j -> j+1 (magnitude[j] >= level > magnitude[j+1]) cross `level`."""
    fraction = (magnitude[j] - level) / (magnitude[j] - magnitude[j + 1])
    return float(frequency[j] + fraction * (frequency[j + 1] - frequency[j]))


def _curve(frequency, magnitude, trusted=None):
    """Validated (frequency, magnitude, trusted) without the DC bin.

    Without ``trusted`` every bin above 0 Hz is trusted and must be finite; with it,
    non-finite bins are allowed and untrusted.
    """
    f, t = np.asarray(frequency, dtype=float), np.asarray(magnitude, dtype=float)
    if f.ndim != 1 or f.shape != t.shape:
        raise ParameterError(f"`frequency` and `magnitude` must be 1-D of the same shape, "
                             f"got {f.shape} and {t.shape}.")
    if trusted is None:
        ok = np.ones(f.shape, dtype=bool)
    else:
        ok = np.asarray(trusted)
        if ok.shape != f.shape or ok.dtype != bool:
            raise ParameterError(f"`trusted` must be a boolean array of the shape of `frequency` "
                                 f"{f.shape}, got {ok.dtype} {ok.shape}.")
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ParameterError(f"`frequency` must be finite and non-negative [Hz], "
                             f"got {np.count_nonzero(~(f >= 0))} values that are not.")
    if np.any(np.diff(f) <= 0):
        k = int(np.flatnonzero(np.diff(f) <= 0)[0])
        raise ParameterError(f"`frequency` must be strictly increasing, got frequency[{k + 1}]={f[k + 1]:g} "
                             f"after frequency[{k}]={f[k]:g}; sort the curve first.")
    above = f > 0
    f, t, ok = f[above], t[above], ok[above]
    if f.size < 2:
        raise ParameterError(f"the curve needs at least 2 points above 0 Hz, got {f.size}.")
    finite = np.isfinite(t)
    if trusted is None and not finite.all():
        raise ParameterError(f"`magnitude` has {np.count_nonzero(~finite)} non-finite values above "
                             "0 Hz; drop those bins first, or pass `trusted` without them.")
    if np.any(t[finite] < 0):
        raise ParameterError(f"`magnitude` must be non-negative (an amplitude ratio), got minimum "
                             f"{t[finite].min():g}.")
    return f, t, ok & finite


def _spot(f, t, ok, at, untrusted_below=0.0):
    """Transmissibility at ``at`` [Hz] between two adjacent trusted bins: (value, reason)."""
    nan = float("nan")
    if not f[0] <= at <= f[-1]:
        return nan, f"{at:g} Hz lies outside the curve ({f[0]:g} to {f[-1]:g} Hz)"
    k = int(np.searchsorted(f, at))
    used = (k,) if f[k] == at else (k - 1, k)
    if not all(ok[i] for i in used):
        why = (f"below {untrusted_below:g} Hz, the high-pass limit" if f[used[0]] < untrusted_below
               else "low coherence or no base power")
        return nan, f"{at:g} Hz lies in untrusted bins ({', '.join(f'{f[i]:.4g}' for i in used)} Hz: {why})"
    return float(np.interp(at, f[list(used)], t[list(used)])), ""


def transmissibility_at(frequency, magnitude, at_frequencies, *, trusted=None):
    """Transmissibility at ``at_frequencies``, linearly interpolated between trusted bins.

    A value comes only from two adjacent trusted bins (or one trusted bin at exactly
    that frequency); elsewhere it is NaN.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Strictly increasing, non-negative frequencies [Hz].
    magnitude : array_like, shape (n,)
        Transmissibility as amplitude ratio [-].
    at_frequencies : float or sequence of float
        Where to read the curve [Hz].
    trusted : array_like of bool, shape (n,), optional
        The bins that may be used (:attr:`TransmissibilityEstimate.trusted`); default all
        above 0 Hz.

    Returns
    -------
    ndarray
        One value [-] per frequency of ``at_frequencies``, NaN where undefined.
    """
    f, t, ok = _curve(frequency, magnitude, trusted)
    spots = np.atleast_1d(np.asarray(at_frequencies, dtype=float))
    return np.array([_spot(f, t, ok, float(at))[0] for at in spots])


def _describe(f, ok):
    idx = np.flatnonzero(ok)
    return f"{f[idx[0]]:.3g} to {f[idx[-1]]:.3g} Hz" if idx.size else "none"


def _resonance(f, t, ok, peak_min):
    """(index or None, reason) of the resonance peak over the trusted bins."""
    idx = np.flatnonzero(ok)
    i = int(idx[np.argmax(t[idx])])
    problems = []
    if i == 0:
        problems.append("is the curve's lowest bin")
    elif not ok[i - 1]:
        problems.append(f"borders untrusted bins below it ({f[i - 1]:.3g} Hz), where a peak "
                        "cannot be seen")
    if i == f.size - 1:
        problems.append("is the curve's highest bin")
    elif not ok[i + 1]:
        problems.append(f"borders untrusted bins above it ({f[i + 1]:.3g} Hz), where a peak "
                        "cannot be seen")
    if t[i] <= peak_min:
        problems.append(f"is not above {peak_min:.3g} (+{decibels(peak_min):.2g} dB), which "
                        "a payload moving with the base (T = 1: locked by stiction, or "
                        "overdamped) can show at the least trusted coherence")
    if problems:
        return None, (f"no resonance peak in the trusted bins: their maximum, T = {t[i]:.3g} at "
                      f"{f[i]:.3g} Hz, " + "; it ".join(problems))
    return i, ""


def _onset(f, t, ok):
    """(isolation onset [Hz], reason)."""
    nan = float("nan")
    idx = np.flatnonzero(ok)
    above_one = idx[t[idx] >= 1.0]
    if above_one.size == 0:
        if idx[0] == 0:
            return float(f[0]), ""
        return nan, (f"T < 1 over every trusted bin ({_describe(f, ok)}): the onset lies at or "
                     f"below {f[idx[0]]:.3g} Hz, where the curve is untrusted")
    j = int(above_one[-1])
    if j == idx[-1]:
        if j == f.size - 1:
            return nan, f"T >= 1 at the top of the curve ({f[j]:.3g} Hz): no isolation"
        return nan, (f"T >= 1 at the highest trusted bin ({f[j]:.3g} Hz); above it the curve is "
                     "untrusted")
    if not ok[j + 1]:
        return nan, (f"T falls below 1 after {f[j]:.3g} Hz, across untrusted bins up to "
                     f"{f[idx[np.searchsorted(idx, j) + 1]]:.3g} Hz")
    return _crossing(f, t, j, 1.0), ""


def _minus_3db(f, t, ok, i):
    """(-3 dB frequency [Hz], reason) above the resonance at index ``i``."""
    level = t[i] / np.sqrt(2.0)
    for k in range(i + 1, f.size):
        if not ok[k]:
            return float("nan"), (f"T has not fallen to peak/sqrt(2) = {level:.3g} before the "
                                  f"untrusted bin at {f[k]:.3g} Hz")
        if t[k] <= level:
            return _crossing(f, t, k - 1, level), ""
    return float("nan"), f"T stays above peak/sqrt(2) = {level:.3g} up to the top of the curve"


def transmissibility_metrics(frequency: ArrayLike, magnitude: ArrayLike, *,
                             trusted: ArrayLike | None = None,
                             at_frequencies: Sequence[float] = REPORTED_FREQUENCIES,
                             highpass_corner: float | None = None,
                             untrusted_factor: float = ANALYSIS["highpass_factor"],
                             rolloff_band: tuple[float, float] | None = None,
                             peak_min: float | None = None) -> TransmissibilityMetrics:
    """Resonance, isolation band, roll-off and spot values of a transmissibility curve.

    Every metric comes from trusted bins only: the DC bin is never used, nor bins
    outside ``trusted``, nor bins below ``untrusted_factor * highpass_corner``. A metric
    the trusted bins do not define is NaN, with the reason in
    :attr:`TransmissibilityMetrics.reasons`. Crossings are linearly interpolated
    between adjacent trusted bins, never across an untrusted one.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Strictly increasing, non-negative frequencies [Hz].
    magnitude : array_like, shape (n,)
        Transmissibility as amplitude ratio [-], non-negative; finite where trusted.
    trusted : array_like of bool, shape (n,), optional
        The bins that may be used (:attr:`TransmissibilityEstimate.trusted`); default
        every bin above 0 Hz (an exact curve).
    at_frequencies : sequence of float
        Frequencies [Hz] at which to report the transmissibility (:func:`transmissibility_at`).
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz]; bins below
        ``untrusted_factor * highpass_corner`` are untrusted (the paper: 1 Hz -> 1.5 Hz).
    untrusted_factor : float
        Multiple of the corner below which the curve is untrusted [-].
    rolloff_band : (float, float), optional
        Band [Hz] for the roll-off fit; default from twice the isolation onset to the top.
    peak_min : float, optional
        Least transmissibility of a resonance peak [-]; default
        ``1/sqrt(ANALYSIS["coherence_min"])`` (1.054, +0.46 dB): at the least trusted
        coherence the PSD ratio of a payload moving with the base (T = 1) can reach it.

    Returns
    -------
    TransmissibilityMetrics
        ``resonance_frequency``/``resonance_peak``: the maximum over the trusted bins, if
        it is a peak (both neighbours trusted and lower) above ``peak_min``;
        ``isolation_onset``: frequency above which T < 1 over the trusted bins (the
        first frequency if T < 1 everywhere and the first bin is trusted);
        ``minus_3db_frequency``: first frequency above resonance where T = peak / sqrt(2);
        ``rolloff_db_per_decade``: least-squares slope of 20 log10 T against log10 f over
        the trusted bins of the roll-off band (at least 3);
        ``untrusted_below``: ``untrusted_factor * highpass_corner``, or 0.

    Raises
    ------
    ParameterError
        Invalid curve or option.

    Warns
    -----
    DataWarning
        No bin of the curve is trusted: every metric is NaN.
    """
    f, t, ok = _curve(frequency, magnitude, trusted)
    corner = optional(positive_real)("highpass_corner", highpass_corner)
    factor = positive_real("untrusted_factor", untrusted_factor)
    peak_min = (1.0 / np.sqrt(ANALYSIS["coherence_min"]) if peak_min is None
                else positive_real("peak_min", peak_min))
    untrusted_below = 0.0 if corner is None else factor * corner
    ok = ok & (f >= untrusted_below)
    spots = np.atleast_1d(np.asarray(at_frequencies, dtype=float))
    if spots.ndim != 1 or not np.all(np.isfinite(spots)):
        raise ParameterError(f"`at_frequencies` must be a 1-D sequence of finite frequencies [Hz], "
                             f"got {at_frequencies!r}.")
    edges = None
    if rolloff_band is not None:
        edges = np.asarray(rolloff_band, dtype=float)
        if edges.shape != (2,) or not np.all(np.isfinite(edges)) or not 0 < edges[0] < edges[1]:
            raise ParameterError(f"`rolloff_band` must be (low, high) with 0 < low < high [Hz], "
                                 f"got {rolloff_band!r}.")

    nan = float("nan")
    values: dict[str, Any] = dict.fromkeys((
        "resonance_frequency", "resonance_peak", "isolation_onset", "minus_3db_frequency",
        "rolloff_db_per_decade"), nan)
    reasons = {}
    at = {}
    if not ok.any():
        reason = (f"no trusted bin in the curve ({f[0]:.3g} to {f[-1]:.3g} Hz): coherence too low, "
                  "base not excited" + (f" or below {untrusted_below:g} Hz (high-pass)"
                                        if untrusted_below else ""))
        warnings.warn(f"transmissibility metrics: {reason}; every metric is NaN", DataWarning,
                      stacklevel=2)
        reasons = dict.fromkeys(values, reason)
        at = {float(fa): nan for fa in spots}
        reasons.update({_spot_key(fa): reason for fa in at})
        return TransmissibilityMetrics(**values, at=MappingProxyType(at), untrusted_below=untrusted_below,
                                       reasons=MappingProxyType(reasons))

    i, reason = _resonance(f, t, ok, peak_min)
    if i is None:
        reasons["resonance_frequency"] = reasons["resonance_peak"] = reason
        reasons["minus_3db_frequency"] = "no resonance peak to fall from (see resonance_frequency)"
    else:
        values["resonance_frequency"], values["resonance_peak"] = float(f[i]), float(t[i])
        values["minus_3db_frequency"], reason = _minus_3db(f, t, ok, i)
        if reason:
            reasons["minus_3db_frequency"] = reason
    values["isolation_onset"], reason = _onset(f, t, ok)
    if reason:
        reasons["isolation_onset"] = reason

    if edges is None and not np.isfinite(values["isolation_onset"]):
        reasons["rolloff_db_per_decade"] = ("its band starts at twice the isolation onset, which is "
                                            "undefined (see isolation_onset)")
    else:
        low, high = (2.0 * values["isolation_onset"], f[-1]) if edges is None else edges
        band = band_mask(f, low, high) & ok & (t > 0)
        if np.count_nonzero(band) >= 3:
            values["rolloff_db_per_decade"] = rolloff_slope(f[band], t[band])
        else:
            reasons["rolloff_db_per_decade"] = (f"{np.count_nonzero(band)} trusted bin(s) in the "
                                                f"roll-off band [{low:.3g}, {high:.3g}] Hz; a fit "
                                                "needs 3")
    for fa in spots:
        at[float(fa)], reason = _spot(f, t, ok, float(fa), untrusted_below)
        if reason:
            reasons[_spot_key(float(fa))] = reason
    idx = np.flatnonzero(ok)
    return TransmissibilityMetrics(**values, at=MappingProxyType(at), untrusted_below=untrusted_below,
                                   reasons=MappingProxyType(reasons),
                                   trusted_range=(float(f[idx[0]]), float(f[idx[-1]])))
