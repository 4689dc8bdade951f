"""Figures of one run: time series and the energy ledger."""
from qzs.analysis.summary import run_title
from qzs.viz.figures import envelope, new_figure, save_figure

__all__ = ["plot_simulation", "plot_energy", "plot_batch"]


def plot_simulation(result, path=None, title=None):
    """Time series of a run: motion, relative position with the stops, forces, accelerations.

    Parameters
    ----------
    result : SimulationResult
        The run.
    path : str or Path, optional
        If given, the figure is also written there (format from the suffix).
    title : str, optional
        Figure title; default :func:`qzs.analysis.summary.run_title` (excitation,
        duration, solver and step).

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
    fade = getattr(result.excitation, "fade_in", 0.0)
    for ax in axes:
        if fade > 0:
            ax.axvspan(0.0, min(fade, t[-1]), color="0.85", lw=0, zorder=0,
                       label=f"fade-in {fade:g} s" if ax is axes[0] else None)
        ax.legend(loc="upper right", fontsize="small", ncols=4)
        ax.grid(True, alpha=0.3)
    every = result.run.get("preview_every", 1)
    subtitle = ("" if every == 1 else
                f"\n(envelope: min/max per {every} of {result.run['samples']:,} samples)")
    fig.suptitle((title or run_title(result)) + subtitle)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_energy(result, path=None):
    """Energy ledger of a run [J]: work in, dissipation, stored energy and the residual.

    Parameters
    ----------
    result : SimulationResult
        The run.
    path : str or Path, optional
        If given, the figure is also written there (format from the suffix).

    Returns
    -------
    matplotlib.figure.Figure
    """
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


def plot_batch(result, path=None, title=None, max_panels=4, max_labels=8):
    """The kept channels of a batch of runs, one panel per channel, one line per case.

    Parameters
    ----------
    result : BatchResult
        The batch (:func:`qzs.engine.batch.simulate_batch`).
    path : str or Path, optional
        If given, the figure is also written there, atomically (format from the suffix).
    title : str, optional
        Figure title; default one naming the cases and the failures.
    max_panels : int
        The first channels drawn (a flag is not drawn).
    max_labels : int
        Cases named in the legend (the first ones).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.engine.channels import CHANNELS

    names = [name for name in result.channels if name in CHANNELS][:max_panels]
    fig, axes = new_figure(max(len(names), 1))
    n = len(result.status)
    for ax, name in zip(axes, names):
        unit = CHANNELS[name][1]
        for i in range(n):
            tt, vv = envelope(result.time, result.channels[name][i])
            ax.plot(tt, vv, lw=0.7, label=f"case {i}" if i < max_labels else None)
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    if names:
        axes[0].legend(loc="upper right", fontsize="small", ncols=4)
    failed = int(sum(result.status))
    fig.suptitle(title if title is not None else f"batch of {n} runs"
                 + (f", {failed} failed" if failed else ""))
    if path is not None:
        save_figure(fig, path)
    return fig
