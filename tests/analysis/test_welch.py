"""Tests of qzs.analysis.welch: scipy's Welch spectra to the last bit, case by case."""
import numpy as np
import pytest
from scipy import signal

from qzs.analysis.welch import transmissibility_arrays, welch_spectra

SAMPLE_RATE = 100.0  # [Hz]
CASES = [(4096, 2048, "hann", "constant"), (1000, 333, ("tukey", 0.3), False),
         (2048, 0, "hann", "linear"), (255, 100, "hamming", "constant")]


def _signals(seed, shape):
    rng = np.random.default_rng(seed)
    base = rng.normal(size=shape)
    kernel = np.array([0.5, 0.3, 0.2])
    payload = (np.apply_along_axis(np.convolve, -1, base, kernel, "same")
               + 0.1 * rng.normal(size=shape))
    return base, payload


@pytest.mark.parametrize("fft_length, noverlap, window, detrend", CASES)
def test_welch_spectra_are_scipys_to_the_last_bit(fft_length, noverlap, window, detrend):
    """One STFT per signal gives scipy.signal.welch's and csd's spectra exactly."""
    base, payload = _signals(fft_length, 60_001)
    options = dict(fs=SAMPLE_RATE, window=window, nperseg=fft_length, noverlap=noverlap,
                   detrend=detrend)
    frequency, base_power, payload_power, cross = welch_spectra(
        base, payload, SAMPLE_RATE, window=window, fft_length=fft_length, noverlap=noverlap,
        detrend=detrend)
    expected_frequency, expected_base = signal.welch(base, **options)
    assert np.array_equal(frequency, expected_frequency)
    assert np.array_equal(base_power, expected_base)
    assert np.array_equal(payload_power, signal.welch(payload, **options)[1])
    assert np.array_equal(cross, signal.csd(base, payload, **options)[1])


@pytest.mark.parametrize("n_samples", [60_001, 4096 + 2 * 2048])  # 29 segments of 4096; 3
@pytest.mark.parametrize("fft_length, noverlap, window, detrend", CASES)
def test_each_row_of_a_population_gets_the_bits_of_its_own_call(fft_length, noverlap, window,
                                                                detrend, n_samples):
    """Rows transformed together, 2-D and 3-D: every spectrum the same bits as the row's
    own 1-D call (the cross spectrum's complex product is where a whole-array product
    would differ: numpy rounds its vector loop, its scalar remainder and its in-place loop
    differently)."""
    if n_samples < fft_length:
        pytest.skip("shorter than a segment")
    base, payload = _signals(n_samples, (2, 3, n_samples))
    options = dict(window=window, fft_length=fft_length, noverlap=noverlap, detrend=detrend)
    together = welch_spectra(base, payload, SAMPLE_RATE, **options)
    flat = welch_spectra(base.reshape(6, -1), payload.reshape(6, -1), SAMPLE_RATE, **options)
    for i, j in np.ndindex(2, 3):
        alone = welch_spectra(base[i, j], payload[i, j], SAMPLE_RATE, **options)
        assert np.array_equal(together[0], alone[0])
        for k in (1, 2, 3):
            assert together[k].shape == (2, 3) + alone[k].shape
            assert np.array_equal(together[k][i, j], alone[k])
            assert np.array_equal(flat[k][3 * i + j], alone[k])


@pytest.mark.parametrize("estimator", ["psd_ratio", "h1", "h2"])
def test_transmissibility_arrays_of_rows_are_each_rows_own(estimator):
    base, payload = _signals(7, (5, 20_000))
    options = dict(window="hann", fft_length=2048, noverlap=1024, detrend="constant",
                   estimator=estimator)
    together = transmissibility_arrays(base, payload, SAMPLE_RATE, **options)
    for i in range(5):
        alone = transmissibility_arrays(base[i], payload[i], SAMPLE_RATE, **options)
        for a, b in zip(together[1:], alone[1:]):
            assert np.array_equal(a[i], b, equal_nan=True)
        assert np.sum(alone[4]) == pytest.approx(1.0, rel=1e-12)  # the base's power shares
        assert alone[4][0] == 0.0
