"""The loop at the motor force: exact sampling with a delay, and the sampled transmissibility.

The zero-order hold of a delayed integrator against its modified z-transform; the sampled
loop's transmissibility far below the rate against the continuous linear model's.
"""
import math

import numpy as np
import pytest

import qzs
from helpers import linear_controller, linear_isolator
from qzs import ControllerParameters, ParameterError
from qzs.analysis import control_design as cd


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


def test_the_sampled_loop_matches_the_simulators_controller_at_low_frequency():
    """At frequencies far below the rate the sampled transmissibility is the continuous one."""
    controller = ControllerParameters(damping_gain=100.0)
    f = np.array([1.0, 3.0, 10.0])
    sampled = cd.sampled_transmissibility(f, controller=controller, rate=1e5)
    continuous = qzs.linearize(controller=controller).transmissibility(f)
    np.testing.assert_allclose(sampled, continuous, rtol=1e-3)


def test_the_loop_transfer_is_the_plant_times_the_controller_on_the_imaginary_axis():
    """``L(jw)`` of python-control against the formula evaluated by hand.

    A linear spring of 100 N/m, 100 N*s/m of damping and 6.4 kg (tests/helpers.py), PI and
    high-passed velocity feedback with a 1 Hz corner.
    """
    isolator = linear_isolator(stiffness=100.0, damping=100.0, mass=6.4)
    controller = linear_controller(pi_kp=50.0, pi_ki=20.0, damping_gain=40.0,
                                   velocity_highpass=1.0)
    s = 1j * np.array([0.1, 1.0, 10.0, 100.0])
    plant = 1 / (6.4 * s ** 2 + 100.0 * s + 100.0)
    expected = (50.0 + 20.0 / s) * plant + 40.0 * s * s / (s + 2 * math.pi) * plant
    loop = cd.loop_transfer(isolator, controller)
    np.testing.assert_allclose(cd.frequency_response(loop, s.imag), expected, rtol=1e-6)


@pytest.mark.parametrize("call, words", [
    (lambda: cd.sampled_loop(rate=0.0), "`rate`"),
    (lambda: cd.discretize_with_delay([[0.0]], [[1.0]], [[1.0]], 0.0), "`period`"),
    (lambda: cd.loop_transfer(delay=-1.0), "`delay`"),
])
def test_bad_input_names_the_argument(call, words):
    with pytest.raises(ParameterError, match=words):
        call()
