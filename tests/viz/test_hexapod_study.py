"""The hexapod study's comparison (qzs.viz.hexapod_study): each case's entry on its trusted
bins, its linear model only where its loop is stable, the units of a cross-axis entry."""
from types import SimpleNamespace

import numpy as np
import pytest

from qzs.viz.hexapod_study import plot_study_comparison

F = np.linspace(0.0, 20.0, 81)


def case(scale, trusted_from, linear_stable):
    response = np.zeros((F.size, 6, 6), complex)
    for k in range(6):
        response[:, k, k] = scale / (1.0 + 1j * F)
    response[:, 4, 0] = 0.3 * scale / (1.0 + F)          # ry per x: rad/m
    trusted = np.broadcast_to((F >= trusted_from)[:, None, None], response.shape).copy()
    return SimpleNamespace(frequency=F, response=response, trusted=trusted,
                           coherence=np.full(response.shape, 0.95), linear_stable=linear_stable,
                           linear_response=1.1 * response)


def test_each_case_draws_its_trusted_bins_and_a_stable_loops_linear_model():
    cases = [("PI", case(1.0, 1.0, True)), ("no loop", case(2.0, 3.0, False))]
    figure = plot_study_comparison(cases, entries=[[(0, 0), (4, 0)]], frequency_range=(0.1, 20.0))
    diagonal, cross, coherence = figure.axes
    for k, (label, result) in enumerate(cases):
        (solid,) = [line for line in diagonal.lines
                    if line.get_label() == f"{label}: simulated (trusted)"]
        expected = np.where(result.trusted[:, 0, 0], 20 * np.log10(np.abs(result.response[:, 0, 0])),
                            np.nan)
        np.testing.assert_allclose(solid.get_ydata(), expected, rtol=1e-13)
    linear = [line.get_label() for line in diagonal.lines if line.get_linestyle() == "--"]
    assert linear == ["PI: linear model"]      # the unstable loop's model is left out
    assert cross.get_title() == "platform ry per base x: cross-axis response [rad/m]"
    assert diagonal.get_title() == "platform x per base x: transmissibility [-]"
    assert coherence.get_ylabel() == "coherence x/x [-]"


@pytest.mark.parametrize("scale", [None, "linear"])
def test_the_comparison_draws_frequency_log_by_default(frequency_axes, scale):
    cases = [("PI", case(1.0, 1.0, True))]
    figure = plot_study_comparison(cases, entries=[[(0, 0)]], frequency_range=(0.1, 20.0),
                                   frequency_scale=scale)
    frequency_axes(figure.axes, scale or "log")
    assert figure.axes[0].get_xlim() == pytest.approx((0.1, 20.0))
