"""What every figure shares: a figure factory, an atomic writer, an envelope for long traces,
and the frequency axis (log by default, linear on request)."""
import numpy as np

__all__ = ["envelope", "new_figure", "save_figure", "figure_bytes", "check_frequency_scale",
           "nice_floor", "frequency_limits", "frequency_axis", "drawn"]

_DPI = 130  # of every figure file [dots per inch]
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
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=_DPI)
    if also_svg and path.suffix.lower() == ".png":
        save_figure(fig, path.with_suffix(".svg"))



def figure_bytes(fig, suffix=".png"):
    """The bytes :func:`save_figure` writes for ``fig`` to a file of this suffix.

    For a figure drawn in one process and written in another
    (:mod:`qzs.workflows.figure_process`).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    suffix : str
        The file's suffix (``".png"``, ``".svg"``, ``".pdf"``); empty: PNG.

    Returns
    -------
    bytes
        The file's contents.
    """
    import io

    buffer = io.BytesIO()
    fig.savefig(buffer, format=str(suffix).lstrip(".") or "png", dpi=_DPI)
    return buffer.getvalue()


def check_frequency_scale(frequency_scale, argument="frequency_scale"):
    """The frequency axis's scale: ``frequency_scale`` checked, or the default if None.

    Parameters
    ----------
    frequency_scale : {"log", "linear"} or None
        The scale asked for; None takes ``qzs.defaults.FIGURES["frequency_scale"]``.
    argument : str
        How the caller names it in messages (``"--frequency-axis"`` on the command line).

    Returns
    -------
    str
        ``"log"`` or ``"linear"``.

    Raises
    ------
    ParameterError
        Any other value.
    """
    from qzs.defaults import FIGURES, FREQUENCY_SCALES
    from qzs.errors import ParameterError

    if frequency_scale is None:
        return FIGURES["frequency_scale"]
    if frequency_scale not in FREQUENCY_SCALES:
        raise ParameterError(f"`{argument}` must be one of {', '.join(FREQUENCY_SCALES)}, got "
                             f"{frequency_scale!r}.")
    return frequency_scale


def nice_floor(value):
    """The largest 1-2-5 number (..., 0.05, 0.1, 0.2, 0.5, 1, ...) not above ``value``.

    Parameters
    ----------
    value : float
        A positive number.

    Returns
    -------
    float
    """
    decade = 10.0 ** np.floor(np.log10(value) + 1e-9)
    for mantissa in (5.0, 2.0, 1.0):
        if mantissa * decade <= value * (1 + 1e-9):
            return float(mantissa * decade)
    return float(decade)  # pragma: no cover  (1 * decade <= value always)


def frequency_limits(frequency_range, frequencies=(), frequency_scale=None):
    """The horizontal limits [Hz] of a frequency axis.

    A linear axis takes ``frequency_range`` as it is. A log axis cannot show 0 Hz: it
    starts at ``frequency_range[0]`` if positive, else at the lowest positive frequency
    of ``frequencies`` (the lowest trusted bin, the band's start), rounded down to a 1-2-5
    number, else at ``qzs.defaults.FIGURES["frequency_floor"]``.

    Parameters
    ----------
    frequency_range : (float, float)
        The range asked for [Hz] (its start may be 0).
    frequencies : array_like
        The frequencies drawn [Hz] (any shape; zero and NaN ones are ignored).
    frequency_scale : {"log", "linear"}, optional
        Default ``FIGURES["frequency_scale"]``.

    Returns
    -------
    (float, float)
    """
    from qzs.defaults import FIGURES

    low, high = float(frequency_range[0]), float(frequency_range[1])
    if check_frequency_scale(frequency_scale) == "linear":
        return low, high
    if low <= 0:
        values = np.asarray(frequencies, dtype=float).ravel()
        values = values[np.isfinite(values) & (values > 0) & (values < high)]
        low = nice_floor(values.min()) if values.size else FIGURES["frequency_floor"]
    return low, high


def frequency_axis(ax, frequency_range, frequencies=(), *, frequency_scale=None, label=None,
                   decades_only=False):
    """Set a frequency axis: scale, limits, and on a log axis plain-number ticks.

    The one place every transmissibility and response figure sets its frequency axis.
    A log axis is labelled 0.1, 1, 10 (and 0.2, 0.5, 2, 5 ... between when it spans
    fewer than three decades), never 10^-1.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes (those sharing its x axis follow).
    frequency_range : (float, float)
        Range asked for [Hz] (see :func:`frequency_limits`).
    frequencies : array_like
        The frequencies drawn [Hz]: a log axis starts at the lowest positive one if
        ``frequency_range`` starts at 0.
    frequency_scale : {"log", "linear"}, optional
        Default ``qzs.defaults.FIGURES["frequency_scale"]``.
    label : str, optional
        Axis label; default none set.
    decades_only : bool
        Label only the decades (0.1, 1, 10) whatever the span: for small panels.

    Returns
    -------
    (float, float)
        The limits set [Hz].
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    scale = check_frequency_scale(frequency_scale)
    low, high = frequency_limits(frequency_range, frequencies, scale)
    ax.set_xscale(scale)
    if scale == "log":
        decades = np.log10(high / low)
        subs = (1.0, 2.0, 5.0) if decades < 3 and not decades_only else (1.0,)
        ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=subs))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        ax.xaxis.set_minor_locator(LogLocator(base=10.0, subs=np.arange(1.0, 10.0)))
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlim(low, high)
    if label is not None:
        ax.set_xlabel(label)
    return low, high


def drawn(frequency, frequency_scale=None):
    """Which bins a frequency axis can draw: all finite ones, and on a log axis f > 0.

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz].
    frequency_scale : {"log", "linear"}, optional
        Default ``qzs.defaults.FIGURES["frequency_scale"]``.

    Returns
    -------
    ndarray of bool
    """
    frequency = np.asarray(frequency, dtype=float)
    keep = np.isfinite(frequency)
    if check_frequency_scale(frequency_scale) == "log":
        keep &= frequency > 0
    return keep
