"""The figure of an experiment log (qzs.viz.experiment): the measured curve in dB on its
trusted bins within the band, the simulation said to lie on top of it when it does."""
from types import SimpleNamespace

import numpy as np
import pytest

from qzs.viz.experiment import plot_experiment

F = np.linspace(0.0, 25.0, 101)


def estimate(magnitude, trusted):
    return SimpleNamespace(frequency=F, magnitude=magnitude, trusted=trusted,
                           coherence=np.where(trusted, 0.99, 0.3), n_averages=12,
                           coherence_min=0.9)


def test_the_measured_curve_is_its_trusted_bins_in_db_within_the_band():
    magnitude = 1.0 / np.abs(1.0 - (F / 3.0) ** 2 + 0.3j * F / 3.0)
    trusted = (F > 1.0) & (F < 18.0)
    measured = estimate(magnitude, trusted)
    simulated = estimate(magnitude * 10 ** (0.05 / 20), trusted)   # within the tolerance
    result = SimpleNamespace(measured=measured, simulated=simulated, band=(0.0, 20.0),
                             untrusted_below=1.0,
                             recording=SimpleNamespace(source="rig/log.csv (map.toml)"))
    figure = plot_experiment(result)
    top = figure.axes[0]
    (solid,) = [line for line in top.lines if line.get_label() == "experiment (12 averages)"]
    keep = (F > 0.0) & (F <= 20.0)   # the band, without the mean (0 Hz)
    np.testing.assert_array_equal(solid.get_xdata(), F[keep])
    np.testing.assert_allclose(solid.get_ydata(),
                               np.where(trusted, 20 * np.log10(magnitude), np.nan)[keep],
                               rtol=1e-14)
    labels = [line.get_label() for line in top.lines]
    assert any("on top of the experiment" in label for label in labels)
    np.testing.assert_array_equal(figure.axes[1].lines[0].get_ydata(), measured.coherence[keep])
    assert top.get_title() == "log.csv"


@pytest.mark.parametrize("scale", [None, "linear"])
def test_frequency_is_log_by_default_and_linear_on_request(frequency_axes, scale):
    magnitude = 1.0 / np.abs(1.0 - (F / 3.0) ** 2 + 0.3j * F / 3.0)
    measured = estimate(magnitude, (F > 1.0) & (F < 18.0))
    result = SimpleNamespace(measured=measured, simulated=None, band=(0.0, 20.0),
                             untrusted_below=1.0,
                             recording=SimpleNamespace(source="rig/log.csv (map.toml)"))
    figure = plot_experiment(result, frequency_scale=scale)
    frequency_axes(figure.axes, scale or "log")
    low = figure.axes[0].get_xlim()[0]
    assert low == pytest.approx(0.0 if scale == "linear" else 1.0)   # lowest trusted: 1.25 Hz
