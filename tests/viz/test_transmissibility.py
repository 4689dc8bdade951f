"""Transmissibility curves in dB (qzs.viz.transmissibility): which curves coincide, from which
frequency on, and a drawn curve that is 20 log10 of its magnitude on its trusted bins only."""
import numpy as np

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
