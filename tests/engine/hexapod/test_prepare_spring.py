"""The six legs evaluate the MagSpring's tanh only: another law is refused, naming the fix."""
import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters
from qzs.engine.hexapod.prepare import check_hexapod_run
from qzs.errors import ParameterError
from qzs.model.hexapod import PlatformParameters, cubic_geometry
from qzs.model.springs import ObliqueSpringQZS, TanhSpring


GEOMETRY = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
PLATFORM = PlatformParameters(mass=22.0, inertia=np.diag([0.5, 0.5, 0.5]))


def test_a_leg_with_another_law_is_refused_and_a_tanh_law_is_not():
    legs = [IsolatorParameters()] * 5 + [IsolatorParameters(spring=ObliqueSpringQZS())]
    with pytest.raises(ParameterError, match=r"leg 6: `spring` \(oblique-spring QZS.*\) is not "
                                             r"supported by the hexapod yet.*TanhSpring"):
        check_hexapod_run(GEOMETRY, PLATFORM, legs, ControllerParameters(),
                          duration=1.0)
    check_hexapod_run(GEOMETRY, PLATFORM,
                      IsolatorParameters(spring=TanhSpring()), ControllerParameters(),
                      duration=1.0)
