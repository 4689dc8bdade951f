"""One case of a study (qzs.workflows.paper.cases): its inputs, its run, its analysis."""
import types

import numpy as np
import pytest

from qzs.model.excitation import Chirp
from qzs.workflows.paper.cases import _locked_below, _spring_case
from qzs.workflows.paper.studies import load_study


def test_locked_fraction_is_taken_below_the_frequency():
    """The chirp is below 0.5 Hz for its first 2.5 s; only then is the payload locked."""
    chirp = Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=100.0)
    time = np.arange(0.0, 100.0, 0.01)
    run = types.SimpleNamespace(time=time, locked=time < 2.5)
    assert _locked_below(run, chirp, 0.5) == pytest.approx(1.0)
    run = types.SimpleNamespace(time=time, locked=time >= 2.5)
    assert _locked_below(run, chirp, 0.5) == pytest.approx(0.0)
    run = types.SimpleNamespace(time=time, locked=time < 1.25)
    assert _locked_below(run, chirp, 0.5) == pytest.approx(0.5)


def test_the_spring_study_reports_the_fitted_law_s_parameters_not_the_true_ones():
    """The spring study's metrics of another law are the fit's numbers by their registry names
    (``spring.c<k>``, docs/model.md §3.1), which the noise moves off the law measured."""
    import qzs
    from qzs.workflows.paper.studies import _study_cases

    law = qzs.PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4), center=-0.06)
    task = _study_cases(load_study("spring"), True, None, law)[0]
    result = _spring_case(task)
    fit = result.extra["law_fit"]
    for k, truth in enumerate(law.coefficients):
        assert result.metrics[f"spring.c{k}"] == fit.parameters[f"c{k}"]
        assert result.metrics[f"spring.c{k}"] != truth
    assert result.metrics["spring.center"] == -0.06
    assert result.metrics["spring_residual_rms"] == fit.residual_rms
