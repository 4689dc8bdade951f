"""Figures and text summaries of simulation results (matplotlib, Agg-safe)."""
import numpy as np

__all__ = ["plot_simulation", "plot_energy", "plot_transmissibility", "plot_spring_fit",
           "summary_text", "envelope", "new_figure", "save_figure"]

_MAX_POINTS = 4000  # per trace: long runs are drawn as a min/max envelope


def envelope(time, values, max_points=_MAX_POINTS):
    """Min/max envelope of a long trace, for plotting without aliasing.

    Returns ``(time, values)`` unchanged when short, else two points (min and
    max) per bin for ``max_points // 2`` bins.
    """
    time = np.asarray(time)
    values = np.asarray(values, dtype=float)
    n = values.size
    if n <= max_points:
        return time, values
    bins = max_points // 2
    width = n // bins
    used = bins * width
    blocks = values[:used].reshape(bins, width)
    t = time[:used].reshape(bins, width)
    low, high = blocks.argmin(axis=1), blocks.argmax(axis=1)
    first = np.minimum(low, high)
    second = np.maximum(low, high)
    rows = np.arange(bins)
    t_out = np.column_stack([t[rows, first], t[rows, second]]).ravel()
    v_out = np.column_stack([blocks[rows, first], blocks[rows, second]]).ravel()
    return t_out, v_out


def new_figure(rows, height=2.1, sharex=True):
    """A figure of ``rows`` stacked axes, 9 in wide (Agg when there is no display)."""
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "svg", "pdf") and not _has_display():
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, 1, sharex=sharex, figsize=(9, height * rows + 0.8),
                             constrained_layout=True)
    return fig, np.atleast_1d(axes)


def _has_display():
    import os

    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def plot_simulation(result, path=None, title=None):
    """Time series of a run: motion, relative position with the stops, forces, accelerations.

    Parameters
    ----------
    result : SimulationResult
    path : str or Path, optional
        If given, the figure is also written there (format from the suffix).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(4)
    t = result.time

    def trace(ax, name, scale=1.0, **style):
        tt, vv = envelope(t, result[name] * scale)
        ax.plot(tt, vv, lw=0.7, **style)

    trace(axes[0], "base_displacement", 1e3, label="base y")
    trace(axes[0], "payload_displacement", 1e3, label="payload x")
    axes[0].set_ylabel("displacement [mm]")

    trace(axes[1], "relative_position", 1e3, color="C2", label="z = x - y")
    run = result.run
    for z_stop in (run["stop_low"], run["stop_high"]):
        axes[1].axhline(z_stop * 1e3, color="k", lw=1.0, ls="--")
    axes[1].axhline(result.controller.position_setpoint * 1e3, color="C3", lw=0.8, ls=":",
                    label="setpoint")
    axes[1].set_ylabel("relative position [mm]")

    for name, label in (("spring_force", "spring"), ("friction_force", "friction"),
                        ("motor_force", "motor"), ("stop_force", "stop")):
        trace(axes[2], name, label=label)
    axes[2].set_ylabel("force [N]")

    trace(axes[3], "base_acceleration", label="base")
    trace(axes[3], "payload_acceleration", label="payload")
    axes[3].set_ylabel("acceleration [m/s$^2$]")
    axes[3].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(loc="upper right", fontsize="small", ncols=4)
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or _title(result))
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_energy(result, path=None):
    """Energy ledger of a run [J]: work in, dissipation, stored energy and the residual."""
    fig, axes = new_figure(2, height=2.6)
    t = result.time
    for name in ("base_work", "motor_work", "friction_dissipation", "stop_dissipation"):
        axes[0].plot(*envelope(t, result[name]), lw=0.8, label=name.replace("_", " "))
    axes[0].set_ylabel("energy [J]")
    axes[1].plot(*envelope(t, result.energy_residual()), lw=0.8, color="k")
    axes[1].set_ylabel("ledger residual [J]")
    axes[1].set_xlabel("time [s]")
    axes[0].legend(fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.suptitle("Energy ledger: dE = W_base + W_motor - D_friction - D_stop")
    if path is not None:
        save_figure(fig, path)
    return fig


def _title(result):
    exc = result.excitation
    return (f"{type(exc).__name__}: {result.run['duration']:g} s, "
            f"{result.run['solver']} dt = {result.run['dt']:g} s")


def save_figure(fig, path, also_svg=False):
    """Write ``fig`` atomically (format from the suffix); a .png also as .svg if asked."""
    from pathlib import Path

    from qzs.io import atomic_path

    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=130)
    if also_svg and path.suffix.lower() == ".png":
        save_figure(fig, path.with_suffix(".svg"))


def summary_text(result):
    """One-screen summary: operating point, stroke used, contacts, time locked, speed."""
    iso, ctrl, run = result.isolator, result.controller, result.run
    z = result.relative_position
    t = result.time
    low, high = run["stop_low"], run["stop_high"]
    used = (z.max() - z.min()) / (high - low)
    lines = [
        f"qzs simulation  {_title(result)}{'' if result.completed else '  [INTERRUPTED]'}",
        f"  steps            {run['steps']:,} in {run['elapsed']:.2f} s "
        f"({result.steps_per_second / 1e6:.2f} M steps/s), {len(result):,} samples at "
        f"{run['sample_rate']:g} Hz",
        f"  operating point  setpoint z_ref = {ctrl.position_setpoint * 1e3:.1f} mm; "
        f"mean z = {z.mean() * 1e3:.2f} mm; final z = {z[-1] * 1e3:.2f} mm",
        f"  stroke used      z in [{z.min() * 1e3:.2f}, {z.max() * 1e3:.2f}] mm = "
        f"{100 * used:.1f} % of the stops' [{low * 1e3:.0f}, {high * 1e3:.0f}] mm",
        f"  stop contacts    {run['stop_contacts']} "
        f"({100 * result.stop_contact.mean():.2f} % of the time in contact)",
        f"  locked           {100 * result.locked.mean():.1f} % of the time; "
        f"{run['stick_events']} stick events",
        f"  motor force      RMS {np.sqrt(np.mean(result.motor_force ** 2)):.2f} N, "
        f"peak {np.abs(result.motor_force).max():.2f} N (limit {iso.motor_force_max:g} N)",
    ]
    deficit = iso.weight_deficit
    if deficit > 0:
        lines.append(
            f"  note             m*g = {iso.mass * iso.gravity:.2f} N exceeds the spring's "
            f"{iso.spring_force:.2f} N plateau: the PI integral must carry {deficit:.2f} N"
            + ("" if ctrl.pi_ki > 0 else " (pi_ki = 0: nothing does; the payload sinks)"))
    residual = np.abs(result.energy_residual()).max()
    scale = max(np.abs(result.base_work).max(), 1e-300)
    lines.append(f"  energy ledger    max residual {residual:.3g} J "
                 f"({residual / scale:.2g} of the base work)")
    lines.append(f"  time span        {t[0]:g} .. {t[-1]:g} s")
    return "\n".join(lines)


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
    untrusted_below : float, optional
        Shade the band below this frequency [Hz] as not trustworthy (high-pass).
    path : str or Path, optional
        Written as given and, for a .png, also as .svg beside it.

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


def plot_spring_fit(displacement, force, spring_force, spring_shape, *, path=None, title=""):
    """MagSpring force against displacement with its tanh fit (paper Fig. 5)."""
    fig, axes = new_figure(1, height=3.8)
    ax = axes[0]
    z = np.linspace(np.min(displacement), np.max(displacement), 400)
    ax.plot(np.asarray(displacement) * 1e3, force, "o", ms=3.5, label="measured (synthetic)")
    ax.plot(z * 1e3, -spring_force * np.tanh(spring_shape * z), "-",
            label=f"fit: a = {spring_force:.2f} N, b = {spring_shape:.2f} 1/m")
    ax.set_xlabel("relative position z [mm]")
    ax.set_ylabel("spring force [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig
