"""The verdict's labels and the band transmissibility of a case."""
import math

import numpy as np
import pytest

from qzs.workflows.questions.common import Answer, CaseCurve, band_transmissibility


def test_an_answer_refuses_an_unknown_label():
    with pytest.raises(ValueError, match="label"):
        Answer("q", "s", "maybe", "a", "e")
    assert Answer("q", "s", "partly", "a", "e").to_dict()["label"] == "partly"


def test_the_band_transmissibility_is_the_rms_over_the_trusted_bins():
    f = np.array([0.5, 1.0, 2.0, 3.0, 4.0])
    t = np.array([9.0, 3.0, 4.0, 0.0, 9.0])
    trusted = np.array([True, True, True, False, True])
    curve = CaseCurve("c", f, t, trusted)
    assert band_transmissibility(curve, (1.0, 3.0)) == pytest.approx(math.sqrt((9 + 16) / 2))


@pytest.mark.parametrize("dt", [0.0, -1e-4, float("nan"), "1e-4", True])
def test_a_bad_step_is_refused_naming_dt(dt):
    from qzs.errors import ParameterError
    from qzs.workflows.questions.common import check_step

    with pytest.raises(ParameterError, match="`dt`"):
        check_step(dt)
