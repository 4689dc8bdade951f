"""Figures of a global sensitivity analysis: the indices as bars with their intervals.

One panel per metric, one row per parameter, the most influential on top. Sobol: the
first-order index ``S1`` and the total index ``ST`` side by side, each with its
confidence interval as an error bar; ``ST - S1`` is what the parameter does through
interactions. Morris: ``mu*`` as a bar with its interval, ``sigma`` as a marker on the
same axis (a ``sigma`` near or above ``mu*`` means a non-linear or interacting effect).
"""
import numpy as np

from qzs._format import unit_label
from qzs.viz.figures import new_figure, save_figure

__all__ = ["plot_sensitivity", "SERIES"]

#: What each method draws: index name -> (legend label, colour).
SERIES = {
    "sobol": {"first_order": ("first order S1 (alone)", "tab:blue"),
              "total_order": ("total ST (alone and in interaction)", "tab:orange")},
    "morris": {"mu_star": ("mu* (mean absolute effect)", "tab:blue"),
               "sigma": ("sigma (spread of the effects)", "k")},
}
_HEIGHT = 0.38  # of one bar [in the rows' units]


def _label(name, unit, kind):
    text = unit_label(name, unit)
    return f"{text}\n(uncertain)" if kind == "uncertain" else text


def _default_title(result):
    level = f"{result.confidence:.0%}"
    if result.method == "sobol":
        how = (f"Sobol indices, {result.samples} base samples ({result.evaluations} cases), "
               f"{level} bootstrap intervals")
    else:
        how = (f"Morris screening, {result.samples} trajectories x {result.levels} levels "
               f"({result.evaluations} cases), {level} intervals")
    failed = f"; {result.failed} cases failed" if result.failed else ""
    return f"{result.title}\n{how}{failed}"


def _errors(values, low, high):
    """Asymmetric error-bar lengths ``(below, above)`` of ``values`` from their interval."""
    return np.vstack([values - low, high - values])


def plot_sensitivity(result, path=None, title=None):
    """Bar chart of a sensitivity analysis's indices with their confidence intervals.

    Parameters
    ----------
    result : SensitivityResult
        The indices (:func:`qzs.workflows.design_space.sensitivity.sensitivity`).
    path : str or Path, optional
        Write the figure there (atomically; format from the suffix, a .png also as .svg).
    title : str, optional
        Figure title; default names the problem, the method and the samples.

    Returns
    -------
    matplotlib.figure.Figure
    """
    n_parameters = len(result.parameters)
    height = 0.45 * n_parameters + 0.9
    fig, axes = new_figure(len(result.metrics), height=height, sharex=False, width=8.0)
    for i, (ax, metric) in enumerate(zip(axes, result.metrics)):
        unit = result.metric_units[i]
        ax.set_title(f"{metric} [{unit if unit not in ('1', '') else '-'}]", fontsize=9,
                     loc="left")
        if result.reasons[i]:
            ax.text(0.5, 0.5, f"indices undefined:\n{result.reasons[i]}", ha="center",
                    va="center", transform=ax.transAxes, fontsize=8, wrap=True)
            ax.set_yticks([])
            ax.set_xticks([])
            continue
        _panel(ax, result, i, unit)
    drawn = [ax for ax in axes if ax.get_legend_handles_labels()[0]]
    if drawn:  # below the panels, where it hides no bar
        handles, labels = drawn[0].get_legend_handles_labels()
        order = [label for label, _ in SERIES[result.method].values()]
        handles, labels = zip(*sorted(zip(handles, labels), key=lambda p: order.index(p[1])))
        fig.legend(handles, labels, loc="outside lower center", ncols=len(labels),
                   fontsize=8, frameon=False)
    fig.suptitle(title or _default_title(result), fontsize=9)
    if path is not None:
        save_figure(fig, path)
    return fig


def _panel(ax, result, i, unit):
    """One metric's bars, its parameters ranked, the largest on top."""
    key = result.total_order if result.method == "sobol" else result.mu_star
    order = np.argsort(-key[i], kind="stable")
    rows = np.arange(order.size)[::-1].astype(float)  # the first of `order` on top
    labels = [_label(result.parameters[j], result.parameter_units[j],
                     result.parameter_kinds[j]) for j in order]
    series = SERIES[result.method]
    if result.method == "sobol":
        for shift, name in zip((_HEIGHT / 2, -_HEIGHT / 2), ("first_order", "total_order")):
            label, colour = series[name]
            values = getattr(result, name)[i, order]
            low, high = result.intervals[name]
            ax.barh(rows + shift, values, height=_HEIGHT, color=colour, alpha=0.85,
                    xerr=_errors(values, low[i, order], high[i, order]), capsize=3, label=label,
                    error_kw={"elinewidth": 1.0, "ecolor": "0.15"})
        top = max(1.0, float(np.nanmax(np.stack(result.intervals["total_order"])[:, i])))
        low = min(0.0, float(np.nanmin(np.stack(result.intervals["first_order"])[:, i])))
        ax.set_xlim(low - 0.02, top + 0.02)
        ax.set_xlabel("Sobol index [-] (share of the metric's variance)")
    else:
        label, colour = series["mu_star"]
        values = result.mu_star[i, order]
        ax.barh(rows, values, height=1.6 * _HEIGHT, color=colour, alpha=0.85,
                xerr=_errors(values, *(end[i, order] for end in result.intervals["mu_star"])),
                capsize=3,
                label=label, error_kw={"elinewidth": 1.0, "ecolor": "0.15"})
        label, colour = series["sigma"]
        ax.plot(result.sigma[i, order], rows, "D", color=colour, ms=5, label=label)
        ax.set_xlabel(unit_label("elementary effect across the parameter's range", unit))
        ax.set_xlim(left=0.0)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4))
    ax.axvline(0.0, color="0.5", lw=0.8)
    ax.set_yticks(rows, labels, fontsize=8)
    ax.set_ylim(-0.7, order.size - 0.3)
    ax.grid(axis="x", alpha=0.3)
