"""The steady-state frequency response: stepped-sine sweeps over the harmonic balance.

Three panels over frequency: the fundamental transmissibility [dB] (sweep up and down, the
harmonic balance of the smooth model solid where stable and dashed where not, the linearised
loop dotted, the chirp-and-Welch estimate faint if there is one, folds marked), the relative
amplitude [mm], and the share of the period the payload is locked [-].
"""
import numpy as np

from qzs._format import decibels
from qzs.defaults import FIGURES
from qzs.viz.figures import check_frequency_scale, drawn, frequency_axis, new_figure, save_figure

__all__ = ["plot_response", "plot_balance", "plot_period"]

_FLOOR = FIGURES["magnitude_floor"]  # amplitude ratio drawn for 0 [-]
_SWEEPS = {"up": ("C0", "^", "stepped sine, sweep up"),
           "down": ("C3", "v", "stepped sine, sweep down")}


def _segments(mask):
    """Index ranges ``[start, stop)`` of the runs of True in ``mask``."""
    mask = np.asarray(mask, bool)
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return list(zip(edges[::2], edges[1::2]))


def _draw_balance(axes, curve, values, scale=1.0):
    """The harmonic balance on ``axes``: stable solid, unstable dashed, invalid grey."""
    f = curve.frequency
    labelled = set()
    for mask, style, label in (
            (curve.stable & curve.valid, dict(color="k", lw=1.2, ls="-"),
             "harmonic balance, stable"),
            (~curve.stable & curve.valid, dict(color="k", lw=1.2, ls="--"),
             "harmonic balance, unstable"),
            (~curve.valid, dict(color="0.6", lw=1.0, ls=":"),
             "harmonic balance, beyond stops or saturation")):
        for start, stop in _segments(mask):
            # overlap one point so that neighbouring segments join
            lo, hi = max(start - 1, 0), min(stop + 1, f.size)
            axes.plot(f[lo:hi], values[lo:hi] * scale, zorder=2, **style,
                      label=None if label in labelled else label)
            labelled.add(label)


def plot_response(response, path=None, title=None, frequency_scale=None):
    """Draw a :class:`~qzs.workflows.response.result.SteadyStateResponse`.

    Parameters
    ----------
    response : SteadyStateResponse
        The stepped-sine response (with its harmonic balance, linear model and chirp).
    path : str or Path, optional
        Write the figure there (format from the extension; a .png also as .svg).
    title : str, optional
        Figure title; default names the amplitude and the step.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax_t, ax_z, ax_l) = new_figure(3, height=2.4, height_ratios=(1.6, 1.0, 0.7))
    f_all = response.frequencies
    scale = check_frequency_scale(frequency_scale)
    curve = response.balance
    if response.linear:
        keep = drawn(response.linear["frequency"], scale)
        ax_t.plot(np.asarray(response.linear["frequency"])[keep],
                  decibels(np.asarray(response.linear["transmissibility"])[keep], _FLOOR),
                  color="0.45", ls=":",
                  lw=1.2, label="linearised loop (no friction)", zorder=1)
    if response.chirp is not None:
        est = response.chirp
        keep = (est.frequency >= f_all[0]) & (est.frequency <= f_all[-1]) & (est.frequency > 0)
        trusted = est.trusted & keep
        ax_t.plot(est.frequency[keep], decibels(est.magnitude[keep], _FLOOR), color="C2",
                  lw=0.6, alpha=0.25, zorder=1)
        ax_t.plot(np.where(trusted, est.frequency, np.nan), decibels(est.magnitude, _FLOOR),
                  color="C2", lw=0.9, alpha=0.8, label="chirp + Welch (paper), trusted bins",
                  zorder=1)
    if curve is not None:
        _draw_balance(ax_t, curve, decibels(curve.transmissibility, _FLOOR))
        _draw_balance(ax_z, curve, curve.relative_amplitude, scale=1e3)
        for fold in curve.folds:
            for ax in (ax_t, ax_z, ax_l):
                ax.axvline(fold, color="0.3", lw=0.6, ls="-.", zorder=0)
        if curve.folds:
            ax_t.plot([], [], color="0.3", lw=0.6, ls="-.",
                      label="folds of the harmonic balance")
    unconverged_label = True
    contact_label = True
    for direction in response.directions:
        colour, marker, label = _SWEEPS[direction]
        b = response.branch(direction)
        f = b["frequency"]
        ok = b["converged"] == 1
        t = np.where(ok, b["transmissibility"], np.nan)
        ax_t.plot(f, decibels(t, _FLOOR), color=colour, marker=marker, ms=4.5, lw=0.8,
                  label=label, zorder=3, mfc="none" if direction == "down" else colour)
        ax_z.plot(f, np.where(ok, b["relative_amplitude"], np.nan) * 1e3, color=colour,
                  marker=marker, ms=4, lw=0.8, zorder=3,
                  mfc="none" if direction == "down" else colour)
        ax_l.plot(f, np.where(ok, b["locked_fraction"], np.nan), color=colour, marker=marker,
                  ms=4, lw=0.8, drawstyle="default", zorder=3,
                  mfc="none" if direction == "down" else colour)
        contact = ok & (b["stop_contacts"] > 0)
        if contact.any():
            ax_t.plot(f[contact], decibels(t[contact], _FLOOR), ls="none", marker="o", ms=9,
                      mfc="none", mec="k", mew=0.8, zorder=4,
                      label="hits the stops" if contact_label else None)
            contact_label = False
        for i in np.flatnonzero(ok & (b["period_multiple"] > 1)):
            ax_t.annotate(f"period {int(b['period_multiple'][i])}",
                          (f[i], decibels(np.asarray(t[i]), _FLOOR)), textcoords="offset points",
                          xytext=(4, 6), fontsize=7, color=colour)
        if (~ok).any():  # no value: a cross on the bottom edge of the top panel
            ax_t.plot(f[~ok], np.full((~ok).sum(), 0.04), ls="none", marker="x", ms=6,
                      color=colour, zorder=4, transform=ax_t.get_xaxis_transform(),
                      label="not periodic (NaN)" if unconverged_label else None)
            unconverged_label = False
    # vertical range from the data actually plotted, not from estimator artefacts
    values = [decibels(response.branch(d)["transmissibility"], _FLOOR)
              for d in response.directions]
    if curve is not None:
        values.append(decibels(curve.transmissibility[curve.valid], _FLOOR))
    values = np.concatenate([v[np.isfinite(v) & (v > -200)] for v in values] or [[0.0]])
    if values.size:
        low, high = values.min(), values.max()
        pad = max(2.0, 0.08 * (high - low))
        ax_t.set_ylim(low - pad, high + pad)
    ax_t.axhline(0.0, color="0.75", lw=0.6, zorder=0)
    ax_t.set_ylabel("fundamental transmissibility\n|X1/Y1| [dB]")
    ax_z.set_ylabel("relative amplitude\n|Z1| [mm]")
    ax_l.set_ylabel("locked share\nof the period [-]")
    ax_l.set_ylim(-0.05, 1.05)
    ax_l.set_xlabel("frequency [Hz]")
    for ax in (ax_t, ax_z, ax_l):
        ax.grid(True, which="both", alpha=0.25)
    if scale == "log":
        frequency_axis(ax_t, (f_all[0] * 0.95, f_all[-1] * 1.05), frequency_scale=scale)
    else:
        pad = 0.02 * np.ptp(f_all) if f_all.size > 1 else 0.1 * f_all[0]
        frequency_axis(ax_t, (f_all[0] - pad, f_all[-1] + pad), frequency_scale=scale)
    handles, labels = [], []
    for ax in (ax_t,):
        h, lab = ax.get_legend_handles_labels()
        handles += h
        labels += lab
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=7, frameon=False)
    if title is None:
        title = (f"Steady-state response, base amplitude {response.amplitude * 1e3:g} mm "
                 f"({response.solver}, dt <= {response.dt:.2g} s, periodic to "
                 f"{response.settings['periodic_tolerance']:g})")
        if curve is not None:
            title += f"\nharmonic balance: {curve.harmonics} harmonics"
            model = curve.model
            if model.stiction_force > 0 or model.coulomb_force > 0:
                title += (f", friction regularised over {model.friction_velocity * 1e3:g} mm/s "
                          f"(it peaks at {model.peak_friction:.3g} N; Fs = "
                          f"{model.stiction_force:g} N)")
    ax_t.set_title(title, fontsize=9)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_balance(curve, path=None, title=None, frequency_scale=None):
    """Draw a harmonic balance :class:`~qzs.analysis.harmonic_balance.FrequencyResponseCurve`.

    Parameters
    ----------
    curve : FrequencyResponseCurve
        The curve (:func:`qzs.analysis.harmonic_balance.frequency_response_curve`).
    path : str or Path, optional
        Write the figure there (format from the extension; a .png also as .svg).
    title : str, optional
        Figure title; default names the harmonics.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax_t, ax_z) = new_figure(2, height=2.4, height_ratios=(1.4, 1.0))
    scale = check_frequency_scale(frequency_scale)
    _draw_balance(ax_t, curve, decibels(curve.transmissibility, _FLOOR))
    _draw_balance(ax_z, curve, curve.relative_amplitude, scale=1e3)
    for fold in curve.folds:
        for ax in (ax_t, ax_z):
            ax.axvline(fold, color="0.3", lw=0.6, ls="-.", zorder=0)
    ax_t.set_ylabel("fundamental transmissibility\n|X1/Y1| [dB]")
    ax_z.set_ylabel("relative amplitude\n|Z1| [mm]")
    ax_z.set_xlabel("frequency [Hz]")
    f = curve.frequency
    frequency_axis(ax_t, (float(np.min(f)) * 0.95, float(np.max(f)) * 1.05),
                   frequency_scale=scale)
    for ax in (ax_t, ax_z):
        ax.grid(True, which="both", alpha=0.25)
    ax_t.legend(fontsize=7, loc="best")
    ax_t.set_title(title if title is not None else
                   f"harmonic balance of the smooth model, {curve.harmonics} harmonics",
                   fontsize=9)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_period(solution, path=None, title=None):
    """One period of a :class:`~qzs.analysis.harmonic_balance.HarmonicBalanceSolution`.

    Parameters
    ----------
    solution : HarmonicBalanceSolution
        The periodic response (:func:`qzs.analysis.harmonic_balance.periodic_response`).
    path : str or Path, optional
        Write the figure there (format from the extension; a .png also as .svg).
    title : str, optional
        Figure title; default names the frequency and the harmonics.

    Returns
    -------
    matplotlib.figure.Figure
    """
    series = solution.time_series()
    fig, axes = new_figure(3, height=1.8)
    for ax, (name, scale, label) in zip(axes, (
            ("relative_position", 1e3, "relative position z [mm]"),
            ("motor_force", 1.0, "motor command [N]"),
            ("payload_acceleration", 1.0, "payload acceleration [m/s$^2$]"))):
        ax.plot(series["time"], series[name] * scale, color="C0", lw=1.0)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time from the base's crest [s]")
    axes[0].set_title(title if title is not None else
                      f"periodic response at {solution.frequency:.4g} Hz, "
                      f"{solution.harmonics} harmonics (|X1/Y1| = "
                      f"{solution.transmissibility:.4g})", fontsize=9)
    if path is not None:
        save_figure(fig, path)
    return fig
