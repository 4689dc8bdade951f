"""Figures of a controller design (qzs.viz.design): the static design's curve is the motor
force m*g - F_spring(z_ref) the payload needs, zero at the mass the spring alone carries."""
import numpy as np
import pytest

from qzs import ControllerParameters, IsolatorParameters
from qzs.analysis.control_design import static_design
from qzs.model.isolator import spring_force
from qzs.viz.design import plot_static_design


def test_the_static_design_draws_the_force_the_payload_needs():
    isolator, controller = IsolatorParameters(), ControllerParameters()
    lifted = float(spring_force(controller.position_setpoint, isolator))
    static = static_design(isolator, controller, mass_range=(5.0, 8.0))
    figure = plot_static_design(static, gravity=isolator.gravity)
    ax = figure.axes[0]
    needed = next(line for line in ax.lines if line.get_label().startswith("needed"))
    mass = needed.get_xdata()
    np.testing.assert_allclose(needed.get_ydata(), mass * isolator.gravity - lifted, rtol=1e-14,
                               atol=1e-12)
    balanced = next(line for line in ax.lines if line.get_label().startswith("spring alone"))
    assert balanced.get_xdata()[0] == pytest.approx(lifted / isolator.gravity, rel=1e-14)
    limits = sorted(line.get_ydata()[0] for line in ax.lines if line.get_linestyle() == "--")
    assert limits == [-isolator.motor_force_max, isolator.motor_force_max]
    design = next(line for line in ax.lines if line.get_label().startswith("design mass"))
    assert design.get_xdata()[0] == pytest.approx(isolator.mass, rel=1e-14)
    assert design.get_ydata()[0] == pytest.approx(isolator.mass * isolator.gravity - lifted,
                                                  rel=1e-12)


@pytest.mark.parametrize("scale", [None, "linear"])
def test_the_damping_search_draws_frequency_log_by_default(frequency_axes, scale):
    """The damping search's transmissibility panel: a log frequency axis from the lowest
    trusted bin (0 Hz dropped), linear on request; the gain panel keeps its own axis."""
    from qzs.viz.design import plot_damping_search

    frequency = np.linspace(0.0, 20.0, 81)
    magnitude = 1.0 / np.abs(1.0 - (frequency / 2.0) ** 2 + 0.4j * frequency / 2.0)
    trusted = frequency >= 0.5
    rows = [{"damping_gain": k, "cost": 1.0 / (1 + k), "linear_cost": 1.0 / (1 + k)}
            for k in (0.0, 10.0, 50.0)]
    curves = {0.0: (frequency, magnitude, trusted), 10.0: (frequency, 0.9 * magnitude, trusted)}
    figure = plot_damping_search(rows, curves, 10.0, 100.0, (1.0, 20.0), "rms",
                                 frequency_scale=scale)
    frequency_axes(figure.axes[1:], scale or "log")
    assert figure.axes[1].get_xlim()[0] == pytest.approx(0.0 if scale == "linear" else 0.5)
    assert figure.axes[1].get_ylabel() == "transmissibility [dB]"


def test_an_unstable_loop_is_off_the_margin_axes():
    """The sampled loop at 10 Hz is unstable (no margin); at 20 and 50 Hz it is stable. The
    margin axes carry the stable rates only; the unstable one is marked along the rate axis."""
    import math

    import matplotlib.pyplot as plt

    from qzs.analysis import control_design as cd
    from qzs.model.controller import ControllerParameters
    from qzs.viz.design import plot_margins

    controller = ControllerParameters(damping_gain=200.0)
    table = [cd.loop_margins(controller=controller, rate=rate).to_dict() for rate in (10, 20, 50)]
    assert [t["stable"] for t in table] == [False, True, True]
    fig = plot_margins(table, math.nan, 6.0, 30.0, 0.0)
    for ax in fig.axes[:2]:
        on_scale = [line for line in ax.get_lines() if line.get_transform() == ax.transData]
        drawn = {float(x) for line in on_scale for x, y in zip(*line.get_data())
                 if math.isfinite(y)}
        assert 10.0 not in drawn and {20.0, 50.0} <= drawn
        marks = [line for line in ax.get_lines() if "unstable" in line.get_label()]
        assert len(marks) == 1 and list(marks[0].get_xdata()) == [10.0]
        assert marks[0].get_transform() != ax.transData  # not a value on the margin scale
    plt.close(fig)
