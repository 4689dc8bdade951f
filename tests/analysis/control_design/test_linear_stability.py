"""Routh-Hurwitz bounds on the gains against the gain where python-control's poles cross.

The closed-form limits of :mod:`qzs.analysis.control_design.linear_stability` (largest
integral gain, the damping gain's range with the high-pass, the least proportional gain on
a spring of zero stiffness) against the gain at which the closed loop's poles, found by
python-control, cross the imaginary axis.
"""
import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from qzs import ControllerParameters, IsolatorParameters, ParameterError
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


def test_the_characteristic_polynomial_has_the_closed_form_coefficients():
    """The quartic of the module's text, coefficient by coefficient, and its degrees."""
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=5.0, pi_ki=2.0, damping_gain=30.0,
                                      velocity_highpass=1.0)
    m, cv = isolator.mass, isolator.viscous_damping
    k = float(spring_stiffness(controller.position_setpoint, isolator))
    w = 2 * math.pi * 1.0
    expected = [m, m * w + cv + 30.0, cv * w + k + 5.0, (k + 5.0) * w + 2.0, 2.0 * w]
    np.testing.assert_allclose(cd.characteristic_polynomial(isolator, controller), expected,
                               rtol=1e-14)
    no_integral = dataclasses.replace(controller, pi_ki=0.0, velocity_highpass=0.0)
    assert len(cd.characteristic_polynomial(isolator, no_integral)) == 3


def test_bad_input_names_the_argument():
    with pytest.raises(ParameterError, match="`isolator`"):
        cd.routh_hurwitz(isolator="x")
