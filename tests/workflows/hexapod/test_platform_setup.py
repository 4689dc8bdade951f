"""The set-up object and its defaults (qzs.workflows.hexapod.platform_setup): the payload the
MagSprings hold, in closed form for the cubic configuration, and the shipped platform carrying
exactly that."""
import math

import pytest

from qzs import ControllerParameters, IsolatorParameters
from qzs.model.hexapod import cubic_geometry
from qzs.model.isolator import spring_force
from qzs.workflows.hexapod.platform_setup import default_cube_center_height, supported_mass
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod


def test_the_cubic_legs_hold_six_spring_forces_at_the_cube_angle():
    """Each leg of a cube standing on a vertex is at arccos(1/sqrt(3)) = 54.7 deg from the
    vertical: six springs of force F hold 6 F / sqrt(3) = 2 sqrt(3) F of weight."""
    isolator, controller = IsolatorParameters(), ControllerParameters()
    force = float(spring_force(controller.position_setpoint, isolator))
    geometry = cubic_geometry(cube_edge=0.15,
                              cube_center_height=default_cube_center_height(0.15))
    expected = 2 * math.sqrt(3) * force / 9.81
    assert supported_mass(geometry, isolator, controller, gravity=9.81) == pytest.approx(
        expected, rel=1e-12)
    assert supported_mass(geometry, gravity=3.0) == pytest.approx(expected * 9.81 / 3.0,
                                                                  rel=1e-12)
    setup = load_hexapod(SHIPPED_DEFAULT)   # "the payload their MagSprings hold"
    assert setup.platform.mass == pytest.approx(2 * math.sqrt(3) * force / setup.platform.gravity,
                                                rel=1e-12)
