"""The analysis behind ``qzs design``: closed forms against python-control and physics.

Routh-Hurwitz boundaries against the gain where python-control's poles cross the imaginary
axis; margins of loops whose margins are known by hand; the exact discretisation of a delayed
integrator against its modified z-transform; the describing function of Coulomb friction
against python-control's numerical one; the hunting prediction against a simulation; the
static design against the spring law.
"""
import dataclasses
import math

import control
import numpy as np
import pytest
from scipy.optimize import brentq

import qzs
from qzs import ControllerParameters, InitialState, IsolatorParameters, ParameterError
from qzs.analysis import control_design as cd
from qzs.model.isolator import spring_stiffness


def largest_real_part(isolator, controller):
    return float(np.max(cd.closed_loop_poles(isolator, controller).real))


def crossing(isolator, controller, name, low, high):
    """The gain ``name`` where python-control's poles cross the imaginary axis."""
    def real_part(value):
        return largest_real_part(isolator, dataclasses.replace(controller, **{name: value}))

    assert real_part(low) * real_part(high) < 0  # stable on one side, unstable on the other
    return brentq(real_part, low, high, xtol=1e-10, rtol=1e-12)


# ---------------------------------------------------------------- Routh-Hurwitz
def test_integral_limit_without_highpass_is_the_cubic_condition_and_the_poles_agree(validation):
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=5.0, damping_gain=30.0, velocity_highpass=0.0)
    k = float(spring_stiffness(controller.position_setpoint, isolator))
    closed = (isolator.viscous_damping + 30.0) * (k + 5.0) / isolator.mass
    assert cd.integral_gain_limit(isolator, controller) == pytest.approx(closed, rel=1e-14)
    found = crossing(isolator, controller, "pi_ki", 0.5 * closed, 2 * closed)
    assert found == pytest.approx(closed, rel=1e-6)
    validation("Routh-Hurwitz: largest stable Ki without the high-pass",
               "Ki < (Cv + Kd)(k + Kp)/m against the Ki where python-control's poles cross "
               "the imaginary axis", abs(found / closed - 1), 1e-6)


def test_damping_gain_upper_bound_with_the_highpass_is_where_the_poles_cross(validation):
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=5.0, pi_ki=2.0, velocity_highpass=1.0)
    low, high = cd.damping_gain_limits(isolator, controller)
    assert low == 0.0 and math.isfinite(high)
    found = crossing(isolator, controller, "damping_gain", 0.5 * high, 2 * high)
    assert found == pytest.approx(high, rel=1e-6)
    validation("Routh-Hurwitz: largest stable Kd with the high-pass",
               "the quartic's a3 a2 a1 > a4 a1^2 + a3^2 a0 against the poles' crossing "
               "(python-control)", abs(found / high - 1), 1e-6)
    # and the Routh table says so on either side
    assert cd.routh_hurwitz(isolator, dataclasses.replace(controller,
                                                          damping_gain=0.99 * high)).stable
    assert not cd.routh_hurwitz(isolator, dataclasses.replace(controller,
                                                              damping_gain=1.01 * high)).stable


def test_integral_limit_with_the_highpass_is_where_the_poles_cross():
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=20.0, damping_gain=200.0, velocity_highpass=1.0)
    limit = cd.integral_gain_limit(isolator, controller)
    found = crossing(isolator, controller, "pi_ki", 0.5 * limit, 2 * limit)
    assert found == pytest.approx(limit, rel=1e-6)


def test_on_a_zero_stiffness_spring_kp_must_exceed_m_ki_over_the_damping(validation):
    # spring_force = 0: no spring at all, k = 0 exactly
    isolator = IsolatorParameters(spring_force=0.0, gravity=0.0)
    controller = ControllerParameters(pi_ki=20.0, damping_gain=28.0, velocity_highpass=0.0)
    rh = cd.routh_hurwitz(isolator, controller)
    expected = isolator.mass * 20.0 / (isolator.viscous_damping + 28.0)
    assert rh.proportional_gain_minimum == pytest.approx(expected, rel=1e-9)
    found = crossing(isolator, controller, "pi_kp", 0.5 * expected, 2 * expected)
    assert found == pytest.approx(expected, rel=1e-6)
    validation("Routh-Hurwitz on a zero-stiffness spring: least Kp",
               "Kp > m Ki / (Cv + Kd) against the poles' crossing (python-control)",
               abs(found / expected - 1), 1e-6)


def test_default_loop_is_stable_and_the_closed_form_agrees_with_the_poles():
    rh = cd.routh_hurwitz()
    assert rh.stable and rh.agrees and rh.largest_real_part < 0
    assert len(rh.coefficients) == 4  # Kd = 0: the cubic
    unstable = cd.routh_hurwitz(controller=ControllerParameters(pi_ki=1e4))
    assert not unstable.stable and unstable.agrees and unstable.largest_real_part > 0


# ---------------------------------------------------------------- margins
def test_margins_of_a_discrete_integrator_against_the_hand_computation(validation):
    gain, period = 10.0, 0.01
    loop = control.tf([gain * period], [1.0, -1.0], period)  # K*T/(z - 1)
    margins = cd.stability_margins_of(loop)
    assert margins.stable
    # phase crossing at the Nyquist frequency, |L(-1)| = K*T/2
    assert margins.gain_margin == pytest.approx(20 * math.log10(2 / (gain * period)), abs=1e-9)
    assert margins.phase_crossover_frequency == pytest.approx(50.0)
    # |L| = K*T/(2 sin(wT/2)) = 1; the phase is -(90 deg + wT/2)
    assert margins.phase_margin == pytest.approx(
        90.0 - math.degrees(math.asin(gain * period / 2)), abs=1e-4)
    validation("Gain margin of a discrete integrator K T/(z - 1)", "20 log10(2/(K T))",
               abs(margins.gain_margin - 20 * math.log10(2 / (gain * period))), 1e-9,
               measure="absolute error [dB]")
    validation("Phase margin of a discrete integrator K T/(z - 1)", "90 deg - asin(K T/2)",
               abs(margins.phase_margin - (90.0 - math.degrees(math.asin(gain * period / 2)))),
               1e-4, measure="absolute error [deg]")


def test_margins_of_a_delayed_continuous_integrator(validation):
    w0, tau = 2.0, 0.1
    margins = cd.stability_margins_of(control.tf([w0], [1.0, 0.0]), delay=tau)
    assert margins.phase_margin == pytest.approx(90.0 - math.degrees(w0 * tau), abs=1e-3)
    assert margins.gain_margin == pytest.approx(20 * math.log10(math.pi / (2 * w0 * tau)),
                                                abs=1e-3)
    assert margins.gain_crossover_frequency == pytest.approx(w0 / (2 * math.pi), rel=1e-4)
    validation("Phase margin of a delayed integrator w0 e^(-s tau)/s (Pade)",
               "90 deg - w0 tau", abs(margins.phase_margin - (90.0 - math.degrees(w0 * tau))),
               1e-3, measure="absolute error [deg]")


@pytest.mark.parametrize("fraction", [0.0, 0.3, 1.0, 1.5])
def test_exact_discretisation_of_a_delayed_integrator(fraction, validation):
    """ZOH of 1/s delayed by (n + e)*T: T*((1 - e) z + e)/(z^(n+1) (z - 1))."""
    period = 0.02
    system = cd.discretize_with_delay([[0.0]], [[1.0]], [[1.0]], period, fraction * period)
    whole, e = int(math.floor(fraction + 1e-12)), fraction - math.floor(fraction + 1e-12)
    omega = np.array([0.3, 3.0, 30.0, 100.0])
    z = np.exp(1j * omega * period)
    expected = period * ((1 - e) * z + e) / (z ** (whole + 1) * (z - 1))
    np.testing.assert_allclose(cd.frequency_response(system, omega), expected, rtol=1e-10)
    validation(f"Zero-order hold of 1/s delayed by {fraction} T",
               "modified z-transform T ((1 - e) z + e) / (z^(n+1) (z - 1))",
               np.abs(cd.frequency_response(system, omega) / expected - 1).max(), 1e-10)


def test_sampled_margins_approach_the_continuous_ones_and_a_slow_rate_fails():
    controller = ControllerParameters(damping_gain=300.0)
    continuous = cd.loop_margins(controller=controller, rate=0.0)
    fast = cd.loop_margins(controller=controller, rate=1e5)
    assert fast.phase_margin == pytest.approx(continuous.phase_margin, abs=0.1)
    slow = cd.loop_margins(controller=controller, rate=20.0)
    assert not slow.stable


def test_the_required_rate_meets_the_margins_and_a_slower_one_does_not():
    controller = ControllerParameters(damping_gain=300.0)
    rate, reason = cd.required_controller_rate(controller=controller, delay=0.001)
    assert math.isfinite(rate) and reason == ""
    assert cd.loop_margins(controller=controller, rate=rate, delay=0.001).meets()
    assert not cd.loop_margins(controller=controller, rate=0.97 * rate, delay=0.001).meets()


def test_the_sampled_loop_matches_the_simulators_controller_at_low_frequency():
    """At frequencies far below the rate the sampled transmissibility is the continuous one."""
    controller = ControllerParameters(damping_gain=100.0)
    f = np.array([1.0, 3.0, 10.0])
    sampled = cd.sampled_transmissibility(f, controller=controller, rate=1e5)
    continuous = qzs.linearize(controller=controller).transmissibility(f)
    np.testing.assert_allclose(sampled, continuous, rtol=1e-3)


# ---------------------------------------------------------------- describing functions
def test_coulomb_describing_function_against_python_controls_numerical_one(validation):
    force = 2.0
    isolator = IsolatorParameters(stiction_force=force, coulomb_force=force)
    amplitude = np.array([1e-3, 1e-2, 0.3])
    numeric = cd.friction_describing_function(isolator, amplitude, points=20000)
    np.testing.assert_allclose(numeric.real, cd.coulomb_describing_function(force, amplitude),
                               rtol=1e-6)
    validation("Describing function of Coulomb friction", "4 Fc / (pi A) against python-control's "
               "numerical first harmonic", np.abs(
                   numeric.real / cd.coulomb_describing_function(force, amplitude) - 1).max(),
               1e-6)
    assert np.all(np.abs(numeric.imag) < 1e-3 * numeric.real)


def test_the_stiction_relay_is_python_controls_hysteresis_relay():
    """Its analytic describing function against python-control's numerical first harmonic."""
    element = control.relay_hysteresis_nonlinearity(2.9, 7.1)
    amplitude = np.array([7.2, 9.0, 15.0])
    analytic = control.describing_function(element, amplitude)
    numeric = control.describing_function(element, amplitude, num_points=20000,
                                          try_method=False)
    np.testing.assert_allclose(numeric, analytic, rtol=2e-3)


def test_the_memoryless_friction_law_predicts_no_limit_cycle_the_stick_slip_relay_does():
    prediction = cd.predict_hunting()
    assert prediction.friction_intersections == ()
    assert prediction.hunts and prediction.in_regime
    assert prediction.slip_jump > prediction.stiffness * 0  # a jump exists
    # inertia carries the slip past the quasi-static re-stick level
    fs = IsolatorParameters().stiction_force
    assert prediction.slip_jump > fs - prediction.steady_restick_force


def test_restick_force_is_the_minimum_of_the_steady_friction_curve():
    isolator = IsolatorParameters()
    v = np.linspace(0, 0.2, 200001)
    curve = (isolator.coulomb_force + (isolator.stiction_force - isolator.coulomb_force)
             * np.exp(-isolator.stribeck_decay * v) + isolator.viscous_damping * v)
    assert cd.restick_force(isolator) == pytest.approx(curve.min(), abs=1e-6)
    flat = IsolatorParameters(stribeck_decay=5.0)  # Cbc*(Fs - Fc) = 45 < Cv: no dip
    assert cd.restick_force(flat) == flat.stiction_force


def test_no_stribeck_dip_no_jump_no_hunting_predicted_and_none_simulated():
    isolator = IsolatorParameters(stribeck_decay=5.0)
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    prediction = cd.predict_hunting(isolator, controller)
    assert prediction.slip_jump == 0.0 and not prediction.hunts
    result = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                          duration=300.0, dt=1e-3, sample_rate=50.0,
                          initial_state=InitialState(relative_position=-0.05))
    late = result.time > 150.0
    assert np.ptp(result.relative_position[late]) < 1e-4  # it settled, no cycle


def test_predicted_hunting_matches_the_simulated_cycle(validation):
    """The relay's plateau d/K and its exact period against the simulator, at rest."""
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    prediction = cd.predict_hunting(isolator, controller)
    result = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                          duration=400.0, dt=1e-3, sample_rate=100.0,
                          initial_state=InitialState(relative_position=-0.06
                                                     + prediction.amplitude))
    late = result.time > 200.0
    zeta = result.relative_position[late] - controller.position_setpoint
    assert 0.5 * np.ptp(zeta) == pytest.approx(prediction.amplitude, rel=0.1)
    locked = result.locked
    breaks = result.time[1:][locked[:-1] & ~locked[1:]]
    period = 2 * np.median(np.diff(breaks[breaks > 200.0]))
    assert period == pytest.approx(prediction.relay_period, rel=0.1)
    validation("Hunting cycle at rest (Kp = 200 N/m, Ki = 80 N/(m s)): plateau",
               "stick-slip relay's plateau d/K against a 400 s simulation",
               abs(0.5 * np.ptp(zeta) / prediction.amplitude - 1), 0.1)
    validation("Hunting cycle at rest: period", "the relay's exact period 4 h K / (Ki d) "
               "against the simulated one", abs(period / prediction.relay_period - 1), 0.1)
    # the describing function's own frequency is the usual square-wave approximation
    assert prediction.period == pytest.approx(period, rel=0.35)


def test_hunting_stiffness_keeps_the_plateau_inside_the_half_width():
    isolator = IsolatorParameters(stiction_force=15.0)
    kp = cd.hunting_stiffness(isolator, ControllerParameters(), 0.02)
    inside = cd.predict_hunting(isolator, ControllerParameters(pi_kp=kp * 1.01))
    outside = cd.predict_hunting(isolator, ControllerParameters(pi_kp=kp * 0.97))
    assert inside.amplitude <= 0.02 < outside.amplitude


# ---------------------------------------------------------------- static design
def test_static_design_numbers_follow_the_spring_law():
    isolator = IsolatorParameters()
    static = cd.static_design(isolator, mass_range=(6.2, 6.6))
    lifted = isolator.spring_force * math.tanh(isolator.spring_shape * 0.060)
    assert static.spring_force_at_setpoint == pytest.approx(lifted, rel=1e-12)
    assert static.static_deficit == pytest.approx(6.4 * 9.81 - lifted, rel=1e-12)
    assert static.motor_force_left == pytest.approx(44.0 - (6.4 * 9.81 - lifted))
    assert static.balanced_mass == pytest.approx(lifted / 9.81)
    assert static.holdable_mass == pytest.approx(((lifted - 44) / 9.81, (lifted + 44) / 9.81))
    # the paper's rig without its 5.5 kg: the spring pushes up beyond what the motor holds
    assert static.moving_mass_without_added == pytest.approx(0.9)
    assert static.deficit_without_added < -isolator.motor_force_max
    assert static.motor_force_left_min == pytest.approx(44.0 - (6.6 * 9.81 - lifted))
    low, high = static.constant_force_band
    assert high == pytest.approx(isolator.constant_force_edge)
    assert 0.5 * (low + high) == pytest.approx(-0.060)


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, words", [
    (lambda: cd.loop_margins(rate=-1.0), "`rate`"),
    (lambda: cd.sampled_loop(rate=0.0), "`rate`"),
    (lambda: cd.loop_margins(delay=float("nan")), "`delay`"),
    (lambda: cd.static_design(mass_range=(7.0, 6.0)), "`mass_range`"),
    (lambda: cd.routh_hurwitz(isolator="x"), "`isolator`"),
    (lambda: cd.hunting_stiffness(half_width=0.0), "`half_width`"),
    (lambda: cd.constant_force_band(controller=ControllerParameters(position_setpoint=0.0)),
     "position_setpoint"),
    (lambda: cd.stability_margins_of(control.tf([1], [1, -1], 0.1), delay=0.1), "`delay`"),
])
def test_bad_input_names_the_argument(call, words):
    with pytest.raises(ParameterError, match=words):
        call()
