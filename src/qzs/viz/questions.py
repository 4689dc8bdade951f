"""Figures of the paper's two open questions (:mod:`qzs.workflows.questions`)."""
import math
import textwrap

import numpy as np

from qzs.viz.figures import new_figure

__all__ = ["plot_friction_compensation", "plot_friction_hunting", "plot_damping_design"]


def plot_friction_compensation(table, reference, band, boundary):
    """T over the band, isolation onset, stick events and motor RMS force against the fraction.

    Parameters
    ----------
    table : list of dict
        Rows of the friction study (``fraction``, ``band_rms``, ``isolation_onset`` [Hz],
        ``stick_events``, ``motor_force_rms`` [N]).
    reference : dict
        The isolator without stiction (the same keys).
    band : tuple of float
        The band of ``band_rms`` [Hz].
    boundary : dict
        ``predicted`` and ``simulated`` fractions where the paper's loop starts to hunt.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(4, height=1.7, width=7.0)
    a = [r["fraction"] for r in table]
    panels = (("band_rms", f"RMS T, {band[0]:g}-{band[1]:g} Hz [-]"),
              ("isolation_onset", "isolation onset [Hz]"),
              ("stick_events", "stick events [-]"), ("motor_force_rms", "motor RMS force [N]"))
    for ax, (key, label) in zip(axes, panels):
        ax.plot(a, [r[key] for r in table], "o-", color="C0", label="Table 1 (Fs = 10 N)")
        if math.isfinite(reference.get(key, math.nan)):
            ax.axhline(reference[key], color="C2", ls="--", label="without stiction (Fs = Fc)")
        for value, style, text in ((boundary["predicted"], ":", "sliding cycle predicted"),
                                   (boundary["simulated"], "-.", "hunts at rest (simulated)")):
            if math.isfinite(value):
                ax.axvline(value, color="C3", ls=style, label=text)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7, loc="best")
    axes[0].set_title("Friction compensation on the paper's isolator (10 mm chirp)", fontsize=9)
    axes[-1].set_xlabel("compensation fraction a [-]")
    return fig


def plot_friction_hunting(rows):
    """Predicted against simulated sliding cycles at rest, per loop and fraction.

    Parameters
    ----------
    rows : list of dict
        The study's hunting rows (``rig``, ``fraction``, ``predicted_velocity_amplitude``,
        ``simulated_velocity_amplitude`` [m/s], ``predicted_frequency``,
        ``simulated_frequency`` [Hz], ``simulated_hunts``, ``in_tolerance_regime``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, height=1.9, width=7.0)
    for i, rig in enumerate(dict.fromkeys(r["rig"] for r in rows)):
        mine = [r for r in rows if r["rig"] == rig]
        a = np.array([r["fraction"] for r in mine])
        for ax, key in zip(axes, ("velocity_amplitude", "frequency")):
            predicted = np.array([r[f"predicted_{key}"] for r in mine], dtype=float)
            simulated = np.array([r[f"simulated_{key}"] if r["simulated_hunts"] else np.nan
                                  for r in mine], dtype=float)
            ax.plot(a, predicted, "s--", color=f"C{i}", mfc="none",
                    label=f"{rig}: predicted")
            ax.plot(a, simulated, "o", color=f"C{i}", label=f"{rig}: simulated")
            regime = [r["in_tolerance_regime"] for r in mine]
            ax.plot(a[regime], predicted[regime], "*", color="k", ms=13, mfc="none",
                    label="in the stated range" if i == 0 and key == "frequency" else None)
    fractions = [r["fraction"] for r in rows]
    axes[1].set_xlim(min(fractions) - 0.05, max(fractions) + 0.05)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("slip velocity,\nfirst harmonic [m/s]", fontsize=8)
    axes[1].set_ylabel("frequency [Hz]", fontsize=8)
    axes[1].set_xlabel("compensation fraction a [-]")
    axes[0].set_title("Hunting at rest: describing function against the released runs",
                      fontsize=9)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=6, loc="best")
    axes[1].legend(fontsize=6, loc="best")
    return fig


def plot_damping_design(curves, rows, band):
    """Transmissibility of the damped cases and their two metrics against the undamped loop.

    Parameters
    ----------
    curves : list of CaseCurve
        The cases, the undamped first (:class:`qzs.workflows.questions.common.CaseCurve`).
    rows : list of dict
        The damped cases' metrics (``label``, ``kind``, ``largest_reduction_db``,
        ``band_rms_change_db`` [dB]).
    band : tuple of float
        The metrics' band [Hz].

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, height=2.6, width=7.5, sharex=False, height_ratios=(1.6, 1.0))
    ax = axes[0]
    for i, curve in enumerate(curves):
        keep = curve.trusted & (curve.frequency > 0)
        style = "-" if i == 0 or rows[i - 1]["kind"] == "paper" else "--"
        ax.plot(curve.frequency[keep], curve.magnitude[keep], style, color=f"C{i}", lw=1.2,
                label=curve.label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axvspan(*band, color="0.9", zorder=0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("transmissibility T [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6.5, loc="lower left")
    ax.set_title("Damping loops on the nonlinear model (10 mm chirp; shaded: the metrics' band)",
                 fontsize=9)
    ax = axes[1]
    x = np.arange(len(rows))
    ax.bar(x - 0.2, [r["largest_reduction_db"] for r in rows], 0.4,
           label="largest per-bin reduction [dB]", color="C0")
    ax.bar(x + 0.2, [-r["band_rms_change_db"] for r in rows], 0.4,
           label="band RMS reduction [dB]", color="C1")
    # wrapped to the bars' width: a long label ran into its neighbour's
    ax.set_xticks(x, [textwrap.fill(r["label"], 20, break_long_words=False) for r in rows],
                  fontsize=6)
    ax.set_ylabel("reduction [dB]")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=7)
    return fig
