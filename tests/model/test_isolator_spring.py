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
