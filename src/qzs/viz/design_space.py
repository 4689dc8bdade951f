"""Figures of a design search: the Pareto front among every evaluated design.

Two objectives: one panel, every evaluated design as a dot (feasible filled, infeasible
hollow), the Pareto set joined as a staircase, the chosen design starred. More
objectives: every pair in a panel. One objective: the objective of each evaluated
design against its generation, the best feasible so far as a line.
"""
import itertools

import numpy as np

from qzs._format import unit_label
from qzs.viz.figures import new_figure, save_figure

__all__ = ["plot_pareto", "goal_label"]


def goal_label(goal):
    """An axis label: the goal, its statistic and its unit (``peak stroke, worst case [m]``).

    Parameters
    ----------
    goal : Goal
        An objective or constraint of a design problem.

    Returns
    -------
    str
    """
    stat = (f", quantile {goal.quantile:g}" if goal.statistic == "quantile"
            else {"mean": "", "worst": ", worst case"}[goal.statistic])
    return unit_label(f"{goal.title}{stat}", goal.units)


def plot_pareto(result, ax=None, *, path=None, title=None):
    """Draw the Pareto front of an :class:`~qzs.workflows.design_space.result.OptimizationResult`.

    Parameters
    ----------
    result : OptimizationResult
        The search.
    ax : matplotlib.axes.Axes, optional
        Draw into this axes (two objectives only); default a new figure.
    path : str or Path, optional
        Also write the figure there (PNG, SVG, PDF by the suffix).
    title : str, optional
        Figure title; default the problem's.

    Returns
    -------
    matplotlib.figure.Figure
    """
    p = result.problem
    objectives = p.objectives
    n_obj = len(objectives)
    values = result.goal_values[:, :n_obj]
    pairs = list(itertools.combinations(range(n_obj), 2))
    if ax is not None:
        fig, axes = ax.figure, [ax]
    elif n_obj == 1:
        fig, axes = new_figure(1, height=3.6, width=6.4)
    else:
        fig, axes = new_figure(len(pairs), height=3.6, width=6.4, sharex=False)
    if n_obj == 1:
        _convergence(result, axes[0])
    else:
        for axis, (i, j) in zip(axes, pairs):
            _front(result, axis, values, i, j)
    fig.suptitle(title or f"{p.title}\n{len(result.designs)} designs evaluated, "
                          f"{result.pareto.size} in the Pareto set", fontsize=10)
    if path is not None:
        save_figure(fig, path)
    return fig


def _front(result, ax, values, i, j):
    goals = result.problem.objectives
    feasible = result.feasible
    ax.scatter(values[feasible, i], values[feasible, j], s=10, color="0.65",
               label=f"feasible ({int(feasible.sum())})", zorder=1)
    if (~feasible).any():
        ax.scatter(values[~feasible, i], values[~feasible, j], s=12, facecolors="none",
                   edgecolors="0.75", linewidths=0.6,
                   label=f"infeasible ({int((~feasible).sum())})", zorder=1)
    members = result.pareto
    if members.size:
        front = values[members][np.argsort(values[members, i])]
        ax.step(front[:, i], front[:, j], where="post", color="C0", linewidth=1.0, zorder=2)
        ax.scatter(front[:, i], front[:, j], s=22, color="C0",
                   label=f"Pareto set ({members.size})", zorder=3)
    chosen = result.chosen
    if chosen is not None:
        ax.scatter([values[chosen, i]], [values[chosen, j]], marker="*", s=160, color="C3",
                   edgecolors="k", linewidths=0.5, label=f"chosen (design {chosen})", zorder=4)
    ax.set_xlabel(goal_label(goals[i]))
    ax.set_ylabel(goal_label(goals[j]))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")


def _convergence(result, ax):
    goal = result.problem.objectives[0]
    values = result.goal_values[:, 0]
    generation = result.generation
    feasible = result.feasible
    ax.scatter(generation[feasible], values[feasible], s=8, color="0.6", label="feasible")
    if (~feasible).any():
        ax.scatter(generation[~feasible], values[~feasible], s=10, facecolors="none",
                   edgecolors="0.75", label="infeasible")
    sign = -1.0 if goal.sense == "maximize" else 1.0
    best = []
    for g in range(int(generation.max()) + 1 if generation.size else 0):
        inside = feasible & (generation <= g)
        best.append(sign * np.min(sign * values[inside]) if inside.any() else np.nan)
    ax.plot(np.arange(len(best)), best, color="C0", label="best feasible so far")
    ax.set_xlabel("generation [-]")
    ax.set_ylabel(goal_label(goal))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
