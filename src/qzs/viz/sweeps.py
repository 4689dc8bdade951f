"""Figures of a sweep store: a metric against one or two parameters, transmissibility bands.

Only finished cases with status ``ok`` are drawn; the title says how many are
left out. Parameters from ``[grid]`` are treated as levels (cases at a level are
reduced to one value, with their spread shaded); sampled parameters as continuous
(scatter, with a binned median).
"""
import json

import numpy as np

from qzs._format import unit_label
from qzs.errors import ParameterError
from qzs.viz.figures import check_frequency_scale, drawn, frequency_axis, new_figure, save_figure

__all__ = ["plot_metric", "plot_transmissibility_band", "scalar_outputs", "varied_parameters",
           "figure_suffixes", "REDUCTIONS", "FIGURE_BYTES"]

REDUCTIONS = ("median", "mean", "min", "max")
#: What one figure file takes at most [bytes] (generous), for the free-space check.
FIGURE_BYTES = 20 * 1024 ** 2
_Y_LABEL = "transmissibility, amplitude ratio sqrt(S_payload/S_base) [-]"


def figure_suffixes():
    """File extensions matplotlib can write a figure to (``.png``, ``.svg``, ``.pdf``...).

    Returns
    -------
    tuple of str
        Sorted, each with its leading dot.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(sorted("." + name for name in FigureCanvasBase.get_supported_filetypes()))


def _usable(dataset):
    status = dataset["status"]  # its CF flags say which code means "ok"
    ok_code = status.attrs["flag_values"][status.attrs["flag_meanings"].split().index("ok")]
    ok = dataset["done"].values & (status.values == ok_code)
    return ok, int(dataset.sizes["case"] - ok.sum())


def _grid_names(dataset):
    try:
        return set(json.loads(dataset.attrs.get("sweep_definition", "{}")).get("grid", {}))
    except ValueError:
        return set()


def varied_parameters(dataset):
    """Names of the varied parameters stored on ``case`` (excluding ``sample``).

    Parameters
    ----------
    dataset : xarray.Dataset
        An opened sweep store (:func:`qzs.workflows.sweeps.open_sweep`).

    Returns
    -------
    list of str
    """
    return [name for name, coord in dataset.coords.items()
            if coord.dims == ("case",) and name not in ("case", "sample")]


def _label(dataset, name):
    variable = dataset[name]
    unit = variable.attrs.get("units", "")
    return unit_label(name, unit) if unit else name


def _check(dataset, name, what, valid):
    if name not in valid:
        raise ParameterError(f"unknown {what} {name!r}; the store has: {', '.join(valid)}.")


def _reduce(values, how):
    return {"median": np.nanmedian, "mean": np.nanmean, "min": np.nanmin,
            "max": np.nanmax}[how](values)


def scalar_outputs(dataset):
    """Per-case numeric outputs that :func:`plot_metric` can draw.

    Parameters
    ----------
    dataset : xarray.Dataset
        An opened sweep store (:func:`qzs.workflows.sweeps.open_sweep`).

    Returns
    -------
    list of str
        Names of the numeric variables on dimension ``case`` (floats and integer counts;
        not the ``status`` flags), sorted.
    """
    return sorted(name for name, v in dataset.data_vars.items()
                  if v.dims == ("case",) and v.dtype.kind in "fiu"
                  and "flag_values" not in v.attrs)


def plot_metric(dataset, metric, x, y=None, *, reduce="median", path=None):
    """A per-case output against one parameter (line) or two (heat map).

    Parameters
    ----------
    dataset : xarray.Dataset
        An opened sweep store (:func:`qzs.workflows.sweeps.open_sweep`).
    metric : str
        A per-case output, e.g. ``"peak_stroke"`` [m] or ``"mean_transmissibility_low"``.
    x, y : str
        Varied parameters; with `y` a heat map.
    reduce : {"median", "mean", "min", "max"}
        How the cases at one grid level (or cell) are combined: e.g. ``"max"`` of
        the peak stroke is the worst case over every other varied parameter.
    path : str or Path, optional
        Write the figure there (format from the suffix).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import pandas as pd

    _check(dataset, metric, "metric", scalar_outputs(dataset))
    params = varied_parameters(dataset)
    for name in (x, y) if y is not None else (x,):
        _check(dataset, name, "parameter", params)
    if reduce not in REDUCTIONS:
        raise ParameterError(f"`reduce` must be one of {REDUCTIONS}, got {reduce!r}.")
    ok, left_out = _usable(dataset)
    frame = pd.DataFrame({"x": dataset[x].values[ok], "m": dataset[metric].values[ok]})
    if y is not None:
        frame["y"] = dataset[y].values[ok]
    grid = _grid_names(dataset)
    fig, (ax,) = new_figure(1, height=4.2)
    if y is None:
        _line(ax, frame, x in grid, reduce)
        ax.set_ylabel(_label(dataset, metric))
    elif x in grid and y in grid:
        table = frame.groupby(["y", "x"])["m"].agg(lambda v: _reduce(v.values, reduce))
        table = table.unstack("x")
        mesh = ax.pcolormesh(np.arange(table.shape[1] + 1) - 0.5,
                             np.arange(table.shape[0] + 1) - 0.5, table.values,
                             shading="flat", cmap="viridis")
        ax.set_xticks(range(table.shape[1]), [f"{v:g}" if isinstance(v, float) else str(v)
                                              for v in table.columns])
        ax.set_yticks(range(table.shape[0]), [f"{v:g}" if isinstance(v, float) else str(v)
                                              for v in table.index])
        if table.size <= 150:
            for (i, j), value in np.ndenumerate(table.values):
                ax.text(j, i, f"{value:.3g}", ha="center", va="center", fontsize=7,
                        color="w" if value < np.nanmean(table.values) else "k")
        fig.colorbar(mesh, ax=ax, label=f"{reduce} of {_label(dataset, metric)}")
    else:
        points = ax.scatter(frame["x"], frame["y"], c=frame["m"], s=18, cmap="viridis")
        fig.colorbar(points, ax=ax, label=_label(dataset, metric))
    ax.set_xlabel(_label(dataset, x))
    if y is None:
        _wide_scale(ax, frame["x"].values)
    if y is not None:
        ax.set_ylabel(_label(dataset, y))
    ax.set_title(_title(dataset, left_out))
    ax.grid(True, alpha=0.3)
    if path is not None:
        save_figure(fig, path)
    return fig


def _wide_scale(ax, values):
    """Symmetric-log x axis for numbers spanning more than two decades (gains, often with 0)."""
    if values.dtype.kind not in "fi" or values.size == 0 or values.min() < 0:
        return
    positive = values[values > 0]
    if positive.size and positive.max() / positive.min() > 100:
        ax.set_xscale("symlog", linthresh=float(positive.min()))


def _line(ax, frame, levels, reduce):
    if levels:
        groups = frame.groupby("x")["m"]
        xs = np.asarray(list(groups.groups))
        center = np.array([_reduce(g.values, reduce) for _, g in groups])
        counts = groups.size().values
        if counts.max() > 1:
            low, high = groups.quantile(0.05).values, groups.quantile(0.95).values
            ax.fill_between(xs, low, high, alpha=0.25, label="5-95 % of the cases")
        ax.plot(xs, center, "o-", label=f"{reduce} over {counts.max()} case(s) per point")
    else:
        ax.scatter(frame["x"], frame["m"], s=10, alpha=0.5, label="cases")
        if len(frame) >= 10:
            edges = np.quantile(frame["x"], np.linspace(0, 1, min(21, len(frame) // 5 + 2)))
            index = np.clip(np.searchsorted(edges, frame["x"], side="right") - 1, 0,
                            edges.size - 2)
            centers = [(edges[k] + edges[k + 1]) / 2 for k in range(edges.size - 1)]
            values = [_reduce(frame["m"].values[index == k], reduce)
                      if np.any(index == k) else np.nan for k in range(edges.size - 1)]
            ax.plot(centers, values, "k-", label=f"binned {reduce}")
    ax.legend(loc="best", fontsize=8)


def plot_transmissibility_band(dataset, *, by=None, percentiles=(5.0, 95.0), path=None,
                               frequency_scale=None):
    """Median transmissibility and its percentile band over the cases of a sweep.

    Parameters
    ----------
    dataset : xarray.Dataset
        An opened sweep store that kept ``transmissibility``.
    by : str, optional
        A grid parameter: one median and band per level (at most 8 levels).
    percentiles : (float, float)
        Lower and upper percentiles of the band [%].
    path : str or Path, optional
        Write the figure there.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis scale; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if "transmissibility" not in dataset:
        raise ParameterError("the store kept no transmissibility curve; set "
                             "`transmissibility = true` in [outputs] and run the sweep again.")
    ok, left_out = _usable(dataset)
    frequency = dataset["frequency"].values
    curves = dataset["transmissibility"].values
    levels = [(None, ok)]
    if by is not None:
        _check(dataset, by, "parameter", varied_parameters(dataset))
        values = dataset[by].values
        distinct = list(dict.fromkeys(values[ok].tolist()))
        if len(distinct) > 8:
            raise ParameterError(f"{by!r} has {len(distinct)} levels among the cases; "
                                 "the band plot takes at most 8 (choose a grid parameter).")
        levels = [(v, ok & (values == v)) for v in sorted(distinct)]
    scale = check_frequency_scale(frequency_scale)
    keep = drawn(frequency, scale)
    frequency, curves = frequency[keep], curves[..., keep]
    fig, (ax,) = new_figure(1, height=4.2)
    for k, (value, mask) in enumerate(levels):
        chosen = curves[mask]
        if chosen.shape[0] == 0:
            continue
        low, median, high = np.nanpercentile(chosen, [percentiles[0], 50, percentiles[1]],
                                             axis=0)
        name = "all cases" if value is None else f"{by} = {value:g}" if isinstance(
            value, float) else f"{by} = {value}"
        line, = ax.plot(frequency, median, label=f"{name}: median of {chosen.shape[0]}")
        ax.fill_between(frequency, low, high, color=line.get_color(), alpha=0.2,
                        label=f"{percentiles[0]:g}-{percentiles[1]:g} % of the cases"
                        if k == 0 else "_nolegend_")
    ax.set_yscale("log")
    frequency_axis(ax, (0.0, float(frequency.max())), frequency, frequency_scale=scale,
                   label="frequency [Hz]")
    ax.axhline(1.0, color="0.5", lw=0.8)
    ax.set_ylabel(_Y_LABEL)
    ax.set_title(_title(dataset, left_out))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if path is not None:
        save_figure(fig, path)
    return fig


def _title(dataset, left_out):
    title = dataset.attrs.get("sweep_title", dataset.attrs.get("sweep_name", "sweep"))
    if left_out:
        title += f"\n({left_out} case(s) not run or failed, not shown)"
    return title
