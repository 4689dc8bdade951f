"""Figures of a controller design (``qzs design``): every axis with its quantity and unit.

Each function takes plain numbers (the records of
:class:`qzs.workflows.design.result.DesignResult`) and returns a matplotlib figure;
:func:`plot_design` draws them all from a result.
"""
import math

import numpy as np

from qzs._format import decibels
from qzs.defaults import FIGURES
from qzs.viz.figures import check_frequency_scale, drawn, frequency_axis, new_figure

__all__ = ["plot_design", "plot_static_design", "plot_pi_search", "plot_hunting",
           "plot_damping_search", "plot_margins", "plot_damping_effect"]

_FAMILY_STYLE = {"base": ("tab:blue", "o", "base motion"),
                 "step": ("tab:orange", "s", "base motion + force step"),
                 "hunting": ("tab:red", "^", "at rest (hunting)")}


def _grid(rows, cols, width=10.0, height=3.2):
    """A ``rows`` x ``cols`` figure, on the backend :func:`new_figure` chooses."""
    import matplotlib.pyplot as plt

    probe, _ = new_figure(1)  # chooses a headless backend when there is no display
    plt.close(probe)
    fig, axes = plt.subplots(rows, cols, figsize=(width, height * rows + 0.6),
                             constrained_layout=True)
    return fig, np.atleast_1d(axes).ravel()


def plot_static_design(static, gravity=9.81):
    """Motor force needed to hold a payload at the setpoint against its mass.

    Parameters
    ----------
    static : StaticDesign
        The static design (:func:`qzs.analysis.control_design.static.static_design`).
    gravity : float
        Gravitational acceleration [m/s^2].

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax,) = new_figure(1, height=3.6)
    lifted, f_max = static.spring_force_at_setpoint, static.motor_force_max
    top = max(static.mass_range[1], static.holdable_mass[1] if math.isfinite(
        static.holdable_mass[1]) else 0) * 1.1 + 0.5
    mass = np.linspace(0.0, top, 200)
    ax.plot(mass, mass * gravity - lifted, color="k", lw=1.5,
            label="needed: m*g - F_spring(z_ref)")
    ax.axhline(f_max, color="tab:red", ls="--", label=f"motor limit +-{f_max:g} N")
    ax.axhline(-f_max, color="tab:red", ls="--")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvspan(*static.mass_range, color="tab:blue", alpha=0.15, label="design's mass range")
    if math.isfinite(static.balanced_mass):
        ax.axvline(static.balanced_mass, color="tab:green", ls=":",
                   label=f"spring alone carries {static.balanced_mass:.2f} kg")
    nominal = (static.weight / gravity) if gravity > 0 else math.nan
    ax.plot([nominal], [static.static_deficit], "o", color="tab:blue",
            label=f"design mass {nominal:.2f} kg: {static.static_deficit:+.2f} N")
    if math.isfinite(static.moving_mass_without_added):
        ax.plot([static.moving_mass_without_added], [static.deficit_without_added], "x",
                color="tab:red", ms=9,
                label=f"without the paper's 5.5 kg: {static.deficit_without_added:+.1f} N")
    ax.set_xlabel("moving mass [kg]")
    ax.set_ylabel("static motor force [N]")
    ax.set_xlim(0, top)
    ax.set_title("Static design at the setpoint: what the motor must add to the MagSpring")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    return fig


def plot_pi_search(details, table, chosen, failing, setpoint, stroke_band, first=None,
                   damping_gains=(0.0, 0.0)):
    """Use of the constant-force band against the proportional gain, per case family.

    Parameters
    ----------
    details : dict
        Proportional gain [N/m] -> list of per-case rows (``family``, ``usage``, ``passes``).
    table : list of dict
        One summary row per gain (``pi_kp`` [N/m], ``passes``).
    chosen : float
        The chosen proportional gain [N/m] (NaN if none).
    failing : float
        The failing gain just below it [N/m] (NaN if none).
    setpoint : float
        Position setpoint [m].
    stroke_band : tuple of float
        The constant-force band [m, m].
    first : dict, optional
        The details of a first search without the final damping gain (drawn dashed).
    damping_gains : tuple of float
        Damping gain of the final search and of the first [N*s/m, N*s/m].

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax,) = new_figure(1, height=4.0)
    searches = [(details, "-", f"Kd = {damping_gains[0]:g} N*s/m")]
    if first:
        searches.append((first, "--", f"Kd = {damping_gains[1]:g} N*s/m"))
    for found, style, tag in searches:
        gains = sorted(found)
        for family, (color, marker, label) in _FAMILY_STYLE.items():
            used = []
            for kp in gains:
                rows = [r for r in found[kp] if r["family"] == family]
                if not rows:
                    used = None
                    break
                used.append(max(r["usage"] for r in rows))
            if used is None:
                continue
            values = np.array(used, dtype=float)
            shown = np.where(np.isfinite(values), values, np.nan) * 100
            ax.plot(gains, shown, color=color, marker=marker, ls=style,
                    mfc=color if style == "-" else "none",
                    label=f"{label} ({tag})" if first else label)
            broken = ~np.isfinite(values)
            if broken.any():
                ax.plot(np.array(gains)[broken], np.full(broken.sum(), 100.0), "x",
                        color=color, ms=10, label=f"{label}: diverged")
    ax.axhline(100.0, color="k", ls="--", lw=1,
               label=f"band edge ({1e3 * (stroke_band[1] - setpoint):.1f} mm above, "
                     f"{1e3 * (setpoint - stroke_band[0]):.1f} mm below)")
    if math.isfinite(chosen):
        ax.axvline(chosen, color="tab:green", lw=1.5, label=f"chosen Kp = {chosen:.3g} N/m")
    if math.isfinite(failing):
        ax.axvline(failing, color="tab:green", lw=1, ls=":",
                   label=f"fails at {failing:.3g} N/m")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("proportional gain Kp [N/m] (Ki = ratio * Kp)")
    ax.set_ylabel("largest use of the band [%]")
    ax.set_title("PI search: worst case of each family (100 % = the constant-force band's edge)")
    from matplotlib.ticker import ScalarFormatter

    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(ScalarFormatter())
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3, which="both")
    return fig


def plot_hunting(locus, traces, rows):
    """The stick-slip relay's describing function against the integral loop, and simulations.

    Parameters
    ----------
    locus : dict or None
        ``loop`` (``G(jw)`` [-]), ``minus_inverse`` (``-1/N(A)`` [-]), ``intersection``
        (complex or None), ``stiction_force`` [N].
    traces : dict
        Stiction force [N] -> ``(time [s], position about the setpoint [m])``.
    rows : list of dict
        Per stiction value: ``prediction`` (``amplitude`` [m], ``hunts``), ``simulation``
        and ``damping_gain`` [N*s/m] (only the rows with 0, the PI loop alone, are drawn).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(2, height=3.4, sharex=False)
    ax = axes[0]
    if locus is not None:
        loop, inverse = np.asarray(locus["loop"]), np.asarray(locus["minus_inverse"])
        ax.plot(loop.real, loop.imag, color="tab:blue", label="integral loop G(jw)")
        ax.plot(inverse.real, inverse.imag, color="tab:red",
                label=f"-1/N(A), stick-slip relay (Fs = {locus['stiction_force']:g} N)")
        point = locus.get("intersection")
        if point is not None:
            ax.plot([point.real], [point.imag], "ko", label="predicted hunting cycle")
            scale = 2 * max(abs(point), 1e-3)
        else:
            scale = 2 * float(np.median(np.abs(inverse)))
        ax.set_xlim(-scale, 0.4 * scale)
        ax.set_ylim(-scale, 0.4 * scale)
        ax.axhline(0, color="0.6", lw=0.8)
        ax.axvline(0, color="0.6", lw=0.8)
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no stick-slip jump or no integral: no hunting predicted",
                transform=ax.transAxes, ha="center")
    ax.set_xlabel("real part [-]")
    ax.set_ylabel("imaginary part [-]")
    ax.set_title("Describing function of the PI loop alone: the integral loop against the "
                 "stick-slip relay")
    ax.grid(alpha=0.3)
    ax = axes[1]
    colors = ("tab:green", "tab:blue", "tab:purple", "tab:orange")
    alone = [row for row in rows if row.get("damping_gain", 0.0) == 0.0]
    for i, row in enumerate(alone):
        fs = row["stiction_force"]
        color = colors[i % len(colors)]
        if fs in traces:
            t, zeta = traces[fs]
            ax.plot(t, 1e3 * np.asarray(zeta), color=color, lw=1, label=f"Fs = {fs:g} N")
        plateau = row["prediction"].get("amplitude")
        if plateau is not None and math.isfinite(plateau) and row["prediction"]["hunts"]:
            ax.axhline(1e3 * plateau, color=color, ls="--", lw=0.8)
            ax.axhline(-1e3 * plateau, color=color, ls="--", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("z - z_ref [mm]")
    ax.set_title("PI loop alone, simulated at rest (dashed: the describing function's "
                 "plateaus +-d/K)")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    return fig


def plot_damping_search(rows, curves, chosen, bound, band, cost, frequency_scale=None):
    """Cost against the damping gain, and transmissibility without and with the chosen gain.

    Parameters
    ----------
    rows : list of dict
        ``damping_gain`` [N*s/m], ``cost`` and ``linear_cost`` [-].
    curves : dict
        Damping gain [N*s/m] -> ``(frequency [Hz], magnitude [-], trusted)``.
    chosen : float
        The chosen damping gain [N*s/m].
    bound : float
        Largest admissible damping gain [N*s/m].
    band : tuple of float
        The cost's band [Hz, Hz].
    cost : str
        ``"rms"`` or ``"peak"``.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    scale = check_frequency_scale(frequency_scale)
    fig, axes = new_figure(2, height=3.3, sharex=False)
    ax = axes[0]
    gains = np.array([r["damping_gain"] for r in rows], dtype=float)
    simulated = np.array([r["cost"] for r in rows], dtype=float)
    linear = np.array([r["linear_cost"] for r in rows], dtype=float)
    positive = gains[gains > 0]
    threshold = positive.min() if positive.size else 1.0
    ax.plot(gains, simulated, "o-", color="tab:blue", label="simulated (nonlinear)")
    ax.plot(gains, linear, "--", color="0.4", label="linear model (no friction but Cv)")
    ax.axvline(chosen, color="tab:green", lw=1.5, label=f"chosen Kd = {chosen:.4g} N*s/m")
    if math.isfinite(bound):
        ax.axvline(bound, color="tab:red", ls=":", label=f"bound {bound:.4g} N*s/m")
    ax.set_xscale("symlog", linthresh=threshold)
    ax.set_xlim(0, gains.max() * 1.3 if gains.size else 1.0)
    ax.set_xlabel("damping gain Kd [N*s/m] (linear scale below the first gain tried)")
    ax.set_ylabel(f"{cost} of T over {band[0]:g}-{band[1]:g} Hz [-]")
    ax.set_title("Damping search")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    ax = axes[1]
    shown = [k for k in (0.0, chosen) if k in curves]
    levels, lowest = [], []
    for gain, color in zip(shown, ("tab:gray", "tab:green")):
        frequency, magnitude, trusted = curves[gain]
        frequency = np.asarray(frequency, dtype=float)
        trusted = np.asarray(trusted, bool) & (frequency > 0)
        keep = drawn(frequency, scale)
        db = decibels(magnitude, FIGURES["magnitude_floor"])
        solid = np.where(trusted, db, np.nan)
        ax.plot(frequency[keep], db[keep], color=color, alpha=0.25, lw=0.8)
        ax.plot(frequency[keep], solid[keep], color=color, lw=1.3, label=f"Kd = {gain:g} N*s/m")
        inside = trusted & (frequency >= band[0]) & (frequency <= band[1])
        levels.extend(db[inside])
        lowest.append(frequency[trusted])
    if levels:
        ax.set_ylim(min(levels) - 6, max(levels) + 6)
    low, _ = frequency_axis(ax, (0.0, band[1] * 1.05), np.concatenate(lowest or [[]]),
                            frequency_scale=scale, label="frequency [Hz]")
    ax.axvspan(max(band[0], low), band[1], color="tab:blue", alpha=0.06, label="cost band")
    ax.set_ylabel("transmissibility [dB]")
    ax.set_title("Simulated transmissibility (faint: untrusted bins)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return fig


def plot_margins(table, required_rate, gain_margin_min, phase_margin_min, delay, by_delay=()):
    """Gain and phase margins of the sampled loop against the controller rate.

    Parameters
    ----------
    table : list of dict
        Per rate: ``rate`` [Hz], ``stable``, ``gain_margin`` [dB], ``phase_margin`` [deg].
    required_rate : float
        The lowest rate keeping the margins [Hz] (NaN if none).
    gain_margin_min : float
        Least gain margin [dB].
    phase_margin_min : float
        Least phase margin [deg].
    delay : float
        The delay of the loop [s].
    by_delay : sequence of dict
        ``delay`` [s] and ``required_rate`` [Hz] (drawn in a third panel if given).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(3 if by_delay else 2, height=2.6, sharex=False)
    rates = np.array([t["rate"] for t in table], dtype=float)
    stable = np.array([t["stable"] for t in table], dtype=bool)
    for ax, key, target, unit, name in (
            (axes[0], "gain_margin", gain_margin_min, "dB", "gain margin"),
            (axes[1], "phase_margin", phase_margin_min, "deg", "phase margin")):
        values = np.array([t[key] if t[key] is not None else np.nan for t in table], float)
        finite = np.where(np.isfinite(values), values, np.nan)
        ax.plot(rates[stable], finite[stable], "o-", color="tab:blue", label="stable loop")
        if (~stable).any():  # no margin to draw: marked along the rate axis, off the scale
            ax.plot(rates[~stable], np.full((~stable).sum(), 0.04), "x", color="tab:red",
                    ms=9, transform=ax.get_xaxis_transform(), clip_on=False,
                    label="unstable loop (no margin)")
        if np.isinf(values).any():
            top = np.nanmax(finite) if np.isfinite(finite).any() else target
            ax.plot(rates[np.isinf(values)], np.full(np.isinf(values).sum(), top), "^",
                    color="tab:blue", label="no -180 deg crossing (infinite)")
        ax.axhline(target, color="k", ls="--", lw=1, label=f"required {target:g} {unit}")
        if math.isfinite(required_rate):
            ax.axvline(required_rate, color="tab:green",
                       label=f"needed rate {required_rate:.3g} Hz")
        ax.set_xscale("log")
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    axes[0].set_title(f"Sampled loop (zero-order hold, delay {1e3 * delay:g} ms)")
    axes[0].set_xlabel("controller rate [Hz]")
    axes[1].set_xlabel("controller rate [Hz]")
    if by_delay:
        ax = axes[2]
        delays = np.array([1e3 * r["delay"] for r in by_delay], dtype=float)
        rates = np.array([np.nan if r["required_rate"] is None else r["required_rate"]
                          for r in by_delay], dtype=float)
        ax.plot(delays, rates, "o-", color="tab:green")
        ax.set_yscale("log")
        ax.set_xlabel("delay from sampling to the motor force [ms]")
        ax.set_ylabel("needed rate [Hz]")
        ax.set_title(f"Lowest rate keeping {gain_margin_min:g} dB and {phase_margin_min:g} deg")
        ax.grid(alpha=0.3, which="both")
    return fig


def plot_damping_effect(rows, delay_rows):
    """Change of the cost with damping: against the gain, Cv, the high-pass, the rate, a delay.

    Parameters
    ----------
    rows : list of dict
        ``factor``, ``damping_gain`` [N*s/m], ``velocity_highpass`` [Hz],
        ``viscous_damping`` [N*s/m], ``controller_rate`` [Hz], ``change_db`` and
        ``linear_change_db`` [dB].
    delay_rows : list of dict
        ``delay`` [s], ``damping_gain`` [N*s/m], ``linear_change_db`` [dB].

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = _grid(3, 2, height=2.7)
    gains = sorted({r["damping_gain"] for r in rows if r["factor"] != "baseline"})
    colors = dict(zip(gains, ("tab:blue", "tab:green", "tab:purple")))

    def finite(values):
        return np.array([np.nan if v is None else v for v in values], dtype=float)

    ax = axes[0]
    sweep = sorted((r for r in rows if r["factor"] == "baseline"),
                   key=lambda r: r["damping_gain"])
    if sweep:
        x = [r["damping_gain"] for r in sweep]
        ax.plot(x, finite(r["change_db"] for r in sweep), "o", color="k", label="simulated")
        ax.plot(x, finite(r["linear_change_db"] for r in sweep), "-", color="k", alpha=0.5,
                label="linear")
        cv = sweep[0]["viscous_damping"]
        ax.axvline(cv, color="tab:orange", ls=":", label=f"Kd = Cv = {cv:g} N*s/m")
        ax.axhline(-3.0, color="tab:red", ls="--", lw=0.8, label="-3 dB")
        ax.set_xscale("log")
        ax.legend(fontsize=7)
    ax.set_xlabel("damping gain Kd [N*s/m] (paper's set-up)")
    panels = (("viscous friction", "viscous_damping", "viscous friction Cv [N*s/m]", "log"),
              ("high-pass", "velocity_highpass", "charge-amplifier high-pass corner [Hz]",
               "symlog"),
              ("controller rate", "controller_rate",
               "controller rate [Hz] (continuous drawn at 20 kHz)", "log"))
    for ax, (factor, key, label, scale) in zip(axes[1:4], panels):
        for gain in gains:
            chosen = sorted((r for r in rows if r["factor"] in (factor, "baseline")
                             and r["damping_gain"] == gain), key=lambda r: (
                r[key] if not (key == "controller_rate" and r[key] == 0) else 2e4))
            x = np.array([r[key] if not (key == "controller_rate" and r[key] == 0) else 2e4
                          for r in chosen], dtype=float)
            ax.plot(x, finite(r["change_db"] for r in chosen), "o", color=colors[gain],
                    label=f"simulated, Kd = {gain:.4g} N*s/m")
            ax.plot(x, finite(r["linear_change_db"] for r in chosen), "-", color=colors[gain],
                    alpha=0.5, label=f"linear, Kd = {gain:.4g} N*s/m")
        if scale == "symlog":
            ax.set_xscale("symlog", linthresh=0.1)
        else:
            ax.set_xscale(scale)
        ax.set_xlabel(label)
    axes[1].legend(fontsize=7)
    ax = axes[4]
    for gain in sorted({r["damping_gain"] for r in delay_rows}):
        chosen = [r for r in delay_rows if r["damping_gain"] == gain]
        ax.plot([1e3 * r["delay"] for r in chosen], [r["linear_change_db"] for r in chosen],
                "-", color=colors.get(gain, "k"), label=f"linear, Kd = {gain:.4g} N*s/m")
    ax.set_xlabel("delay [ms] (linear sampled model)")
    ax.legend(fontsize=7)
    for ax in axes[:5]:
        ax.axhline(0, color="0.5", lw=0.8)
        ax.set_ylabel("change of the cost [dB]")
        ax.grid(alpha=0.3, which="both")
    axes[5].axis("off")
    axes[5].text(0.02, 0.5, "Change of the band cost when the damping loop is switched on,\n"
                 "against the cost without it (negative: better isolation).\n"
                 "Markers: simulated (stick-slip, stops, saturation);\n"
                 "lines: the linear model (viscous friction only).",
                 transform=axes[5].transAxes, fontsize=9, va="center")
    fig.suptitle("Why active damping did not help much: what it achieves against each factor")
    return fig


def plot_design(result, frequency_scale=None):
    """Every figure of a design.

    Parameters
    ----------
    result : DesignResult
        The design (:func:`qzs.workflows.design.driver.design_controller`).
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the transmissibility figure; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        ``static_design``, ``pi_search``, ``hunting``, ``damping``, ``margins``,
        ``damping_effect``.
    """
    s = result.settings
    figures = {"static_design": plot_static_design(result.static,
                                                   s["isolator"].get("gravity", 9.81))}
    pi = result.pi_search
    if result.series.get("pi_details"):
        first = result.series.get("pi_details_first") or None
        figures["pi_search"] = plot_pi_search(
            result.series["pi_details"], pi.get("table", []), pi["pi_kp"], pi["failing_kp"],
            s["controller"]["position_setpoint"], s["stroke_band"], first=first,
            damping_gains=(pi["damping_gain"], pi.get("first_search", {}).get(
                "damping_gain", 0.0)))
    figures["hunting"] = plot_hunting(result.series.get("hunting_loop"),
                                      result.series.get("hunting_traces", {}),
                                      result.hunting["rows"])
    if result.damping["rows"]:
        figures["damping"] = plot_damping_search(result.damping["rows"],
                                                 result.series.get("damping_curves", {}),
                                                 result.damping["chosen"],
                                                 result.damping["bound"], s["band"], s["cost"],
                                                 frequency_scale=frequency_scale)
    figures["margins"] = plot_margins(result.margins["table"], result.margins["required_rate"],
                                      s["gain_margin_min"], s["phase_margin_min"], s["delay"],
                                      result.margins.get("by_delay", ()))
    figures["damping_effect"] = plot_damping_effect(result.why["rows"],
                                                    result.why["delay_rows"])
    return figures
