"""Figures of a hexapod run (qzs.viz.hexapod): the platform against the base per axis, each
leg's position between its stops and its motor force within the saturation limits."""
from types import SimpleNamespace

import numpy as np

from qzs import IsolatorParameters, Sine
from qzs.viz.hexapod import plot_hexapod


class FakeRun(SimpleNamespace):
    """What plot_hexapod reads of a HexapodResult: channels by name, run and legs."""

    def __getitem__(self, name):
        return self.channels[name]


def fake_run():
    t = np.linspace(0.0, 1.0, 101)
    base = np.zeros((t.size, 6))
    base[:, 2] = 0.004 * np.sin(2 * np.pi * 3 * t)
    pose = 0.5 * base + 1e-4 * np.arange(6)
    legs = np.arange(6) * 1e-3 - 0.06 + 0.001 * np.sin(2 * np.pi * t)[:, None]
    motor = np.arange(1, 7) * np.cos(2 * np.pi * t)[:, None]
    return FakeRun(channels={"time": t, "platform_pose": pose, "base_pose": base,
                             "relative_position": legs, "motor_force": motor},
                   run={"stops": [(-0.14, 0.02)] * 6, "duration": 1.0, "solver": "ode3",
                        "dt": 1e-4},
                   isolators=[IsolatorParameters()] * 6,
                   excitation={"z": Sine(amplitude=0.004, frequency=3.0)})


def test_each_panel_draws_the_channels_it_names():
    run = fake_run()
    figure = plot_hexapod(run)
    lines = {line.get_label(): line for line in figure.axes[0].lines}
    assert set(lines) == {"base z", "platform x", "platform y", "platform z"}  # only z moves
    np.testing.assert_array_equal(lines["platform z"].get_ydata(), run["platform_pose"][:, 2] * 1e3)
    np.testing.assert_array_equal(lines["base z"].get_ydata(), run["base_pose"][:, 2] * 1e3)
    rotations = figure.axes[1].lines
    np.testing.assert_array_equal(rotations[0].get_ydata(), run["platform_pose"][:, 3] * 1e3)
    legs = [line for line in figure.axes[2].lines if line.get_label().startswith("leg")]
    for i, line in enumerate(legs):
        np.testing.assert_array_equal(line.get_ydata(), run["relative_position"][:, i] * 1e3)
    stops = sorted(line.get_ydata()[0] for line in figure.axes[2].lines
                   if line.get_linestyle() == "--")
    assert stops == [-140.0, 20.0]
    limit = IsolatorParameters().motor_force_max
    limits = sorted(line.get_ydata()[0] for line in figure.axes[3].lines
                    if line.get_linestyle() == ":")
    assert limits == [-limit, limit]
    assert "base z: Sine" in figure._suptitle.get_text()
