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


OFF_CENTRE = PlatformParameters(mass=22.0, inertia=np.diag([0.5, 0.5, 0.5]),
                                center_of_mass=(0.05, 0.0, 0.0))


def test_each_leg_s_law_is_checked_against_its_own_load():
    """A centre of mass off the axis loads the legs unequally (about 88, 62 and 37 N): a law
    holding leg 4's 37 N near the setpoint is taken there, and refused on leg 3, whose 62 N
    would put its equilibrium 0.25 m below, naming leg 3."""
    loads = static_leg_forces(GEOMETRY, OFF_CENTRE)
    assert loads[3] < loads[2] - 20.0 and loads[2] < loads[0] - 20.0
    light = PolynomialSpring(coefficients=(loads[3] + 1.0, -100.0), center=-0.06)
    legs = [IsolatorParameters()] * 6
    check_hexapod_run(GEOMETRY, OFF_CENTRE, legs[:3] + [IsolatorParameters(spring=light)]
                      + legs[4:], NO_INTEGRAL, duration=1.0)
    with pytest.raises(ParameterError, match=r"leg 3: `spring`: .*static load along the leg"):
        check_hexapod_run(GEOMETRY, OFF_CENTRE, legs[:2] + [IsolatorParameters(spring=light)]
                          + legs[3:], NO_INTEGRAL, duration=1.0)


def test_each_leg_s_pi_preload_is_its_load_less_its_own_spring_at_the_setpoint():
    """docs/model.md §5 per leg: the PI integral starts with the leg's static load less what
    that leg's own law gives at the setpoint (a polynomial 7 N above the tanh's there on leg
    3, the oblique QZS on leg 5), so each motor starts at its own share, the base at rest."""
    from qzs import Sine
    from qzs.engine.hexapod import simulate_hexapod
    from qzs.model.isolator import spring_force

    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
    tanh = IsolatorParameters()
    above = float(spring_force(controller.position_setpoint, tanh)) + 7.0
    legs = [tanh, tanh, IsolatorParameters(spring=PolynomialSpring(coefficients=(above, -200.0),
                                                                   center=-0.06)),
            tanh, IsolatorParameters(spring=ObliqueSpringQZS()), tanh]
    result = simulate_hexapod(GEOMETRY, OFF_CENTRE, legs, controller,
                              excitation={"z": Sine(amplitude=0.001, frequency=2.0)},
                              duration=0.01)
    loads = static_leg_forces(GEOMETRY, OFF_CENTRE)
    springs = [float(spring_force(controller.position_setpoint, leg)) for leg in legs]
    assert springs[2] == pytest.approx(springs[0] + 7.0, rel=1e-12)
    np.testing.assert_allclose(result["pi_force"][0], loads - springs, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(result["spring_force"][0], springs, rtol=1e-12)
