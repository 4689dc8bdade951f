"""Figures of a hexapod run: platform pose against the base, leg strokes, motor forces."""
import numpy as np

from qzs.defaults import AXES
from qzs.viz.figures import envelope, new_figure, save_figure

__all__ = ["plot_hexapod"]


def plot_hexapod(result, path=None, title=None):
    """Time series of a hexapod run in four panels (docs/hexapod.md, "Dynamics").

    1. the platform's translation against the base's [mm] (each axis that moves, and the
       platform's response in the others);
    2. the platform's rotation against the base's [mrad];
    3. every leg's relative position ``z_i`` [mm] with its stops;
    4. every leg's motor force [N] with the saturation limits.

    Parameters
    ----------
    result : HexapodResult
        The run (:func:`qzs.engine.hexapod.simulate_hexapod`).
    path : str or Path, optional
        If given, the figure is also written there (format from the suffix).
    title : str, optional
        Figure title; default the excitation, duration, solver and step.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(4, height=2.2)
    t = result["time"]
    pose, base = result["platform_pose"], result["base_pose"]
    for panel, columns, scale, unit in ((0, range(3), 1e3, "mm"), (1, range(3, 6), 1e3, "mrad")):
        ax = axes[panel]
        for a in columns:
            color = f"C{a % 3}"
            if np.any(base[:, a] != 0):
                tt, vv = envelope(t, base[:, a] * scale)
                ax.plot(tt, vv, lw=0.7, ls="--", color=color, label=f"base {AXES[a]}")
            tt, vv = envelope(t, pose[:, a] * scale)
            ax.plot(tt, vv, lw=0.8, color=color, label=f"platform {AXES[a]}")
        kind = "translation" if panel == 0 else "rotation"
        ax.set_ylabel(f"{kind} [{unit}]")
    z = result["relative_position"]
    for i in range(z.shape[1]):
        tt, vv = envelope(t, z[:, i] * 1e3)
        axes[2].plot(tt, vv, lw=0.7, color=f"C{i}", label=f"leg {i + 1}")
    stops = np.asarray(result.run["stops"]) * 1e3
    for level in np.unique(np.round(stops, 9)):
        axes[2].axhline(level, color="k", lw=1.0, ls="--")
    axes[2].set_ylabel("leg position z [mm]")
    motor = result["motor_force"]
    for i in range(motor.shape[1]):
        tt, vv = envelope(t, motor[:, i])
        axes[3].plot(tt, vv, lw=0.7, color=f"C{i}", label=f"leg {i + 1}")
    for limit in sorted({iso.motor_force_max for iso in result.isolators}):
        for sign in (-1.0, 1.0):
            axes[3].axhline(sign * limit, color="k", lw=1.0, ls=":",
                            label="saturation" if sign > 0 and limit == max(
                                iso.motor_force_max for iso in result.isolators) else None)
    axes[3].set_ylabel("motor force [N]")
    axes[3].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(loc="upper right", fontsize="x-small", ncols=6)
        ax.grid(True, alpha=0.3)
    run = result.run
    moving = ", ".join(f"{axis}: {type(e).__name__}" for axis, e in result.excitation.items())
    fig.suptitle(title or f"hexapod, base {moving or 'at rest'}; {run['duration']:g} s, "
                          f"{run['solver']} dt = {run['dt']:g} s")
    if path is not None:
        save_figure(fig, path)
    return fig
