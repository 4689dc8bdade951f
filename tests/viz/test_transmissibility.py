"""Transmissibility curves in dB (qzs.viz.transmissibility): which curves coincide, from which
frequency on, and a drawn curve that is 20 log10 of its magnitude on its trusted bins only."""
import numpy as np
import pytest

from qzs.viz.transmissibility import coinciding, plot_transmissibility

F = np.linspace(0.0, 20.0, 81)


def curve(label, magnitude, **extra):
    return {"label": label, "frequency": F, "magnitude": magnitude, **extra}


def test_curves_within_the_tolerance_coincide_and_others_do_not():
    base = 1.0 / (1.0 + F)
    curves = [curve("a", base), curve("b", base * 10 ** (0.1 / 20)), curve("c", 2.0 * base)]
    groups, merged_above = coinciding(curves, tolerance_db=0.5)
    assert groups == [[0, 1], [2]]
    assert merged_above is None              # 6 dB apart everywhere
    apart_below_5 = np.where(F < 5.0, 2.0 * base, base)
    groups, merged_above = coinciding([curve("a", base), curve("d", apart_below_5)],
                                      tolerance_db=0.5)
    assert groups == [[0], [1]] and merged_above == 5.0


def test_the_solid_curve_is_the_trusted_bins_in_db():
    magnitude = 1.0 / np.abs(1.0 - (F / 4.0) ** 2 + 0.2j * F / 4.0)
    trusted = F > 2.0
    figure = plot_transmissibility([curve("model", magnitude, trusted=trusted)],
                                   frequency_range=(0.0, 20.0))
    solid = next(line for line in figure.axes[0].lines if line.get_label() == "model")
    x, y = solid.get_xdata(), solid.get_ydata()
    keep = F > 0
    np.testing.assert_array_equal(x, F[keep])
    expected = np.where(trusted, 20 * np.log10(magnitude), np.nan)[keep]
    np.testing.assert_allclose(y, expected, rtol=1e-14)
    assert np.isnan(y[~trusted[keep]]).all()


@pytest.mark.parametrize("scale", [None, "log", "linear"])
def test_frequency_is_log_by_default_and_linear_on_request(frequency_axes, scale):
    """Log by default (qzs.defaults.FIGURES), from the lowest trusted or linearised bin
    rounded down to 1-2-5; the 0 Hz bin dropped, with no warning; linear when asked."""
    import warnings

    import matplotlib.pyplot as plt

    magnitude = 1.0 / np.abs(1.0 - (F / 4.0) ** 2 + 0.2j * F / 4.0)
    curves = [curve("model", magnitude, trusted=F > 2.0, coherence=np.full(F.shape, 0.95))]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figure = plot_transmissibility(curves, frequency_range=(0.0, 20.0),
                                       frequency_scale=scale)
        figure.canvas.draw()
    frequency_axes(figure.axes, scale or "log")
    assert figure.axes[0].get_xlim() == pytest.approx((0.0 if scale == "linear" else 2.0, 20.0))
    assert figure.axes[0].get_ylabel().startswith("transmissibility [dB]")
    assert figure.axes[1].get_ylabel() == "coherence [-]"
    # a linearised curve is exact at every bin: the log axis starts at its lowest one
    curves[0]["linear"] = magnitude
    figure = plot_transmissibility(curves, frequency_range=(0.0, 20.0))
    assert figure.axes[0].get_xlim()[0] == pytest.approx(0.2)   # F[1] = 0.25 Hz
    plt.close("all")
