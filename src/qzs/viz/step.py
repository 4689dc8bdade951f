"""The figure of a step choice: the estimated error of each candidate step and the tolerance."""
import numpy as np

from qzs.viz.figures import new_figure, save_figure

__all__ = ["plot_step_choice"]


def plot_step_choice(choice, path=None, title=None):
    """Each candidate step's estimated error against the step, with the tolerance and the
    chosen step (log-log: the scheme's order is the slope where the estimate holds). The
    chosen step is the coarsest whose estimate times the search's safety factor (2 by
    default, docs/model.md §7) meets the tolerance.

    Parameters
    ----------
    choice : StepChoice
        The record (:func:`qzs.engine.step_choice.choose`).
    path : str or Path, optional
        If given, the figure is also written there, atomically (format from the suffix).
    title : str, optional
        Figure title; default the chosen step and how it was chosen.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax,) = new_figure(1, height=3.2, width=6.5)
    unit = choice.unit if choice.chosen else "-"
    rows = np.array([row[:3] for row in choice.history], dtype=float).reshape(-1, 3)
    if rows.size:
        ax.loglog(rows[:, 0], rows[:, 1], "o--", color="0.5", lw=0.8,
                  label="difference to the next finer step")
        ax.loglog(rows[:, 0], rows[:, 2], "o-", lw=1.2, label="estimated error")
    if choice.chosen:
        ax.axhline(choice.tolerance, color="C3", lw=1.0,
                   label=f"tolerance {choice.tolerance:g} {unit} (the estimate times a safety "
                         "factor must meet it)")
    else:
        ax.text(0.5, 0.5, "a literal step: no candidate was tried", transform=ax.transAxes,
                ha="center", va="center")
    ax.axvline(choice.dt, color="C2", lw=1.0, ls=":", label=f"dt = {choice.dt:.3g} s")
    ax.set_xlabel("step dt [s]")
    ax.set_ylabel(f"error [{unit}]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    state = ("given literally" if not choice.chosen
             else "meets the tolerance" if choice.met else "fallback: tolerance not met")
    fig.suptitle(title if title is not None else f"step choice: dt = {choice.dt:.4g} s ({state})")
    if path is not None:
        save_figure(fig, path)
    return fig
