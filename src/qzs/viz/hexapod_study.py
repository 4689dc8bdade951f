"""Figures of the shipped hexapod study (``qzs hexapod study``): cases side by side.

One figure compares the study's controller cases on the entries that matter for a chirp
in z and one in x: the vertical and lateral transmissibility (the diagonal), the
strongest cross-axis response, and the coherence of the diagonal with its threshold.
Trusted bins are drawn solid, untrusted ones faint (docs/model.md §10); the linear model
dashed in the case's colour, and left out where its loop is unstable (its frequency
response is then no steady state).
"""
import numpy as np

from qzs.analysis.hexapod_linear import entry_unit
from qzs._format import decibels
from qzs.defaults import AXES, FIGURES
from qzs.viz.figures import check_frequency_scale, frequency_axis, frequency_limits, save_figure

__all__ = ["plot_study_comparison", "AXES"]

_FLOOR = FIGURES["magnitude_floor"]


def plot_study_comparison(cases, *, entries, coherence_min=0.9, frequency_range=(0.1, 20.0),
                          untrusted_below=None, title=None, out=None, frequency_scale=None):
    """Draw chosen entries of several simulated matrices, one column per excited axis.

    Parameters
    ----------
    cases : sequence of (str, HexapodTransmissibility)
        Label and result of each case (same excited axes).
    entries : sequence of sequence of (int, int)
        Per figure column, the ``(output, input)`` entries drawn in its rows (the first
        row of every column is the diagonal, whose coherence the last row shows); a
        column with fewer entries than another leaves its lower panels out.
    coherence_min : float
        The trusted-bin coherence threshold drawn as a line [-].
    frequency_range : (float, float)
        Horizontal range [Hz].
    untrusted_below : float, optional
        Shade the band below this frequency [Hz], untrusted in every entry (the sweep's
        start).
    title : str, optional
        Figure title.
    out : str or Path, optional
        Write the figure there (atomically; a .png also as .svg).
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.viz.figures import new_figure  # noqa: F401  (sets a headless backend if needed)
    import matplotlib.pyplot as plt

    columns = len(entries)
    rows = max(len(column) for column in entries) + 1
    fig, axes = plt.subplots(rows, columns, sharex=True, figsize=(6.2 * columns, 2.7 * rows),
                             constrained_layout=True, squeeze=False,
                             gridspec_kw={"height_ratios": [1.0] * (rows - 1) + [0.6]})
    scale = check_frequency_scale(frequency_scale)
    low, high = frequency_limits(frequency_range,
                                 np.concatenate([r.frequency for _, r in cases]), scale)
    for c, column in enumerate(entries):
        for r, (i, j) in enumerate(column):
            ax = axes[r, c]
            levels = []
            for k, (label, result) in enumerate(cases):
                f = result.frequency
                keep = (f > 0) & (f >= low) & (f <= high)
                level = decibels(result.response[:, i, j], _FLOOR)
                good = keep & result.trusted[:, i, j]
                color = f"C{k}"
                width = max(2.6 - 0.8 * k, 0.9)  # the first case widest: equal curves stay visible
                ax.plot(f[keep], level[keep], color=color, lw=0.6, alpha=0.25)
                ax.plot(f, np.where(good, level, np.nan), color=color, lw=width,
                        label=f"{label}: simulated (trusted)")
                levels.append(level[good])
                if result.linear_stable:
                    linear = decibels(result.linear_response[:, i, j], _FLOOR)
                    if np.nanmax(linear[keep]) > -150:
                        ax.plot(f[keep], linear[keep], color=color, ls="--", lw=0.9,
                                label=f"{label}: linear model")
                        levels.append(linear[keep])
            shown = np.concatenate([v for v in levels if v.size] or [np.zeros(1)])
            top = 10 * np.ceil(np.nanmax(shown) / 10 + 0.05)
            bottom = max(10 * np.floor(np.nanmin(shown) / 10 - 0.05), top - 80)
            ax.set_ylim(bottom, top)
            frequency_axis(ax, (low, high), frequency_scale=scale)
            ax.grid(True, which="both", lw=0.3, alpha=0.5)
            kind = "transmissibility" if i == j else "cross-axis response"
            unit = entry_unit(i, j, dimensionless="-")
            ax.set_title(f"platform {AXES[i]} per base {AXES[j]}: {kind} [{unit}]",
                         fontsize=10)
            ax.set_ylabel("|T| [dB]" if i < 3 and j < 3 or i >= 3 and j >= 3
                          else f"|T| [dB re 1 {unit}]", fontsize=9)
            if untrusted_below:
                ax.axvspan(low, untrusted_below, color="0.92", zorder=0, lw=0)
        ax = axes[rows - 1, c]
        i, j = column[0]
        for k, (label, result) in enumerate(cases):
            f = result.frequency
            keep = (f > 0) & (f >= low) & (f <= high)
            ax.plot(f[keep], result.coherence[keep, i, j], color=f"C{k}", lw=1.0, label=label)
        ax.axhline(coherence_min, color="0.3", ls=":", lw=0.9,
                   label=f"trusted at >= {coherence_min:g}")
        ax.set_ylim(0, 1.05)
        if untrusted_below:
            ax.axvspan(low, untrusted_below, color="0.92", zorder=0, lw=0)
        ax.set_ylabel(f"coherence {AXES[i]}/{AXES[j]} [-]", fontsize=9)
        ax.set_xlabel("frequency [Hz]", fontsize=9)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        for r in range(len(column), rows - 1):
            axes[r, c].set_visible(False)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(handles), 3),
               fontsize=8)
    if title:
        fig.suptitle(title, fontsize=11)
    if out is not None:
        save_figure(fig, out, also_svg=True)
    return fig
