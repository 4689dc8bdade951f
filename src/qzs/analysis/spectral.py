"""Transmissibility estimation and metrics for a base-excited isolator.

Pure numpy/scipy.signal: Welch spectra of base and payload acceleration, their ratio
(the paper's 'transmissibility', Section 4), and scalar metrics read off the curve.
Segments follow scipy's rule: ``step = fft_length - round(overlap * fft_length)`` and
``n_averages = (n_samples - noverlap) // step``.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

import numpy as np
from scipy import signal

from qzs._validation import finite_series, integer
from qzs.defaults import ANALYSIS, REPORTED_FREQUENCIES
from qzs.errors import DataError, ParameterError

__all__ = ["TransmissibilityEstimate", "TransmissibilityMetrics", "amplitude_spectrum", "band_mask",
           "highpass",
           "required_duration", "required_samples", "transmissibility",
           "transmissibility_metrics", "welch_average_count"]

ESTIMATORS = ("psd_ratio", "h1", "h2")
_MAGNITUDE_NAMES = {"psd_ratio": "amplitude ratio sqrt(S_payload / S_base)",
                    "h1": "|H1| = |S_base,payload| / S_base", "h2": "|H2| = S_payload / |S_payload,base|"}


# ---------------------------------------------------------------- validation
def _positive(name, value, allow_none=False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value) or value <= 0:
        raise ParameterError(f"`{name}` must be a positive finite number, got {value!r}.")
    return float(value)


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
    b, a = signal.bilinear([1.0, 0.0], [1.0, 2 * np.pi * corner], fs=sample_rate)
    return signal.lfilter(b, a, values)


def band_mask(frequency, low, high):
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

    Returns
    -------
    ndarray of bool
    """
    f = np.asarray(frequency, dtype=float)
    return (f > 0) & (f >= low) & (f <= high)


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
    return required_samples(fft_length, n_averages, overlap) / _positive("sample_rate", sample_rate)


# ---------------------------------------------------------------- estimation
@dataclass(frozen=True, eq=False)
class TransmissibilityEstimate:
    """Transmissibility from base to payload acceleration, one value per frequency bin.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Bin frequencies [Hz], from 0 to the Nyquist frequency.
    magnitude : ndarray, shape (n,)
        Amplitude ratio [-]; for ``psd_ratio`` it is ``sqrt(S_payload / S_base)``.
    phase : ndarray, shape (n,)
        Phase of payload relative to base [rad]; NaN for ``psd_ratio``.
    coherence : ndarray, shape (n,)
        Magnitude-squared coherence [-], 0..1.
    estimator : str
        ``"psd_ratio"``, ``"h1"`` or ``"h2"``.
    fft_length, n_averages : int
        Segment length [samples] and number of segments averaged.
    sample_rate : float
        Sample rate [Hz].
    highpass_corner : float or None
        Corner of a high-pass filter in the measurement chain [Hz], if any.
    """

    frequency: np.ndarray
    magnitude: np.ndarray
    phase: np.ndarray
    coherence: np.ndarray
    estimator: str
    fft_length: int
    n_averages: int
    sample_rate: float
    highpass_corner: float | None = None

    def magnitude_db(self):
        """Magnitude in decibels, ``20 * log10(magnitude)`` [dB] (-inf where it is 0)."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(self.magnitude)

    def metrics(self, **options):
        """Scalar metrics of this curve; keywords go to :func:`transmissibility_metrics`."""
        options.setdefault("highpass_corner", self.highpass_corner)
        return transmissibility_metrics(self.frequency, self.magnitude, **options)

    def to_xarray(self):
        """Repackage as an ``xarray.Dataset`` on coordinate ``frequency`` [Hz], with units attrs."""
        import xarray as xr

        name = _MAGNITUDE_NAMES[self.estimator]
        attrs = {"estimator": self.estimator, "fft_length": self.fft_length,
                 "n_averages": self.n_averages, "sample_rate": self.sample_rate}
        if self.highpass_corner is not None:
            attrs["highpass_corner"] = self.highpass_corner
        variables = {"magnitude": (self.magnitude, "1", f"transmissibility, {name}"),
                     "phase": (self.phase, "rad", "phase of payload relative to base"),
                     "coherence": (self.coherence, "1", "magnitude-squared coherence")}
        return xr.Dataset({key: ("frequency", values, {"units": units, "long_name": long_name})
                           for key, (values, units, long_name) in variables.items()},
                          coords={"frequency": ("frequency", self.frequency,
                                                {"units": "Hz", "long_name": "frequency"})},
                          attrs=attrs)


def transmissibility(base, payload, sample_rate, *, fft_length=ANALYSIS["fft_length"],
                     overlap=ANALYSIS["overlap"], window="hann",
                     n_averages=None, estimator="psd_ratio", detrend="constant", highpass_corner=None):
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
        ``psd_ratio``: ``sqrt(S_pp / S_bb)`` (the paper's definition, no phase);
        ``h1``: ``S_bp / S_bb`` (unbiased by payload noise);
        ``h2``: ``S_pp / S_pb`` (unbiased by base noise).
    detrend : str, callable or False
        Per-segment detrending, as in ``scipy.signal.welch``.
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz], recorded for the metrics.

    Returns
    -------
    TransmissibilityEstimate

    Raises
    ------
    ParameterError
        Invalid option.
    DataError
        Signals not 1-D, of different lengths, non-finite, or too short.
    """
    sample_rate = _positive("sample_rate", sample_rate)
    fft_length = integer("fft_length", fft_length, 8)
    noverlap = _noverlap(fft_length, overlap)
    highpass_corner = _positive("highpass_corner", highpass_corner, allow_none=True)
    if estimator not in ESTIMATORS:
        raise ParameterError(f"`estimator` must be one of {ESTIMATORS}, got {estimator!r}.")
    base, payload = _signal("base", base), _signal("payload", payload)
    if base.size != payload.size:
        raise DataError(f"`base` and `payload` must have the same length, "
                        f"got {base.size} and {payload.size}.")
    if n_averages is None:
        needed, what = fft_length, f"fft_length={fft_length}"
    else:
        needed = required_samples(fft_length, n_averages, overlap)
        what = f"n_averages={n_averages} with fft_length={fft_length} and overlap={overlap}"
    if base.size < needed:
        raise DataError(f"{what} needs at least {needed} samples ({needed / sample_rate:g} s at "
                        f"{sample_rate:g} Hz), got {base.size} ({base.size / sample_rate:g} s); "
                        f"record longer or reduce `fft_length`/`n_averages`.")
    if n_averages is not None:
        base, payload = base[:needed], payload[:needed]
    kw = dict(fs=sample_rate, window=window, nperseg=fft_length, noverlap=noverlap, detrend=detrend)
    with np.errstate(divide="ignore", invalid="ignore"):
        frequency, coherence = signal.coherence(base, payload, **kw)
        if estimator == "psd_ratio":
            s_bb, s_pp = signal.welch(base, **kw)[1], signal.welch(payload, **kw)[1]
            magnitude = np.sqrt(np.divide(s_pp, s_bb, out=np.full_like(s_pp, np.nan), where=s_bb > 0))
            phase = np.full_like(magnitude, np.nan)
        else:
            if estimator == "h1":
                numerator, denominator = signal.csd(base, payload, **kw)[1], signal.welch(base, **kw)[1]
            else:
                numerator, denominator = signal.welch(payload, **kw)[1], signal.csd(payload, base, **kw)[1]
            response = np.divide(numerator, denominator, out=np.full(frequency.shape, np.nan, complex),
                                 where=np.abs(denominator) > 0)
            magnitude, phase = np.abs(response), np.angle(response)
    arrays = [np.asarray(a, dtype=float) for a in (frequency, magnitude, phase, np.clip(coherence, 0, 1))]
    for array in arrays:
        array.setflags(write=False)
    return TransmissibilityEstimate(*arrays, estimator=estimator, fft_length=fft_length,
                                    n_averages=welch_average_count(base.size, fft_length, overlap),
                                    sample_rate=sample_rate, highpass_corner=highpass_corner)


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
    sample_rate = _positive("sample_rate", sample_rate)
    fft_length = integer("fft_length", fft_length, 8)
    noverlap = _noverlap(fft_length, overlap)
    values = _signal("signal_values", signal_values)
    if values.size < fft_length:
        raise DataError(f"fft_length={fft_length} needs at least {fft_length} samples "
                        f"({fft_length / sample_rate:g} s at {sample_rate:g} Hz), got {values.size}.")
    frequency, power = signal.welch(values, fs=sample_rate, window=window, nperseg=fft_length,
                                    noverlap=noverlap, scaling="spectrum")
    return frequency, np.sqrt(power)


# ---------------------------------------------------------------- metrics
@dataclass(frozen=True)
class TransmissibilityMetrics:
    """Scalar metrics of a transmissibility curve; frequencies in [Hz], ratios [-].

    NaN marks a metric the curve does not define (see :func:`transmissibility_metrics`).

    Attributes
    ----------
    resonance_frequency : float
        Frequency of the maximum over the trusted band [Hz].
    resonance_peak : float
        Transmissibility at that maximum, an amplitude ratio [-].
    isolation_onset : float
        Frequency above which the transmissibility stays below 1 [Hz].
    minus_3db_frequency : float
        First frequency above resonance where the curve falls to ``peak / sqrt(2)`` [Hz].
    at : Mapping[float, float]
        Each requested frequency [Hz] -> the interpolated transmissibility [-].
    rolloff_db_per_decade : float
        Least-squares slope of ``20 log10 T`` against ``log10 f`` [dB/decade].
    untrusted_below : float
        Frequency below which the curve is untrusted [Hz]; 0 if all of it is trusted.
    """

    resonance_frequency: float
    resonance_peak: float
    isolation_onset: float
    minus_3db_frequency: float
    at: Mapping[float, float]
    rolloff_db_per_decade: float
    untrusted_below: float

    def to_dict(self):
        """Flat dict; ``at`` becomes keys ``transmissibility_at_<f>_hz``."""
        names = ("resonance_frequency", "resonance_peak", "isolation_onset", "minus_3db_frequency",
                 "rolloff_db_per_decade", "untrusted_below")
        out = {name: getattr(self, name) for name in names}
        out.update({f"transmissibility_at_{f:g}_hz": value for f, value in self.at.items()})
        return out


def _crossing(frequency, magnitude, j, level):
    """Frequency where bins j -> j+1 (magnitude[j] >= level > magnitude[j+1]) cross `level`."""
    fraction = (magnitude[j] - level) / (magnitude[j] - magnitude[j + 1])
    return float(frequency[j] + fraction * (frequency[j + 1] - frequency[j]))


def _curve(frequency, magnitude):
    """Validated (frequency, magnitude) without the DC bin."""
    f, t = np.asarray(frequency, dtype=float), np.asarray(magnitude, dtype=float)
    if f.ndim != 1 or f.shape != t.shape:
        raise ParameterError(f"`frequency` and `magnitude` must be 1-D of the same shape, "
                             f"got {f.shape} and {t.shape}.")
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ParameterError(f"`frequency` must be finite and non-negative [Hz], "
                             f"got {np.count_nonzero(~(f >= 0))} values that are not.")
    if np.any(np.diff(f) <= 0):
        k = int(np.flatnonzero(np.diff(f) <= 0)[0])
        raise ParameterError(f"`frequency` must be strictly increasing, got frequency[{k + 1}]={f[k + 1]:g} "
                             f"after frequency[{k}]={f[k]:g}; sort the curve first.")
    f, t = f[f > 0], t[f > 0]
    if f.size < 2:
        raise ParameterError(f"the curve needs at least 2 points above 0 Hz, got {f.size}.")
    bad = np.count_nonzero(~np.isfinite(t))
    if bad:
        raise ParameterError(f"`magnitude` has {bad} non-finite values above 0 Hz; drop those bins first.")
    if np.any(t < 0):
        raise ParameterError(f"`magnitude` must be non-negative (an amplitude ratio), got minimum {t.min():g}.")
    return f, t


def transmissibility_metrics(frequency, magnitude, *, at_frequencies=REPORTED_FREQUENCIES,
                             highpass_corner=None, untrusted_factor=1.5, rolloff_band=None):
    """Resonance, isolation band, roll-off and spot values of a transmissibility curve.

    The DC bin (frequency 0) is dropped before anything else. Crossings are linearly
    interpolated between bins.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Strictly increasing, non-negative frequencies [Hz].
    magnitude : array_like, shape (n,)
        Transmissibility as amplitude ratio [-], finite and non-negative.
    at_frequencies : sequence of float
        Frequencies [Hz] at which to report the transmissibility (NaN outside the curve).
    highpass_corner : float, optional
        High-pass corner of the measurement chain [Hz]; results below
        ``untrusted_factor * highpass_corner`` are untrusted (the paper: 1 Hz -> ~1.5 Hz).
    untrusted_factor : float
        Multiple of the corner below which the curve is untrusted.
    rolloff_band : (float, float), optional
        Band [Hz] for the roll-off fit; default from twice the isolation onset to the top.

    Returns
    -------
    TransmissibilityMetrics
        ``resonance_frequency``/``resonance_peak``: maximum over the trusted band;
        ``isolation_onset``: frequency above which T < 1 up to the top of the curve
        (the first frequency if T < 1 everywhere, NaN if T >= 1 at the top);
        ``minus_3db_frequency``: first frequency above resonance where T = peak / sqrt(2);
        ``rolloff_db_per_decade``: least-squares slope of 20 log10 T against log10 f;
        ``untrusted_below``: ``untrusted_factor * highpass_corner``, or 0.

    Raises
    ------
    ParameterError
        Invalid curve or option.
    """
    f, t = _curve(frequency, magnitude)
    corner = _positive("highpass_corner", highpass_corner, allow_none=True)
    factor = _positive("untrusted_factor", untrusted_factor)
    untrusted_below = 0.0 if corner is None else factor * corner
    spots = np.atleast_1d(np.asarray(at_frequencies, dtype=float))
    if spots.ndim != 1 or not np.all(np.isfinite(spots)):
        raise ParameterError(f"`at_frequencies` must be a 1-D sequence of finite frequencies [Hz], "
                             f"got {at_frequencies!r}.")

    nan = float("nan")
    resonance_frequency = resonance_peak = minus_3db = nan
    trusted = np.flatnonzero(f >= untrusted_below)
    if trusted.size:
        i = int(trusted[np.argmax(t[trusted])])
        resonance_frequency, resonance_peak = float(f[i]), float(t[i])
        below = np.flatnonzero(t[i:] <= resonance_peak / np.sqrt(2.0))
        if resonance_peak > 0 and below.size:
            minus_3db = _crossing(f, t, i + int(below[0]) - 1, resonance_peak / np.sqrt(2.0))
    above_one = np.flatnonzero(t >= 1.0)
    if above_one.size == 0:
        onset = float(f[0])
    elif above_one[-1] == f.size - 1:
        onset = nan
    else:
        onset = _crossing(f, t, int(above_one[-1]), 1.0)

    if rolloff_band is None:
        low, high = 2.0 * onset, f[-1]
    else:
        edges = np.asarray(rolloff_band, dtype=float)
        if edges.shape != (2,) or not np.all(np.isfinite(edges)) or not 0 < edges[0] < edges[1]:
            raise ParameterError(f"`rolloff_band` must be (low, high) with 0 < low < high [Hz], "
                                 f"got {rolloff_band!r}.")
        low, high = edges
    band = band_mask(f, low, high) & (t > 0)
    rolloff = nan
    if np.count_nonzero(band) >= 3:
        rolloff = float(np.polyfit(np.log10(f[band]), 20.0 * np.log10(t[band]), 1)[0])
    at = {float(fa): float(np.interp(fa, f, t, left=nan, right=nan)) for fa in spots}
    return TransmissibilityMetrics(resonance_frequency=resonance_frequency, resonance_peak=resonance_peak,
                                   isolation_onset=onset, minus_3db_frequency=minus_3db,
                                   at=MappingProxyType(at), rolloff_db_per_decade=rolloff,
                                   untrusted_below=untrusted_below)
