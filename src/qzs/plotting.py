"""Figures and text summaries of simulation results (matplotlib, Agg-safe)."""
import numpy as np

__all__ = ["plot_simulation", "plot_energy", "summary_text", "envelope"]

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


def _figure(rows, height=2.1):
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "svg", "pdf") and not _has_display():
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(9, height * rows + 0.8),
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
    fig, axes = _figure(4)
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
        _save(fig, path)
    return fig


def plot_energy(result, path=None):
    """Energy ledger of a run [J]: work in, dissipation, stored energy and the residual."""
    fig, axes = _figure(2, height=2.6)
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
        _save(fig, path)
    return fig


def _title(result):
    exc = result.excitation
    return (f"{type(exc).__name__}: {result.run['duration']:g} s, "
            f"{result.run['solver']} dt = {result.run['dt']:g} s")


def _save(fig, path):
    from qzs.io import atomic_path

    from pathlib import Path

    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=130)


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
