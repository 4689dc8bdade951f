"""The smooth model of harmonic balance with a spring law (issue 41): it carries the
isolator's law and evaluates it, the tanh's arithmetic untouched, NaN outside a refusing
table."""
import dataclasses

import numpy as np
import pytest

from qzs import IsolatorParameters, ParameterError
from qzs.analysis.harmonic_balance import SmoothModel, smooth_right_hand_side
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring

DUFFING = PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4), center=-0.06)


def test_the_model_carries_the_isolators_law_and_evaluates_it():
    model = SmoothModel.from_parameters(IsolatorParameters(spring=DUFFING), amplitude=0.005)
    assert model.spring_law == DUFFING
    z = np.linspace(-0.14, 0.02, 321)
    force, slope = model.spring(z)
    u = z + 0.06
    assert np.allclose(force, 62.78 - 100.0 * u - 5e4 * u ** 3, rtol=1e-14, atol=1e-12)
    assert np.allclose(slope, -100.0 - 1.5e5 * u ** 2, rtol=1e-14, atol=1e-12)
    # the ODE's spring is the law's too: at rest at the centre the constant carries 62.78 N
    state = np.array([-0.06, 0.0, 0.0, 0.0])
    acceleration = smooth_right_hand_side(0.25, state, 1.0, model)[1]
    expected = (62.78 - model.mass * model.gravity) / model.mass  # base at rest at t = T/4
    assert acceleration == pytest.approx(expected, rel=1e-12)


def test_the_tanh_stays_the_fields_and_a_tanh_law_is_the_same_model():
    default = SmoothModel.from_parameters(IsolatorParameters(), amplitude=0.005)
    assert default.spring_law is None
    as_law = SmoothModel.from_parameters(IsolatorParameters(spring=TanhSpring()), amplitude=0.005)
    assert as_law == default
    direct = dataclasses.replace(default, spring_law=TanhSpring())
    assert direct.spring_law is None and direct == default


@pytest.mark.parametrize("law, names", [
    (TanhSpring(plateau=50.0), ("spring_law", "spring_force", "spring_shape")),
    (TanhSpring(shape=70.0), ("spring_law", "spring_force", "spring_shape")),  # shape alone
    ("oblique", ("spring_law",)),
])
def test_a_law_that_is_none_or_disagrees_with_the_fields_is_refused(law, names):
    model = SmoothModel.from_parameters(amplitude=0.005)
    with pytest.raises(ParameterError, match="spring_law") as error:
        dataclasses.replace(model, spring_law=law)
    assert error.value.options == names


def test_a_refusing_table_is_nan_outside_so_newton_backs_off_instead_of_raising():
    table = TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.1, -0.02, 81))
    model = SmoothModel.from_parameters(IsolatorParameters(spring=table), amplitude=0.005)
    z = np.array([-0.11, -0.1, -0.06, -0.02, -0.01, np.nan])
    force, slope = model.spring(z)
    inside = np.array([False, True, True, True, False, False])
    assert np.all(np.isnan(force[~inside])) and np.all(np.isnan(slope[~inside]))
    assert np.array_equal(force[inside], table.force(z[inside]))
    assert np.array_equal(slope[inside], -table.stiffness(z[inside]))
    extending = dataclasses.replace(table, outside="extend")
    model = SmoothModel.from_parameters(IsolatorParameters(spring=extending), amplitude=0.005)
    assert np.array_equal(model.spring(z[:-1])[0], extending.force(z[:-1]))
