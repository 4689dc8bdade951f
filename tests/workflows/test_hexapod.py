"""Six-axis set-ups (qzs.workflows.hexapod): the payload the MagSprings hold, in closed form for
the cubic configuration, and the shipped platform carrying exactly that."""
import math

import pytest

from qzs import ControllerParameters, IsolatorParameters
from qzs.model.hexapod import cubic_geometry
from qzs.model.isolator import spring_force
from qzs.workflows.hexapod import (SHIPPED_DEFAULT, default_cube_center_height, load_hexapod,
                                   supported_mass)


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


@pytest.mark.parametrize("tables, message", [
    ('[platform]\nmass = "heavy"\n', r"`\[platform\] mass` must be a number, got 'heavy'; "
                                      r"give a number in kg, e.g. mass = 21.5"),
    ('[platform]\ngravity = "g"\n', r"`\[platform\] gravity` must be a number, got 'g'"),
    ('[platform]\nprincipal_inertia = ["a", "b", "c"]\n', r"`principal_inertia` must be 3"),
])
def test_a_hexapod_file_with_text_for_a_number_names_the_table_and_key(tmp_path, tables,
                                                                       message):
    from qzs.errors import ParameterError

    path = tmp_path / "bad.toml"
    path.write_text('[geometry]\nkind = "cubic"\ncube_edge = 0.15\n' + tables)
    with pytest.raises(ParameterError, match=message) as caught:
        load_hexapod(path)
    assert str(path) in str(caught.value)


@pytest.mark.parametrize("geometry, message", [
    ('kind = "cubic"\ncube_edge = "big"\n', r"`\[geometry\] cube_edge` must be a number"),
    ('kind = "radial"\nbase_radius = 0.1\ntop_radius = 0.1\nheight = 0.1\n'
     'base_angle = "x"\ntop_angle = 10\n', r"`\[geometry\] base_angle` must be a number"),
])
def test_a_geometry_with_text_for_a_number_names_the_key(tmp_path, geometry, message):
    from qzs.errors import ParameterError

    path = tmp_path / "bad.toml"
    path.write_text("[geometry]\n" + geometry)
    with pytest.raises(ParameterError, match=message):
        load_hexapod(path)
