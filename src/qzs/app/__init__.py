"""The interactive tuning page behind ``qzs app`` (docs/app.md).

A layer above ``workflows`` and below ``cli``: it may use every layer below it, and only
the command line imports it. The logic and the widgets are apart:

============  ===========================================================================
``compute``   what the page shows, as data: a validated request (:class:`PageRequest`),
              its figures' arrays (:func:`compute_page`), the TOML export
              (:func:`config_text`); no widget, no Panel
``figure``    the page's figure drawn with matplotlib, as PNG bytes (the PNG export)
``platform``  the six-axis platform's tab as data: geometry, modes, the 6x6 grid as PNG
``updates``   one computation at a time per page, the newest request only, a superseded
              result dropped (:class:`LatestOnly`); no Panel either
``page``      the Panel widgets and Bokeh plots of one browser session
``server``    the Bokeh server: warms the kernels, binds the address, serves the page
``browser``   driving the page in headless Chromium (Playwright): tests and benchmark
============  ===========================================================================

Panel is an optional dependency (``pip install "qzs[app]"``); only ``page`` and ``server``
import it, lazily, so ``import qzs`` and the other layers never need it.
"""
from qzs._lazy import lazy_exports

_LAZY = {
    "PageRequest": "qzs.app.compute", "PageData": "qzs.app.compute",
    "SizeLimitError": "qzs.errors", "page_request": "qzs.app.compute",
    "compute_page": "qzs.app.compute", "config_text": "qzs.app.compute",
    "LIMITS": "qzs.app.compute",
    "figure_png": "qzs.app.figure",
    "LatestOnly": "qzs.app.updates",
    "PlatformData": "qzs.app.platform", "compute_platform": "qzs.app.platform",
    "serve": "qzs.app.server",
}

__all__ = list(_LAZY)

__getattr__, __dir__ = lazy_exports(__name__, _LAZY)
