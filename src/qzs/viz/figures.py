"""What every figure shares: a figure factory, an atomic writer, an envelope for long traces."""
import numpy as np

__all__ = ["envelope", "new_figure", "save_figure"]

_MAX_POINTS = 4000  # per trace: long runs are drawn as a min/max envelope
#: Prefixes of matplotlib's backends that open windows (and so need a display).
_WINDOW_BACKENDS = ("gtk", "qt", "tk", "wx", "macosx")


def envelope(time, values, max_points=_MAX_POINTS):
    """Min/max envelope of a long trace, for plotting without aliasing.

    Returns ``(time, values)`` unchanged when short, else two points (min and
    max) per bin for ``max_points // 2`` bins.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s].
    values : array_like, shape (n,)
        The trace (any unit).
    max_points : int
        Most points to return.

    Returns
    -------
    time, values : ndarray
        The envelope's times [s] and values, in time order within each bin.
    """
    time = np.asarray(time)
    values = np.asarray(values, dtype=float)
    n = values.size
    if n <= max_points:
        return time, values
    bins = max_points // 2
    width = -(-n // bins)  # every sample in a bin: the last one is padded with the last sample
    bins = -(-n // width)
    pad = bins * width - n
    blocks = np.concatenate([values, np.repeat(values[-1], pad)]).reshape(bins, width)
    t = np.concatenate([time, np.repeat(time[-1], pad)]).reshape(bins, width)
    low, high = blocks.argmin(axis=1), blocks.argmax(axis=1)
    first = np.minimum(low, high)
    second = np.maximum(low, high)
    rows = np.arange(bins)
    t_out = np.column_stack([t[rows, first], t[rows, second]]).ravel()
    v_out = np.column_stack([blocks[rows, first], blocks[rows, second]]).ravel()
    return t_out, v_out


def new_figure(rows, height=2.1, sharex=True, width=9.0, height_ratios=None):
    """A figure of ``rows`` stacked axes (Agg for a window backend without a display).

    Parameters
    ----------
    rows : int
        Number of axes, stacked vertically.
    height : float
        Height of each axes [in] (the figure adds 0.8 in); with ``height_ratios``, the
        mean height.
    sharex : bool
        Share the horizontal axis.
    width : float
        Figure width [in].
    height_ratios : sequence of float, optional
        Relative heights of the axes, top first; default all equal.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : ndarray of matplotlib.axes.Axes
        The ``rows`` axes, top first.
    """
    import matplotlib

    # A window backend cannot open without a display: draw with Agg instead. Any other
    # backend is kept, Jupyter's inline and widget backends included (they need no display).
    if matplotlib.get_backend().lower().startswith(_WINDOW_BACKENDS) and not _has_display():
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    extra = {} if height_ratios is None else {"gridspec_kw": {"height_ratios": height_ratios}}
    fig, axes = plt.subplots(rows, 1, sharex=sharex, figsize=(width, height * rows + 0.8),
                             constrained_layout=True, **extra)
    return fig, np.atleast_1d(axes)


def _has_display():
    import os

    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def save_figure(fig, path, also_svg=False):
    """Write ``fig`` atomically (format from the suffix); a .png also as .svg if asked.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        Target file; its suffix chooses the format (none: PNG).
    also_svg : bool
        For a .png, write the same figure beside it as .svg too.
    """
    from pathlib import Path

    from qzs.iotools.files import atomic_path

    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=130)
    if also_svg and path.suffix.lower() == ".png":
        save_figure(fig, path.with_suffix(".svg"))


