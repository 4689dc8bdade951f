"""Figure of an experiment log: measured and simulated transmissibility, and the coherence."""
from pathlib import Path

import numpy as np

from qzs._format import decibels
from qzs.analysis.spectral import band_mask
from qzs.defaults import FIGURES
from qzs.viz.figures import check_frequency_scale, drawn, frequency_axis, new_figure, save_figure
from qzs.viz.transmissibility import COINCIDE_DB, coinciding

__all__ = ["plot_experiment"]


def plot_experiment(result, *, path=None, title=None, frequency_scale=None):
    """Measured and simulated transmissibility [dB] and the coherence, flagged band shaded.

    Trusted bins (docs/model.md §10) are drawn solid and set the vertical range;
    untrusted bins are drawn faint.

    Parameters
    ----------
    result : ExperimentResult
        The processed experiment.
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str, optional
        Figure title; default the log's file name.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale = check_frequency_scale(frequency_scale)
    fig, (top, bottom) = new_figure(2, height=2.6, sharex=False, width=10.0,
                                    height_ratios=(3, 1.4))
    bottom.sharex(top)
    limits = []
    simulated_label = "simulation (same chirp and processing)"
    if result.simulated is not None:
        curves = [dict(label=name, frequency=e.frequency, magnitude=e.magnitude,
                       trusted=getattr(e, "trusted", None))
                  for name, e in (("experiment", result.measured), ("simulation", result.simulated))]
        groups, _ = coinciding(curves, frequency_range=(0.0, result.band[1]))
        if len(groups) == 1:
            simulated_label += f", on top of the experiment (within {COINCIDE_DB:g} dB)"
    for estimate, color, ls, label, band in (
            (result.measured, "C0", "-", f"experiment ({result.measured.n_averages} averages)",
             (0.0, result.band[1])),
            (result.simulated, "C3", "--", simulated_label,
             (0.0, result.band[1]))):
        if estimate is None:
            continue
        f = estimate.frequency
        keep = band_mask(f, *band) & drawn(f, scale)
        trusted = getattr(estimate, "trusted", None)
        trusted = keep if trusted is None else keep & trusted
        db = decibels(estimate.magnitude, FIGURES["magnitude_floor"])
        top.plot(f[keep], db[keep], color=color, lw=0.8, ls=ls, alpha=0.25)
        top.plot(f[keep], np.where(trusted, db, np.nan)[keep], color=color, lw=1.1, ls=ls,
                 label=label)
        limits.extend(db[trusted][np.isfinite(db[trusted])])
        if estimate is result.measured:
            bottom.plot(f[keep], estimate.coherence[keep], color=color, lw=0.8)
    top.plot([], [], color="0.45", lw=1.0, alpha=0.45, label="faint: untrusted bins")
    lowest = [e.frequency[e.trusted] for e in (result.measured, result.simulated)
              if e is not None and getattr(e, "trusted", None) is not None]
    low, _ = frequency_axis(top, (0.0, result.band[1]), np.concatenate(lowest or [[]]),
                            frequency_scale=scale)
    for ax in (top, bottom):
        if result.untrusted_below > 0:
            ax.axvspan(low, result.untrusted_below, color="0.88", zorder=0,
                       label=f"not trustworthy (< {result.untrusted_below:g} Hz, high-pass)")
        ax.grid(True, which="both", alpha=0.3)
    if limits:
        low, high = min(min(limits), 0.0), max(max(limits), 0.0)
        pad = max(1.0, 0.06 * (high - low))
        top.set_ylim(low - pad, high + pad)
    coherence_min = getattr(result.measured, "coherence_min", None)
    if coherence_min is not None:
        bottom.axhline(coherence_min, color="k", lw=0.8, ls=":")
    top.axhline(0.0, color="k", lw=0.6)
    top.set_ylabel("transmissibility [dB]\nsqrt(S_payload/S_base)")
    fig.legend(*top.get_legend_handles_labels(), fontsize="small", loc="outside lower center",
               ncol=2)  # below the panels: never over a curve
    bottom.set_ylim(0, 1.05)
    bottom.set_ylabel("coherence [-]")
    bottom.set_xlabel("frequency [Hz]")
    top.set_title(title if title is not None else Path(result.recording.source.split(" (")[0]).name)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig
