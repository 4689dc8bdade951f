"""Sweep figures: a metric against one or two parameters, the Monte Carlo transmissibility band."""
import argparse

import matplotlib
import numpy as np
import pytest

from qzs import ParameterError
from qzs.cli.sweep import add_parsers, run_plot_command as run_sweep_plot_command
from qzs.workflows.sweeps import run_sweep
from qzs.viz.sweeps import plot_metric, plot_transmissibility_band, scalar_outputs

matplotlib.use("Agg")

BASE = {"excitation": {"f1": 10.0},
        "analysis": {"fft_length": 1024, "n_averages": 6, "band": [0.0, 10.0]},
        "outputs": {"bands": {"low": [1.0, 3.0]}}}


@pytest.fixture(scope="module")
def grid_store(tmp_path_factory):
    store = tmp_path_factory.mktemp("plots") / "grid.zarr"
    run_sweep({**BASE, "sweep": {"name": "grid", "batch_size": 6},
               "grid": {"pi_kp": [5.0, 50.0, 500.0], "stiction_force": [5.0, 15.0]}},
              store, progress=False)
    return store


@pytest.fixture(scope="module")
def monte_carlo_store(tmp_path_factory):
    store = tmp_path_factory.mktemp("plots") / "mc.zarr"
    run_sweep({**BASE, "sweep": {"name": "mc", "method": "lhs", "samples": 6, "seed": 2,
                                 "batch_size": 6},
               "distributions": {"stiction_force": {"distribution": "uniform", "low": 5.0,
                                                    "high": 15.0}}}, store, progress=False)
    return store


def _axes_data(figure):
    return figure.axes[0]


def test_line_and_heat_map_of_a_grid(grid_store, tmp_path):
    from qzs.workflows.sweeps import open_sweep

    data = open_sweep(grid_store)
    assert {"peak_stroke", "mean_transmissibility_low", "resonance_peak"} <= set(
        scalar_outputs(data))
    figure = plot_metric(data, "peak_stroke", "pi_kp", reduce="max",
                         path=tmp_path / "line.png")
    line = [l for l in _axes_data(figure).lines if l.get_marker() == "o"][0]
    worst = data["peak_stroke"].values.reshape(3, 2).max(axis=1)
    np.testing.assert_allclose(line.get_ydata(), worst)
    assert (tmp_path / "line.png").stat().st_size > 1000
    figure = plot_metric(data, "peak_stroke", "pi_kp", "stiction_force",
                         path=tmp_path / "heat.png")
    mesh = _axes_data(figure).collections[0]
    np.testing.assert_allclose(np.sort(np.ravel(mesh.get_array())),
                               np.sort(data["peak_stroke"].values))
    assert "[m]" in figure.axes[1].get_ylabel()


def test_monte_carlo_band_and_scatter(monte_carlo_store, tmp_path):
    from qzs.workflows.sweeps import open_sweep

    data = open_sweep(monte_carlo_store)
    figure = plot_transmissibility_band(data, path=tmp_path / "band.png")
    median = _axes_data(figure).lines[0].get_ydata()
    np.testing.assert_allclose(median, np.median(data["transmissibility"].values, axis=0))
    assert "sqrt(S_payload/S_base)" in _axes_data(figure).get_ylabel()
    figure = plot_metric(data, "mean_transmissibility_low", "stiction_force")
    points = _axes_data(figure).collections[0].get_offsets()
    np.testing.assert_allclose(np.sort(points[:, 0]), np.sort(data["stiction_force"].values))


def test_plot_errors_name_the_choices(grid_store):
    from qzs.workflows.sweeps import open_sweep

    data = open_sweep(grid_store)
    with pytest.raises(ParameterError, match="unknown metric 'peak'.*peak_stroke"):
        plot_metric(data, "peak", "pi_kp")
    with pytest.raises(ParameterError, match="unknown parameter 'mass'.*pi_kp"):
        plot_metric(data, "peak_stroke", "mass")


def test_plot_command_writes_the_default_figures(grid_store, monkeypatch, tmp_path, capsys):
    monkeypatch.chdir(tmp_path)
    parser = argparse.ArgumentParser(prog="qzs")
    add_parsers(parser.add_subparsers(dest="command", required=True))
    for argv, name in ((["sweep-plot", str(grid_store)], "grid-transmissibility.png"),
                       (["sweep-plot", str(grid_store), "--x", "stiction_force"],
                        "grid-transmissibility-stiction_force.png"),
                       (["sweep-plot", str(grid_store), "--metric", "stop_contacts", "--x",
                         "pi_kp", "--y", "stiction_force", "--reduce", "max"],
                        "grid-stop_contacts-pi_kp-stiction_force.png")):
        assert run_sweep_plot_command(parser.parse_args(argv)) == 0
        assert (tmp_path / name).exists() and f"wrote {name}" in capsys.readouterr().out


def test_the_band_draws_frequency_log_by_default_and_linear_on_request(monte_carlo_store,
                                                                       frequency_axes):
    from qzs.workflows.sweeps import open_sweep

    data = open_sweep(monte_carlo_store)
    frequency_axes(plot_transmissibility_band(data).axes, "log")
    frequency_axes(plot_transmissibility_band(data, frequency_scale="linear").axes, "linear")
