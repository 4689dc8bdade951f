"""The sensitivity bar chart draws the indices and their intervals, labelled with units."""
from types import MappingProxyType

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.container import BarContainer

from qzs.viz.sensitivity import SERIES, plot_sensitivity
from qzs.workflows.design_space.sensitivity import SensitivityResult

PARAMETERS = ("pi_kp", "mass", "stiction_force")
UNITS = ("N/m", "kg", "N")


def sobol_result(reasons=("", "")):
    first = np.array([[0.05, 0.60, 0.20], [0.30, 0.01, 0.40]])
    total = np.array([[0.10, 0.70, 0.25], [0.45, 0.02, 0.50]])
    interval = lambda values, below, above: (values - below, values + above)
    return SensitivityResult(
        method="sobol", parameters=PARAMETERS, parameter_units=UNITS,
        parameter_kinds=("variable", "variable", "uncertain"),
        metrics=("transmissibility_at_12_hz", "peak_stroke"), metric_units=("1", "m"),
        first_order=first, total_order=total,
        intervals={"first_order": interval(first, 0.03, 0.04),
                   "total_order": interval(total, 0.02, 0.05)},
        confidence=0.9, samples=256, evaluations=256 * 5, reasons=reasons, problem="toy",
        title="A toy problem", settings=MappingProxyType({}))


def morris_result():
    mu_star = np.array([[0.2, 0.9, 0.4]])
    return SensitivityResult(
        method="morris", parameters=PARAMETERS, parameter_units=UNITS,
        parameter_kinds=("variable", "variable", "uncertain"), metrics=("peak_stroke",),
        metric_units=("m",), mu_star=mu_star,
        intervals={"mu_star": (mu_star - 0.1, mu_star + 0.15)},
        mu=mu_star * 0.5, sigma=np.array([[0.05, 0.3, 0.6]]), confidence=0.95, samples=10,
        levels=4, evaluations=40, reasons=("",), problem="toy", title="A toy problem")


def bars(ax):
    """Label -> (parameter -> (value, (low, high))) read off the axes' bar containers."""
    names = {tick.get_position()[1]: tick.get_text().split(" [")[0]
             for tick in ax.get_yticklabels()}
    found = {}
    for container in ax.containers:
        if not isinstance(container, BarContainer):
            continue
        segments = container.errorbar.lines[2][0].get_segments()
        drawn = {}
        for patch, segment in zip(container.patches, segments):
            centre = patch.get_y() + patch.get_height() / 2
            row = min(names, key=lambda y: abs(y - centre))
            drawn[names[row]] = (patch.get_width(), (segment[0][0], segment[1][0]))
        found[container.get_label()] = drawn
    return found


def test_sobol_bars_and_error_bars_are_the_indices_and_their_intervals():
    result = sobol_result()
    fig = plot_sensitivity(result)
    axes = fig.axes
    assert len(axes) == 2
    for i, ax in enumerate(axes):
        drawn = bars(ax)
        for name in ("first_order", "total_order"):
            label = SERIES["sobol"][name][0]
            values, (lows, highs) = getattr(result, name)[i], result.intervals[name]
            for j, parameter in enumerate(PARAMETERS):
                value, (low, high) = drawn[label][parameter]
                assert value == pytest.approx(values[j])
                assert (low, high) == pytest.approx((lows[i, j], highs[i, j]))
        # ranked by the total index, the largest on top
        ticks = sorted(ax.get_yticklabels(), key=lambda t: -t.get_position()[1])
        order = [t.get_text().split(" [")[0] for t in ticks]
        assert order == [PARAMETERS[j] for j in np.argsort(-result.total_order[i])]
        assert ax.get_xlabel() == "Sobol index [-] (share of the metric's variance)"
    labels = [t.get_text() for t in axes[0].get_yticklabels()]
    assert "mass [kg]" in labels and "pi_kp [N/m]" in labels
    assert "stiction_force [N]\n(uncertain)" in labels
    assert axes[0].get_title(loc="left") == "transmissibility_at_12_hz [-]"
    assert axes[1].get_title(loc="left") == "peak_stroke [m]"
    assert "256 base samples (1280 cases), 90% bootstrap intervals" in fig._suptitle.get_text()
    plt.close(fig)


def test_morris_bars_are_mu_star_with_sigma_as_markers():
    result = morris_result()
    fig = plot_sensitivity(result)
    (ax,) = fig.axes
    drawn = bars(ax)[SERIES["morris"]["mu_star"][0]]
    for j, parameter in enumerate(PARAMETERS):
        value, interval = drawn[parameter]
        assert value == pytest.approx(result.mu_star[0, j])
        assert interval == pytest.approx(tuple(end[0, j] for end in result.intervals["mu_star"]))
    (sigma,) = [line for line in ax.get_lines()
                if line.get_label() == SERIES["morris"]["sigma"][0]]
    order = np.argsort(-result.mu_star[0])
    assert np.allclose(sigma.get_xdata(), result.sigma[0, order])
    assert ax.get_xlabel() == "elementary effect across the parameter's range [m]"
    plt.close(fig)


def test_an_undefined_metric_says_why_and_the_figure_is_written(tmp_path):
    result = sobol_result(reasons=("", "3 of 1280 cases gave NaN (a failed run)"))
    path = tmp_path / "sensitivity.png"
    fig = plot_sensitivity(result, path=path, title="given title")
    assert path.stat().st_size > 0
    assert fig._suptitle.get_text() == "given title"
    texts = [t.get_text() for t in fig.axes[1].texts]
    assert any("3 of 1280 cases gave NaN" in t for t in texts)
    assert not [c for c in fig.axes[1].containers if isinstance(c, BarContainer)]
    plt.close(fig)


def test_the_result_delegates_its_plot():
    fig = sobol_result().plot()
    assert len(fig.axes) == 2
    plt.close(fig)
