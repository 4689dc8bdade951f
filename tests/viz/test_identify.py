"""Figures of the identification (qzs.viz.identify): the spring fit's curve is the tanh law
with the fitted coefficients, over the measured span."""
import numpy as np

from qzs.viz.identify import plot_spring_fit, plot_spring_law_fit


def test_the_spring_fit_draws_the_measured_points_and_the_fitted_tanh():
    z = np.linspace(-0.05, 0.02, 15)
    force = -60.0 * np.tanh(35.0 * z) + 0.1 * np.sin(40 * z)
    figure = plot_spring_fit(z, force, 60.5, 34.0)
    points, fit = figure.axes[0].lines
    np.testing.assert_array_equal(points.get_xdata(), z * 1e3)
    np.testing.assert_array_equal(points.get_ydata(), force)
    x = fit.get_xdata() / 1e3
    assert (x[0], x[-1]) == (z.min(), z.max())
    np.testing.assert_allclose(fit.get_ydata(), -60.5 * np.tanh(34.0 * x), rtol=1e-12)
    assert fit.get_label() == "fit: a = 60.50 N, b = 34.00 1/m"
    assert figure.axes[0].get_xlabel() == "relative position z [mm]"


def test_a_spring_law_fit_draws_the_data_every_candidate_and_the_residuals():
    from qzs.identify import fit_spring
    from qzs.model.springs import PolynomialSpring

    z = np.linspace(-0.1, 0.1, 41)
    force = PolynomialSpring(coefficients=(5.0, -300.0, 0.0, -2e5)).force(z) + 0.2 * np.sin(90 * z)
    fit = fit_spring(z, force, law="best")
    top, bottom = plot_spring_law_fit(fit, title="cubic").axes
    points, *curves = top.lines
    np.testing.assert_array_equal(points.get_xdata(), z * 1e3)
    assert len(curves) == len(fit.candidates)  # every candidate, the chosen one last
    x = curves[-1].get_xdata() / 1e3
    np.testing.assert_allclose(curves[-1].get_ydata(), fit.law.force(x))
    assert curves[-1].get_label().startswith(f"{fit.kind} fit") and "(chosen)" in \
        curves[-1].get_label()
    residuals = bottom.lines[0]
    np.testing.assert_array_equal(residuals.get_ydata(), fit.residual)
    assert bottom.get_xlabel() == "relative position z [mm] (model convention)"
    assert top.get_ylabel() == "spring force on the payload F [N]"


def test_the_transmissibility_fit_draws_frequency_on_a_log_axis(frequency_axes):
    from types import SimpleNamespace

    from qzs.viz.identify import plot_transmissibility_fit

    frequency = np.linspace(0.0, 10.0, 41)
    measured = 1.0 / np.abs(1.0 - (frequency / 2.0) ** 2 + 0.4j * frequency / 2.0)
    fit = SimpleNamespace(frequency=frequency, measured=measured, fitted=1.01 * measured,
                          parameters={"stiction_force": 10.0})
    frequency_axes(plot_transmissibility_fit(fit).axes, "log")
    frequency_axes(plot_transmissibility_fit(fit, frequency_scale="linear").axes, "linear")
