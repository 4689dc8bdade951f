"""The page's figure drawn with matplotlib (qzs.app.figure): every panel, and the PNG export."""
import pytest


def test_png_export_has_every_panel(default_page):
    from qzs.app.figure import figure_png, page_figure

    pinned = [("pin", default_page.frequency, default_page.transmissibility_db - 1.0)]
    figure = page_figure(default_page, pinned)
    labels = [axes.get_ylabel() for axes in figure.axes]
    assert labels == ["transmissibility [dB]", "time locked [%]", "displacement from rest [mm]",
                      "relative position z [mm]", "motor force [N]"]
    assert all("[" in axes.get_xlabel() or axes.get_xlabel() == "" for axes in figure.axes)
    assert figure_png(default_page, pinned)[:8] == b"\x89PNG\r\n\x1a\n"


def test_each_locked_share_is_drawn_on_its_own_bar(default_page):
    """The bar named for the sine shows the sine run's share, the chirp's bar the chirp's."""
    from qzs.app.figure import page_figure

    figure = page_figure(default_page)
    (axes,) = [a for a in figure.axes if a.get_ylabel() == "time locked [%]"]
    names = [label.get_text() for label in axes.get_xticklabels()]
    heights = [bar.get_height() for bar in axes.patches]
    shares = default_page.locked_share
    assert names == ["3 Hz sine", "chirp"]
    assert heights == pytest.approx([100 * shares["sine"], 100 * shares["excitation"]],
                                    rel=1e-12)



def test_export_draws_frequency_on_a_log_axis_without_0_hz(default_page):
    """The exported transmissibility uses the frequency axis of every qzs figure: log, no
    bin at or below 0 Hz drawn (a pinned curve holding one drops it), starting at the
    lowest bin drawn; the legend placed where it covers least."""
    import numpy as np

    from qzs.app.figure import page_figure

    frequency = np.concatenate([[0.0], default_page.frequency])
    pinned = [("pin", frequency, np.concatenate([[0.0], default_page.transmissibility_db]))]
    figure = page_figure(default_page, pinned)
    axes = figure.axes[0]
    assert axes.get_xscale() == "log"
    curves = [line for line in axes.get_lines() if not line.get_label().startswith("_")]
    assert len(curves) == 3  # the pin, the simulation, the linear model (not the 0 dB line)
    for line in curves:
        assert np.all(np.asarray(line.get_xdata(), dtype=float) > 0), line.get_label()
    low = min(default_page.frequency.min(), default_page.linear_frequency.min())
    assert 0 < axes.get_xlim()[0] <= low
    assert axes.get_legend()._loc == 0  # "best"
