"""The six legs take any spring law; one that cannot hold a leg's static load in its stroke
is refused before the run, as the single axis refuses one that cannot hold the payload."""
import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters
from qzs.engine.hexapod.prepare import check_hexapod_run
from qzs.errors import ParameterError
from qzs.model.hexapod import PlatformParameters, cubic_geometry, static_leg_forces
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring

GEOMETRY = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
PLATFORM = PlatformParameters(mass=22.0, inertia=np.diag([0.5, 0.5, 0.5]))
NO_INTEGRAL = ControllerParameters(pi_ki=0.0)


def test_every_law_is_taken_leg_by_leg():
    legs = [IsolatorParameters()] * 5 + [IsolatorParameters(spring=ObliqueSpringQZS())]
    check_hexapod_run(GEOMETRY, PLATFORM, legs, ControllerParameters(), duration=1.0)
    check_hexapod_run(GEOMETRY, PLATFORM, IsolatorParameters(spring=TanhSpring()),
                      ControllerParameters(), duration=1.0)


def test_a_law_that_cannot_hold_the_leg_s_load_is_refused_naming_the_leg():
    """Without an integral, a spring of 10 N and 100 N/m about the setpoint has its
    equilibrium for a leg's load (about 62 N along a cubic leg: a sixth of the weight over
    cos 54.7 deg) 0.5 m below it, beyond the 0.08 m stroke: refused, leg 4 and `spring`
    named; the spring 1 N above the load at the setpoint, holding it 10 mm above, is taken."""
    load = static_leg_forces(GEOMETRY, PLATFORM)[3]
    assert 55.0 < load < 70.0
    weak = PolynomialSpring(coefficients=(10.0, -100.0), center=-0.06)
    legs = [IsolatorParameters()] * 3 + [IsolatorParameters(spring=weak)] + \
        [IsolatorParameters()] * 2
    with pytest.raises(ParameterError, match=r"leg 4: `spring`: .*static load along the leg") \
            as error:
        check_hexapod_run(GEOMETRY, PLATFORM, legs, NO_INTEGRAL, duration=1.0)
    assert "spring" in error.value.options
    holding = PolynomialSpring(coefficients=(load + 1.0, -100.0), center=-0.06)  # at -0.05 m
    check_hexapod_run(GEOMETRY, PLATFORM, [IsolatorParameters(spring=holding)] * 6,
                      NO_INTEGRAL, duration=1.0)


def test_a_refusing_table_narrower_than_the_stroke_is_refused_without_an_integral():
    """The stroke [-0.14, 0.02] m reaches past a refusing table over [-0.1, 0.0] m: refused,
    as the single axis refuses it; the same table extended beyond its ends is taken."""
    positions = np.linspace(-0.1, 0.0, 41)
    for outside, refused in (("refuse", True), ("extend", False)):
        table = TabulatedSpring.from_law(ObliqueSpringQZS(), positions,
                                         outside=outside)
        legs = IsolatorParameters(spring=table)
        if refused:
            with pytest.raises(ParameterError, match=r"leg 1: `spring`: .*stroke"):
                check_hexapod_run(GEOMETRY, PLATFORM, legs, NO_INTEGRAL, duration=1.0)
        else:
            check_hexapod_run(GEOMETRY, PLATFORM, legs, NO_INTEGRAL, duration=1.0)
