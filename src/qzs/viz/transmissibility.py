"""Transmissibility curves in dB against frequency, as the paper draws them."""
import numpy as np

from qzs.viz.figures import new_figure, save_figure

__all__ = ["plot_transmissibility"]


def plot_transmissibility(curves, *, frequency_range=(0.0, 20.0), scale="linear", title="",
                          path=None, untrusted_below=None, estimator="sqrt(S_payload/S_base)"):
    """Transmissibility curves in dB against frequency, as the paper draws them.

    Parameters
    ----------
    curves : sequence of dict
        Each with ``label``, ``frequency`` [Hz], ``magnitude`` (amplitude ratio) and
        optionally ``linear`` (the linearised model's magnitude on the same
        frequencies, drawn dashed in the same colour) and ``style`` (matplotlib kwargs).
    frequency_range : (float, float)
        Axis limits [Hz].
    scale : {"linear", "log"}
        Frequency axis scale.
    title : str
        Figure title.
    path : str or Path, optional
        Written as given and, for a .png, also as .svg beside it.
    untrusted_below : float, optional
        Shade the band below this frequency [Hz] as not trustworthy (high-pass).
    estimator : str
        How the magnitude was estimated, for the axis label (default the PSD ratio).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(1, height=4.2)
    ax = axes[0]
    for i, curve in enumerate(curves):
        f = np.asarray(curve["frequency"])
        keep = (f >= frequency_range[0]) & (f <= frequency_range[1]) & (f > 0)
        style = {"color": f"C{i}", "lw": 1.0, **curve.get("style", {})}
        ax.plot(f[keep], 20 * np.log10(np.maximum(curve["magnitude"][keep], 1e-12)),
                label=curve["label"], **style)
        if curve.get("linear") is not None:
            ax.plot(f[keep], 20 * np.log10(np.maximum(curve["linear"][keep], 1e-12)),
                    color=style["color"], lw=0.8, ls="--")
    if any(c.get("linear") is not None for c in curves):
        ax.plot([], [], color="0.4", ls="--", lw=0.8, label="linearised model")
    if untrusted_below:
        ax.axvspan(frequency_range[0], untrusted_below, color="0.85", zorder=0,
                   label=f"untrustworthy (< {untrusted_below:g} Hz, high-pass)")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xscale(scale)
    low = frequency_range[0] if scale == "linear" else max(frequency_range[0], 0.01)
    ax.set_xlim(low, frequency_range[1])
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"transmissibility {estimator} [dB]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig
