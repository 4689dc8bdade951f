"""Tests of qzs.spectral against closed forms (no pinned numbers)."""
import math

import numpy as np
import pytest
from scipy import optimize, signal

from qzs.errors import DataError, ParameterError
from qzs.analysis.spectral import (
    amplitude_spectrum,
    required_duration,
    required_samples,
    rolloff_slope,
    transmissibility,
    transmissibility_metrics,
    welch_average_count,
)

SAMPLE_RATE = 100.0  # [Hz]
NATURAL_FREQUENCY = 2.0  # [Hz]
DAMPING_RATIO = 0.1


def sdof_response(frequency, natural_frequency=NATURAL_FREQUENCY, damping_ratio=DAMPING_RATIO):
    """Closed-form base-excitation transmissibility (c s + k) / (m s^2 + c s + k) at s = j w."""
    r = np.asarray(frequency, dtype=float) / natural_frequency
    return (1 + 2j * damping_ratio * r) / (1 - r**2 + 2j * damping_ratio * r)


def bilinear_analog_frequency(frequency, sample_rate=SAMPLE_RATE):
    """Analogue frequency [Hz] that the bilinear transform maps onto digital `frequency`."""
    return sample_rate / np.pi * np.tan(np.pi * np.asarray(frequency) / sample_rate)


def simulate_sdof(n_samples, payload_noise=0.0, seed=0):
    """White base acceleration through the bilinear-discretised SDOF filter."""
    mass, omega = 1.0, 2 * np.pi * NATURAL_FREQUENCY
    stiffness, damping = mass * omega**2, 2 * DAMPING_RATIO * mass * omega
    b, a = signal.bilinear([damping, stiffness], [mass, damping, stiffness], fs=SAMPLE_RATE)
    rng = np.random.default_rng(seed)
    settle = 2000
    base = rng.standard_normal(n_samples + settle)
    payload = signal.lfilter(b, a, base)[settle:] + payload_noise * rng.standard_normal(n_samples)
    return base[settle:], payload


@pytest.fixture(scope="module")
def clean_record():
    return simulate_sdof(required_samples(4096, 60))


@pytest.fixture(scope="module")
def noisy_record():
    return simulate_sdof(required_samples(4096, 150), payload_noise=0.05, seed=1)


# ---------------------------------------------------------------- estimators
@pytest.mark.parametrize("estimator", ["psd_ratio", "h1", "h2"])
def test_estimators_match_closed_form_of_linear_system(clean_record, estimator, validation):
    base, payload = clean_record
    estimate = transmissibility(base, payload, SAMPLE_RATE, fft_length=4096, estimator=estimator)
    band = (estimate.frequency > 0.3) & (estimate.frequency < 40.0)
    exact = sdof_response(bilinear_analog_frequency(estimate.frequency[band]))
    np.testing.assert_allclose(estimate.magnitude[band], np.abs(exact), rtol=0.03)
    validation(f"Welch estimate ({estimator}) of a 2 Hz, 10 % damped SDOF, 0.3-40 Hz",
               "(1 + 2j zeta r) / (1 - r^2 + 2j zeta r), bilinear-warped frequency",
               np.abs(estimate.magnitude[band] / np.abs(exact) - 1).max(), 0.03)
    assert np.all(estimate.coherence[band] > 0.97)
    assert estimate.estimator == estimator and estimate.n_averages == 60
    # every estimator carries the phase of S_bp (S_bb and S_pp are real)
    phase_error = np.angle(np.exp(1j * (estimate.phase[band] - np.angle(exact))))
    assert np.max(np.abs(phase_error)) < 0.03


def test_estimators_with_payload_noise_follow_their_bias_formulas(noisy_record):
    """Payload noise n: E[S_pp] = |H|^2 S_bb + S_nn, so H1 -> |H|, H2 -> |H| / coherence.

    Checked per bin, where coherence > 0.5, within 4 standard deviations of the Welch random
    error (Bendat & Piersol): sqrt((1 - g) / (2 n g)) for a response magnitude and
    sqrt(2 g) (1 - g) / sqrt(n) for the coherence g, n averages.
    """
    base, payload = noisy_record
    noise_ratio = 0.05**2  # S_nn / S_bb for white signals of variance 0.05^2 and 1
    estimates = {name: transmissibility(base, payload, SAMPLE_RATE, fft_length=4096, estimator=name)
                 for name in ("psd_ratio", "h1", "h2")}
    frequency = estimates["h1"].frequency
    band = (frequency > 0.3) & (frequency < 40.0)
    exact = np.abs(sdof_response(bilinear_analog_frequency(frequency[band])))
    coherence = exact**2 / (exact**2 + noise_ratio)
    expected = {"h1": exact, "h2": exact / coherence, "psd_ratio": np.sqrt(exact**2 + noise_ratio)}
    coherent = coherence > 0.5
    random_error = np.sqrt((1 - coherence) / (2 * estimates["h1"].n_averages * coherence))
    for name, estimate in estimates.items():
        relative = estimate.magnitude[band] / expected[name] - 1
        assert np.all(np.abs(relative[coherent]) < 0.02 + 4 * random_error[coherent]), name
    # where payload noise matters, H2 and the PSD ratio are biased up and H1 is not
    noisy = coherent & (coherence < 0.8)
    assert abs(np.median(estimates["h1"].magnitude[band][noisy] / exact[noisy]) - 1) < 0.03
    assert np.median(estimates["h2"].magnitude[band][noisy] / exact[noisy]) > 1.15
    assert np.median(estimates["psd_ratio"].magnitude[band][noisy] / exact[noisy]) > 1.05
    assert np.median(np.abs(estimates["h1"].coherence[band] - coherence)) < 0.02
    coherence_error = np.sqrt(2 * coherence) * (1 - coherence) / np.sqrt(estimates["h1"].n_averages)
    assert np.all(np.abs(estimates["h1"].coherence[band] - coherence)[coherent]
                  < 0.02 + 4 * coherence_error[coherent])


def test_sine_amplitude_on_bin_is_its_rms(validation):
    """As scipy's test_window_correction: a bin-centred sine shows A^2/2 of power, i.e. RMS A/sqrt(2)."""
    sample_rate, fft_length, amplitude, bin_index = 1000.0, 1024, 2.5, 50
    time = np.arange(8 * fft_length) / sample_rate
    tone = bin_index * sample_rate / fft_length
    frequency, rms = amplitude_spectrum(amplitude * np.sin(2 * np.pi * tone * time + 0.3), sample_rate,
                                        fft_length=fft_length)
    assert np.argmax(rms) == bin_index and frequency[bin_index] == pytest.approx(tone)
    assert rms[bin_index] == pytest.approx(amplitude / math.sqrt(2), rel=1e-9)
    validation("Amplitude spectrum of a bin-centred sine", "A / sqrt(2) (scipy's "
               "test_window_correction)", abs(rms[bin_index] / (amplitude / math.sqrt(2)) - 1),
               1e-9)


def test_sine_amplitude_between_bins_shows_window_scalloping(validation):
    sample_rate, fft_length, amplitude = 1000.0, 1024, 1.0
    tone = 50.5 * sample_rate / fft_length
    time = np.arange(16 * fft_length) / sample_rate
    _, rms = amplitude_spectrum(amplitude * np.sin(2 * np.pi * tone * time), sample_rate, fft_length=fft_length)
    window = signal.get_window("hann", fft_length)
    scalloping = abs(np.sum(window * np.exp(-1j * np.pi * np.arange(fft_length) / fft_length))) / window.sum()
    assert rms[50] == pytest.approx(amplitude / math.sqrt(2) * scalloping, rel=1e-3)
    validation("Amplitude spectrum of a sine between two bins", "A / sqrt(2) times the Hann "
               "window's scalloping loss", abs(rms[50] / (amplitude / math.sqrt(2) * scalloping)
                                              - 1), 1e-3)


# ---------------------------------------------------------------- run sizing
@pytest.mark.parametrize("fft_length, overlap", [(8, 0.5), (1000, 0.5), (4096, 0.0), (4096, 0.75), (999, 0.3)])
@pytest.mark.parametrize("n_averages", [1, 2, 29, 122])
def test_required_samples_round_trips_and_matches_scipy(fft_length, overlap, n_averages):
    n = required_samples(fft_length, n_averages, overlap)
    assert welch_average_count(n, fft_length, overlap) == n_averages
    assert welch_average_count(n - 1, fft_length, overlap) == n_averages - 1
    noverlap = int(round(overlap * fft_length))
    _, times, _ = signal.spectrogram(np.zeros(n + fft_length // 3), nperseg=fft_length, noverlap=noverlap)
    assert welch_average_count(n + fft_length // 3, fft_length, overlap) == times.size
    assert required_duration(fft_length, n_averages, 1000.0, overlap) == n / 1000.0


def test_required_duration_of_paper_simulation():
    step = 32768 - round(0.5 * 32768)
    assert required_duration(32768, 122, 1000.0) == pytest.approx((32768 + 121 * step) / 1000.0)


def test_n_averages_uses_start_of_record(clean_record):
    base, payload = clean_record
    for count in (1, 7, 60):
        estimate = transmissibility(base, payload, SAMPLE_RATE, fft_length=4096, n_averages=count)
        assert estimate.n_averages == count
        n = required_samples(4096, count)
        reference = transmissibility(base[:n], payload[:n], SAMPLE_RATE, fft_length=4096)
        np.testing.assert_array_equal(estimate.magnitude, reference.magnitude)


def test_result_object_repackages(clean_record):
    base, payload = clean_record
    estimate = transmissibility(base, payload, SAMPLE_RATE, fft_length=4096, estimator="h1", highpass_corner=1.0)
    dataset = estimate.to_xarray()
    assert dataset["frequency"].attrs["units"] == "Hz" and dataset["phase"].attrs["units"] == "rad"
    np.testing.assert_array_equal(dataset["magnitude"].values, estimate.magnitude)
    assert dataset.attrs["n_averages"] == estimate.n_averages and dataset.attrs["estimator"] == "h1"
    np.testing.assert_allclose(10 ** (estimate.magnitude_db()[1:] / 20), estimate.magnitude[1:])
    metrics = estimate.metrics()
    assert metrics.untrusted_below == 1.5
    exact_peak = transmissibility_metrics(estimate.frequency, np.abs(sdof_response(estimate.frequency)))
    assert metrics.resonance_frequency == pytest.approx(exact_peak.resonance_frequency, abs=0.1)
    with pytest.raises(TypeError):
        estimate.metrics(not_an_option=1)
    with pytest.raises(AttributeError):
        estimate.n_averages = 3


# ---------------------------------------------------------------- metrics
@pytest.fixture(scope="module")
def sdof_curve():
    frequency = np.linspace(0.0, 20.0, 20001)
    return frequency, np.abs(sdof_response(frequency))


def test_metrics_of_sdof_curve(sdof_curve, validation):
    frequency, magnitude = sdof_curve
    zeta, step = DAMPING_RATIO, frequency[1]
    metrics = transmissibility_metrics(frequency, magnitude)
    peak_ratio = math.sqrt(math.sqrt(1 + 8 * zeta**2) - 1) / (2 * zeta)  # d|T|/dr = 0
    peak_frequency = peak_ratio * NATURAL_FREQUENCY
    peak = abs(sdof_response(peak_frequency))
    assert metrics.resonance_frequency == pytest.approx(peak_frequency, abs=step)
    # the grid maximum is within half a step of the true peak (|T| is unimodal there)
    neighbours = abs(sdof_response(peak_frequency - step)), abs(sdof_response(peak_frequency + step))
    assert min(neighbours) <= metrics.resonance_peak <= peak
    # |T| = 1 at r = sqrt(2) whatever the damping
    assert metrics.isolation_onset == pytest.approx(math.sqrt(2) * NATURAL_FREQUENCY, abs=1e-4)
    half_power = optimize.brentq(lambda f: abs(sdof_response(f)) - peak / math.sqrt(2), peak_frequency, 20.0)
    assert metrics.minus_3db_frequency == pytest.approx(half_power, abs=1e-3)
    validation("Resonance frequency of an SDOF curve", "r = sqrt(sqrt(1 + 8 zeta^2) - 1)/(2 zeta)",
               abs(metrics.resonance_frequency - peak_frequency), step,
               measure="absolute error [Hz]")
    validation("Isolation onset of an SDOF curve", "|T| = 1 at r = sqrt(2), any damping",
               abs(metrics.isolation_onset - math.sqrt(2) * NATURAL_FREQUENCY), 1e-4,
               measure="absolute error [Hz]")
    validation("-3 dB frequency of an SDOF curve", "root of |T| = peak / sqrt(2) (brentq)",
               abs(metrics.minus_3db_frequency - half_power), 1e-3, measure="absolute error [Hz]")
    for f, value in metrics.at.items():
        assert value == pytest.approx(abs(sdof_response(f)), rel=1e-5)
    assert metrics.untrusted_below == 0.0


def test_metrics_roll_off_of_power_laws(validation):
    frequency = np.logspace(-1, 2, 300)
    for exponent in (1, 2, 3):
        metrics = transmissibility_metrics(frequency, frequency**-exponent)
        assert metrics.isolation_onset == pytest.approx(1.0, rel=1e-3)
        assert metrics.rolloff_db_per_decade == pytest.approx(-20.0 * exponent, rel=1e-9)
        validation(f"Roll-off of T = f^-{exponent}", f"{-20 * exponent} dB/decade",
                   abs(metrics.rolloff_db_per_decade / (-20.0 * exponent) - 1), 1e-9)
    # default band starts at twice the isolation onset: a -20 dB/decade stretch below it is left out
    broken = np.where(frequency < 2.0, 1.0 / frequency, 0.5 * (frequency / 2.0) ** -3)
    metrics = transmissibility_metrics(frequency, broken)
    assert metrics.isolation_onset == pytest.approx(1.0, rel=1e-3)
    assert metrics.rolloff_db_per_decade == pytest.approx(-60.0, rel=1e-9)
    lightly_damped = np.abs(sdof_response(frequency, 1.0, 1e-4))
    banded = transmissibility_metrics(frequency, lightly_damped, rolloff_band=(10.0, 100.0))
    assert banded.rolloff_db_per_decade == pytest.approx(-40.0, abs=0.2)


def test_rolloff_slope_of_a_power_law_is_20_db_per_decade_per_power():
    frequency = np.geomspace(2.0, 200.0, 50)
    for exponent in (0.5, 1.0, 2.0, 4.0):
        slope = rolloff_slope(frequency, 3.0 * frequency ** -exponent)
        assert type(slope) is float
        assert slope == pytest.approx(-20.0 * exponent, rel=1e-12)


def test_minus_3db_of_piecewise_linear_curve():
    frequency = np.array([0.0, 1.0, 5.0, 10.0, 12.0])
    magnitude = np.array([1.0, 1.0, 4.0, 0.0, 0.0])
    metrics = transmissibility_metrics(frequency, magnitude)
    assert metrics.resonance_frequency == 5.0 and metrics.resonance_peak == 4.0
    assert metrics.minus_3db_frequency == pytest.approx(10.0 - 5.0 / math.sqrt(2))
    assert metrics.isolation_onset == pytest.approx(5.0 + 5.0 * 3.0 / 4.0)


def test_metrics_interpolate_and_flag_outside():
    frequency = np.linspace(0.5, 10.0, 20)
    metrics = transmissibility_metrics(frequency, 3.0 - 0.1 * frequency, at_frequencies=(0.2, 1.0, 3.3, 10.0, 16.0))
    assert metrics.at[1.0] == pytest.approx(2.9) and metrics.at[3.3] == pytest.approx(2.67)
    assert metrics.at[10.0] == pytest.approx(2.0)
    assert math.isnan(metrics.at[0.2]) and math.isnan(metrics.at[16.0])
    assert math.isnan(metrics.isolation_onset) and math.isnan(metrics.rolloff_db_per_decade)
    assert metrics.to_dict()["transmissibility_at_3.3_hz"] == metrics.at[3.3]


def test_untrusted_band_hides_highpass_artefact():
    frequency = np.linspace(0.0, 20.0, 2001)
    magnitude = np.abs(sdof_response(frequency)) + 10.0 * np.exp(-(((frequency - 0.5) / 0.1) ** 2))
    assert transmissibility_metrics(frequency, magnitude).resonance_frequency == pytest.approx(0.5, abs=0.05)
    trusted = transmissibility_metrics(frequency, magnitude, highpass_corner=1.0)
    assert trusted.untrusted_below == 1.5
    assert trusted.resonance_frequency == pytest.approx(NATURAL_FREQUENCY, abs=0.05)
    assert transmissibility_metrics(frequency, magnitude, highpass_corner=1.0, untrusted_factor=3).untrusted_below == 3


def test_isolated_everywhere_starts_at_first_bin():
    frequency = np.linspace(0.0, 10.0, 11)
    metrics = transmissibility_metrics(frequency, np.full(11, 0.5))
    assert metrics.isolation_onset == 1.0


# ---------------------------------------------------------------- bad input
GOOD = np.random.default_rng(2).standard_normal(256)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"fft_length": 4}, ParameterError, r"`fft_length` must be an integer >= 8, got 4"),
    ({"fft_length": 64.0}, ParameterError, r"`fft_length`.*got 64.0"),
    ({"fft_length": True}, ParameterError, r"`fft_length`.*got the boolean True"),
    ({"overlap": 1.0}, ParameterError, r"`overlap` must be a fraction in \[0, 1\), got 1.0"),
    ({"overlap": -0.1}, ParameterError, r"`overlap`.*got -0.1"),
    ({"estimator": "h3"}, ParameterError, r"`estimator` must be one of .*got 'h3'"),
    ({"sample_rate": 0.0}, ParameterError, r"`sample_rate` must be positive, got 0.0"),
    ({"sample_rate": float("nan")}, ParameterError, r"`sample_rate`.*nan"),
    ({"n_averages": 0}, ParameterError, r"`n_averages` must be an integer >= 1, got 0"),
    ({"highpass_corner": -1.0}, ParameterError, r"`highpass_corner`.*got -1.0"),
    ({"payload": GOOD[:-1]}, DataError, r"`base` and `payload` must have the same length, got 256 and 255"),
    ({"base": np.where(np.arange(256) % 50 == 0, np.nan, GOOD)}, DataError, r"`base` has 6 non-finite"),
    ({"payload": GOOD.reshape(16, 16)}, DataError, r"`payload` must be a 1-D.*\(16, 16\)"),
    ({"fft_length": 512}, DataError, r"needs at least 512 samples \(5.12 s at 100 Hz\), got 256"),
    ({"fft_length": 64, "n_averages": 8}, DataError, r"n_averages=8 .*needs at least 288 samples \(2.88 s"),
])
def test_transmissibility_rejects_bad_input(kwargs, error, match):
    arguments = {"base": GOOD, "payload": GOOD, "sample_rate": 100.0, "fft_length": 64} | kwargs
    with pytest.raises(error, match=match):
        transmissibility(arguments.pop("base"), arguments.pop("payload"), arguments.pop("sample_rate"), **arguments)


def test_transmissibility_rejects_unknown_keyword():
    with pytest.raises(TypeError):
        transmissibility(GOOD, GOOD, 100.0, nperseg=64)


FREQUENCY = np.linspace(0.0, 10.0, 11)


@pytest.mark.parametrize("frequency, magnitude, kwargs, match", [
    (FREQUENCY, np.ones(10), {}, r"same shape, got \(11,\) and \(10,\)"),
    (FREQUENCY[::-1], np.ones(11), {}, r"strictly increasing"),
    (np.where(FREQUENCY == 3, np.nan, FREQUENCY), np.ones(11), {}, r"`frequency` must be finite"),
    (FREQUENCY, np.where(FREQUENCY == 3, np.nan, 1.0), {}, r"`magnitude` has 1 non-finite"),
    (FREQUENCY, np.where(FREQUENCY == 3, -0.5, 1.0), {}, r"non-negative.*-0.5"),
    (FREQUENCY[:2], np.ones(2), {}, r"at least 2 points above 0 Hz, got 1"),
    (FREQUENCY, np.ones(11), {"rolloff_band": (5.0, 2.0)}, r"`rolloff_band`.*\(5.0, 2.0\)"),
    (FREQUENCY, np.ones(11), {"rolloff_band": (1.0,)}, r"`rolloff_band`"),
    (FREQUENCY, np.ones(11), {"highpass_corner": 0.0}, r"`highpass_corner`.*got 0.0"),
    (FREQUENCY, np.ones(11), {"untrusted_factor": -1}, r"`untrusted_factor`.*got -1"),
    (FREQUENCY, np.ones(11), {"at_frequencies": (1.0, np.inf)}, r"`at_frequencies`"),
])
def test_metrics_reject_bad_input(frequency, magnitude, kwargs, match):
    with pytest.raises(ParameterError, match=match):
        transmissibility_metrics(frequency, magnitude, **kwargs)


@pytest.mark.parametrize("call, match", [
    (lambda: welch_average_count(-1, 64, 0.5), r"`n_samples`"),
    (lambda: required_samples(64, 0), r"`n_averages` must be an integer >= 1, got 0"),
    (lambda: required_samples(64, 2, overlap=0.999), r"`overlap`=0.999 leaves no step"),
    (lambda: required_duration(64, 2, -5.0), r"`sample_rate`.*-5.0"),
    (lambda: amplitude_spectrum(GOOD, 100.0, fft_length=512), r"needs at least 512 samples"),
])
def test_sizing_helpers_reject_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_to_dict_gives_each_nan_its_reason():
    """The README's promise: the metrics' dict says why a value is NaN, in the dict itself."""
    import pickle

    from qzs.analysis.spectral import UndefinedValue, transmissibility_metrics

    f = np.linspace(0.0, 20.0, 401)
    magnitude = 1.0 / np.abs(1 - (f / 3.0) ** 2 + 0.2j * f / 3.0)
    trusted = f >= 8.0  # only above the resonance: no peak, no onset of isolation
    metrics = transmissibility_metrics(f, magnitude, trusted=trusted, at_frequencies=(1.0, 10.0))
    record = metrics.to_dict()
    undefined = [name for name, value in record.items() if math.isnan(value)]
    assert "resonance_frequency" in undefined and "transmissibility_at_1_hz" in undefined
    assert not math.isnan(record["transmissibility_at_10_hz"])
    for name in undefined:
        value = record[name]
        assert isinstance(value, UndefinedValue) and value.reason == metrics.reason(name) != ""
        assert value.reason in repr(record)  # printed, the dict says why
        assert str(value) == "nan" and f"{value:.3g}" == "nan"  # tables stay as they were
        again = pickle.loads(pickle.dumps(value))
        assert math.isnan(again) and again.reason == value.reason
    for name in set(record) - set(undefined):
        assert type(record[name]) is float or not isinstance(record[name], UndefinedValue)
    assert np.isnan(np.array(list(record.values()), dtype=float)).sum() == len(undefined)
