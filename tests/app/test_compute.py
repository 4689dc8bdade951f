"""The tuning page's logic without a browser: qzs.app.compute, what the page shows as data.

Reference checks: the page's transmissibility is what ``qzs.transmissibility`` gives for
the same run, its linear curve what ``qzs.linearize`` gives, its errors the API's own, its
TOML export what ``qzs.iotools.load_config`` reads back to the same parameters.

Properties that fail if the page's numbers are wrong: its Welch segment length is the longest
power of two (256 to 32768) whose half-overlapping segments number at least 24, counted
here as scipy's Welch counts them (``1 + (n - L) // (L/2)``), and the estimate averages
that many; its locked shares, strokes and motor peak are those of ``qzs.simulate`` runs of
the same sine and chirp at the page's steps, each under its own name ("sine" the
time-response sine, "excitation" the chirp, or the stepped sine's mean over its
frequencies).
"""
import dataclasses
import math

import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters, linearize, simulate, transmissibility
from qzs.app import compute
from qzs.app.compute import (LIMITS, MAX_STEPS, PAGE_DEFAULTS, PageRequest, SizeLimitError,
                             compute_page, config_text, page_request, page_values, welch_length)
from qzs.errors import ExcitationError, ParameterError
from qzs.iotools.config import load_config
from qzs.model.excitation import build_excitation
from qzs.model.registry import PARAMETERS


@pytest.fixture(scope="module")
def stepped_page():
    return compute_page(page_request({"excitation.kind": "stepped", "frequency_count": 4,
                                      "excitation.f0": 1.0, "excitation.f1": 8.0}))


# ---------------------------------------------------------------- the figures' data
def test_transmissibility_is_the_api_estimate_of_the_same_run(default_page):
    """The page's curve: qzs.transmissibility of qzs.simulate at the page's step, the
    trusted bins and nothing else."""
    request = default_page.request
    result = simulate(request.chirp(), request.isolator, request.controller,
                      dt=default_page.dt, sample_rate=request.sample_rate)
    estimate = transmissibility(result.base_acceleration, result.payload_acceleration,
                                request.sample_rate, fft_length=welch_length(len(result)))
    np.testing.assert_array_equal(default_page.frequency, estimate.frequency[estimate.trusted])
    np.testing.assert_allclose(default_page.transmissibility_db,
                               20 * np.log10(estimate.magnitude[estimate.trusted]), rtol=0,
                               atol=1e-12)
    assert 0 < default_page.frequency.size < estimate.frequency.size  # untrusted bins left out
    assert default_page.estimate.trusted.sum() == default_page.frequency.size


def test_linear_curve_is_the_linearised_loop(default_page):
    request = default_page.request
    expected = linearize(request.isolator, request.controller).transmissibility(
        default_page.linear_frequency)
    np.testing.assert_allclose(default_page.linear_db, 20 * np.log10(expected), atol=1e-12)
    assert default_page.linear_frequency[-1] == pytest.approx(request.band[1])


def test_default_page_uses_the_accuracy_driven_step(default_page):
    """The default chirp's step is chosen for 0.01 dB: 1 ms, far inside the tolerance."""
    assert default_page.dt == pytest.approx(1e-3)
    assert default_page.step_error < 0.01 / 2
    assert default_page.notes == ()


def test_time_traces_and_limits(default_page):
    request, data = default_page.request, default_page
    for name, (time_, values) in data.traces.items():
        assert time_.size == values.size <= compute.TRACE_POINTS, name
        assert time_[-1] == pytest.approx(request.sine_duration)
    base = data.traces["base_displacement"][1]
    assert np.max(np.abs(base)) == pytest.approx(request.amplitude, rel=1e-3)
    assert data.traces["payload_displacement"][1][0] == 0.0  # from its rest position
    assert data.stop_low < data.position_setpoint < data.stop_high
    assert data.stop_high - data.stop_low == pytest.approx(2 * request.isolator.stroke_half)
    assert data.motor_force_max == request.isolator.motor_force_max
    for share in data.locked_share.values():
        assert 0.0 <= share <= 1.0
    assert data.summary["peak_stroke"] > 0


def test_stepped_sine_points_are_the_workflow_response(stepped_page):
    response = stepped_page.response
    branch = response.branch("up")
    np.testing.assert_allclose(branch["frequency"], np.geomspace(1.0, 8.0, 4))
    keep = np.isfinite(branch["transmissibility"])
    np.testing.assert_array_equal(stepped_page.frequency, branch["frequency"][keep])
    np.testing.assert_allclose(stepped_page.transmissibility_db,
                               20 * np.log10(branch["transmissibility"][keep]))
    assert stepped_page.estimate is None
    assert math.isnan(stepped_page.summary["motor_force_peak"])


def test_stepped_frequencies_from_zero_exclude_zero():
    request = page_request({"excitation.kind": "stepped", "frequency_count": 4,
                            "excitation.f0": 0.0, "excitation.f1": 8.0})
    np.testing.assert_allclose(request.stepped_frequencies(), [2.0, 4.0, 6.0, 8.0])


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize("values, same_as", [
    ({"coulomb_force": 20.0}, lambda: IsolatorParameters(coulomb_force=20.0)),
    ({"mass": -1.0}, lambda: IsolatorParameters(mass=-1.0)),
    ({"pi_kp": "a lot"}, lambda: ControllerParameters(pi_kp="a lot")),
    ({"excitation.amplitude": -0.01}, lambda: build_excitation("chirp", {"amplitude": -0.01})),
])
def test_invalid_values_raise_the_api_error(values, same_as):
    """The page's message is the API's message, word for word."""
    with pytest.raises(ParameterError) as expected:
        same_as()
    with pytest.raises(type(expected.value)) as got:
        page_request(values)
    assert str(got.value) == str(expected.value)


def test_an_invalid_excitation_is_an_excitation_error():
    with pytest.raises(ExcitationError):
        page_request({"excitation.amplitude": math.nan})


def test_unknown_setting_is_refused():
    with pytest.raises(ParameterError, match="unknown page setting 'excitation.phase'"):
        page_request({"excitation.phase": 1.0})
    with pytest.raises(ParameterError, match="unknown page setting 'stiction'"):
        page_request({"stiction": 1.0})  # not a registry name either
    assert page_request({"stroke_half": 0.05}).isolator.stroke_half == 0.05  # any registry name


@pytest.mark.parametrize("name, value", [
    ("excitation.duration", 601.0), ("excitation.duration", 5.0), ("frequency_count", 41),
    ("sine.duration", 61.0), ("sine.frequency", 51.0), ("sample_rate", 4000.0),
    ("excitation.f1", 60.0),
])
def test_size_limits_refuse_oversize_requests(name, value):
    with pytest.raises(SizeLimitError) as error:
        page_request({name: value})
    low, high, unit = LIMITS[name]
    assert (error.value.name, error.value.value) == (name, value)
    assert (error.value.low, error.value.high, error.value.unit) == (low, high, unit)
    assert "qzs simulate" in str(error.value)


def test_the_limits_hold_at_their_edges():
    page_request({"excitation.duration": LIMITS["excitation.duration"][1],
                  "frequency_count": LIMITS["frequency_count"][1]})


def test_sample_rate_must_resolve_the_band(monkeypatch):
    page_request({"sample_rate": 250.0, "excitation.f1": 50.0})  # 5 samples per period
    monkeypatch.setitem(LIMITS, "excitation.f1", (0.0, 100.0, "Hz"))
    with pytest.raises(ParameterError, match="at least 5 times"):
        page_request({"sample_rate": 250.0, "excitation.f1": 60.0})
    with pytest.raises(ParameterError, match="must be one of"):
        page_request({"sample_rate": 750.0})


def test_step_bound_refuses_a_run_too_long(monkeypatch):
    """The integration steps are bounded after the step is chosen."""
    monkeypatch.setattr(compute, "MAX_STEPS", 1000)
    with pytest.raises(SizeLimitError) as error:
        compute_page(page_request())
    assert error.value.name == "integration steps of the chirp"
    assert error.value.value == pytest.approx(PAGE_DEFAULTS["excitation.duration"] / 1e-3)
    assert MAX_STEPS >= 600 / 1e-4  # the longest chirp at the paper's step fits the default


def test_request_is_frozen_and_keyword_only():
    request = page_request()
    with pytest.raises(dataclasses.FrozenInstanceError):
        request.amplitude = 1.0
    with pytest.raises(TypeError):
        PageRequest(IsolatorParameters(), ControllerParameters())


def test_page_values_round_trip():
    values = page_values()
    assert page_request(values) == page_request()
    for name in compute.MODEL_PARAMETERS:
        if name != compute.COMPENSATION:
            assert values[name] == PARAMETERS[name].default  # the registry's defaults
    assert values[compute.COMPENSATION] == 0.0  # none: no block
    changed = page_request({**values, "stiction_force": 5.0, "excitation.kind": "stepped",
                            compute.COMPENSATION: 0.6})
    assert changed.controller.compensation.fraction == 0.6
    assert page_request(page_values(changed)) == changed


# ---------------------------------------------------------------- TOML export
@pytest.mark.parametrize("kind", ["chirp", "stepped"])
def test_toml_export_round_trips_through_load_config(tmp_path, kind):
    request = page_request({"stiction_force": 7.25, "pi_kp": 33.0, "damping_gain": 12.5,
                            "controller_rate": 1000.0, "excitation.kind": kind,
                            "excitation.f1": 15.0, "excitation.amplitude": 0.004})
    path = tmp_path / "page.toml"
    path.write_text(config_text(request, dt=5e-4), encoding="utf-8")
    config = load_config(path)
    assert config["isolator"] == request.isolator
    assert config["controller"] == request.controller
    options = dict(config["excitation"])
    kind_read = options.pop("kind")
    excitation = build_excitation(kind_read, options)
    assert excitation == (request.chirp() if kind == "chirp" else request.sine())
    assert config["simulation"]["dt"] == 5e-4
    assert config["simulation"]["sample_rate"] == request.sample_rate


def test_toml_export_runs_with_qzs_simulate(tmp_path):
    path = tmp_path / "page.toml"
    request = page_request({"stiction_force": 6.0, "excitation.duration": 10.0})
    path.write_text(config_text(request, dt=1e-3), encoding="utf-8")
    from qzs.cli import main

    assert main(["simulate", "--config", str(path), "--plot", "none", "--quiet"]) == 0


# ---------------------------------------------------------------- the page's numbers
def welch_segments(samples, length):
    """Half-overlapping segments of ``length`` in ``samples``, as scipy.signal.welch takes
    them (the last partial segment dropped)."""
    return 0 if samples < length else 1 + (samples - length) // (length // 2)


def test_welch_length_is_the_longest_power_of_two_with_24_segments():
    """docs/app.md: segments of about 1/24 of the run, a power of two, at most the paper's
    32768; at least 256 however short the run. Checked on both sides of every boundary."""
    powers = [2 ** k for k in range(8, 16)]
    samples = [n for length in powers for n in (25 * length // 2 - 1, 25 * length // 2,
                                                25 * length // 2 + 1, 40 * length)]
    samples += [1000, 200_001, 10 ** 7]
    for n in samples:
        fitting = [length for length in powers if welch_segments(n, length) >= 24]
        assert welch_length(n) == (max(fitting) if fitting else 256), n


@pytest.fixture(scope="module")
def default_runs(default_page):
    """The default page's chirp and sine, run by qzs.simulate at the page's steps."""
    request = default_page.request
    chirp = simulate(request.chirp(), request.isolator, request.controller,
                     dt=default_page.dt, sample_rate=request.sample_rate)
    sine = simulate(request.sine(), request.isolator, request.controller,
                    duration=request.sine_duration, dt=default_page.sine_dt,
                    sample_rate=request.sample_rate)
    return chirp, sine


def test_the_chirps_estimate_averages_24_segments_or_more(default_page, default_runs):
    chirp, _ = default_runs
    estimate = default_page.estimate
    assert estimate.fft_length == 8192  # docs/app.md, for the default 200 s at 1 kHz
    assert welch_segments(len(chirp), 8192) >= 24 > welch_segments(len(chirp), 16384)
    assert estimate.n_averages == welch_segments(len(chirp), estimate.fft_length)


def test_locked_shares_and_summary_are_the_runs_own(default_page, default_runs):
    """Each share is the mean of that run's ``locked`` flag; the two differ (10.2 % and
    10.3 %), so shares given to the wrong run fail."""
    chirp, sine = default_runs
    shares = default_page.locked_share
    assert shares["sine"] == np.mean(sine["locked"])
    assert shares["excitation"] == np.mean(chirp["locked"])
    assert shares["sine"] != shares["excitation"]
    center = 0.5 * (chirp.run["stop_low"] + chirp.run["stop_high"])
    summary = default_page.summary
    assert summary["peak_stroke"] == np.max(np.abs(chirp.relative_position - center))
    assert summary["sine_peak_stroke"] == np.max(np.abs(sine.relative_position - center))
    assert summary["motor_force_peak"] == np.max(np.abs(chirp.motor_force))
    assert summary["sine_motor_force_peak"] == np.max(np.abs(sine.motor_force))
    assert summary["stop_contacts"] == chirp.run["stop_contacts"]
    # the time traces are the sine run's, not the chirp's
    assert default_page.traces["relative_position"][1].max() == sine.relative_position.max()


def test_a_stepped_sines_locked_share_is_the_mean_over_its_frequencies(stepped_page):
    """docs/app.md: the stepped sine's share is the mean over its frequencies (here 1, 0.34,
    0 and 0: the mean, not the largest or the last)."""
    locked = stepped_page.response.branch("up")["locked_fraction"]
    assert np.ptp(locked) > 0.5
    assert stepped_page.locked_share["excitation"] == pytest.approx(np.mean(locked), rel=1e-12)

