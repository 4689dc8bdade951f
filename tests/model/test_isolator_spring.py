"""IsolatorParameters takes a spring law (docs/model.md §3.1): the tanh's fields stay its own."""
import pytest

from qzs.errors import ParameterError
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS
from qzs.model.springs import ObliqueSpringQZS, TanhSpring


def test_the_default_law_is_the_magsprings_tanh_of_the_fields():
    iso = IsolatorParameters(spring_force=55.0, spring_shape=70.0)
    assert iso.spring is None
    assert iso.spring_law == TanhSpring(plateau=55.0, shape=70.0)
    assert "spring" not in iso.to_dict() and "spring" not in PARAMETERS


def test_a_tanh_law_sets_the_fields_and_a_disagreeing_field_is_refused():
    iso = IsolatorParameters(spring=TanhSpring(plateau=55.0, shape=70.0))
    assert (iso.spring_force, iso.spring_shape) == (55.0, 70.0)
    agreeing = IsolatorParameters(spring=TanhSpring(plateau=55.0), spring_force=55.0)
    assert agreeing.spring_force == 55.0
    with pytest.raises(ParameterError, match=r"`spring_shape` \(70.0\) disagree") as error:
        IsolatorParameters(spring=TanhSpring(shape=80.0), spring_shape=70.0)
    assert error.value.options == ("spring", "spring_shape")


def test_another_law_is_kept_and_written_as_its_dict():
    law = ObliqueSpringQZS()
    iso = IsolatorParameters(spring=law)
    assert iso.spring_law is law
    assert iso.to_dict()["spring"] == {"law": "oblique", **{k: v for k, v in law.to_dict().items()
                                                         if k != "law"}}


def test_a_spring_that_is_no_law_is_refused():
    with pytest.raises(ParameterError, match=r"`spring` must be a spring law .* got 3.0") as error:
        IsolatorParameters(spring=3.0)
    assert error.value.options == ("spring",)


def test_the_model_functions_follow_the_isolators_law():
    """spring_force, spring_stiffness and spring_energy are the law's where the isolator has
    one (what linearisation, summaries and static checks read), the tanh of the fields bit for
    bit where it has the tanh (set or default)."""
    import numpy as np

    from qzs.model.isolator import spring_energy, spring_force, spring_stiffness
    from qzs.model.springs import PolynomialSpring

    z = np.linspace(-0.09, -0.03, 7)
    duffing = PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5.0e4), center=-0.06)
    iso = IsolatorParameters(spring=duffing)
    u = z + 0.06
    np.testing.assert_allclose(spring_force(z, iso), 62.78 - 100.0 * u - 5.0e4 * u ** 3,
                               rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(spring_stiffness(z, iso), 100.0 + 1.5e5 * u ** 2, rtol=1e-13)
    np.testing.assert_allclose(spring_energy(z, iso),
                               -(62.78 * u - 50.0 * u ** 2 - 1.25e4 * u ** 4), rtol=1e-12,
                               atol=1e-15)
    default, named = IsolatorParameters(), IsolatorParameters(spring=TanhSpring())
    for function in (spring_force, spring_stiffness, spring_energy):
        expected = function(z, default)
        assert np.array_equal(function(z, named), expected)
        assert np.array_equal(expected, function(z, IsolatorParameters(spring=None)))
    assert np.array_equal(spring_force(z, default), -60.84 * np.tanh(78.10 * z))
