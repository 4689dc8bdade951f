"""Welch spectra and the transmissibility arrays of one record or of many at once.

The array arithmetic behind :func:`qzs.analysis.spectral.transmissibility` and
:func:`qzs.analysis.spectral.transmissibility_batch`, along the last axis of its inputs:
a 1-D record is one case, a 2-D array (cases x samples) a population, transformed by one
:class:`scipy.signal.ShortTimeFFT` (its window and PSD scale built once, every case's
segments in one call). A case's numbers are the same bits either way: the FFTs, the
segment means and the band sums run along the last axis, case by case.
No validation here: the callers in :mod:`qzs.analysis.spectral` check their input.
"""
import numpy as np

__all__ = ["welch_spectra", "transmissibility_arrays", "CASES_PER_BLOCK"]

#: Cases transformed at once. One ShortTimeFFT serves the whole population, but its arrays
#: are taken a few cases at a time: 256 cases of 60 s at 1 kHz in one block (100 MB per
#: complex array) took 3.1 s on the 2-core test machine, in blocks of 4 1.3 s, one case at
#: a time 1.8 s (16384-point segments, loaded machine; the bits are the same either way).
CASES_PER_BLOCK = 4


def welch_spectra(base, payload, sample_rate, *, window, fft_length, noverlap, detrend):
    """The Welch auto- and cross-spectra of two signals, from one STFT of each.

    ``scipy.signal.welch(base)``, ``welch(payload)`` and ``csd(base, payload)`` to the
    last bit (one-sided densities, mean over segments): the same
    :class:`scipy.signal.ShortTimeFFT` and the same arithmetic as ``csd``, but each
    signal's segments are transformed once instead of twice (``welch`` and ``csd`` each
    transform their own), which halves the cost of a transmissibility estimate.

    Parameters
    ----------
    base, payload : ndarray, shape (..., n)
        The signals (float) along the last axis, n >= ``fft_length``; leading axes
        (cases) are transformed together.
    sample_rate : float
        Sample rate [Hz].
    window : str, tuple or array_like
        As for ``scipy.signal.welch``.
    fft_length : int
        Segment and FFT length [samples].
    noverlap : int
        Samples shared by neighbouring segments.
    detrend : str, callable or False
        As for ``scipy.signal.welch``. Cases are transformed together with ``"constant"``
        or False, one after the other otherwise.

    Returns
    -------
    frequency : ndarray, shape (n_bins,)
        Bin frequencies [Hz].
    base_power, payload_power : ndarray, shape (..., n_bins)
        Power spectral densities [unit^2/Hz].
    cross : ndarray of complex, shape (..., n_bins)
        Cross-spectral density of base and payload [unit^2/Hz] (``csd(base, payload)``).
    """
    from scipy import signal  # on first use: importing scipy.signal takes about 0.9 s

    shape = base.shape
    if isinstance(window, (str, tuple)):
        win = signal.get_window(window, fft_length)
    else:
        win = np.asarray(window)
    hop = fft_length - noverlap
    transform = signal.ShortTimeFFT(win, hop, sample_rate, fft_mode="onesided",
                                    mfft=fft_length, scale_to="psd", phase_shift=None)
    options = dict(detr=None if detrend is False else detrend, p0=0,
                   p1=(base.shape[-1] - noverlap) // transform.hop, k_offset=fft_length // 2)
    if base.ndim == 1:
        return transform.f, *_spectra(transform, base, payload, options)
    base, payload = (x.reshape(-1, x.shape[-1]) for x in (base, payload))
    if detrend is False or (isinstance(detrend, str) and detrend == "constant"):
        blocks = [_spectra(transform, base[i:i + CASES_PER_BLOCK],
                           payload[i:i + CASES_PER_BLOCK], options)
                  for i in range(0, base.shape[0], CASES_PER_BLOCK)]
    else:  # scipy's linear detrend (least squares) or a caller's, of many segments at once,
        # is not each segment's own to the last bit: case by case
        blocks = [[spectrum[np.newaxis] for spectrum in _spectra(transform, b, p, options)]
                  for b, p in zip(base, payload)]
    return transform.f, *(np.concatenate([block[k] for block in blocks]).reshape(
        shape[:-1] + (-1,)) for k in range(3))


def _spectra(transform, base, payload, options):
    """Base, payload and cross spectra along the last axis, with ``transform``'s STFT."""
    stft_base = transform.stft_detrend(base, **options)  # shape (..., n_bins, n_segments)
    stft_payload = transform.stft_detrend(payload, **options)
    inner = slice(1, -1 if transform.mfft % 2 == 0 else None)  # one-sided: double all but DC
    spectra = []                                                # (and Nyquist)
    for product in (stft_base.real ** 2 + stft_base.imag ** 2,
                    stft_payload.real ** 2 + stft_payload.imag ** 2,
                    _cross(stft_payload, stft_base)):
        product[..., inner, :] *= 2
        spectra.append(product.mean(axis=-1) if product.shape[-1] > 1 else product[..., 0])
    return spectra


def _cross(stft_payload, stft_base):
    """``stft_payload * stft_base.conj()``, each case's product on its own, the same bits.

    numpy's complex product rounds differently in its vector loop, in the scalar code
    that takes the elements left over, and in the loop it runs when it reuses the
    conjugate's temporary array (arrays of 256 KiB or more): which element goes where
    depends on the whole array's size, so a case's bits would change with the number of
    cases. The product is the one-case expression, case by case.
    """
    if stft_base.ndim == 2:
        return stft_payload * stft_base.conj()
    shape = stft_base.shape[-2:]
    cases = [payload * base.conj()  # the one-case expression, as written above
             for payload, base in zip(stft_payload.reshape(-1, *shape),
                                      stft_base.reshape(-1, *shape))]
    return cases[0].reshape(stft_base.shape) if len(cases) == 1 else np.reshape(
        cases, stft_base.shape)


def _by_case(function, *arrays):
    """``function`` of each case (the last axis of ``arrays``), stacked: the same bits as one
    case's call whatever the number of cases (numpy reduces and multiplies a 2-D array's
    rows in another order than a row alone)."""
    if arrays[0].ndim == 1:
        return function(*arrays)
    rows = [function(*case) for case in zip(*(a.reshape(-1, a.shape[-1]) for a in arrays))]
    shape = arrays[0].shape[:-1] + rows[0].shape
    return rows[0].reshape(shape) if len(rows) == 1 else np.reshape(rows, shape)


def transmissibility_arrays(base, payload, sample_rate, *, window, fft_length, noverlap,
                            detrend, estimator):
    """A transmissibility estimate's arrays along the last axis of ``base`` and ``payload``.

    Parameters
    ----------
    base, payload : ndarray, shape (..., n)
        Base and payload acceleration (float, finite), n >= ``fft_length``.
    sample_rate : float
        Sample rate [Hz].
    fft_length : int
        Segment and FFT length [samples].
    window, noverlap, detrend
        As for :func:`welch_spectra`.
    estimator : {"psd_ratio", "h1", "h2"}
        As for :func:`qzs.analysis.spectral.transmissibility`.

    Returns
    -------
    frequency : ndarray, shape (n_bins,)
        Bin frequencies [Hz].
    magnitude, phase, coherence, base_share : ndarray, shape (..., n_bins)
        The amplitude ratio [-], the phase of the cross spectrum [rad], the
        magnitude-squared coherence [-] (0..1, 0 where undefined) and each bin's share of
        the base's power above 0 Hz [-] (0 at DC).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        # each spectrum once; the coherence is scipy.signal.coherence's own formula on them
        frequency, s_bb, s_pp, s_bp = welch_spectra(base, payload, sample_rate, window=window,
                                                    fft_length=fft_length, noverlap=noverlap,
                                                    detrend=detrend)
        coherence = np.abs(s_bp) ** 2 / s_bb / s_pp
        if estimator == "psd_ratio":
            magnitude = np.sqrt(np.divide(s_pp, s_bb, out=np.full_like(s_pp, np.nan),
                                          where=s_bb > 0))
            # S_bb and S_pp are real: H1 = S_bp/S_bb and H2 = S_pp/S_pb share the phase of S_bp
            phase = np.where(s_bb > 0, np.angle(s_bp), np.nan)
        else:
            if estimator == "h1":
                numerator, denominator = s_bp, s_bb
            else:
                from scipy import signal

                denominator = _by_case(lambda p, b: signal.csd(
                    p, b, fs=sample_rate, window=window, nperseg=fft_length, noverlap=noverlap,
                    detrend=detrend)[1], payload, base)
                numerator = s_pp
            response = np.divide(numerator, denominator,
                                 out=np.full(s_bp.shape, np.nan, complex),
                                 where=np.abs(denominator) > 0)
            magnitude, phase = np.abs(response), np.angle(response)
        # each case's sum on its own: numpy sums the rows of a 2-D array in another order
        total = _by_case(lambda power: np.sum(power[frequency > 0], keepdims=True), s_bb)
        share = np.divide(s_bb, total, out=np.zeros_like(s_bb), where=total > 0)
        base_share = np.where(frequency > 0, share, 0.0)
        coherence = np.nan_to_num(np.clip(coherence, 0, 1), nan=0.0)
    return frequency, magnitude, phase, coherence, base_share
