"""The smooth model of harmonic balance (qzs.analysis.harmonic_balance.smooth_model): the
model's force laws with the friction regularised, the motor command, and the same model as an
ODE against Newton's law written out."""
import dataclasses
import math

import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters, ParameterError
from qzs.analysis.harmonic_balance import SmoothModel, smooth_right_hand_side
from qzs.model.isolator import friction_force, friction_slope, spring_force, spring_stiffness


def test_the_forces_are_the_models_laws_with_the_friction_regularised():
    isolator = IsolatorParameters(stiction_force=12.0, coulomb_force=2.5, stribeck_decay=40.0)
    model = SmoothModel.from_parameters(isolator, amplitude=0.01, friction_velocity=2e-3)
    plant = dataclasses.replace(isolator, friction_regularisation=2e-3)
    z = np.linspace(-0.2, 0.2, 401)
    v = np.linspace(-0.3, 0.3, 401)
    force, slope = model.spring(z)
    assert np.array_equal(force, spring_force(z, plant))
    assert np.array_equal(slope, -spring_stiffness(z, plant))
    force, slope = model.friction(v)
    assert np.array_equal(force, friction_force(v, plant))
    assert np.array_equal(slope, friction_slope(v, plant))
    assert model.friction_regularisation == model.friction_velocity == 2e-3


def test_regularised_friction_is_odd_continuous_and_dissipative():
    model = SmoothModel.from_parameters(amplitude=0.01)
    v = np.linspace(-0.2, 0.2, 4001)
    force, slope = model.friction(v)
    np.testing.assert_allclose(force, -model.friction(-v)[0], atol=1e-12)
    assert np.all(force * v <= 0)
    step = 1e-8
    numeric = (model.friction(v + step)[0] - model.friction(v - step)[0]) / (2 * step)
    assert np.max(np.abs(numeric - slope)) < 1e-5 * np.max(np.abs(slope))
    # the level at rest is the stiction; a few v_reg above, the simulator's sliding law
    tiny = 1e-9 * model.friction_velocity
    level = (model.friction(tiny)[0] + model.viscous_damping * tiny) / math.tanh(1e-9)
    assert level == pytest.approx(-model.stiction_force)
    for velocity in (8 * model.friction_velocity, 0.1):
        level = (model.coulomb_force + (model.stiction_force - model.coulomb_force)
                 * math.exp(-model.stribeck_decay * velocity))
        expected = -level - model.viscous_damping * velocity
        assert model.friction(velocity)[0] == pytest.approx(expected, rel=1e-6)


def test_peak_friction_falls_short_of_the_stiction_unless_the_regularisation_is_small():
    peaks = [SmoothModel.from_parameters(amplitude=0.01, friction_velocity=v).peak_friction
             for v in (2e-3, 1e-3, 1e-5)]
    assert peaks[0] < peaks[1] < peaks[2] < 10.0  # Table 1: Fs = 10 N
    assert peaks[1] == pytest.approx(8.1, abs=0.05)  # FRICTION_VELOCITY's comment
    assert peaks[2] > 9.9
    frictionless = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    assert SmoothModel.from_parameters(frictionless, amplitude=0.01).peak_friction == 0.0


def test_from_parameters_keeps_the_plant_and_centres_the_stops():
    isolator = IsolatorParameters(mass=5.0, stroke_half=0.05)
    controller = ControllerParameters(position_setpoint=-0.04, pi_kp=80.0, damping_gain=20.0,
                                      controller_rate=1000.0)
    model = SmoothModel.from_parameters(isolator, controller, amplitude=0.003)
    assert model.mass == 5.0 and model.pi_kp == 80.0 and model.damping_gain == 20.0
    assert (model.stop_low, model.stop_high) == pytest.approx((-0.09, 0.01))
    assert model.motor_force_max == isolator.motor_force_max
    centred = SmoothModel.from_parameters(dataclasses.replace(isolator, stop_center=0.0),
                                          controller, amplitude=0.003)
    assert (centred.stop_low, centred.stop_high) == (-0.05, 0.05)
    assert model.states == ("z", "v", "w", "I")
    passive = SmoothModel.from_parameters(
        controller=ControllerParameters(pi_kp=0.0, pi_ki=0.0), amplitude=0.003)
    assert passive.states == ("z", "v")


def test_motor_force_is_pi_plus_damping_on_the_measured_velocity():
    model = SmoothModel.from_parameters(controller=ControllerParameters(
        pi_kp=50.0, pi_ki=20.0, damping_gain=30.0, velocity_highpass=1.0), amplitude=0.01)
    z, integral, xd, w = -0.05, 0.3, 0.02, 0.005
    expected = 50.0 * (-0.06 - z) + 20.0 * integral - 30.0 * (xd - w)
    assert model.motor_force(z, integral, xd, w) == pytest.approx(expected, rel=1e-15)
    unfiltered = dataclasses.replace(model, velocity_highpass=0.0)
    assert unfiltered.motor_force(z, integral, xd, w) == pytest.approx(
        expected + 30.0 * (-w), rel=1e-15)


def test_the_ode_is_newtons_law_of_the_smooth_model():
    model = SmoothModel.from_parameters(controller=ControllerParameters(damping_gain=30.0),
                                        amplitude=0.01)
    state = np.array([-0.055, 0.03, 0.004, 0.7])
    time, frequency = 0.13, 2.5
    omega = 2 * np.pi * frequency
    yd = -model.amplitude * omega * math.sin(omega * time)
    ydd = -model.amplitude * omega ** 2 * math.cos(omega * time)
    z, v, w, integral = state
    spring = -model.spring_force * math.tanh(model.spring_shape * z)
    level = model.coulomb_force + (model.stiction_force - model.coulomb_force) * math.exp(
        -model.stribeck_decay * abs(v))
    friction = -level * math.tanh(v / model.friction_velocity) - model.viscous_damping * v
    motor = (model.pi_kp * (model.position_setpoint - z) + model.pi_ki * integral
             - model.damping_gain * (yd + v - w))
    expected = [v, (spring + friction + motor) / model.mass - model.gravity - ydd,
                model.highpass_omega * (yd + v - w), model.position_setpoint - z]
    np.testing.assert_allclose(smooth_right_hand_side(time, state, frequency, model), expected,
                               rtol=1e-12)
    # columns: several states at once
    many = np.column_stack([state, 0.5 * state])
    np.testing.assert_allclose(smooth_right_hand_side(time, many, frequency, model)[:, 1],
                               smooth_right_hand_side(time, 0.5 * state, frequency, model),
                               rtol=1e-15)


@pytest.mark.parametrize("options, name", [
    (dict(amplitude=-1.0), "amplitude"),
    (dict(amplitude=0.01, friction_velocity=0.0), "friction_velocity"),
])
def test_bad_input_is_refused(options, name):
    with pytest.raises(ParameterError, match=name):
        SmoothModel.from_parameters(**options)


def test_a_negative_gain_is_refused():
    model = SmoothModel.from_parameters(amplitude=0.01)
    with pytest.raises(ParameterError, match="damping_gain"):
        dataclasses.replace(model, damping_gain=-1.0)

