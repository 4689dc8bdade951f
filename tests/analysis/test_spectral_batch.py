"""Tests of qzs.analysis.spectral.transmissibility_batch: each case's own estimate, bit for bit."""
import numpy as np
import pytest
from scipy import signal

from qzs.analysis.spectral import transmissibility, transmissibility_batch
from qzs.errors import DataError, ParameterError

SAMPLE_RATE = 100.0  # [Hz]
FIELDS = ("frequency", "magnitude", "phase", "coherence", "base_share", "trusted")


def sdof_population(natural_frequencies, damping_ratios, n_samples, seed=0):
    """White base acceleration through each case's bilinear-discretised SDOF filter
    (c s + k) / (m s^2 + c s + k), m = 1 kg; rows are cases."""
    rng = np.random.default_rng(seed)
    settle = 2000
    base = rng.standard_normal((len(damping_ratios), n_samples + settle))
    payload = np.empty_like(base)
    for i, (f_n, zeta) in enumerate(zip(natural_frequencies, damping_ratios)):
        omega = 2 * np.pi * f_n
        b, a = signal.bilinear([2 * zeta * omega, omega**2], [1.0, 2 * zeta * omega, omega**2],
                               fs=SAMPLE_RATE)
        payload[i] = signal.lfilter(b, a, base[i])
    return base[:, settle:], payload[:, settle:]


def assert_same(batch, single):
    for name in FIELDS:
        assert np.array_equal(getattr(batch, name), getattr(single, name), equal_nan=True), name
    for name in ("estimator", "fft_length", "n_averages", "sample_rate", "highpass_corner",
                 "coherence_min", "base_share_min", "highpass_factor"):
        assert getattr(batch, name) == getattr(single, name), name


@pytest.mark.parametrize("estimator", ["psd_ratio", "h1", "h2"])
@pytest.mark.parametrize("options", [
    {}, {"n_averages": 3}, {"highpass_corner": 0.5, "coherence_min": 0.5},
    {"window": ("tukey", 0.3), "detrend": False, "overlap": 0.3},
    {"detrend": "linear", "base_share_min": 1e-4}])
def test_every_case_of_random_signals_is_its_own_estimate_bit_for_bit(estimator, options):
    """Stronger than equal to round-off (1e-12): the same bits, whatever the options."""
    rng = np.random.default_rng(34)
    base = rng.normal(size=(9, 12_001))
    payload = np.cumsum(rng.normal(size=base.shape), axis=1) * 0.01 + 0.5 * base
    batch = transmissibility_batch(base, payload, SAMPLE_RATE, fft_length=1024,
                                   estimator=estimator, **options)
    assert len(batch) == 9
    for i in range(9):
        assert_same(batch[i], transmissibility(base[i], payload[i], SAMPLE_RATE, fft_length=1024,
                                               estimator=estimator, **options))
    assert all(estimate.frequency is batch[0].frequency for estimate in batch)
    with pytest.raises(ValueError, match="read-only"):
        batch[3].magnitude[0] = 0.0


def test_a_population_of_linear_isolators_gives_each_its_closed_form(validation):
    """Physical signals: 16 SDOF isolators (natural frequency 1-4 Hz, damping 5-40 %); the
    batched estimate of each is its own estimate to the bit and within 3 % of its closed
    form |(1 + 2j zeta r) / (1 - r^2 + 2j zeta r)| (bilinear-warped frequency) where coherent."""
    rng = np.random.default_rng(16)
    natural, damping = rng.uniform(1.0, 4.0, 16), rng.uniform(0.05, 0.4, 16)
    base, payload = sdof_population(natural, damping, 4096 + 59 * 2048)
    batch = transmissibility_batch(base, payload, SAMPLE_RATE, fft_length=4096)
    worst = 0.0
    for i, estimate in enumerate(batch):
        assert_same(estimate, transmissibility(base[i], payload[i], SAMPLE_RATE, fft_length=4096))
        assert estimate.n_averages == 60
        f = estimate.frequency
        band = (f > 0.3) & (f < 40.0)
        r = SAMPLE_RATE / np.pi * np.tan(np.pi * f[band] / SAMPLE_RATE) / natural[i]
        exact = np.abs((1 + 2j * damping[i] * r) / (1 - r**2 + 2j * damping[i] * r))
        assert np.all(estimate.coherence[band] > 0.97)
        worst = max(worst, np.max(np.abs(estimate.magnitude[band] / exact - 1)))
    assert worst < 0.03
    validation("Batched Welch estimate of 16 SDOF isolators, 0.3-40 Hz",
               "(1 + 2j zeta r) / (1 - r^2 + 2j zeta r), bilinear-warped frequency", worst, 0.03)


@pytest.mark.parametrize("base, payload, error, match", [
    (np.zeros(5000), np.zeros(5000), DataError, r"`base` must be a 2-D array, one series per row"),
    (np.zeros((3, 5000)), np.zeros((2, 5000)), DataError, r"same shape, got \(3, 5000\) and "
                                                          r"\(2, 5000\)"),
    (np.zeros((3, 500)), np.zeros((3, 500)), DataError, r"needs at least 1024 samples"),
    (np.zeros((3, 5000)), np.where(np.arange(3)[:, None] == 1, np.nan, np.zeros((3, 5000))),
     DataError, r"`payload` has non-finite .* in 1 of 3 rows \(\[1\]\); estimate those cases"),
])
def test_bad_populations_are_refused_naming_the_argument_and_the_cases(base, payload, error,
                                                                     match):
    with pytest.raises(error, match=match):
        transmissibility_batch(base, payload, SAMPLE_RATE, fft_length=1024)


def test_a_population_of_no_case_has_no_estimate():
    assert transmissibility_batch(np.zeros((0, 5000)), np.zeros((0, 5000)), SAMPLE_RATE,
                                  fft_length=1024) == ()


def test_bad_options_are_refused_as_for_one_case():
    signals = np.zeros((2, 5000))
    with pytest.raises(ParameterError, match="`estimator` must be one of"):
        transmissibility_batch(signals, signals, SAMPLE_RATE, fft_length=1024, estimator="h3")
    with pytest.raises(ParameterError, match="`overlap` must be a fraction"):
        transmissibility_batch(signals, signals, SAMPLE_RATE, fft_length=1024, overlap=1.0)
