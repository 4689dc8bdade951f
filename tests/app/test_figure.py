"""The page's figure drawn with matplotlib (qzs.app.figure): every panel, and the PNG export."""


def test_png_export_has_every_panel(default_page):
    from qzs.app.figure import figure_png, page_figure

    pinned = [("pin", default_page.frequency, default_page.transmissibility_db - 1.0)]
    figure = page_figure(default_page, pinned)
    labels = [axes.get_ylabel() for axes in figure.axes]
    assert labels == ["transmissibility [dB]", "time locked [%]", "displacement from rest [mm]",
                      "relative position z [mm]", "motor force [N]"]
    assert all("[" in axes.get_xlabel() or axes.get_xlabel() == "" for axes in figure.axes)
    assert figure_png(default_page, pinned)[:8] == b"\x89PNG\r\n\x1a\n"
