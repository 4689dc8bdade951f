"""The static design at the setpoint against the spring law ``F = a*tanh(b*z)``."""
import math

import pytest

from qzs import ControllerParameters, IsolatorParameters, ParameterError
from qzs.analysis import control_design as cd


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


@pytest.mark.parametrize("call, words", [
    (lambda: cd.static_design(mass_range=(7.0, 6.0)), "`mass_range`"),
    (lambda: cd.constant_force_band(controller=ControllerParameters(position_setpoint=0.0)),
     "position_setpoint"),
])
def test_bad_input_names_the_argument(call, words):
    with pytest.raises(ParameterError, match=words):
        call()
