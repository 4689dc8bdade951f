"""The C model and the FMU evaluate the MagSpring's tanh only: another law is refused, not run
as the tanh (docs/model.md §3.1)."""
import pytest

from qzs.errors import ParameterError
from qzs.export.cmodel import simulate_c
from qzs.model.excitation import Sine
from qzs.model.isolator import IsolatorParameters
from qzs.model.springs import ObliqueSpringQZS


def test_the_c_model_refuses_another_law_naming_the_fix():
    with pytest.raises(ParameterError, match=r"`spring` \(oblique-spring QZS.*\) is not supported "
                                             r"by the C model yet.*spring=None or a TanhSpring"):
        simulate_c(Sine(amplitude=1e-3, frequency=2.0), IsolatorParameters(
            spring=ObliqueSpringQZS()), duration=0.01)
