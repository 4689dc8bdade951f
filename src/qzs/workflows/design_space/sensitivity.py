"""Global sensitivity of a problem's metrics to its parameters: Sobol and Morris (SALib).

``qzs sensitivity FILE.toml`` measures how much each parameter of a design problem moves
its metrics over the whole space, not at one point:

- its decision variables (``[variables]``), each uniform between its bounds (on
  ``log10`` for ``scale = "log"``, rounded for ``integer = true``), and
- its uncertain parameters (``[uncertain]``), each from its distribution.

SALib samples the unit hypercube of an uncertain parameter, its probabilities, and each
probability ``u`` becomes the parameter's value through its inverse CDF
(:meth:`~qzs.workflows.design_space.problem.Uncertainty.quantile`), so every
distribution of a problem file (truncated normals and lists of values included) is
measured as it is drawn elsewhere; SALib's own ``dists`` know fewer of them.

Sobol (``method = "sobol"``, the default): Saltelli's scheme
(``SALib.sample.sobol.sample``, scrambled Sobol' points, no second order), ``N`` base
samples, ``N * (D + 2)`` evaluations for ``D`` parameters. ``SALib.analyze.sobol``
estimates each parameter's first-order index ``S1`` (the share of the metric's variance
it explains alone) and total index ``ST`` (alone and in interaction), each with a
bootstrap confidence interval at ``confidence``. ``N`` must be a power of two (the
Sobol' sequence is balanced only then).

Morris (``method = "morris"``): a screening for many parameters, ``r`` trajectories of
``D + 1`` evaluations on a grid of ``levels`` levels (``SALib.sample.morris``).
``mu_star`` is the mean absolute elementary effect, the change of the metric for a step
across a parameter's range divided by the step as a fraction of the range [the metric's
unit]: ``|slope| * (high - low)`` for a linear metric of a variable. ``sigma``, the
spread of the effects, is large for a parameter acting through interactions or
non-linearly. An uncertain parameter's levels are the medians of ``levels`` equally
likely strata (its grid spans the central ``(levels - 1) / levels`` of its probability;
the ends, at probability 0 and 1, are infinite for an unbounded distribution).

Each sample point is one case ``{name: value}``, evaluated by
:func:`qzs.workflows.design_space.evaluation.evaluate_cases`, the path of every design of an
optimisation: simulated metrics through the sweep batch task (the step chosen first for
the problem's ``tolerance_db`` if ``[simulation]`` gives no ``dt``, by the optimiser's
:func:`~qzs.workflows.design_space.optimizer.fix_step`, so both integrate a problem at
one step), linear metrics by the
linear analysis. A case whose metric is undefined (a failed run) leaves that metric's
indices undefined: they are NaN, with the reason in :attr:`SensitivityResult.reasons`.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import unit_label
from qzs._optional import require
from qzs._validation import seed as checked_seed
from qzs.errors import CountLimitError, ParameterError, ProblemError
from qzs.identify._protocol import deprecated_alias
from qzs.iotools.schema import Schema, Variable, to_dataset
from qzs.workflows.design_space.evaluation import cases_per_batch, evaluate_cases
from qzs.workflows.design_space.metrics import METRICS
from qzs.workflows.design_space.problem import (SENSITIVITY_METHODS, DesignProblem,
                                                load_problem)
from qzs.workflows.sweeps.definition import MAX_CASES

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["sensitivity", "SensitivityResult", "sensitivity_dataset", "sensitivity_summary",
           "sensitivity_schema", "parameter_ranking", "SENSITIVITY_SUFFIXES",
           "NUM_RESAMPLES", "INDICES", "run_sensitivity", "SENSITIVITY_FILES"]

#: The files :meth:`SensitivityResult.save` writes, by suffix.
SENSITIVITY_SUFFIXES = (".nc", ".csv", ".mat")
#: Bootstrap resamples behind every confidence interval (SALib's default).
NUM_RESAMPLES = 100
#: Where an uncertain parameter's probability is clipped: its inverse CDF stays finite.
_CLIP = 1e-12
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
    """Global sensitivity indices of a problem's metrics (:func:`sensitivity`).

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


# ---------------------------------------------------------------- the analysis
def sensitivity(problem: DesignProblem | str | Path | Mapping[str, Any], *,
                method: str | None = None, samples: int | None = None,
                seed: int | None = None, metrics: Sequence[str] | None = None,
                evaluate: Callable[[list[dict[str, float]]], Mapping[str, Any]] | None = None,
                client: Any = None, threads: int | None = None,
                progress: bool = True) -> SensitivityResult:
    """Global sensitivity of a problem's metrics to its variables and uncertain parameters.

    The layout and the methods are in :mod:`qzs.workflows.design_space.sensitivity`;
    every setting not given comes from the problem's ``[sensitivity]`` table. Everything
    is checked before any case is evaluated.

    Parameters
    ----------
    problem : DesignProblem, str, Path or dict
        The problem, or what :func:`~qzs.workflows.design_space.problem.load_problem`
        reads (a TOML file, a shipped problem's name, a parsed document).
    method : {"sobol", "morris"}, optional
        Sobol indices (Saltelli's scheme) or Morris screening; default ``[sensitivity]
        method``.
    samples : int, optional
        Sobol: base samples ``N``, a power of two (default ``[sensitivity] samples``);
        Morris: trajectories ``r`` >= 2 (default ``[sensitivity] trajectories``).
    seed : int, optional
        Seed of the sampling and of the bootstrap intervals; default ``[sensitivity]
        seed``.
    metrics : sequence of str, optional
        Metric columns of the problem's goals (``transmissibility_at_12_hz``); default
        ``[sensitivity] metrics`` (every goal's).
    evaluate : callable, optional
        ``evaluate(settings) -> {column: values}``: evaluates the cases (a list of dicts,
        parameter name -> value [its unit]) in place of qzs, one value per case for each
        metric column. The sampling, the analysis and the result are the same; a check of
        the pipeline on a function with known indices (Ishigami's) plugs in here.
    client : distributed.Client, optional
        Run the simulated cases on this Dask cluster (results are the same).
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a cluster.
    progress : bool
        Show a progress bar over the evaluated cases (tqdm).

    Returns
    -------
    SensitivityResult

    Raises
    ------
    ProblemError
        The problem (or its ``[sensitivity]`` table) is invalid: a ``samples`` that is not
        a power of two for Sobol, fewer than 2 trajectories, an odd number of ``levels``.
    ParameterError
        An argument is: an unknown ``method``, a ``samples`` that is not a power of two,
        a metric the problem's goals do not have, an ``evaluate`` that is not callable or
        returns the wrong columns or lengths.
    CountLimitError
        More than :data:`qzs.workflows.sweeps.definition.MAX_CASES` evaluations.
    """
    began = time.perf_counter()
    if not isinstance(problem, DesignProblem):
        problem = load_problem(problem)
    require("SALib", "qzs sensitivity (Sobol and Morris indices)")
    plan = _plan(problem, method, samples, seed, metrics, evaluate)
    names, units, kinds = _parameters(problem)
    salib = _salib_problem(problem, plan)
    unit_samples = _sample(salib, plan)
    settings = _settings(problem, unit_samples)
    values, messages, definition = _evaluate(problem, settings, plan, evaluate, client,
                                             threads, progress)
    failed = ~np.all([np.isfinite(values[c]) for c in plan["metrics"]], axis=0)
    indices, reasons = _analyse(salib, plan, unit_samples, values, messages)
    simulation = definition.simulation
    settings_record = {
        "problem_hash": problem.hash, "problem_source": problem.source,
        "evaluator": "qzs" if evaluate is None else "given",
        "dt": simulation["dt"] if plan["simulated"] and evaluate is None else None,
        "step_note": (simulation.get("step_note") if plan["simulated"] and evaluate is None
                      else None)}
    return SensitivityResult(
        method=plan["method"], parameters=names, parameter_units=units,
        parameter_kinds=kinds, metrics=tuple(plan["metrics"]),
        metric_units=tuple(_metric_units(problem, c) for c in plan["metrics"]),
        **indices, confidence=plan["confidence"], samples=plan["samples"],
        levels=plan["levels"] if plan["method"] == "morris" else 0,
        evaluations=len(settings), failed=int(failed.sum()), seed=plan["seed"],
        elapsed=time.perf_counter() - began, reasons=tuple(reasons), problem=problem.name,
        title=problem.title, settings=MappingProxyType(settings_record))


def _plan(problem, method, samples, seed, metrics, evaluate):
    """Every setting resolved and checked: from the arguments, else ``[sensitivity]``."""
    table = problem.sensitivity

    def refuse(key, value, fix, given):
        if given:
            raise ParameterError(f"`{key}` {fix}, got {value!r}.")
        raise ProblemError("sensitivity", key, value, fix, source=problem.source)

    if method is not None and method not in SENSITIVITY_METHODS:
        raise ParameterError(f"`method` must be one of {SENSITIVITY_METHODS} (SALib's "
                             f"Saltelli/Sobol or Morris), got {method!r}.")
    method = method or table["method"]
    key = "samples" if method == "sobol" else "trajectories"
    given = samples is not None
    samples = samples if given else table[key]
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)):
        refuse("samples" if given else key, samples, "must be a whole number", given)
    samples = int(samples)
    if method == "sobol" and (samples < 2 or samples & (samples - 1)):
        lower = 1 << max(1, samples.bit_length() - 1)
        refuse("samples" if given else key, samples,
               f"must be a power of two >= 2 for Sobol indices (Saltelli's scheme is "
               f"balanced only then); use {lower} or {2 * lower}", given)
    if method == "morris" and samples < 2:
        refuse("samples" if given else key, samples, "Morris needs at least 2 trajectories "
                                                     "(the spread sigma of the effects)",
               given)
    levels = table["levels"]
    if method == "morris" and (levels < 2 or levels % 2):
        refuse("levels", levels, "Morris needs an even number of levels >= 2 (4 is usual); "
                                 "an odd number biases the grid", False)
    seed = int(table["seed"] if seed is None else checked_seed("seed", seed))
    columns = list(problem.columns)
    if metrics is None:
        metrics = list(table["metrics"])
    else:
        metrics = [metrics] if isinstance(metrics, str) else list(metrics)
        unknown = [m for m in metrics if m not in columns]
        if not metrics or unknown:
            raise ParameterError(f"`metrics` must name metric columns of the problem's goals "
                                 f"({', '.join(columns)}), got {metrics!r}; add a goal for "
                                 "another metric to the problem.")
    if evaluate is not None and not callable(evaluate):
        raise ParameterError(f"`evaluate` must be a callable evaluate(settings) -> "
                             f"{{column: values}}, got {evaluate!r}.")
    d = len(problem.variables) + len(problem.uncertain)
    cases = samples * (d + 2) if method == "sobol" else samples * (d + 1)
    if cases > MAX_CASES:
        raise CountLimitError("samples", cases, MAX_CASES, "evaluations",
                              f"use fewer samples ({method}, {d} parameters)")
    goals = {g.column: g for g in problem.goals}
    simulated = any(METRICS[goals[c].metric].source != "linear" for c in metrics)
    return {"method": method, "samples": samples, "levels": int(levels), "seed": seed,
            "confidence": float(table["confidence"]), "metrics": metrics,
            "simulated": simulated, "cases": cases}


def _parameters(problem):
    """Names, units and kinds of the parameters measured: variables, then uncertain."""
    entries = [(v.name, v.units, "variable") for v in problem.variables]
    entries += [(u.name, u.units, "uncertain") for u in problem.uncertain]
    return tuple(zip(*entries)) if entries else ((), (), ())


def _salib_problem(problem, plan):
    """SALib's problem: a variable's search bounds, an uncertain parameter's probability.

    Morris's grid of an uncertain parameter is the medians of ``levels`` equally likely
    strata: its ends at probability 0 and 1 would be infinite for unbounded distributions.
    """
    names, _, _ = _parameters(problem)
    bounds = [list(v.search_bounds) for v in problem.variables]
    margin = 0.5 / plan["levels"] if plan["method"] == "morris" else 0.0
    bounds += [[margin, 1.0 - margin] for _ in problem.uncertain]
    return {"num_vars": len(names), "names": list(names), "bounds": bounds}


def _sample(salib, plan):
    """SALib's sample, in its space: search space of the variables, probabilities."""
    if plan["method"] == "sobol":
        from SALib.sample import sobol

        return sobol.sample(salib, plan["samples"], calc_second_order=False,
                            seed=plan["seed"])
    from SALib.sample import morris

    return morris.sample(salib, plan["samples"], num_levels=plan["levels"],
                         seed=plan["seed"])


def _settings(problem, unit_samples):
    """One case dict per sample point, each parameter in its unit."""
    columns = {}
    for j, variable in enumerate(problem.variables):
        columns[variable.name] = variable.to_unit(unit_samples[:, j])
    offset = len(problem.variables)
    for j, uncertain in enumerate(problem.uncertain):
        u = np.clip(unit_samples[:, offset + j], _CLIP, 1.0 - _CLIP)
        columns[uncertain.name] = np.asarray(uncertain.quantile(u), dtype=float)
    names = list(columns)
    return [dict(zip(names, row)) for row in
            np.column_stack([columns[n] for n in names]).tolist()] if names else []


def _evaluate(problem, settings, plan, evaluate, client, threads, progress):
    """The metric columns of every case, by qzs or by ``evaluate``; the step fixed first."""
    from qzs.engine.progress import progress_bar

    n, metrics = len(settings), plan["metrics"]
    definition = problem.sweep
    batch_size = None if client is not None else max(definition.batch_size, -(-n // 50))
    if evaluate is None and plan["simulated"]:  # before any probe (and its progress bar)
        from qzs.workflows.design_space.optimizer import check_run_length

        at_once = min(n, cases_per_batch(n, client, batch_size))
        check_run_length(problem, threads=threads, cases=at_once)
    with progress_bar(total=n, unit="case", desc=f"sensitivity ({plan['method']})",
                      disable=not progress, leave=False) as bar:
        if evaluate is not None:
            returned = evaluate([dict(case) for case in settings])
            values = _check_returned(returned, metrics, n)
            bar.update(n)
            return values, [""] * n, definition
        if plan["simulated"]:  # the step the optimiser would integrate this problem at
            from qzs.workflows.design_space.optimizer import fix_step

            problem = fix_step(problem)
            check_run_length(problem, threads=threads, cases=at_once)
            definition = problem.sweep
        values, _, messages, _ = evaluate_cases(problem, settings, columns=metrics,
                                                client=client, threads=threads,
                                                batch_size=batch_size, progress=bar.update)
    return values, messages, definition


def _check_returned(returned, metrics, n):
    if not isinstance(returned, Mapping):
        raise ParameterError(f"`evaluate` must return a dict of metric column -> values, "
                             f"got {type(returned).__name__}.")
    values = {}
    for column in metrics:
        if column not in returned:
            raise ParameterError(f"`evaluate` returned no {column!r} (it returned "
                                 f"{sorted(returned)}); return every metric column "
                                 f"{metrics}.")
        array = np.asarray(returned[column], dtype=float)
        if array.shape != (n,):
            raise ParameterError(f"`evaluate` must return one value per case for "
                                 f"{column!r}: shape ({n},), got {array.shape}.")
        values[column] = array
    return values


def _undefined(y, messages):
    """Why a metric's indices are undefined ('' if they are not)."""
    bad = ~np.isfinite(y)
    if bad.any():
        first = next((messages[i] for i in np.flatnonzero(bad) if messages[i]), "")
        kind = "NaN" if np.isnan(y[bad]).all() else "not finite"
        return (f"{int(bad.sum())} of {y.size} cases gave {kind} (a failed run or an "
                f"undefined metric)" + (f"; first: {first}" if first else ""))
    return ""


def _analyse(salib, plan, unit_samples, values, messages):
    """SALib's analysis of each metric; NaN indices with a reason where undefined."""
    method, metrics = plan["method"], plan["metrics"]
    d = salib["num_vars"]
    names = _INDICES[method]
    out = {name: np.full((len(metrics), d), np.nan) for name in names}
    intervals = {name: np.full((len(metrics), d, 2), np.nan) for name in _INTERVALS[method]}
    reasons = []
    for i, column in enumerate(metrics):
        y = values[column]
        reason = _undefined(y, messages)
        if not reason and method == "sobol" and np.ptp(y) == 0:
            reason = f"the metric does not vary over the sample (always {y[0]:g})"
        reasons.append(reason)
        if reason:
            continue
        if method == "sobol":
            from SALib.analyze import sobol

            found = sobol.analyze(salib, y, calc_second_order=False,
                                  num_resamples=NUM_RESAMPLES,
                                  conf_level=plan["confidence"], seed=plan["seed"])
            pairs = (("first_order", "S1"), ("total_order", "ST"))
        else:
            from SALib.analyze import morris

            found = morris.analyze(salib, unit_samples, y, num_resamples=NUM_RESAMPLES,
                                   conf_level=plan["confidence"], num_levels=plan["levels"],
                                   seed=plan["seed"])
            pairs = (("mu_star", "mu_star"), ("mu", "mu"), ("sigma", "sigma"))
        for name, key in pairs:
            out[name][i] = np.asarray(found[key], dtype=float)
            if name in intervals:
                half = np.asarray(found[f"{key}_conf"], dtype=float)
                intervals[name][i] = np.column_stack([out[name][i] - half,
                                                      out[name][i] + half])
    result = dict(out)
    result["intervals"] = MappingProxyType({name: (interval[..., 0], interval[..., 1])
                                            for name, interval in intervals.items()})
    return result, reasons


def _metric_units(problem, column):
    return next(g.units for g in problem.goals if g.column == column)


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


#: What :func:`run_sensitivity` writes into its folder.
SENSITIVITY_FILES = ("sensitivity.nc", "sensitivity.csv", "sensitivity.mat", "sensitivity.png",
                     "sensitivity.txt")


def run_sensitivity(problem: DesignProblem | str | Path | Mapping[str, Any],
                    folder: str | Path, *, method: str | None = None,
                    samples: int | None = None, seed: int | None = None,
                    scheduler: Any = None, workers: int | None = None,
                    threads: int | None = None,
                    progress: bool = True) -> tuple[SensitivityResult, list[Path]]:
    """Run :func:`sensitivity` (locally or on Dask) and write its files into ``folder``.

    Parameters
    ----------
    problem : DesignProblem, str, Path or dict
        The problem, a TOML file, a shipped problem's name or a parsed document.
    folder : str or Path
        Where :data:`SENSITIVITY_FILES` go (created if missing; each file atomic).
    method, samples, seed : optional
        As :func:`sensitivity` takes them.
    scheduler : str or distributed.Client, optional
        Evaluate on this Dask cluster.
    workers : int, optional
        Start a local Dask cluster of this many single-threaded worker processes.
    threads : int, optional
        Threads per batch.
    progress : bool
        Show a progress bar.

    Returns
    -------
    result : SensitivityResult
    written : list of Path
    """
    import matplotlib.pyplot as plt

    from qzs.iotools.files import atomic_path
    from qzs.iotools.paths import removed_on_error
    from qzs.workflows.sweeps.cluster import dask_client

    with dask_client(scheduler, workers) as client:
        result = sensitivity(problem, method=method, samples=samples, seed=seed, client=client,
                             threads=threads, progress=progress)
    folder = Path(folder)
    with removed_on_error(folder):  # a folder made here holds all of the files or goes
        folder.mkdir(parents=True, exist_ok=True)
        written = [result.save(folder / name) for name in SENSITIVITY_FILES[:3]]
        figure = result.plot(folder / "sensitivity.png")
        plt.close(figure)
        written.append(folder / "sensitivity.png")
        with atomic_path(folder / "sensitivity.txt") as tmp:
            Path(tmp).write_text(result.summary() + "\n", encoding="utf-8")
        written.append(folder / "sensitivity.txt")
    return result, written
