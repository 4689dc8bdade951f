"""The six-axis platform's 6x6 transmissibility as a grid of magnitude plots.

Row ``i``, column ``j``: the platform's motion along axis ``i`` per base motion along axis
``j`` (x, y, z [m]; rx, ry, rz [rad]), in dB of its unit (1, m/rad or rad/m). The linear
model is drawn dashed; a simulated estimate solid on its trusted bins only (docs/model.md
§10), faint elsewhere.
"""
import numpy as np

from qzs.analysis.hexapod_linear import entry_unit
from qzs._format import decibels
from qzs.defaults import AXES, FIGURES
from qzs.viz.figures import (check_frequency_scale, frequency_axis, frequency_limits, nice_floor,
                             save_figure)

__all__ = ["plot_transmissibility_matrix", "AXES"]

_FLOOR = FIGURES["magnitude_floor"]


def plot_transmissibility_matrix(frequency, *, linear=None, simulated=None, trusted=None,
                                 frequency_range=None, floor_db=-80.0, title=None, out=None,
                                 excited=None, linear_label=None, untrusted_below=None,
                                 frequency_scale=None):
    """Draw the 6x6 transmissibility matrix; optionally write it.

    Parameters
    ----------
    frequency : array_like, shape (n,)
        Frequencies [Hz] of ``simulated`` (and of ``linear`` if it is an array).
    linear : HexapodLinearModel or array_like, shape (n, 6, 6), optional
        The linear model (its ``transmissibility`` evaluated at ``frequency``), or its
        complex or magnitude values; drawn dashed.
    simulated : array_like, shape (n, 6, 6), optional
        Simulated magnitudes (NaN where a base axis was not excited); drawn solid.
    trusted : array_like of bool, shape (n, 6, 6), optional
        Which simulated bins are trusted; default all finite ones.
    frequency_range : (float, float), optional
        Horizontal range [Hz]; default the positive frequencies given.
    floor_db : float
        Lowest level drawn [dB]: entries that stay below it (the uncoupled ones of a
        symmetric platform) show as empty panels marked "< floor".
    title : str, optional
        Figure title.
    out : str or Path, optional
        Write the figure there (atomically; format from the suffix).
    excited : array_like of bool, shape (6,), optional
        Which base axes were excited in the simulation; the panels of the others are
        left empty (no curve, not even the linear one) and marked "not excited". Default:
        every column drawn.
    linear_label : str, optional
        Legend text of the linear curves; default "linear model".
    untrusted_below : float, optional
        Shade the band below this frequency [Hz] grey: untrusted in every entry (e.g. a
        chirp's start).
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.viz.figures import new_figure  # noqa: F401  (sets a headless backend if needed)
    import matplotlib.pyplot as plt

    from qzs.errors import ParameterError

    frequency = np.asarray(frequency, dtype=float)
    if frequency.ndim != 1 or frequency.size < 2:
        raise ParameterError(f"`frequency` must be a 1-d array of at least 2 frequencies [Hz], "
                             f"got shape {frequency.shape}.")
    if linear is not None and hasattr(linear, "transmissibility"):
        linear = linear.transmissibility(np.where(frequency > 0, frequency, np.nan))
    curves = {}
    for name, values in (("linear", linear), ("simulated", simulated)):
        if values is None:
            continue
        values = np.asarray(values)
        if values.shape != (frequency.size, 6, 6):
            raise ParameterError(f"`{name}` must have shape ({frequency.size}, 6, 6), got "
                                 f"{values.shape}.")
        curves[name] = decibels(values, _FLOOR)
    if not curves:
        raise ParameterError("give `linear`, `simulated` or both.")
    if trusted is None and simulated is not None:
        trusted = np.isfinite(np.abs(np.asarray(simulated)))
    if trusted is not None:
        trusted = np.asarray(trusted, dtype=bool)
        if trusted.shape != (frequency.size, 6, 6):
            raise ParameterError(f"`trusted` must have shape ({frequency.size}, 6, 6), got "
                                 f"{trusted.shape}.")
    if excited is None:
        excited = np.ones(6, dtype=bool)
    excited = np.asarray(excited, dtype=bool)
    if excited.shape != (6,):
        raise ParameterError(f"`excited` must be six flags, one per base axis, got shape "
                             f"{excited.shape}.")
    scale = check_frequency_scale(frequency_scale)
    positive = frequency > 0
    low, high = frequency_limits(frequency_range or (0.0, frequency[positive].max()),
                                 frequency[positive], scale)
    if scale == "log":
        low = nice_floor(low)  # small panels label the decades only: let 0.1 Hz be one
    shown = positive & (frequency >= low) & (frequency <= high)

    fig, axes = plt.subplots(6, 6, sharex=True, figsize=(15, 12.5), constrained_layout=True)
    # the vertical range from what is read: the linear curves and the trusted simulated bins
    peaks = []
    if "linear" in curves:
        peaks.append(np.nanmax(np.where(excited[None, None, :], curves["linear"],
                                        np.nan)[shown], initial=-np.inf))
    if "simulated" in curves:
        peaks.append(np.nanmax(np.where(trusted, curves["simulated"], np.nan)[shown],
                               initial=-np.inf))
    top = max([float(p) for p in peaks if np.isfinite(p)] or [0.0])
    top = 10 * np.ceil(top / 10 + 0.05)
    for i in range(6):
        for j in range(6):
            ax = axes[i, j]
            drawn = False
            if not excited[j]:
                ax.text(0.5, 0.5, "not excited", transform=ax.transAxes, ha="center",
                        va="center", color="0.5", fontsize=8)
            elif "simulated" in curves:
                level = curves["simulated"][:, i, j]
                good = positive & np.asarray(trusted)[:, i, j] & np.isfinite(level)
                ax.plot(frequency[positive], np.where(positive, level, np.nan)[positive],
                        color="C0", lw=0.6, alpha=0.25)
                ax.plot(frequency, np.where(good, level, np.nan), color="C0", lw=1.0,
                        label="simulated (trusted bins)")
                drawn |= bool(np.any(good & (level > floor_db)))
            if "linear" in curves and excited[j]:
                level = curves["linear"][:, i, j]
                ax.plot(frequency[positive], level[positive], color="k", ls="--", lw=0.9,
                        label=linear_label or "linear model")
                drawn |= bool(np.any(level[positive] > floor_db))
            if not drawn and excited[j]:
                faint = "simulated" in curves and bool(np.any(
                    curves["simulated"][positive, i, j] > floor_db))
                ax.text(0.5, 0.5, "no trusted bin" if faint else f"< {floor_db:g} dB",
                        transform=ax.transAxes, ha="center", va="center", color="0.5",
                        fontsize=8)
            frequency_axis(ax, (low, high), frequency_scale=scale, decades_only=True)
            ax.set_ylim(floor_db, top)
            if untrusted_below is not None and untrusted_below > low and excited[j]:
                ax.axvspan(low, untrusted_below, color="0.92", zorder=0, lw=0)
            ax.grid(True, which="both", lw=0.3, alpha=0.5)
            ax.tick_params(labelsize=7)
            if i == 0:
                ax.set_title(f"base {AXES[j]}" + ("" if excited[j] else " (not excited)"),
                             fontsize=9)
            if j == 0:
                ax.set_ylabel(f"platform {AXES[i]}\n|T| [dB]", fontsize=8)
            if i == 5:
                ax.set_xlabel("frequency [Hz]", fontsize=8)
            ax.text(0.97, 0.95, f"[{entry_unit(i, j)}]", transform=ax.transAxes, ha="right",
                    va="top", fontsize=6.5, color="0.35")
    first = int(np.argmax(excited))
    handles, labels = axes[first, first].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", fontsize=8, ncol=len(handles))
    fig.suptitle(title or "Platform motion per base motion: transmissibility matrix "
                          "(amplitude ratio, dB of its unit)", fontsize=11)
    if out is not None:
        save_figure(fig, out)
    return fig
