"""Figure of an experiment log: measured and simulated transmissibility, and the coherence."""
from pathlib import Path

import numpy as np

from qzs.analysis.spectral import band_mask
from qzs.viz.figures import new_figure, save_figure

__all__ = ["plot_experiment"]


def plot_experiment(result, *, path=None, title=None):
    """Measured and simulated transmissibility [dB] and the coherence, flagged band shaded.

    Parameters
    ----------
    result : ExperimentResult
        The processed experiment.
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str, optional
        Figure title; default the log's file name.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (top, bottom) = new_figure(2, height=2.6, sharex=False)
    bottom.sharex(top)
    f, measured, coherence = result._in_band(result.measured)
    top.plot(f, 20 * np.log10(np.maximum(measured, 1e-12)), color="C0", lw=1.0,
             label=f"experiment ({result.measured.n_averages} averages)")
    if result.simulated is not None:
        g = result.simulated.frequency
        keep = band_mask(g, 0.0, result.band[1])
        top.plot(g[keep], 20 * np.log10(np.maximum(result.simulated.magnitude[keep], 1e-12)),
                 color="C3", lw=1.0, ls="--", label="simulation (same chirp and processing)")
    bottom.plot(f, coherence, color="C0", lw=0.8)
    for ax in (top, bottom):
        if result.untrusted_below > 0:
            ax.axvspan(0, result.untrusted_below, color="0.85", zorder=0,
                       label=f"not trustworthy (< {result.untrusted_below:g} Hz, high-pass)")
        ax.grid(True, alpha=0.3)
    top.axhline(0.0, color="k", lw=0.6)
    top.set_xlim(0, result.band[1])
    top.set_ylabel("transmissibility [dB]\nsqrt(S_payload/S_base)")
    top.legend(fontsize="small")
    bottom.set_ylim(0, 1.05)
    bottom.set_ylabel("coherence [-]")
    bottom.set_xlabel("frequency [Hz]")
    top.set_title(title if title is not None else Path(result.recording.source.split(" (")[0]).name)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig
