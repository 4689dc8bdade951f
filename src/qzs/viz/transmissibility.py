"""Transmissibility curves in dB against frequency, as the paper draws them, with their coherence.

Only trusted bins (docs/model.md §10) are drawn solid and set the vertical range; untrusted
bins are drawn faint. Curves that coincide are said so in the legend, and
:func:`overlap_notes` gives the same in sentences for a caption.
"""
import textwrap

import numpy as np

from qzs._format import decibels
from qzs.defaults import ANALYSIS, FIGURES
from qzs.viz.figures import check_frequency_scale, frequency_axis, new_figure, save_figure

__all__ = ["plot_transmissibility", "coinciding", "overlap_notes"]

#: Curves whose trusted bins all lie within this many dB of each other coincide [dB].
COINCIDE_DB = 0.5
_FLOOR = FIGURES["magnitude_floor"]  # amplitude ratio drawn for 0 [-]


def _trusted(curve):
    f = np.asarray(curve["frequency"], dtype=float)
    trusted = curve.get("trusted")
    ok = np.ones(f.shape, bool) if trusted is None else np.asarray(trusted, dtype=bool)
    return ok & (f > 0) & np.isfinite(np.asarray(curve["magnitude"], dtype=float))


def _in_range(f, frequency_range):
    return (f > 0) & (f >= frequency_range[0]) & (f <= frequency_range[1])


def coinciding(curves, *, key="magnitude", frequency_range=(0.0, np.inf), tolerance_db=COINCIDE_DB):
    """Which curves lie on top of each other, and from which frequency on all of them do.

    Two curves coincide when, on every frequency both have trusted in
    ``frequency_range``, they differ by at most ``tolerance_db``.

    Parameters
    ----------
    curves : sequence of dict
        As for :func:`plot_transmissibility`.
    key : str
        ``"magnitude"`` (trusted bins only) or ``"linear"`` (the linearised model's
        curve, exact: every bin).
    frequency_range : (float, float)
        Band compared [Hz].
    tolerance_db : float
        Largest difference of coinciding curves [dB].

    Returns
    -------
    groups : list of list of int
        Indices of the curves that coincide, one list per group, in order; a curve that
        coincides with no other is a group of one. Curves without ``key`` are left out.
    merged_above : float or None
        Lowest compared frequency [Hz] from which all those curves lie within
        ``tolerance_db`` of each other up to the top of the range; None if that never
        happens or fewer than two curves are compared.
    """
    use = [i for i, c in enumerate(curves) if c.get(key) is not None]
    common = None
    grids = {}
    for i in use:
        c = curves[i]
        f = np.asarray(c["frequency"], dtype=float)
        ok = (_trusted(c) if key == "magnitude" else np.ones(f.shape, bool)) & _in_range(f, frequency_range)
        grids[i] = dict(zip(f[ok], decibels(np.asarray(c[key])[ok], _FLOOR)))
        common = set(grids[i]) if common is None else common & set(grids[i])
    groups, assigned = [], set()
    for i in use:
        if i in assigned:
            continue
        group = [i]
        for j in use:
            if j > i and j not in assigned:
                shared = set(grids[i]) & set(grids[j])
                if shared and max(abs(grids[i][f] - grids[j][f]) for f in shared) <= tolerance_db:
                    group.append(j)
        assigned.update(group)
        groups.append(group)
    merged_above = None
    if len(use) >= 2 and common:
        frequencies = np.array(sorted(common))
        spread = np.array([np.ptp([grids[i][f] for i in use]) for f in frequencies])
        apart = np.flatnonzero(spread > tolerance_db)
        if apart.size == 0:
            merged_above = float(frequencies[0])
        elif apart[-1] < frequencies.size - 1:
            merged_above = float(frequencies[apart[-1] + 1])
    return groups, merged_above


def overlap_notes(curves, *, frequency_range=(0.0, np.inf), tolerance_db=COINCIDE_DB):
    """Sentences saying which curves (and linearised curves) lie on top of each other.

    Parameters
    ----------
    curves : sequence of dict
        As for :func:`plot_transmissibility`.
    frequency_range : (float, float)
        Band compared [Hz].
    tolerance_db : float
        Largest difference of coinciding curves [dB].

    Returns
    -------
    list of str
    """
    notes = []
    for key, what in (("magnitude", "simulated curves"), ("linear", "linearised curves")):
        groups, merged = coinciding(curves, key=key, frequency_range=frequency_range,
                                    tolerance_db=tolerance_db)
        compared = sum(len(g) for g in groups)
        for group in groups:
            if len(group) > 1:
                names = "; ".join(curves[i]["label"] for i in group)
                whole = "All" if len(group) == compared else "The"
                notes.append(f"{whole} {what} of {names} lie on top of each other (within "
                             f"{tolerance_db:g} dB{' over their trusted bins' if key == 'magnitude' else ''}).")
        if merged is not None and compared >= 2 and len(groups) > 1 \
                and merged > frequency_range[0]:
            notes.append(f"Above {merged:.2g} Hz all {what} lie within {tolerance_db:g} dB of "
                         "each other.")
    return notes


def _ylimits(curves, frequency_range):
    values = []
    for curve in curves:
        f = np.asarray(curve["frequency"], dtype=float)
        keep = _trusted(curve) & _in_range(f, frequency_range)
        values.append(decibels(np.asarray(curve["magnitude"])[keep], _FLOOR))
        if curve.get("linear") is not None:
            band = _in_range(f, frequency_range)
            values.append(decibels(np.asarray(curve["linear"])[band], _FLOOR))
    values = np.concatenate(values) if values else np.array([])
    values = values[np.isfinite(values) & (values > decibels(_FLOOR))]
    if values.size == 0:
        return None
    low, high = min(values.min(), 0.0), max(values.max(), 0.0)
    pad = max(1.0, 0.06 * (high - low))
    return low - pad, high + pad


def plot_transmissibility(curves, *, frequency_range=(0.0, 20.0), frequency_scale=None, title="",
                          path=None, untrusted_below=None, estimator="sqrt(S_payload/S_base)",
                          coherence_min=ANALYSIS["coherence_min"]):
    """Transmissibility curves in dB against frequency, and their coherence below.

    Trusted bins are drawn solid and alone set the vertical range; untrusted bins are
    drawn faint. The linearised model's curves are dashed in their case's colour, named
    in the legend; curves that coincide (:func:`coinciding`) are said so there.

    Parameters
    ----------
    curves : sequence of dict
        Each with ``label``, ``frequency`` [Hz], ``magnitude`` (amplitude ratio) and
        optionally ``trusted`` (bool per bin; default all above 0 Hz), ``coherence``
        (magnitude-squared, per bin), ``linear`` (the linearised model's magnitude on the
        same frequencies, drawn dashed in the same colour) and ``style`` (matplotlib kwargs).
    frequency_range : (float, float)
        Axis limits [Hz]; a log axis starting at 0 starts at the lowest trusted bin
        instead (:func:`qzs.viz.figures.frequency_limits`).
    frequency_scale : {"log", "linear"}, optional
        Frequency axis scale; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    title : str
        Figure title.
    path : str or Path, optional
        Written as given and, for a .png, also as .svg beside it.
    untrusted_below : float, optional
        Shade the band below this frequency [Hz] as not trustworthy (high-pass).
    estimator : str
        How the magnitude was estimated, for the axis label (default the PSD ratio).
    coherence_min : float
        The coherence a trusted bin needs [-], drawn as a line on the coherence panel.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D

    scale = check_frequency_scale(frequency_scale)
    with_coherence = any(c.get("coherence") is not None for c in curves)
    if with_coherence:
        fig, (ax, cax) = new_figure(2, height=2.9, width=10.0, height_ratios=(3, 1))
    else:
        fig, (ax,) = new_figure(1, height=4.2, width=10.0)
        cax = None
    groups, _ = coinciding(curves, frequency_range=frequency_range)
    same_as = {j: group[0] for group in groups for j in group[1:]}
    handles = []
    for i, curve in enumerate(curves):
        f = np.asarray(curve["frequency"], dtype=float)
        keep = _in_range(f, frequency_range)
        ok = _trusted(curve)
        style = {"color": f"C{i}", "lw": 1.3, **curve.get("style", {})}
        db = decibels(curve["magnitude"], _FLOOR)
        ax.plot(f[keep], db[keep], color=style["color"], lw=0.8, alpha=0.25)
        solid = np.where(ok, db, np.nan)
        label = curve["label"]
        if i in same_as:
            label += f" (on top of {curves[same_as[i]]['label']})"
        (line,) = ax.plot(f[keep], solid[keep], label=label, **style)
        handles.append(line)
        if cax is not None and curve.get("coherence") is not None:
            cax.plot(f[keep], np.asarray(curve["coherence"])[keep], color=style["color"], lw=0.9)
    linear_groups, _ = coinciding(curves, key="linear", frequency_range=frequency_range)
    compared = sum(len(g) for g in linear_groups)
    for group in linear_groups:
        first = curves[group[0]]
        f = np.asarray(first["frequency"], dtype=float)
        keep = _in_range(f, frequency_range)
        if compared == 1:
            color, label = first.get("style", {}).get("color", f"C{group[0]}"), "linearised model"
        elif len(group) == compared:
            every = "both" if compared == 2 else f"all {compared}"
            color, label = "0.15", f"linearised model (the same for {every} cases)"
        else:
            color = first.get("style", {}).get("color", f"C{group[0]}")
            names = "; ".join(curves[i]["label"] for i in group)
            label = f"linearised: {names}" + (" (on top of each other)" if len(group) > 1 else "")
        (line,) = ax.plot(f[keep], decibels(first["linear"], _FLOOR)[keep], color=color, lw=0.9,
                          ls="--", label=label)
        handles.append(line)
    handles.append(Line2D([], [], color="0.45", lw=1.0, alpha=0.45,
                          label=f"faint: untrusted (coherence < {coherence_min:g} or no base power)"))
    axes = [ax] if cax is None else [ax, cax]
    # a log axis starts at the lowest bin read: a trusted one, or the linearised model's
    # (exact at every bin, it shows the resonance the chirp cannot reach)
    shown = [np.asarray(c["frequency"], dtype=float)[_trusted(c)] for c in curves]
    shown += [np.asarray(c["frequency"], dtype=float) for c in curves
              if c.get("linear") is not None]
    low, high = frequency_axis(ax, frequency_range, np.concatenate(shown or [[]]),
                               frequency_scale=scale)
    if untrusted_below:
        for a in axes:
            span = a.axvspan(low, untrusted_below, color="0.88", zorder=0,
                             label=f"below {untrusted_below:g} Hz: untrusted after the high-pass")
        handles.append(span)
    ax.axhline(0.0, color="k", lw=0.6)
    limits = _ylimits(curves, (low, high))
    if limits is not None:
        ax.set_ylim(*limits)
    for a in axes:
        a.grid(True, which="both", alpha=0.3)
    ax.set_ylabel(f"transmissibility [dB]\n{estimator}")
    longest = max(len(h.get_label()) for h in handles)
    for h in handles:
        h.set_label(textwrap.fill(h.get_label(), 90))
    fig.legend(handles=handles, fontsize="small", loc="outside lower center",
               ncol=1 if longest > 60 or len(handles) < 3 else 2)
    ax.set_title(title)
    if cax is not None:
        cax.axhline(coherence_min, color="k", lw=0.8, ls=":")
        cax.text(0.995, coherence_min - 0.03, f"trusted from {coherence_min:g}", ha="right",
                 va="top", transform=cax.get_yaxis_transform(), fontsize="small")
        cax.set_ylim(0, 1.05)
        cax.set_ylabel("coherence [-]")
        cax.set_xlabel("frequency [Hz]")
    else:
        ax.set_xlabel("frequency [Hz]")
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig
