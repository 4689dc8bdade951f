"""Tests of the controller's blocks as values (qzs.model.controller): PIDamping and what adds to it.

Friction compensation, dither and a user's linear controller: what they accept, what they
refuse (naming the argument and the fix), how they add, and what a run records of them.
"""
import dataclasses

import control
import numpy as np
import pytest

from qzs import (ControllerParameters, Dither, FrictionCompensation, IsolatorParameters,
                 LinearController, ParameterError, PIDamping)
from qzs.analysis.harmonic_balance import SmoothModel
from qzs.analysis.hexapod_linear import hexapod_linearize
from qzs.model import PlatformParameters, cubic_geometry
from qzs.model.controller import MAX_STATES, SENSORS, block_parameters


# ------------------------------------------------------------------ PIDamping and adding blocks
def test_pidamping_is_todays_controller_and_prints_as_before_without_blocks():
    assert PIDamping is ControllerParameters
    default = PIDamping()
    assert not default.has_blocks
    assert "compensation" not in repr(default) and "linear" not in repr(default)
    assert set(default.to_dict()) == {"position_setpoint", "pi_kp", "pi_ki", "damping_gain",
                                      "velocity_highpass", "controller_rate"}
    assert block_parameters(default) == {}


def test_blocks_add_to_a_controller_each_into_its_own_slot():
    compensation = FrictionCompensation(fraction=0.8)
    dither = Dither(amplitude=2.0, frequency=40.0)
    linear = LinearController.from_transfer_function([-5.0, 0.0], [1.0, 30.0])
    controller = PIDamping(damping_gain=10.0) + compensation + dither + linear
    assert controller.compensation is compensation and controller.dither is dither
    assert controller.linear is linear and controller.damping_gain == 10.0
    assert controller.has_blocks
    assert (linear + PIDamping()).linear is linear  # either side
    assert dataclasses.replace(controller, pi_kp=80.0).compensation is compensation


@pytest.mark.parametrize("left, right, match", [
    (FrictionCompensation(), Dither(), "start from PIDamping"),
    (PIDamping() + Dither(), Dither(), "already has a `dither` block"),
])
def test_adding_blocks_wrongly_says_how_to(left, right, match):
    with pytest.raises(ParameterError, match=match):
        left + right


def test_a_block_in_the_wrong_slot_is_refused():
    with pytest.raises(ParameterError, match="`dither` must be a Dither"):
        ControllerParameters(dither=FrictionCompensation())


# ------------------------------------------------------------------ friction compensation
@pytest.mark.parametrize("value", [-0.1, 1.51, float("nan")])
def test_a_compensation_fraction_outside_0_to_1_5_is_refused(value):
    with pytest.raises(ParameterError, match=r"`fraction` .*0 is none, 1 cancels"):
        FrictionCompensation(fraction=value)


def test_compensation_takes_the_plants_friction_law_where_it_sets_none():
    plant = IsolatorParameters(stiction_force=12.0, coulomb_force=2.0)
    law = FrictionCompensation(coulomb_force=1.5, viscous_damping=80.0).law(plant)
    assert law == (12.0, 1.5, plant.stribeck_decay, 80.0)
    with pytest.raises(ParameterError, match="must not exceed `stiction_force`"):
        FrictionCompensation(stiction_force=5.0, coulomb_force=6.0)


def test_compensation_from_a_friction_fit_takes_its_levels_and_its_cv_only_if_asked():
    fit = type("Fit", (), dict(stiction_force=9.0, coulomb_force=1.2, stribeck_decay=90.0,
                               viscous_damping=101.0))()
    block = FrictionCompensation.from_fit(fit, fraction=0.5, deadband=1e-4)
    assert block.law(IsolatorParameters()) == (9.0, 1.2, 90.0, 0.0)
    assert (block.fraction, block.deadband) == (0.5, 1e-4)
    viscous = FrictionCompensation.from_fit(fit, viscous_damping=fit.viscous_damping)
    assert viscous.law(IsolatorParameters())[3] == 101.0


def test_the_default_compensation_leaves_the_viscous_friction_to_the_loop():
    plant = IsolatorParameters()
    assert FrictionCompensation().law(plant)[3] == 0.0
    assert FrictionCompensation(viscous_damping=None).law(plant)[3] == plant.viscous_damping


def test_dither_needs_a_positive_frequency():
    with pytest.raises(ParameterError, match="`frequency` must be positive"):
        Dither(frequency=0.0)


# ------------------------------------------------------------------ linear controller
def test_a_transfer_function_becomes_a_state_space_with_the_same_response():
    tf = control.tf([-20.0, -200.0], [1.0, 50.0, 400.0])
    linear = LinearController.from_system(tf, ["measured_payload_velocity"])
    assert linear.states == 2 and not linear.discrete
    omega = np.array([0.3, 3.0, 30.0, 300.0])
    np.testing.assert_allclose(linear.to_system()(1j * omega).ravel(), tf(1j * omega).ravel(),
                               rtol=1e-12)


def test_a_discrete_system_keeps_its_sample_time():
    linear = LinearController.from_system(control.tf([0.5, 0.1], [1.0, -0.9], 1e-3),
                                          "position_error")
    assert linear.discrete and linear.sample_time == 1e-3


@pytest.mark.parametrize("build, match", [
    (lambda: LinearController.from_system(control.tf([1.0, 2.0, 3.0], [1.0, 4.0])),
     "improper"),
    (lambda: LinearController.from_system(control.tf([1.0], [1.0, 1.0]),
                                          ["position_error", "relative_velocity"]),
     "has 1 inputs but `inputs` names 2"),
    (lambda: LinearController.from_system(control.ss([[-1.0]], [[1.0]], [[1.0], [2.0]],
                                                     [[0.0], [0.0]])),
     "one output"),
    (lambda: LinearController.from_transfer_function([1.0], [1.0, 1.0], "encoder_speed"),
     "unknown sensor 'encoder_speed'"),
    (lambda: LinearController(a=[[np.nan]], b=[[1.0]], c=[1.0], d=[0.0]), "non-finite"),
    (lambda: LinearController(a=[[-1.0]], b=[[1.0]], c=[np.inf], d=[0.0]), "non-finite"),
    (lambda: LinearController(a=[[-1.0]], b=[[1.0, 2.0]], c=[1.0], d=[0.0]),
     r"`b` must have shape \(1, 1\)"),
    (lambda: LinearController.from_system(control.ss(-np.eye(MAX_STATES + 1),
                                                     np.ones((MAX_STATES + 1, 1)),
                                                     np.ones((1, MAX_STATES + 1)), 0.0)),
     f"at most {MAX_STATES} states"),
    (lambda: LinearController(a=[[-10.0]], b=[[1.0]], c=[1.0], d=[0.5],
                              inputs=("payload_acceleration",)),
     "algebraic loop"),
    (lambda: LinearController.from_system(np.eye(2)), "StateSpace or TransferFunction"),
    (lambda: LinearController.from_transfer_function([1.0], [0.0]), "`denominator` must not"),
    (lambda: LinearController(a=[[-1.0]], b=[[1.0]], c=[1.0], d=[0.0], tracking_time=0.0),
     "`tracking_time` must be positive"),
])
def test_a_bad_linear_controller_is_refused_naming_what_and_how(build, match):
    with pytest.raises(ParameterError, match=match):
        build()


def test_a_discrete_controller_may_feed_the_acceleration_straight_through():
    linear = LinearController(a=[[0.5]], b=[[1.0]], c=[1.0], d=[0.5],
                              inputs=("payload_acceleration",), sample_time=1e-3)
    assert linear.d == (0.5,)


def test_the_antiwindup_gain_makes_the_command_track_saturation_in_the_tracking_time():
    # C L = 1/T_t: the command's excess decays with the time constant T_t (docs/model.md §5)
    linear = LinearController(a=np.diag([-1.0, -2.0]), b=[[1.0], [1.0]], c=[3.0, -4.0],
                              d=[0.0], tracking_time=0.05)
    gain = linear.antiwindup_gain()
    assert np.dot(linear.c, gain) == pytest.approx(1 / 0.05, rel=1e-14)
    pi = LinearController(a=[[0.0]], b=[[1.0]], c=[20.0], d=[50.0], inputs="position_error",
                          tracking_time=2.5)
    assert pi.antiwindup_gain()[0] == pytest.approx(1 / (20.0 * 2.5))  # classic 1/(Ki T_t)
    sampled = dataclasses.replace(pi, sample_time=1e-3)
    assert 20.0 * sampled.antiwindup_gain()[0] == pytest.approx(1e-3 / 2.5)


def test_block_parameters_carry_units_and_the_matrices_row_by_row():
    linear = LinearController(a=[[-1.0, 2.0], [0.0, -3.0]], b=[[1.0], [0.5]], c=[4.0, 5.0],
                              d=[0.25], inputs=("relative_velocity",))
    meta = block_parameters(PIDamping() + linear + Dither(amplitude=3.0))
    assert meta["linear.a"] == ([-1.0, 2.0, 0.0, -3.0], "1/s")
    assert meta["linear.states"] == (2, "1")
    assert meta["linear.inputs"] == ("relative_velocity", "-")
    assert meta["dither.amplitude"] == (3.0, "N") and meta["dither.frequency"][1] == "Hz"
    assert set(SENSORS) >= set(meta["linear.inputs"][0].split())


def _smooth_model(controller):
    return SmoothModel.from_parameters(controller=controller, amplitude=1e-3)


def _hexapod_linear(controller):
    geometry = cubic_geometry(cube_edge=0.2, cube_center_height=0.2)
    platform = PlatformParameters(mass=20.0, inertia=np.eye(3))
    return hexapod_linearize(geometry, platform, controller=controller)


@pytest.mark.parametrize("call, match", [(_smooth_model, "the harmonic balance"),
                                         (_hexapod_linear, "the six-axis linear model")])
def test_what_models_pi_and_damping_alone_refuses_blocks_naming_the_way_out(call, match):
    with pytest.raises(ParameterError, match=match + r" models PI \+ damping alone; "
                                                     r"`controller` has blocks .*dither"):
        call(PIDamping() + Dither())


@pytest.mark.parametrize("sample_time", [-1.0, float("nan"), float("inf"), "0.01"])
def test_a_transfer_function_with_a_bad_sample_time_names_it(sample_time):
    """A negative, NaN or infinite `sample_time` (or text) is qzs's error naming it, not
    python-control's "invalid timebase" ValueError."""
    with pytest.raises(ParameterError) as error:
        LinearController.from_transfer_function([1.0], [1.0, 2.0], sample_time=sample_time)
    assert "sample_time" in error.value.options and "`sample_time`" in str(error.value)


# ------------------------------------------------------------------ bounds and what a block says
def test_a_controller_of_exactly_max_states_is_accepted():
    # the kernels hold MAX_STATES states: that many is the largest controller, not one too many
    n = MAX_STATES
    linear = LinearController(a=-np.eye(n), b=np.ones((n, 1)), c=np.ones(n), d=[0.0])
    assert linear.states == n


def test_a_sensor_named_twice_is_refused_naming_inputs():
    with pytest.raises(ParameterError, match=r"`inputs` names a sensor twice") as error:
        LinearController(a=[[-1.0]], b=[[1.0, 1.0]], c=[1.0], d=[0.0, 0.0],
                         inputs=("position_error", "position_error"))
    assert error.value.options == ("inputs",)


def test_a_negative_dither_amplitude_is_refused():
    with pytest.raises(ParameterError, match="`amplitude`"):
        Dither(amplitude=-1.0)


def test_a_pure_coulomb_compensator_with_equal_levels_is_accepted():
    # Fc = Fs is the Coulomb law without a Stribeck peak: a valid law, not a swap
    law = FrictionCompensation(stiction_force=3.0, coulomb_force=3.0).law(IsolatorParameters())
    assert law[:2] == (3.0, 3.0)


def test_a_discrete_antiwindup_never_corrects_more_than_the_whole_excess_in_a_period():
    # L * min(T_s/T_t, 1): a period longer than T_t brings the command back to the limit in
    # one sample (C L = 1), never past it (docs/model.md §5.1)
    slow = LinearController(a=[[1.0]], b=[[1.0]], c=[20.0], d=[0.0], inputs="position_error",
                            sample_time=0.5, tracking_time=0.1)
    assert np.dot(slow.c, slow.antiwindup_gain()) == pytest.approx(1.0, rel=1e-14)


def test_the_sample_rates_are_the_inverse_of_the_periods_each_once():
    linear = LinearController(a=[[1.0]], b=[[1.0]], c=[1.0], d=[0.0], inputs="position_error",
                              sample_time=2e-3)
    assert PIDamping(linear=linear).sample_rates == pytest.approx((500.0,))
    assert PIDamping(controller_rate=500.0, linear=linear).sample_rates == pytest.approx((500.0,))
    assert PIDamping(controller_rate=1000.0, linear=linear).sample_rates == pytest.approx(
        (1000.0, 500.0))
    assert PIDamping(linear=dataclasses.replace(linear, sample_time=0.0)).sample_rates == ()


def test_describe_names_the_observer_only_when_there_is_one():
    with_observer = PIDamping() + FrictionCompensation(fraction=0.5, observer_bandwidth=5.0)
    assert "observer 5 Hz" in with_observer.describe()
    assert "observer" not in (PIDamping() + FrictionCompensation(fraction=0.5)).describe()
