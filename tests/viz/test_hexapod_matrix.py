"""The 6x6 transmissibility grid (qzs.viz.hexapod_matrix): panel (i, j) draws entry (i, j) in
dB of its unit, and a base axis that was not excited leaves its column empty."""
import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.viz.hexapod_matrix import plot_transmissibility_matrix

F = np.linspace(0.0, 20.0, 41)


def matrix():
    """Entry (i, j) = (i + 1) (j + 2) / (1 + f): every entry distinct, none below the floor."""
    i, j = np.meshgrid(np.arange(6), np.arange(6), indexing="ij")
    return (i + 1.0)[None] * (j + 2.0)[None] / (1.0 + F)[:, None, None]


def test_each_panel_is_its_entry_in_db_with_its_unit():
    linear = matrix()
    excited = np.array([True, True, True, False, True, True])
    figure = plot_transmissibility_matrix(F, linear=linear, excited=excited)
    axes = np.array(figure.axes).reshape(6, 6)
    for i in range(6):
        for j in range(6):
            lines = axes[i, j].lines
            if not excited[j]:
                assert len(lines) == 0 and "not excited" in axes[0, j].get_title()
                continue
            (line,) = lines
            np.testing.assert_array_equal(line.get_xdata(), F[1:])
            np.testing.assert_allclose(line.get_ydata(), 20 * np.log10(linear[1:, i, j]),
                                       rtol=1e-13)
    units = {(0, 0): "[1]", (0, 3): "[m/rad]", (3, 0): "[rad/m]", (4, 5): "[1]"}
    for (i, j), unit in units.items():
        assert unit in [text.get_text() for text in axes[i, j].texts]


def test_a_matrix_of_the_wrong_shape_is_refused():
    with pytest.raises(ParameterError, match=r"`simulated` must have shape \(41, 6, 6\)"):
        plot_transmissibility_matrix(F, simulated=np.ones((41, 6, 5)))


@pytest.mark.parametrize("scale", [None, "linear"])
def test_every_panel_has_a_log_frequency_axis_unless_linear_is_asked(frequency_axes, scale):
    figure = plot_transmissibility_matrix(F, linear=matrix(), frequency_scale=scale)
    frequency_axes(figure.axes, scale or "log")
    if scale is None:   # from the lowest positive bin, 0.5 Hz, to the top
        assert figure.axes[0].get_xlim() == pytest.approx((0.5, 20.0))
        assert [ax.get_xlabel() for ax in figure.axes[-6:]] == ["frequency [Hz]"] * 6
