"""Which bins of a transmissibility estimate are trusted, and metrics from those bins only.

The helper :func:`assert_metrics_from_trusted` is the check every metric must pass: a
finite metric is read between adjacent trusted bins (or on one), and the metrics do not
change when every untrusted bin's value is replaced by garbage.
"""
import math
import warnings

import numpy as np
import pytest
from scipy import signal

import qzs
from qzs.analysis.spectral import (band_mask, transmissibility, transmissibility_at,
                                   transmissibility_metrics, trusted_bins)
from qzs.defaults import ANALYSIS
from qzs.errors import DataWarning, ParameterError

SPOT_KEYS = ("transmissibility_at_",)


def _bracketed(f, ok, value):
    """``value`` [Hz] is a trusted bin or lies between two adjacent trusted bins."""
    k = int(np.searchsorted(f, value))
    if k < f.size and math.isclose(f[k], value, rel_tol=0, abs_tol=1e-12):
        return bool(ok[k])
    return 0 < k < f.size and bool(ok[k - 1] and ok[k])


def assert_metrics_from_trusted(frequency, magnitude, trusted, metrics, reasons,
                                recompute=None, seed=0):
    """Every finite metric comes from trusted bins; every NaN one has a reason.

    ``metrics`` and ``reasons`` are dicts (:meth:`TransmissibilityMetrics.to_dict`, its
    ``reasons``); ``recompute(magnitude)`` gives the metrics dict of another magnitude
    on the same bins and trust (default :func:`transmissibility_metrics`).
    """
    f, t, ok = (np.asarray(a) for a in (frequency, magnitude, trusted))
    assert not ok[f == 0].any(), "the DC bin is never trusted"
    for name, value in metrics.items():
        if name in ("untrusted_below", "trusted_from", "trusted_to"):
            continue
        if isinstance(value, float) and math.isnan(value):
            assert reasons.get(name), f"{name} is NaN without a reason"
            continue
        if name == "resonance_frequency":
            i = int(np.flatnonzero(f == value)[0])
            assert ok[i] and ok[i - 1] and ok[i + 1], f"resonance at untrusted {value} Hz"
            assert metrics["resonance_peak"] == t[i]
        elif name in ("isolation_onset", "minus_3db_frequency"):
            assert _bracketed(f, ok, value), f"{name} = {value} Hz is not between trusted bins"
        elif name.startswith(SPOT_KEYS):
            at = float(name[len("transmissibility_at_"):-len("_hz")])
            assert _bracketed(f, ok, at), f"{name} read from untrusted bins"
    rng = np.random.default_rng(seed)
    garbage = np.where(ok, t, rng.uniform(0.0, 1e6, t.size))
    garbage[f == 0] = rng.uniform(0.0, 1e6)
    if recompute is None:
        def recompute(values):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DataWarning)
                return transmissibility_metrics(f, values, trusted=ok).to_dict()
    again = recompute(garbage)
    for name, value in metrics.items():
        if name in again:
            np.testing.assert_equal(again[name], value, err_msg=f"{name} depends on untrusted bins")


# ---------------------------------------------------------------- the rule
def test_trusted_bins_rule():
    f = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
    coherence = np.array([1.0, 0.95, 0.89, 0.95, 0.95, 0.95])
    share = np.array([0.5, 0.1, 0.1, 1e-12, 0.1, 0.1])
    magnitude = np.array([1.0, 1.0, 1.0, 1.0, np.nan, 1.0])
    ok = trusted_bins(f, coherence, share, magnitude=magnitude)
    assert ok.tolist() == [False, True, False, False, False, True]
    ok = trusted_bins(f, coherence, share, highpass_corner=0.5, highpass_factor=1.5)
    assert ok.tolist() == [False, False, False, False, True, True]
    assert trusted_bins(f, coherence, share, coherence_min=0.8)[2]
    with pytest.raises(ParameterError, match="coherence_min"):
        trusted_bins(f, coherence, share, coherence_min=0.0)
    with pytest.raises(ParameterError, match="base_share_min"):
        trusted_bins(f, coherence, share, base_share_min=1.0)


def chirp_record(sample_rate=100.0, duration=400.0, noise=0.02, seed=4):
    """A 0-20 Hz constant-displacement chirp through a 2 Hz SDOF, payload noise added."""
    time = np.arange(0.0, duration, 1.0 / sample_rate)
    rate = 20.0 / duration
    phase = 2 * np.pi * 0.5 * rate * time ** 2
    base = -0.01 * (2 * np.pi * rate * time) ** 2 * np.sin(phase)  # ~ y'' of 0.01 sin(phase)
    omega, zeta = 2 * np.pi * 2.0, 0.1
    b, a = signal.bilinear([2 * zeta * omega, omega ** 2], [1.0, 2 * zeta * omega, omega ** 2],
                           fs=sample_rate)
    payload = signal.lfilter(b, a, base)
    payload = payload + noise * np.random.default_rng(seed).standard_normal(time.size)
    return base, payload, sample_rate


def test_low_frequency_artefact_is_untrusted_and_left_out():
    """Where the chirp puts almost no base acceleration, payload noise makes a huge ratio."""
    base, payload, rate = chirp_record()
    estimate = transmissibility(base, payload, rate, fft_length=2048)
    f, t = estimate.frequency, estimate.magnitude
    low = band_mask(f, 0.0, 0.5)
    assert t[low].max() > 5, "the artefact this test is about"
    assert not estimate.trusted[low & (t > 1.5)].any()
    assert not estimate.trusted[np.argmax(np.where(low, t, 0))]
    assert not estimate.trusted[0]
    assert np.all(estimate.coherence[estimate.trusted] >= ANALYSIS["coherence_min"])
    assert np.all(estimate.base_share[estimate.trusted] >= ANALYSIS["base_share_min"])
    assert estimate.base_share[0] == 0 and estimate.base_share[1:].sum() == pytest.approx(1.0)
    keep = band_mask(f, 0.0, 20.0)
    naive = transmissibility_metrics(f[keep], t[keep])  # every bin taken at its word
    assert naive.resonance_frequency < 0.5 and naive.resonance_peak > 5
    metrics = estimate.metrics()
    assert metrics.resonance_frequency == pytest.approx(2.0, abs=0.15)
    assert 3.0 < metrics.resonance_peak < 7.0
    assert_metrics_from_trusted(f, t, estimate.trusted, metrics.to_dict(), metrics.reasons)
    dataset = estimate.to_xarray()
    np.testing.assert_array_equal(dataset["trusted"].values.astype(bool), estimate.trusted)
    assert dataset.attrs["coherence_min"] == ANALYSIS["coherence_min"]


def test_thresholds_are_options():
    base, payload, rate = chirp_record()
    strict = transmissibility(base, payload, rate, fft_length=2048, coherence_min=0.999)
    loose = transmissibility(base, payload, rate, fft_length=2048, coherence_min=0.5)
    assert strict.trusted.sum() < loose.trusted.sum()
    assert np.all(strict.trusted <= loose.trusted)
    assert strict.coherence_min == 0.999


# ---------------------------------------------------------------- metrics, reasons
F = np.linspace(0.0, 10.0, 101)


def sdof(f, fn=2.0, zeta=0.1):
    r = np.asarray(f) / fn
    return np.abs((1 + 2j * zeta * r) / (1 - r ** 2 + 2j * zeta * r))


def test_metrics_ignore_whatever_the_untrusted_bins_hold():
    magnitude = sdof(F)
    trusted = F > 0
    trusted[(F > 0.2) & (F < 0.6)] = False
    trusted[(F > 6.0) & (F < 6.5)] = False
    metrics = transmissibility_metrics(F, magnitude, trusted=trusted)
    assert metrics.resonance_frequency == pytest.approx(1.9, abs=0.11)
    assert_metrics_from_trusted(F, magnitude, trusted, metrics.to_dict(), metrics.reasons)
    # NaN in untrusted bins is accepted when `trusted` says so
    holes = np.where(trusted, magnitude, np.nan)
    holes[0] = np.nan
    assert transmissibility_metrics(F, holes, trusted=trusted).to_dict() == pytest.approx(
        metrics.to_dict(), nan_ok=True)


def test_a_maximum_at_the_edge_of_the_trusted_bins_is_no_resonance():
    magnitude = sdof(F)
    trusted = (F >= 2.05)  # the peak (1.98 Hz) is just below the trusted bins
    metrics = transmissibility_metrics(F, magnitude, trusted=trusted)
    assert math.isnan(metrics.resonance_frequency) and math.isnan(metrics.resonance_peak)
    assert "borders untrusted bins below" in metrics.reasons["resonance_frequency"]
    assert math.isnan(metrics.minus_3db_frequency) and metrics.reasons["minus_3db_frequency"]
    assert metrics.trusted_range == (pytest.approx(2.1), 10.0)


def test_a_maximum_near_one_is_no_resonance():
    """A locked payload moves with the base: T = 1 within the PSD ratio's bias is no peak."""
    flat = np.where(F < 3.0, 1.03, 0.5)
    metrics = transmissibility_metrics(F, flat)
    assert math.isnan(metrics.resonance_frequency)
    assert "locked by stiction" in metrics.reasons["resonance_frequency"]
    bump = flat.copy()
    bump[15] = 1.2  # 1.5 Hz
    assert transmissibility_metrics(F, bump).resonance_frequency == pytest.approx(1.5)
    bump[15] = 1.05
    assert math.isnan(transmissibility_metrics(F, bump).resonance_frequency)


def test_crossings_are_never_interpolated_across_untrusted_bins():
    magnitude = sdof(F)
    onset = transmissibility_metrics(F, magnitude).isolation_onset  # sqrt(2) * 2 Hz
    trusted = F > 0
    trusted[(F > 2.7) & (F < 2.95)] = False
    metrics = transmissibility_metrics(F, magnitude, trusted=trusted)
    assert onset == pytest.approx(2.828, abs=5e-3)
    assert math.isnan(metrics.isolation_onset)
    assert "across untrusted bins" in metrics.reasons["isolation_onset"]
    assert "isolation onset" in metrics.reasons["rolloff_db_per_decade"]
    trusted = F > 0
    trusted[(F > 2.15) & (F < 3.5)] = False
    metrics = transmissibility_metrics(F, magnitude, trusted=trusted)
    assert math.isnan(metrics.minus_3db_frequency)
    assert "untrusted bin" in metrics.reasons["minus_3db_frequency"]


def test_spot_values_need_trusted_neighbours():
    magnitude = sdof(F)
    trusted = F > 0
    trusted[np.isclose(F, 4.0)] = False
    values = transmissibility_at(F, magnitude, [3.85, 4.0, 4.05, 12.0], trusted=trusted)
    assert np.isnan(values[1:]).all() and values[0] == pytest.approx(
        np.interp(3.85, F, magnitude))
    metrics = transmissibility_metrics(F, magnitude, trusted=trusted, at_frequencies=(4.0, 12.0))
    assert "untrusted bins" in metrics.reasons["transmissibility_at_4_hz"]
    assert "outside the curve" in metrics.reasons["transmissibility_at_12_hz"]
    below = transmissibility_metrics(F, magnitude, highpass_corner=1.0, at_frequencies=(1.0,))
    assert "high-pass" in below.reasons["transmissibility_at_1_hz"]


def test_no_trusted_bin_warns_and_gives_reasons():
    with pytest.warns(DataWarning, match="no trusted bin"):
        metrics = transmissibility_metrics(F, sdof(F), trusted=np.zeros(F.size, bool))
    values = metrics.to_dict()
    for name, value in values.items():
        if name != "untrusted_below":
            assert math.isnan(value) and "no trusted bin" in metrics.reason(name)
    with pytest.warns(DataWarning, match=r"no trusted bin in the band \[1, 2\] Hz"):
        assert not band_mask(F, 1.0, 2.0, trusted=F > 5).any()
    with pytest.raises(ParameterError, match="`trusted`"):
        transmissibility_metrics(F, sdof(F), trusted=np.ones(5, bool))


# ---------------------------------------------------------------- the README's example
@pytest.fixture(scope="module")
def readme_run():
    isolator = qzs.IsolatorParameters(stiction_force=5.0, stop_model="plastic")
    controller = qzs.ControllerParameters(pi_kp=20.0, pi_ki=5.0, damping_gain=30.0)
    return qzs.simulate(qzs.Sine(amplitude=0.005, frequency=3.0), isolator, controller,
                        duration=20.0, solver="rk4", sample_rate=2000.0)


def test_readme_example_gives_no_metric_from_an_untrusted_bin(readme_run):
    """A 3 Hz sine excites 3 Hz only: no resonance at 998 Hz, nothing read off leakage."""
    estimate = qzs.transmissibility(readme_run.base_acceleration,
                                    readme_run.payload_acceleration, sample_rate=2000.0,
                                    fft_length=4096)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        metrics = estimate.metrics()
    values = metrics.to_dict()
    assert not (values["resonance_frequency"] > 10.0)  # NaN, or near the 3 Hz tone
    assert not (values["resonance_peak"] > 10.0)
    trusted_f = estimate.frequency[estimate.trusted]
    assert trusted_f.size and trusted_f.min() > 1.0 and trusted_f.max() < 6.0
    assert values["transmissibility_at_3_hz"] == pytest.approx(
        np.interp(3.0, estimate.frequency, estimate.magnitude))
    assert_metrics_from_trusted(estimate.frequency, estimate.magnitude, estimate.trusted,
                                values, metrics.reasons)
