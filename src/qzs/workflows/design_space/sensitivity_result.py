"""The result of a global sensitivity analysis: :class:`SensitivityResult`, the Sobol or
Morris indices of a problem's metrics, and its views -- the ranking, the text table and the
CF-1.10 dataset written as .nc, .csv or .mat. The analysis is
:func:`qzs.workflows.design_space.sensitivity.sensitivity`, which re-exports these names.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from qzs._format import unit_label
from qzs.errors import ParameterError
from qzs._validation import deprecated_alias
from qzs.iotools.schema import Schema, Variable, to_dataset

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["SensitivityResult", "sensitivity_dataset", "sensitivity_summary",
           "sensitivity_schema", "parameter_ranking", "SENSITIVITY_SUFFIXES", "INDICES"]

#: The files :meth:`SensitivityResult.save` writes, by suffix.
SENSITIVITY_SUFFIXES = (".nc", ".csv", ".mat")


#: Index name -> (description, unit: "1" or None for the metric's own).
INDICES = {
    "first_order": ("first-order Sobol index S1: share of the metric's variance the "
                    "parameter explains alone", "1"),
    "total_order": ("total Sobol index ST: share of the variance the parameter explains "
                    "alone and in interaction", "1"),
    "mu_star": ("Morris mu*: mean absolute elementary effect (change across the range)",
                None),
    "mu": ("Morris mu: mean elementary effect (signed)", None),
    "sigma": ("Morris sigma: standard deviation of the elementary effects", None),
}


_INDICES = {"sobol": ("first_order", "total_order"), "morris": ("mu_star", "mu", "sigma")}


_INTERVALS = {"sobol": ("first_order", "total_order"), "morris": ("mu_star",)}


def _stacked(result, name):
    """An interval as the old ``<index>_interval`` array ``(metric, parameter, 2)``, or None."""
    return np.stack(result.intervals[name], axis=-1) if name in result.intervals else None


@dataclass(frozen=True, kw_only=True, eq=False)
class SensitivityResult:
    """Global sensitivity indices of a problem's metrics
    (:func:`~qzs.workflows.design_space.sensitivity.sensitivity`).

    Arrays are ``(metric, parameter)``; ``intervals`` maps each estimated index to its
    ``(low, high)`` arrays at ``confidence``. The indices of the other method are None. A
    metric whose indices are undefined (a failed case, a metric that never varies) has NaN
    indices and its reason in ``reasons``. The object holds data; its methods delegate
    to this module's functions, :mod:`qzs.viz.sensitivity` and
    :func:`qzs.iotools.writer.write_dataset`.

    Attributes
    ----------
    method : {"sobol", "morris"}
        The method.
    parameters : tuple of str
        The parameters measured: the problem's variables, then its uncertain parameters.
    parameter_units : tuple of str
        Their units.
    parameter_kinds : tuple of str
        ``"variable"`` or ``"uncertain"``, per parameter.
    metrics : tuple of str
        The metric columns (``linear_transmissibility_at_3_hz``).
    metric_units : tuple of str
        Their units.
    first_order, total_order : ndarray or None
        Sobol: first-order and total indices [-].
    mu_star, mu, sigma : ndarray or None
        Morris: mean absolute, mean and standard deviation of the elementary effects
        [the metric's unit].
    intervals : Mapping[str, tuple of ndarray]
        Index name (Sobol: ``first_order``, ``total_order``; Morris: ``mu_star``) -> its
        ``(low, high)`` confidence interval at ``confidence``, each ``(metric, parameter)``
        [the index's unit] (bootstrap, :data:`NUM_RESAMPLES` resamples). The old
        ``<index>_interval`` arrays ``(metric, parameter, 2)`` are deprecated aliases.
    confidence : float
        The intervals' confidence level [-] (0.95).
    samples : int
        Sobol: base samples ``N``; Morris: trajectories ``r``.
    levels : int
        Morris: grid levels (0 for Sobol).
    evaluations : int
        Cases evaluated: ``N * (D + 2)`` or ``r * (D + 1)``.
    failed : int
        Cases whose metrics are undefined (a run that failed) [-].
    seed : int
        Seed of the sampling and of the bootstrap.
    elapsed : float
        Wall time [s], sampling, evaluation and analysis.
    reasons : tuple of str
        Per metric, why its indices are undefined ('' where they are defined).
    problem : str
        The problem's name.
    title : str
        The problem's title.
    settings : mapping
        ``problem_hash``, ``problem_source``, ``evaluator`` (``"qzs"`` or ``"given"``), ``dt``
        [s] and ``step_note`` (the step of the simulated cases; None without simulation).
    """

    method: str
    parameters: tuple
    parameter_units: tuple
    parameter_kinds: tuple
    metrics: tuple
    metric_units: tuple
    first_order: np.ndarray | None = None
    total_order: np.ndarray | None = None
    mu_star: np.ndarray | None = None
    mu: np.ndarray | None = None
    sigma: np.ndarray | None = None
    intervals: Mapping[str, tuple] = field(default_factory=lambda: MappingProxyType({}))
    confidence: float = 0.95
    samples: int = 0
    levels: int = 0
    evaluations: int = 0
    failed: int = 0
    seed: int = 0
    elapsed: float = 0.0
    reasons: tuple = ()
    problem: str = ""
    title: str = ""
    settings: Mapping = field(default_factory=lambda: MappingProxyType({}), repr=False)

    @property
    def indices(self) -> dict[str, np.ndarray]:
        """The method's indices by name (``first_order`` ... or ``mu_star`` ...).

        Returns
        -------
        dict of str to ndarray, shape (n_metrics, n_parameters)
        """
        return {name: getattr(self, name) for name in _INDICES[self.method]}

    first_order_interval = deprecated_alias("first_order_interval", "intervals['first_order']",
                                            lambda result: _stacked(result, "first_order"))
    total_order_interval = deprecated_alias("total_order_interval", "intervals['total_order']",
                                            lambda result: _stacked(result, "total_order"))
    mu_star_interval = deprecated_alias("mu_star_interval", "intervals['mu_star']",
                                        lambda result: _stacked(result, "mu_star"))

    def ranking(self, metric: str | None = None) -> tuple[str, ...]:
        """The parameters, most influential first (:func:`parameter_ranking`).

        Parameters
        ----------
        metric : str, optional
            A metric column of :attr:`metrics`; default the first.

        Returns
        -------
        tuple of str
            By total index (Sobol) or ``mu_star`` (Morris), largest first.
        """
        return parameter_ranking(self, metric)

    def summary(self) -> str:
        """A text table per metric (:func:`sensitivity_summary`).

        Returns
        -------
        str
        """
        return sensitivity_summary(self)

    def to_xarray(self) -> xr.Dataset:
        """Repackage as an ``xarray.Dataset`` (:func:`sensitivity_dataset`).

        Returns
        -------
        xarray.Dataset
        """
        return sensitivity_dataset(self)

    #: The extensions :meth:`save` accepts.
    save_suffixes = SENSITIVITY_SUFFIXES

    def save(self, path: str | Path) -> Path:
        """Write :meth:`to_xarray` atomically: ``.nc`` (NetCDF), ``.csv`` (one row per
        metric and parameter) or ``.mat`` (MATLAB).

        Parameters
        ----------
        path : str or Path
            The file; its suffix chooses the format (:data:`SENSITIVITY_SUFFIXES`).

        Returns
        -------
        Path
            ``path``.
        """
        from qzs.iotools.result_files import save_by_extension

        return save_by_extension(path, dataset=self.to_xarray)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> Figure:
        """Bars of the indices with their intervals, one panel per metric
        (:func:`qzs.viz.sensitivity.plot_sensitivity`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (atomically; format from the suffix).
        title : str, optional
            Figure title; default one naming the problem, the method and the samples.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.sensitivity import plot_sensitivity

        return plot_sensitivity(self, path=path, title=title)


# ---------------------------------------------------------------- views
def _metric_index(result, metric):
    if metric is None:
        return 0
    if metric not in result.metrics:
        raise ParameterError(f"`metric` must be one of {list(result.metrics)}, got "
                             f"{metric!r}.")
    return result.metrics.index(metric)


def parameter_ranking(result: SensitivityResult, metric: str | None = None) -> tuple[str, ...]:
    """The parameters ordered by their influence on one metric, largest first.

    Parameters
    ----------
    result : SensitivityResult
        The indices.
    metric : str, optional
        A metric column of ``result.metrics``; default the first.

    Returns
    -------
    tuple of str
        By total index ``ST`` (Sobol) or ``mu_star`` (Morris); ties keep the problem's
        order.

    Raises
    ------
    ParameterError
        An unknown metric, or one whose indices are undefined (the reason is given).
    """
    i = _metric_index(result, metric)
    if result.reasons[i]:
        raise ParameterError(f"the indices of {result.metrics[i]!r} are undefined: "
                             f"{result.reasons[i]}; no ranking.")
    key = result.indices["total_order" if result.method == "sobol" else "mu_star"]
    order = np.argsort(-key[i], kind="stable")
    return tuple(result.parameters[j] for j in order)


def _label(name, unit):
    return unit_label(name, unit)


def sensitivity_summary(result: SensitivityResult) -> str:
    """A text table of the indices per metric, most influential parameter first.

    Parameters
    ----------
    result : SensitivityResult
        The indices.

    Returns
    -------
    str
    """
    level = f"{result.confidence:.0%}"
    if result.method == "sobol":
        head = (f"Sobol indices of {result.problem}: {result.samples} base samples, "
                f"{result.evaluations} cases, {level} intervals (bootstrap)")
        columns = f"{'parameter':<32} {'S1':>8} {'+-':>7} {'ST':>8} {'+-':>7}"
    else:
        head = (f"Morris screening of {result.problem}: {result.samples} trajectories, "
                f"{result.levels} levels, {result.evaluations} cases, {level} intervals")
        columns = f"{'parameter':<32} {'mu*':>10} {'+-':>9} {'sigma':>10} {'mu':>10}"
    lines = [head]
    indices, intervals = result.indices, result.intervals
    if result.failed:
        lines.append(f"{result.failed} of {result.evaluations} cases failed")
    for i, metric in enumerate(result.metrics):
        unit = result.metric_units[i]
        lines += ["", unit_label(metric, unit)]
        if result.reasons[i]:
            lines.append(f"  undefined: {result.reasons[i]}")
            continue
        lines.append("  " + columns)
        for name in parameter_ranking(result, metric):
            j = result.parameters.index(name)
            label = _label(name, result.parameter_units[j])
            if result.parameter_kinds[j] == "uncertain":
                label += " ~"
            half = {name: (high[i, j] - low[i, j]) / 2 for name, (low, high) in intervals.items()}
            if result.method == "sobol":
                s1, st = indices["first_order"][i, j], indices["total_order"][i, j]
                lines.append(f"  {label:<32} {s1:8.3f} {half['first_order']:7.3f} {st:8.3f} "
                             f"{half['total_order']:7.3f}")
            else:
                ms, sg, mu = (indices[name][i, j] for name in ("mu_star", "sigma", "mu"))
                lines.append(f"  {label:<32} {ms:10.4g} {half['mu_star']:9.3g} {sg:10.4g} "
                             f"{mu:10.4g}")
    if "uncertain" in result.parameter_kinds:
        lines += ["", "~ uncertain parameter (sampled from its distribution)"]
    return "\n".join(lines)


def sensitivity_schema(result: SensitivityResult) -> Schema:
    """The CF-1.10 layout of a sensitivity result: indices on ``(metric, parameter)``.

    Parameters
    ----------
    result : SensitivityResult
        The indices.

    Returns
    -------
    Schema
    """
    on = ("metric", "parameter")
    shared = set(result.metric_units)
    common = shared.pop() if len(shared) == 1 else None
    coordinates = (
        Variable(name="metric", dims=("metric",), dtype="str",
                 long_name="metric column of the problem's goals"),
        Variable(name="parameter", dims=("parameter",), dtype="str",
                 long_name="registry parameter"),
        Variable(name="metric_unit", dims=("metric",), dtype="str",
                 long_name="unit of the metric"),
        Variable(name="parameter_unit", dims=("parameter",), dtype="str",
                 long_name="unit of the parameter"),
        Variable(name="parameter_kind", dims=("parameter",), dtype="str",
                 long_name="variable (uniform between its bounds) or uncertain (from "
                           "its distribution)"))
    level = f"{result.confidence:.0%}"
    variables = []
    for name in _INDICES[result.method]:
        doc, unit = INDICES[name]
        note = {} if unit or common else {"comment": "in the unit of each metric "
                                                     "(metric_unit)"}
        unit = unit or common
        variables.append(Variable(name=name, dims=on, units=unit, long_name=doc,
                                  attributes=note))
        if name in _INTERVALS[result.method]:
            for end in ("lower", "upper"):
                variables.append(Variable(
                    name=f"{name}_{end}", dims=on, units=unit, attributes=note,
                    long_name=f"{end} end of the {level} confidence interval of {name} "
                              f"(bootstrap)"))
    variables.append(Variable(name="reason", dims=("metric",), dtype="str",
                              long_name="why the metric's indices are undefined ('' if "
                                        "defined)"))
    return Schema(kind="a sensitivity analysis",
                  dimensions={"metric": len(result.metrics),
                              "parameter": len(result.parameters)},
                  coordinates=coordinates, variables=tuple(variables))


def sensitivity_dataset(result: SensitivityResult) -> xr.Dataset:
    """The indices as an ``xarray.Dataset`` on ``(metric, parameter)``, CF-1.10.

    Each index a variable with its unit (``1`` for Sobol, the metric's for Morris), each
    interval two (``<index>_lower``, ``<index>_upper``); units and kinds as coordinates;
    the method, samples, evaluations, confidence and wall time as global attributes.

    Parameters
    ----------
    result : SensitivityResult
        The indices.

    Returns
    -------
    xarray.Dataset
    """
    from qzs._version import __version__

    values = {"metric": list(result.metrics), "parameter": list(result.parameters),
              "metric_unit": list(result.metric_units),
              "parameter_unit": list(result.parameter_units),
              "parameter_kind": list(result.parameter_kinds), "reason": list(result.reasons)}
    for name in _INDICES[result.method]:
        values[name] = getattr(result, name)
        if name in _INTERVALS[result.method]:
            values[f"{name}_lower"], values[f"{name}_upper"] = result.intervals[name]
    method = ("Sobol indices, Saltelli's scheme (SALib)" if result.method == "sobol"
              else "Morris elementary effects (SALib)")
    attrs = {"title": f"global sensitivity of {result.title}",
             "source": f"qzs {__version__}: {method}", "qzs_version": __version__,
             "problem": result.problem, "method": result.method, "samples": result.samples,
             "evaluations": result.evaluations, "failed": result.failed,
             "confidence_level": result.confidence, "seed": result.seed,
             "elapsed": result.elapsed, "elapsed_units": "s"}
    if result.method == "morris":
        attrs["levels"] = result.levels
    for key, value in result.settings.items():
        if value is not None:
            attrs[key] = value
    if result.settings.get("dt") is not None:
        attrs["dt_units"] = "s"
    return to_dataset(sensitivity_schema(result), values, attrs)
