"""Figures of one run (qzs.viz.simulation): the traces are the run's channels, with the stops,
the setpoint and the energy ledger's residual."""
import numpy as np
import pytest

from qzs import Sine, simulate
from qzs.viz.simulation import plot_energy, plot_simulation


@pytest.fixture(scope="module")
def run():
    return simulate(Sine(amplitude=0.004, frequency=3.0), duration=1.0, dt=1e-4,
                    sample_rate=500.0)


def test_the_time_series_are_the_runs_channels(run):
    figure = plot_simulation(run)
    panel = figure.axes[1]
    (relative,) = [line for line in panel.lines if line.get_label() == "z = x - y"]
    np.testing.assert_array_equal(relative.get_xdata(), run.time)
    np.testing.assert_array_equal(relative.get_ydata(), run.relative_position * 1e3)
    levels = sorted(line.get_ydata()[0] for line in panel.lines if line.get_linestyle() == "--")
    assert levels == [run.run["stop_low"] * 1e3, run.run["stop_high"] * 1e3]
    (setpoint,) = [line for line in panel.lines if line.get_label() == "setpoint"]
    assert setpoint.get_ydata()[0] == run.controller.position_setpoint * 1e3
    forces = {line.get_label(): line.get_ydata() for line in figure.axes[2].lines}
    np.testing.assert_array_equal(forces["motor"], run.motor_force)


def test_the_energy_figure_draws_the_ledgers_residual(run):
    figure = plot_energy(run)
    (residual,) = figure.axes[1].lines
    np.testing.assert_array_equal(residual.get_ydata(), run.energy_residual())
    labels = [line.get_label() for line in figure.axes[0].lines]
    assert labels == ["base work", "motor work", "friction dissipation", "stop dissipation"]


def test_a_streamed_runs_title_fits_the_figure(monkeypatch):
    """The title of a long streamed run (its own line, then the envelope's) stays inside the
    figure: it was one line, cut at both edges for a 2000 s chirp."""
    from qzs import Chirp
    from qzs.engine import driver

    monkeypatch.setattr(driver, "PREVIEW_SAMPLES", 250)
    streamed = simulate(Chirp(duration=2000.0), duration=1.0, dt=1e-3, sample_rate=1000.0,
                        sink=lambda data, flags: None)
    assert streamed.run["preview_every"] > 1
    figure = plot_simulation(streamed)
    figure.canvas.draw()
    title = figure._suptitle
    box = title.get_window_extent(figure.canvas.get_renderer())
    assert "envelope" in title.get_text()
    assert 0 <= box.x0 and box.x1 <= figure.bbox.width and box.y1 <= figure.bbox.height
