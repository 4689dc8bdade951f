"""The open questions' figures draw what they are given."""
import math

import matplotlib
import numpy as np

from qzs.viz.questions import plot_damping_design, plot_friction_compensation
from qzs.workflows.questions.common import CaseCurve

matplotlib.use("Agg")


def test_the_friction_figure_draws_the_table_and_the_boundaries():
    table = [{"fraction": a, "band_rms": 0.9 - 0.01 * a, "isolation_onset": 2.0,
              "stick_events": 10 - a, "motor_force_rms": 2 + a} for a in (0.0, 0.5, 1.0)]
    reference = {"band_rms": 0.8, "isolation_onset": 0.7, "stick_events": 5.0,
                 "motor_force_rms": 2.0}
    fig = plot_friction_compensation(table, reference, (1.0, 3.0),
                                     {"predicted": 1.0, "simulated": math.nan})
    line = fig.axes[0].lines[0]
    np.testing.assert_array_equal(line.get_ydata(), [r["band_rms"] for r in table])
    # the reference and the predicted boundary only (the simulated one is undefined)
    assert len(fig.axes[0].lines) == 3


def test_the_damping_figure_draws_each_curve_and_both_metrics():
    f = np.linspace(0.5, 20, 40)
    curves = [CaseCurve(name, f, 1 / (1 + k * f), np.ones(f.size, bool))
                for k, name in ((0.1, "none"), (0.3, "Kd"))]
    rows = [{"label": "Kd", "kind": "paper", "largest_reduction_db": 4.0,
             "band_rms_change_db": -2.0}]
    fig = plot_damping_design(curves, rows, (1.5, 20.0))
    assert len(fig.axes[0].lines) == 2
    heights = [p.get_height() for p in fig.axes[1].patches]
    assert heights == [4.0, 2.0]


def test_the_damping_figure_labels_do_not_run_into_each_other():
    """Six bars with the study's long labels: no two tick labels share any area."""
    f = np.linspace(0.5, 20, 40)
    curves = [CaseCurve("none", f, 1 / (1 + f), np.ones(f.size, bool))]
    labels = ["Kd = 20 N*s/m", "Kd = 50 N*s/m", "Kd = 100 N*s/m",
              "Kd = 253 N*s/m (the motor's limit)", "shaped skyhook, k = 209 N*s/m",
              "Kd = 100 N*s/m + base-velocity cancellation (0.25 Cv, 0.7 Hz)"]
    rows = [{"label": label, "kind": "paper", "largest_reduction_db": 4.0,
             "band_rms_change_db": -2.0} for label in labels]
    fig = plot_damping_design(curves, rows, (1.5, 20.0))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in fig.axes[1].get_xticklabels()]
    assert len(boxes) == len(labels)
    for left, right in zip(boxes, boxes[1:]):
        assert left.x1 < right.x0, (left, right)
