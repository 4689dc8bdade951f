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
the problem's ``tolerance`` if ``[simulation]`` gives no ``dt``, by the optimiser's
:func:`~qzs.workflows.design_space.optimizer.fix_step`, so both integrate a problem at
one step), linear metrics by the
linear analysis. A case whose metric is undefined (a failed run) leaves that metric's
indices undefined: they are NaN, with the reason in :attr:`SensitivityResult.reasons`.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from qzs._optional import require
from qzs._validation import seed as checked_seed
from qzs.errors import CountLimitError, ParameterError, ProblemError
from qzs.workflows.design_space.evaluation import cases_per_batch, evaluate_cases
from qzs.workflows.design_space.metrics import METRICS
from qzs.workflows.design_space.problem import (SENSITIVITY_METHODS, DesignProblem,
                                                load_problem)
from qzs.workflows.design_space.sensitivity_result import (_INDICES, _INTERVALS, INDICES,
                                                           SENSITIVITY_SUFFIXES,
                                                           SensitivityResult,
                                                           parameter_ranking,
                                                           sensitivity_dataset,
                                                           sensitivity_schema,
                                                           sensitivity_summary)
from qzs.workflows.sweeps.definition import MAX_CASES

__all__ = ["sensitivity", "SensitivityResult", "sensitivity_dataset", "sensitivity_summary",
           "sensitivity_schema", "parameter_ranking", "SENSITIVITY_SUFFIXES",
           "NUM_RESAMPLES", "INDICES", "run_sensitivity", "SENSITIVITY_FILES"]

#: Bootstrap resamples behind every confidence interval (SALib's default).
NUM_RESAMPLES = 100
#: Where an uncertain parameter's probability is clipped: its inverse CDF stays finite.
_CLIP = 1e-12


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
