"""The start of a run: the PI preload carries the static load only; excitations fade in.

Issue 10: the preload used to include ``m*ydd(0)``, so a random base motion that starts
with an acceleration dropped the payload onto the lower stop; a sine at full amplitude
kicked the payload 36 mm off its setpoint.
"""
import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters, Sine, simulate
from qzs.engine.base_motion import base_motion_series
from qzs.engine.prepare import prepare_run
from qzs.engine import kernels as K
from qzs.errors import ExcitationError, ParameterError
from qzs.model.excitation import (DEFAULT_FADE_IN, Chirp, DisplacementRecord, RandomExcitation,
                                  build_excitation)

RANDOM = dict(amplitude=0.002, f_low=0.5, f_high=20.0, seed=7, duration=60.0)


def test_preload_carries_the_static_load_only():
    """The integral at t = 0 does not depend on the base's acceleration at t = 0."""
    at_rest = prepare_run(Sine(amplitude=0.0), duration=1.0)
    # y = A cos(w t): the base starts at full acceleration -A w^2 = -39.5 m/s^2
    shaken = prepare_run(Sine(amplitude=0.001, frequency=100.0, phase=np.pi / 2, fade_in=0.0),
                         duration=1.0)
    assert base_motion_series(shaken.excitation, [0.0])[2][0] < -39.0
    assert shaken.state[K.S_INT] == at_rest.state[K.S_INT]
    # and it is the static load: the motor then supplies m*g - a*tanh(-b*z_ref)
    iso, ctrl = IsolatorParameters(), ControllerParameters()
    static = iso.mass * iso.gravity - iso.spring_force * np.tanh(-iso.spring_shape
                                                                 * ctrl.position_setpoint)
    assert shaken.state[K.A_F_MOTOR] == pytest.approx(static, rel=1e-12)


def test_random_run_from_the_issue_touches_no_stop():
    """`qzs simulate --excitation random --f0 0.5 --f1 20 --amplitude 0.002 --seed 7`: with the
    static preload (and even without a fade-in) the payload stays far from the stops."""
    result = simulate(RandomExcitation(**RANDOM, fade_in=0.0), duration=60.0, sample_rate=200.0)
    assert result.run["stop_contacts"] == 0
    assert abs(result.motor_force[0]) < 5.0  # was -22.6 N
    z = result.relative_position - result.controller.position_setpoint
    assert np.abs(z).max() < 0.02  # the stops are 80 mm away


def test_faded_in_sine_stays_near_the_setpoint():
    """A 1 mm, 100 Hz sine: faded in, the payload stays within 2 mm of the setpoint; started
    at full amplitude it is kicked tens of millimetres off (the reason for the default)."""
    faded = simulate(Sine(amplitude=0.001, frequency=100.0), duration=6.0, sample_rate=1000.0)
    kicked = simulate(Sine(amplitude=0.001, frequency=100.0, fade_in=0.0), duration=6.0,
                      sample_rate=1000.0)
    setpoint = faded.controller.position_setpoint
    assert faded.excitation.fade_in == DEFAULT_FADE_IN > 0
    assert np.abs(faded.relative_position - setpoint).max() < 0.002
    assert np.abs(kicked.relative_position - setpoint).max() > 0.010


@pytest.mark.parametrize("excitation", [
    Sine(amplitude=0.002, frequency=3.0, phase=0.7, fade_in=1.5),
    RandomExcitation(amplitude=0.001, duration=10.0, fade_in=1.5),
    Chirp(amplitude=0.002, f0=2.0, f1=5.0, duration=10.0, fade_in=1.5),
])
def test_fade_in_is_a_raised_cosine_with_consistent_derivatives(excitation):
    """y = w*y_raw with w(s) = s - sin(2 pi s)/(2 pi), s = t/T (a ramp whose slope is a raised
    cosine): zero motion at t = 0, the raw signal after T, and velocity and acceleration the
    exact, continuous derivatives (central differences agree everywhere, the ends included)."""
    raw = type(excitation)(**{**_fields(excitation), "fade_in": 0.0})
    t = np.linspace(0.0, 3.0, 30001)
    y, yd, ydd = base_motion_series(excitation, t)
    y0, yd0, ydd0 = base_motion_series(raw, t)
    s = t / 1.5
    w = np.where(s < 1.0, s - np.sin(2 * np.pi * s) / (2 * np.pi), 1.0)
    np.testing.assert_allclose(y, w * y0, atol=1e-15)
    assert y[0] == 0.0 and yd[0] == 0.0 and ydd[0] == 0.0
    after = t >= 1.5
    np.testing.assert_array_equal(y[after], y0[after])
    np.testing.assert_array_equal(ydd[after], ydd0[after])
    h = t[1] - t[0]
    inner = slice(1, -1)
    scale_v, scale_a = np.abs(yd).max(), np.abs(ydd).max()
    np.testing.assert_allclose((y[2:] - y[:-2]) / (2 * h), yd[inner], atol=1e-4 * scale_v)
    np.testing.assert_allclose((yd[2:] - yd[:-2]) / (2 * h), ydd[inner], atol=2e-3 * scale_a)


def _fields(excitation):
    import dataclasses

    return {f.name: getattr(excitation, f.name) for f in dataclasses.fields(excitation)}


def test_fade_in_defaults_and_switch():
    assert Chirp().fade_in == 0.0  # a chirp from 0 Hz starts gently
    for kind in ("sine", "random"):
        assert build_excitation(kind).fade_in == DEFAULT_FADE_IN
        assert build_excitation(kind, {"fade_in": 0}).fade_in == 0.0
    record = DisplacementRecord(time=np.arange(10.0), displacement=np.zeros(10))
    assert record.fade_in == DEFAULT_FADE_IN
    with pytest.raises(ExcitationError, match="`fade_in` must be"):
        Sine(fade_in=-1.0)
    with pytest.raises(ExcitationError, match=r"`fade_in` \(20.0 s\) must not exceed"):
        RandomExcitation(duration=10.0, fade_in=20.0)


@pytest.mark.parametrize("seed", [-1, 1.5, True, 2 ** 63])
def test_bad_seed_is_named(seed):
    with pytest.raises(ExcitationError, match=r"`seed` must be an integer in \[0, 9223372036854775807\]"):
        RandomExcitation(seed=seed)


# ---------------------------------------------------------------- steps per period
@pytest.mark.parametrize("excitation, duration, name", [
    (Sine(frequency=4000.0), 2.0, "frequency"),   # 2.5 steps per period at dt = 1e-4 s
    (Sine(frequency=1e9), 1.0, "frequency"),      # used to diverge without naming it
    (RandomExcitation(f_low=1.0, f_high=2000.0, duration=1.0), 1.0, "f1"),
])
def test_a_step_too_coarse_for_the_excitation_is_refused_before_the_run(excitation, duration,
                                                                        name):
    from qzs.errors import UnresolvedExcitationError

    with pytest.raises(UnresolvedExcitationError, match=f"`{name}`") as caught:
        prepare_run(excitation, duration=duration, dt=1e-4)
    error = caught.value
    assert error.frequency == pytest.approx(excitation.max_frequency) and error.dt == 1e-4
    assert error.frequency * error.dt * error.minimum > 1.0  # it does fall short


def test_the_resolution_limit_is_the_step_that_gives_ten_steps_per_period():
    from qzs.engine.prepare import MIN_STEPS_PER_PERIOD, check_resolution, resolving_step

    sine = Sine(frequency=400.0)
    assert resolving_step(sine) == pytest.approx(1.0 / (MIN_STEPS_PER_PERIOD * 400.0))
    check_resolution(sine, 2.5e-4)  # exactly 10 steps per period: accepted
    with pytest.raises(ParameterError):
        check_resolution(sine, 2.6e-4)
    # a chirp cut short reaches only the frequency of its end
    chirp = Chirp(f0=0.0, f1=2000.0, duration=100.0)
    check_resolution(chirp, 1e-4, duration=50.0)  # 1000 Hz: 10 steps per period
    with pytest.raises(ParameterError):
        check_resolution(chirp, 1e-4)
    # a record's sample rate bounds its content from above only: not checked
    record = DisplacementRecord(time=np.arange(100) / 1e4, displacement=np.zeros(100))
    assert resolving_step(record) == np.inf


@pytest.mark.parametrize("rate, dt, expected", [
    (1000.0, 1e-3, True), (500.0, 1e-3, True), (1.0 / 3.0, 1e-3, True), (250.0, 1e-4, True),
    (300.0, 1e-3, False), (2000.0, 1e-3, False), (400.0, 1e-3, False)])
def test_a_rate_divides_1_over_dt_when_it_is_a_whole_fraction_of_it(rate, dt, expected):
    from qzs.engine.prepare import divides

    assert divides(rate, dt) is expected




# ---------------------------------------------------------------- a random record's memory
def test_a_random_record_that_would_not_fit_in_memory_is_refused_before_it_is_made():
    """A 1e12 s record for a 2 s run: numpy's "Unable to allocate 1.42 PiB" once, naming
    neither the record's length nor the fix (it need not be longer than the run)."""
    import time

    began = time.perf_counter()
    with pytest.raises(ParameterError) as caught:
        simulate(RandomExcitation(duration=1e12), duration=2.0)
    assert time.perf_counter() - began < 1.0
    message = str(caught.value)
    assert caught.value.options == ("excitation.duration", "duration")
    assert message.startswith("`excitation.duration` = 1e+12 s makes the random excitation's "
                              "record 4e+14 points"), message
    assert "the record need not be longer than the run (`duration` = 2 s)" in message


def test_the_record_check_is_the_memory_guard_at_its_threshold(monkeypatch):
    from qzs.engine import driver
    from qzs.engine.prepare import RECORD_BYTES_PER_POINT, check_record

    excitation = RandomExcitation(duration=100.0, f_high=20.0)
    needed = excitation.record_points * RECORD_BYTES_PER_POINT
    assert excitation.record_points == 40_001  # 20 points a period of f_high, both ends
    assert excitation.pack()[1].shape[1] == excitation.record_points  # what _spline makes
    monkeypatch.setattr(driver, "available_memory", lambda: 2 * needed)
    check_record(excitation, 10.0)
    monkeypatch.setattr(driver, "available_memory", lambda: 2 * needed - 2)
    with pytest.raises(ParameterError, match="`excitation.duration` = 100 s makes"):
        check_record(excitation, 10.0)
    check_record(Chirp(duration=1e12), 10.0)  # no record: nothing to refuse


def test_a_discrete_sample_time_shorter_than_a_step_is_refused_before_the_run():
    # half a step or less rounds to 0 steps: a "discrete" controller that never samples
    from qzs import LinearController, PIDamping
    from qzs.engine.prepare import pack_model

    short = LinearController(a=[[0.5]], b=[[1.0]], c=[1.0], d=[0.0], inputs=("position_error",),
                             sample_time=4e-5)
    with pytest.raises(ParameterError, match=r"`sample_time` .* use sample_time=0.0001 s"):
        pack_model(IsolatorParameters(), PIDamping() + short, 1e-4)


def test_a_feedthrough_on_the_measured_velocity_leaves_the_motor_at_the_static_load():
    """The preload is bumpless with a linear controller too (docs/model.md §5.1, initial
    state): on a base already moving at t = 0 (no fade-in), a static gain on the measured
    velocity, whose output at t = 0 is 0 (the high-pass has settled), leaves the motor at
    ``m*g - a*tanh(-b*z_ref)``, the static load the spring does not carry."""
    from qzs import LinearController, PIDamping

    moving = Sine(amplitude=0.01, frequency=3.0, fade_in=0.0)
    iso = IsolatorParameters()
    gain = LinearController.from_transfer_function([-40.0], [1.0], "measured_payload_velocity")
    run = prepare_run(moving, iso, PIDamping(linear=gain), duration=1.0)
    assert base_motion_series(run.excitation, [0.0])[1][0] > 0.18  # y'(0) = 2 pi f A
    assert run.state[K.A_F_LINEAR] == 0.0
    static = iso.mass * iso.gravity - iso.spring_force * np.tanh(
        -iso.spring_shape * PIDamping().position_setpoint)
    assert run.state[K.A_F_MOTOR] == pytest.approx(static, rel=1e-12)
