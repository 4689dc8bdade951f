"""The loop at the motor force with a user's controller: continuous, sampled, hybrid.

The general sampled loop (the plant held and read at the samples, its delay line built
anew) against the PI + damping one of ``discretize_with_delay``; the exact sampled
transmissibility against the simulated steady state of a discrete lead-lag, of a sampled PI
+ damping around a continuous lead-lag, and of both sampled with an acceleration feedback
(which reads the acceleration with PI + damping's new force, as the simulator does).
"""
import math

import control
import numpy as np
import pytest
from helpers import lead_lag, linear_isolator, steady_transmissibility

from qzs import FrictionCompensation, LinearController, ParameterError, PIDamping
from qzs.analysis import control_design as cd

NOTHING = FrictionCompensation(fraction=0.0)  # a block that adds nothing: the general path


def acceleration_feedback(sample_time):
    """``F = -5 kg * y_acc`` through a 50 Hz first-order low-pass, held every ``sample_time``."""
    corner = 2 * math.pi * 50.0
    system = control.c2d(control.tf([-5.0 * corner], [1.0, corner]), sample_time, "zoh")
    return LinearController.from_system(system, inputs=("payload_acceleration",))


@pytest.mark.parametrize("rate, delay", [(1000.0, 0.0), (200.0, 0.3e-3), (200.0, 8.5e-3),
                                         (50.0, 20e-3)])
def test_the_general_sampled_loop_is_the_pi_and_damping_one(rate, delay, validation):
    """Two constructions of ``L(z)``: the held plant with its own delay line, and the
    modified z-transform of ``discretize_with_delay`` times the PI + damping row."""
    controller = PIDamping(damping_gain=100.0, pi_ki=20.0)
    omega = np.logspace(-3, math.log10(math.pi * rate * 0.999), 60)
    reference = cd.frequency_response(cd.sampled_loop(None, controller, rate, delay), omega)
    general = cd.frequency_response(cd.sampled_loop(None, controller + NOTHING, rate, delay),
                                    omega)
    error = np.max(np.abs(general / reference - 1))
    assert error < 1e-9
    validation(f"Sampled loop with blocks at {rate:g} Hz, delay {delay * 1e3:g} ms",
               "PI + damping's sampled loop (discretize_with_delay)", error, 1e-9)


def test_the_exact_sampled_transmissibility_approaches_the_approximation_and_the_continuous():
    controller = PIDamping(damping_gain=100.0)
    f = np.array([0.5, 2.0, 5.0])
    exact = cd.sampled_transmissibility(f, controller=controller, rate=1000.0, exact=True)
    np.testing.assert_array_equal(
        exact, cd.sampled_transmissibility(f, controller=controller + NOTHING, rate=1000.0))
    approximate = cd.sampled_transmissibility(f, controller=controller, rate=1000.0)
    assert np.max(np.abs(exact / approximate - 1)) < 1e-4  # well below the Nyquist frequency
    assert np.max(np.abs(exact / approximate - 1)) > 1e-7  # but not the same formula
    fast = cd.sampled_transmissibility(f, controller=controller, rate=1e6, exact=True)
    np.testing.assert_allclose(fast, cd.sampled_transmissibility(
        f, controller=controller + NOTHING, rate=0.0), rtol=1e-5)


def test_a_discrete_linear_pi_and_damping_is_the_sampled_pi_and_damping():
    """The forward-Euler PI + damping as a discrete LinearController (a continuous PIDamping
    of zero gains around it) has the sampled PIDamping's loop and transmissibility."""
    period = 1e-3
    sampled = PIDamping(damping_gain=20.0, controller_rate=1 / period)
    as_linear = LinearController(a=[[1.0]], b=[[period, 0.0]], c=[sampled.pi_ki],
                                 d=[sampled.pi_kp, -sampled.damping_gain],
                                 inputs=("position_error", "measured_payload_velocity"),
                                 sample_time=period)
    controller = PIDamping(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0) + as_linear
    omega = np.logspace(-2, 3, 40)
    np.testing.assert_allclose(cd.frequency_response(cd.sampled_loop(controller=controller),
                                                     omega),
                               cd.frequency_response(cd.sampled_loop(controller=sampled), omega),
                               rtol=1e-9)
    f = np.array([1.0, 10.0, 100.0])
    np.testing.assert_allclose(cd.sampled_transmissibility(f, controller=controller),
                               cd.sampled_transmissibility(f, controller=sampled, exact=True),
                               rtol=1e-10)


#: name: (controller, what it is); PI + damping continuous unless sampled at 1 kHz.
HYBRIDS = {
    "discrete lead-lag": (PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0,
                                    damping_gain=0.0) + lead_lag(1e-3),
                          "continuous PI, the lead-lag at 1 kHz"),
    "continuous lead-lag": (PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0,
                                      damping_gain=20.0, controller_rate=1000.0) + lead_lag(),
                            "PI + damping at 1 kHz, the lead-lag continuous"),
    "acceleration feedback": (PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0,
                                        damping_gain=20.0, controller_rate=1000.0)
                              + acceleration_feedback(1e-3),
                              "PI + damping and an acceleration feedback, both at 1 kHz"),
}


@pytest.mark.parametrize("frequency", [2.0, 5.0, 10.0])
@pytest.mark.parametrize("name", list(HYBRIDS))
def test_simulated_transmissibility_is_the_sampled_loops_closed_form(name, frequency,
                                                                      validation):
    """Frictionless, no stop, linear spring; ``1/(T f)`` a whole number, so the components
    the hold adds lie at other harmonics and the fundamental is the closed form's."""
    controller, what = HYBRIDS[name]
    isolator = linear_isolator()
    expected = float(cd.sampled_transmissibility(frequency, isolator, controller))
    simulated = steady_transmissibility(frequency, isolator, controller)
    assert simulated == pytest.approx(expected, rel=1e-4)
    assert cd.loop_margins(isolator, controller).stable
    validation(f"Simulated steady state, {what}, {frequency:g} Hz",
               "the sampled-data loop's exact response at the excitation frequency",
               abs(simulated / expected - 1), 1e-4)


def test_simulated_transmissibility_with_a_sampled_friction_observer():
    """Half the viscous friction compensated, the rest observed (10 Hz), sampled at 1 kHz."""
    isolator = linear_isolator()
    controller = PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0, damping_gain=100.0,
                           velocity_highpass=0.0, controller_rate=1000.0) + FrictionCompensation(
        fraction=0.5, observer_bandwidth=10.0)
    expected = float(cd.sampled_transmissibility(2.0, isolator, controller))
    assert steady_transmissibility(2.0, isolator, controller) == pytest.approx(expected,
                                                                               rel=1e-4)


def test_the_continuous_loop_is_minus_the_controller_times_the_plant():
    """``L(jw) = -K(jw) P(jw)``: a lead-lag on the measured velocity of a plant with Kp."""
    isolator = linear_isolator(stiffness=100.0, damping=100.0, mass=6.4)
    controller = PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=0.0, damping_gain=0.0,
                           velocity_highpass=1.0) + lead_lag()
    s = 1j * np.array([0.1, 1.0, 10.0, 100.0])
    plant = 1 / (6.4 * s ** 2 + 100.0 * s + 100.0)
    lead = -50.0 * (1 + s / (4 * math.pi)) / (1 + s / (40 * math.pi))
    expected = 50.0 * plant - lead * s * s / (s + 2 * math.pi) * plant
    np.testing.assert_allclose(cd.frequency_response(cd.loop_transfer(isolator, controller),
                                                     s.imag), expected, rtol=1e-8)


def test_bad_input_names_the_argument():
    two_rates = PIDamping(controller_rate=500.0) + lead_lag(1e-3)
    with pytest.raises(ParameterError, match=r"two rates.*`rate` = 1000 Hz"):
        cd.sampled_loop(controller=two_rates)
    with pytest.raises(ParameterError, match="`rate` must be positive"):
        cd.sampled_loop(controller=PIDamping() + NOTHING, rate=0.0)
    with pytest.raises(ParameterError, match=r"`controller` has a discrete"):
        cd.loop_transfer(controller=PIDamping() + lead_lag(1e-3))
    with pytest.raises(ParameterError, match="`delay`"):
        cd.sampled_loop(controller=PIDamping(controller_rate=100.0) + NOTHING, delay=-1.0)
    with pytest.raises(ParameterError, match="`exact` must be True or False"):
        cd.sampled_transmissibility(1.0, exact="yes")
    with pytest.raises(ParameterError, match=r"`controller` has a discrete.*its own sample"):
        cd.required_controller_rate(controller=PIDamping() + lead_lag(1e-3))
