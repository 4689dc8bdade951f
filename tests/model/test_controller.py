"""Tests of the controller (qzs.control and its simulation): closed forms and control laws."""
import dataclasses
import math

import numpy as np
import pytest
from helpers import linear_controller, linear_isolator

from qzs import (
    Chirp,
    ControllerParameters,
    InitialState,
    IsolatorParameters,
    ParameterError,
    Sine,
    closed_loop_natural_frequency,
    passive_natural_frequency,
    simulate,
    spring_force,
)
from qzs.model import spring_stiffness

DEFAULT_PLANT = IsolatorParameters()


# ------------------------------------------------------------------ natural frequency
def test_default_pi_moves_the_resonance_to_the_papers_0_45_hz(validation):
    controller = ControllerParameters()
    assert controller.pi_kp == 50.0
    frequency = closed_loop_natural_frequency(DEFAULT_PLANT, controller)
    assert frequency == pytest.approx(0.45, abs=0.01)
    validation("Closed-loop natural frequency with the default PI (Kp = 50 N/m)",
               "paper, Section 3.1: PI moves the resonance within 0.08-0.45 Hz (upper end)",
               abs(frequency - 0.45), 0.01, measure=f"absolute error [Hz], {frequency:.4f} Hz")
    k = spring_stiffness(-0.060, DEFAULT_PLANT) + 50.0
    assert frequency == pytest.approx(math.sqrt(k / 6.4) / (2 * math.pi), rel=1e-12)
    assert closed_loop_natural_frequency() == frequency  # defaults


def test_closed_loop_frequency_without_gain_is_the_passive_one_and_grows_with_kp():
    passive = ControllerParameters(pi_kp=0.0)
    assert closed_loop_natural_frequency(DEFAULT_PLANT, passive) == pytest.approx(
        passive_natural_frequency(DEFAULT_PLANT, -0.060), rel=1e-12)
    gains = [0.0, 10.0, 50.0, 200.0]
    frequencies = [closed_loop_natural_frequency(DEFAULT_PLANT, ControllerParameters(pi_kp=g)) for g in gains]
    assert np.all(np.diff(frequencies) > 0)


def test_closed_loop_frequency_uses_the_given_operating_point():
    controller = ControllerParameters(pi_kp=0.0)
    at_centre = closed_loop_natural_frequency(DEFAULT_PLANT, controller, relative_position=0.0)
    assert at_centre == pytest.approx(passive_natural_frequency(DEFAULT_PLANT, 0.0), rel=1e-12)


# ------------------------------------------------------------------ parameters
def test_defaults_are_those_of_model_md():
    expected = dict(position_setpoint=-0.060, pi_kp=50.0, pi_ki=20.0, damping_gain=0.0,
                    velocity_highpass=1.0, controller_rate=0.0)
    assert ControllerParameters().to_dict() == expected
    for field in dataclasses.fields(ControllerParameters):
        assert field.metadata.get("unit"), field.name


@pytest.mark.parametrize("name, value, match", [
    ("pi_kp", -1.0, "must be non-negative, got -1.0"),
    ("pi_ki", float("nan"), "must be finite, got nan"),
    ("damping_gain", float("inf"), "must be finite, got inf"),
    ("velocity_highpass", False, "must be a number, got the boolean False"),
    ("controller_rate", -100.0, "must be non-negative, got -100.0"),
    ("position_setpoint", "middle", "must be a number, got 'middle'"),
])
def test_invalid_controller_parameter_is_named_with_its_value(name, value, match):
    with pytest.raises(ParameterError, match=match) as info:
        ControllerParameters(**{name: value})
    assert f"`{name}`" in str(info.value)


def test_controller_rejects_unknown_keyword_and_positional_use():
    with pytest.raises(TypeError, match="kp"):
        ControllerParameters(kp=50.0)
    with pytest.raises(TypeError):
        ControllerParameters(-0.06)


# ------------------------------------------------------------------ control law in the simulation
def test_bumpless_start_motor_carries_what_the_spring_does_not(default_chirp_run):
    """The PI integral is preloaded with the static load only (docs/model.md §5): the motor
    carries the weight the spring does not, and friction the base's inertial force m*ydd(0)."""
    r = default_chirp_run
    m, g = DEFAULT_PLANT.mass, DEFAULT_PLANT.gravity
    expected = -spring_force(-0.060, DEFAULT_PLANT) + m * g
    assert r.motor_force[0] == pytest.approx(expected, rel=1e-12)
    assert r.base_acceleration[0] != 0.0
    assert r.friction_force[0] == pytest.approx(m * r.base_acceleration[0], rel=1e-9)
    assert r.locked[0]


def test_explicit_zero_integral_leaves_the_deficit_to_friction():
    r = simulate(Chirp(duration=1.0), duration=0.01, initial_state=InitialState(pi_integral=0.0))
    deficit = DEFAULT_PLANT.mass * (DEFAULT_PLANT.gravity + r.base_acceleration[0]) - r.spring_force[0]
    assert r.motor_force[0] == 0.0
    assert r.friction_force[0] == pytest.approx(deficit, rel=1e-12)
    assert r.locked.all()  # 2 N is well inside the 10 N of stiction


def test_motor_force_is_the_saturated_sum_and_damping_uses_the_measured_velocity(sampled_chirp_run,
                                                                                  default_chirp_run):
    for r in (default_chirp_run, sampled_chirp_run):
        fmax = r.isolator.motor_force_max
        np.testing.assert_array_equal(r.motor_force, np.clip(r.pi_force + r.damping_force, -fmax, fmax))
    r = default_chirp_run  # continuous controller: the damping law holds at every sample
    np.testing.assert_array_equal(r.damping_force, -r.controller.damping_gain * r.measured_payload_velocity)


def test_anti_windup_freezes_the_integral_while_saturated():
    """A motor too weak for the weight deficit: the payload sinks and the PI saturates.

    The integral ``I = (F_pi - Kp*e)/Ki`` must stop growing while the motor is saturated
    and the error pushes further into saturation; without anti-windup it would grow by
    the integral of e (about 0.08 m * 10 s).
    """
    plant = IsolatorParameters(motor_force_max=0.5)
    controller = ControllerParameters()
    r = simulate(Sine(amplitude=0.010, frequency=3.0), plant, controller, duration=10.0,
                 dt=1e-4, sample_rate=1e4)
    error = controller.position_setpoint - r.relative_position
    integral = (r.pi_force - controller.pi_kp * error) / controller.pi_ki
    saturated = (r.motor_force == plant.motor_force_max) & (error > 0)
    both = saturated[1:] & saturated[:-1]
    assert both.sum() > 0.5 * len(r)  # the test exercises saturation
    growth_while_saturated = np.sum(np.diff(integral)[both])
    dt = 1e-4
    windup_without_guard = np.sum(error[1:][both]) * dt
    assert windup_without_guard > 0.3
    assert abs(growth_while_saturated) < 1e-9


def test_sampled_controller_holds_its_output_between_samples():
    """Zero-order hold at 1 kHz with dt = 0.1 ms: the force is constant over 10 steps."""
    controller = ControllerParameters(controller_rate=1000.0, damping_gain=20.0)
    r = simulate(Chirp(duration=20.0), controller=controller, duration=3.0, dt=1e-4, sample_rate=1e4)
    blocks = r.motor_force[1:].reshape(-1, 10)
    assert np.all(np.ptp(blocks, axis=1) == 0.0)
    assert np.count_nonzero(np.diff(blocks[:, 0])) > 0.9 * (blocks.shape[0] - 1)


def test_sampled_controller_law_at_the_sampling_instants():
    """Held outputs equal the PI law at the sample, the integral advances by forward Euler.

    With ``I_k`` the integral at sample k (period T): ``F_pi,k = Kp*e_k + Ki*I_k``,
    ``I_(k+1) = I_k + e_k*T`` (no saturation here), ``F_d,k = -Kd*v_measured(t_k)``.
    """
    T, per = 1e-3, 10
    plant = linear_isolator(stiffness=100.0, damping=50.0)
    controller = linear_controller(pi_kp=400.0, pi_ki=800.0, damping_gain=30.0, velocity_highpass=1.0,
                                   controller_rate=1 / T)
    r = simulate(Sine(amplitude=0.01, frequency=2.0), plant, controller, duration=1.0, dt=T / per,
                 sample_rate=per / T)
    instants = np.arange(0, len(r) - 1, per)  # state rows at t_k; held values appear one row later
    e = controller.position_setpoint - r.relative_position[instants]
    pi_held = r.pi_force[instants + 1]
    integral_term = pi_held - controller.pi_kp * e
    np.testing.assert_allclose(np.diff(integral_term), controller.pi_ki * e[:-1] * T, rtol=1e-9,
                               atol=1e-12)
    np.testing.assert_allclose(r.damping_force[instants + 1],
                               -controller.damping_gain * r.measured_payload_velocity[instants],
                               rtol=0, atol=1e-12 * np.abs(r.damping_force).max())


def test_charge_amplifier_highpass_closed_form_on_a_stuck_payload(validation):
    """Payload stuck to a sine base: ``xd = A*w*cos(w t)`` exactly, so the measured velocity
    is the first-order high-pass ``s/(s + wh)`` of it, settled at t = 0 (output 0), in closed form.
    """
    amplitude, frequency, corner = 0.01, 2.0, 1.0
    w, wh = 2 * np.pi * frequency, 2 * np.pi * corner
    plant = IsolatorParameters(stiction_force=1e6, coulomb_force=1.0)
    controller = ControllerParameters(damping_gain=10.0, velocity_highpass=corner)
    r = simulate(Sine(amplitude=amplitude, frequency=frequency, fade_in=0.0), plant, controller,
                 duration=3.0, dt=1e-4, sample_rate=1000.0)
    assert r.locked.all()
    t = r.time
    u0 = amplitude * w
    lowpass_gain = wh / (wh + 1j * w)
    steady = np.real(u0 * lowpass_gain * np.exp(1j * w * t))
    lowpass = steady + (u0 - np.real(u0 * lowpass_gain)) * np.exp(-wh * t)
    expected = u0 * np.cos(w * t) - lowpass
    np.testing.assert_allclose(r.measured_payload_velocity, expected, rtol=0, atol=1e-9 * u0)
    validation("Charge amplifier's high-pass on a stuck payload's velocity",
               "s/(s + w_hp) of A w cos(w t), transient included",
               np.abs(r.measured_payload_velocity - expected).max() / u0, 1e-9,
               measure="absolute error / A w")
    np.testing.assert_allclose(r.damping_force, -10.0 * expected, rtol=0, atol=1e-8 * u0)


def test_highpass_off_measures_the_true_payload_velocity():
    controller = ControllerParameters(damping_gain=5.0, velocity_highpass=0.0)
    r = simulate(Chirp(duration=20.0), controller=controller, duration=4.0)
    np.testing.assert_array_equal(r.measured_payload_velocity, r.payload_velocity)


# ------------------------------------------------------------------ sampled -> continuous
RATES = np.array([500.0, 1000.0, 2000.0, 5000.0, 10000.0])


def _sampled_minus_continuous(excitation, plant, controller, duration, channels):
    continuous = simulate(excitation, plant, controller, duration=duration, dt=1e-4, sample_rate=1000.0)
    out = []
    for rate in RATES:
        sampled = simulate(excitation, plant, dataclasses.replace(controller, controller_rate=rate),
                           duration=duration, dt=1e-4, sample_rate=1000.0)
        out.append([np.max(np.abs(sampled[c] - continuous[c])) for c in channels])
    return np.array(out).T


def test_sampled_controller_converges_to_the_continuous_one_at_first_order(validation):
    """Zero-order hold delays the command by T/2 on average: the difference is O(T)."""
    plant = linear_isolator(stiffness=100.0, damping=50.0)
    controller = linear_controller(pi_kp=400.0, pi_ki=800.0, damping_gain=30.0, velocity_highpass=1.0)
    differences = _sampled_minus_continuous(Sine(amplitude=0.01, frequency=2.0), plant, controller, 3.0,
                                            ["relative_position", "payload_acceleration"])
    for channel, difference in zip(("relative position", "payload acceleration"), differences):
        assert np.all(np.diff(difference) < 0)
        slope = np.polyfit(np.log(1 / RATES), np.log(difference), 1)[0]
        assert slope == pytest.approx(1.0, abs=0.15)
        validation(f"Sampled controller converges to the continuous one ({channel})",
                   "order 1 in the period T (zero-order hold delays by T/2), linear plant",
                   abs(slope - 1.0), 0.15, measure=f"|slope - 1|, slope {slope:.3f}")
    assert differences[0, -1] < 1e-3 * 0.01  # 10 kHz: well below the 10 mm excitation


def test_sampled_controller_converges_on_the_stick_slip_default():
    """Default plant, through the first stick-slip cycles: the PI command converges at first order."""
    differences = _sampled_minus_continuous(Chirp(duration=10.0, f1=5.0), DEFAULT_PLANT,
                                            ControllerParameters(), 7.0, ["pi_force", "relative_position"])
    pi_difference, position_difference = differences
    assert np.all(np.diff(pi_difference) < 0)
    slope = np.polyfit(np.log(1 / RATES), np.log(pi_difference), 1)[0]
    assert slope == pytest.approx(1.0, abs=0.15)
    assert np.all(np.diff(position_difference) < 0)
    assert position_difference.max() < 1e-4
