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
                             compute_page, config_text, law_slider_range, page_parameters,
                             page_request, page_values, welch_length)
from qzs.errors import ExcitationError, ParameterError
from qzs.iotools.config import load_config
from qzs.model.excitation import build_excitation
from qzs.model.registry import PARAMETERS, law_parameters
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring


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



# ---------------------------------------------------------------- a spring law (--spring)
OBLIQUE = ObliqueSpringQZS()
POLYNOMIAL = PolynomialSpring(coefficients=[62.78, -150.0, 0.0, -4000.0], center=-0.06)
TABLE = TabulatedSpring(positions=np.linspace(-0.14, 0.02, 17),
                        forces=62.78 - 150.0 * (np.linspace(-0.14, 0.02, 17) + 0.06))


def test_a_page_request_with_a_law_changes_that_law():
    """The spring.* values change the page's law, the tanh's fields stay the paper's, and
    the request's values name the law's parameters and read back to the same request."""
    request = page_request({"spring.vertical_stiffness": 150.0, "spring.preload": 60.0,
                            "stiction_force": 6.0}, spring=OBLIQUE)
    assert request.spring is OBLIQUE
    assert request.isolator == IsolatorParameters(
        stiction_force=6.0, spring=dataclasses.replace(OBLIQUE, vertical_stiffness=150.0,
                                                       preload=60.0))
    values = page_values(request)
    assert "spring_force" not in values and "spring_shape" not in values
    assert [n for n in values if n.startswith("spring.")] == list(law_parameters(OBLIQUE))
    assert values["spring.vertical_stiffness"] == 150.0 and values["spring.preload"] == 60.0
    assert page_request(values, spring=OBLIQUE) == request
    # a polynomial's coefficients, by power
    poly = page_request({"spring.c1": -120.0}, spring=POLYNOMIAL).isolator.spring
    np.testing.assert_array_equal(poly.coefficients, [62.78, -120.0, 0.0, -4000.0])
    # the page's start: the file's law as it is
    assert page_request(spring=TABLE).isolator.spring == TABLE
    assert page_parameters(TABLE) == tuple(n for n in compute.MODEL_PARAMETERS
                                           if n not in compute.TANH_PARAMETERS)


def test_a_tanh_law_sets_the_magsprings_sliders():
    """A TanhSpring file is the MagSpring with its numbers: the page keeps spring_force and
    spring_shape, starting at the file's values, and runs the tanh of the fields."""
    request = page_request({"spring_shape": 60.0}, spring=TanhSpring(plateau=55.0, shape=70.0))
    assert page_parameters(request.spring) == compute.MODEL_PARAMETERS
    assert request.isolator == IsolatorParameters(spring_force=55.0, spring_shape=60.0)
    assert page_values(request)["spring_force"] == 55.0


@pytest.mark.parametrize("law, values, named", [
    (OBLIQUE, {"spring.c3": 1.0}, "spring.c3"),            # not the oblique law's
    (TABLE, {"spring.center": -0.05}, "spring.center"),    # a table has none
    (OBLIQUE, {"spring_force": 50.0}, "spring_force"),     # the tanh's, with another law
    (None, {"spring.preload": 60.0}, "spring.preload"),    # no law: the MagSpring's page
    (OBLIQUE, {"spring.free_length": -0.1}, "spring.free_length"),  # the law's own check
])
def test_a_spring_value_the_law_refuses_is_a_page_error_naming_it(law, values, named):
    with pytest.raises(ParameterError, match=f"`{named}`") as error:
        page_request(values, spring=law)
    assert named in error.value.options


def test_a_request_whose_law_is_not_the_pages_is_refused():
    with pytest.raises(ParameterError, match="'tanh' spring law .* 'oblique' law"):
        PageRequest(isolator=IsolatorParameters(), controller=ControllerParameters(),
                    spring=OBLIQUE)
    with pytest.raises(ParameterError, match="`spring` must be a spring law"):
        page_request(spring="oblique")


def test_law_slider_ranges_lie_around_the_laws_values():
    """[0, 2x] where the law keeps the value >= 0 (the stiffnesses), x +- 50 % else, a zero
    coefficient +- m*g/h^k; each holds the law's value, its step a 1-2-5 number between a
    500th and a 200th of the span, its ends whole steps."""
    paper = IsolatorParameters()
    weight, h = paper.mass * paper.gravity, paper.stroke_half
    expected = {(OBLIQUE, "spring.vertical_stiffness"): (0.0, 400.0),
                (OBLIQUE, "spring.oblique_stiffness"): (0.0, 400.0),
                (OBLIQUE, "spring.free_length"): (0.09375, 0.28125),
                (OBLIQUE, "spring.horizontal_distance"): (0.0625, 0.1875),
                (OBLIQUE, "spring.center"): (-0.09, -0.03),
                (OBLIQUE, "spring.preload"): (31.39, 94.17),
                (POLYNOMIAL, "spring.c1"): (-225.0, -75.0),
                (POLYNOMIAL, "spring.c2"): (-weight / h ** 2, weight / h ** 2),
                (POLYNOMIAL, "spring.c3"): (-6000.0, -2000.0)}
    for (law, name), (low, high) in expected.items():
        start, end, step = law_slider_range(law, name)
        span = high - low
        assert span / 500 <= step <= span / 200, name
        mantissa = step / 10 ** np.floor(np.log10(step))
        assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-9, name
        assert start <= low < start + step and end - step < high <= end, name
        value = page_values(page_request(spring=law))[name]
        assert start <= value <= end, name
    with pytest.raises(ParameterError, match="`name`"):
        law_slider_range(TABLE, "spring.center")


def test_the_exported_law_reproduces_the_pages_run(tmp_path):
    """The TOML export with the law's slider values, read by load_config and run by
    qzs.simulate (as `qzs simulate --config` does), gives the page's transmissibility bit
    for bit; the linear overlay is the law's linearised loop, not the MagSpring's."""
    request = page_request({"spring.vertical_stiffness": 180.0, "spring.oblique_stiffness": 210.0,
                            "excitation.duration": 40.0, "excitation.f1": 10.0}, spring=OBLIQUE)
    data = compute_page(request)
    path = tmp_path / "page.toml"
    path.write_text(config_text(request, data.dt), encoding="utf-8")
    config = load_config(path)
    assert config["isolator"] == request.isolator
    assert config["isolator"].spring.vertical_stiffness == 180.0
    options = dict(config["excitation"])
    excitation = build_excitation(options.pop("kind"), options)
    result = simulate(excitation, config["isolator"], config["controller"],
                      dt=config["simulation"]["dt"],
                      sample_rate=config["simulation"]["sample_rate"])
    estimate = transmissibility(result.base_acceleration, result.payload_acceleration,
                                request.sample_rate, fft_length=welch_length(len(result)))
    np.testing.assert_array_equal(data.transmissibility_db,
                                  20 * np.log10(estimate.magnitude[estimate.trusted]))
    law_linear = linearize(request.isolator, request.controller).transmissibility(
        data.linear_frequency)
    np.testing.assert_allclose(data.linear_db, 20 * np.log10(law_linear), rtol=0, atol=1e-12)
    tanh_linear = linearize(IsolatorParameters(), request.controller).transmissibility(
        data.linear_frequency)
    assert np.max(np.abs(data.linear_db - 20 * np.log10(tanh_linear))) > 0.1  # [dB]
