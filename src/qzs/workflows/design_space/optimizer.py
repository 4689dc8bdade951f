"""NSGA-II over a design problem, one evaluation task per generation (pymoo).

Why pymoo: its NSGA-II asks for a whole generation at once and is told the results
(``ask``/``tell``), which is exactly one evaluation task per generation
(:func:`~qzs.workflows.design_space.evaluation.evaluate_batch`: the lane kernel's runs
in lockstep shares, one per core); it handles inequality constraints by constrained
domination (a feasible design beats an infeasible one, infeasible ones rank by their total
violation) without penalty weights; and its random state is one seeded generator, so a run is repeatable.
Optuna's multi-objective samplers work trial by trial around a database and would
serialise what the lane kernel does at once.

Resuming replays: the algorithm is started again from its seed and asked for the same
generations; a generation the store already holds is answered from the store (after
checking, bit for bit, that the optimiser asked for the same designs), the rest are
evaluated. So an interrupted and resumed run ends with exactly the designs, Pareto set
and chosen design of an uninterrupted one.
"""
import dataclasses
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from qzs._optional import require
from qzs.errors import OutputPathError, ProblemError
from qzs.iotools.paths import removed_on_error
from qzs.workflows.design_space.evaluation import evaluate
from qzs.workflows.design_space.metrics import METRICS, goal_values
from qzs.workflows.design_space.problem import MIN_POPULATION, DesignProblem, load_problem
from qzs.workflows.design_space.result import OptimizationResult, objective_matrix
from qzs.workflows.design_space.store import DesignStore, check, check_same_search

__all__ = ["optimize", "fix_step", "probe_designs", "check_run_length", "GENERATION_REMEDY"]


def probe_designs(problem):
    """Designs the step is chosen on: the lower corner, the centre and the upper corner.

    The centre is the middle of the search space (the geometric mean of a log-scale
    variable's bounds).

    Parameters
    ----------
    problem : DesignProblem
        The problem.

    Returns
    -------
    ndarray, shape (3, n_variables)
        [the variables' units].
    """
    low = np.array([v.search_bounds[0] for v in problem.variables])
    high = np.array([v.search_bounds[1] for v in problem.variables])
    points = np.vstack([low, 0.5 * (low + high), high])
    return np.column_stack([v.to_unit(points[:, j]) for j, v in enumerate(problem.variables)])


#: What to do about a generation whose samples would not fit in memory, in a problem file's
#: words.
GENERATION_REMEDY = ("shorten the runs ([excitation] duration, [analysis] duration or "
                     "n_averages, an `excitation.duration` variable's `high`), lower [analysis] "
                     "sample_rate, or evaluate fewer designs at once ([optimizer] population, "
                     "--population; [robust] samples)")


def check_run_length(problem, *, threads=None, cases=None):
    """Refuse, before any probe or store, a problem whose simulations would take absurdly
    long or keep more samples than the memory holds (``[analysis] duration = 1e9``, or an
    ``excitation.duration`` searched up to it: the longest of :func:`probe_designs`, the
    variables' bounds, counts); a problem of linear metrics only simulates nothing and
    passes. :func:`qzs.workflows.sweeps.store_checks.check_run_length` for a sweep.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    threads : int, optional
        Threads a generation's runs are shared over [-]; default the machine's cores.
    cases : int, optional
        Runs evaluated together [-]; default a generation's (population x draws).

    Raises
    ------
    RunTooLongError
        One design's run would take more than a day at the kernel's best speed.
    ResultTooLargeError
        The samples of ``cases`` runs would take more than half the memory available.
    """
    from qzs.workflows.sweeps.store_checks import check_run_length as check_sweep

    if any(METRICS[g.metric].source != "linear" for g in problem.goals):
        if cases is None:
            cases = problem.optimizer["population"] * problem.samples
        check_sweep(problem.sweep, _probe_settings(problem), threads=threads, cases=cases,
                    remedy=GENERATION_REMEDY)


def _probe_settings(problem):
    """The parameters of :func:`probe_designs`, each at the uncertain parameters' medians."""
    nominal = {u.name: u.nominal for u in problem.uncertain}
    names = [v.name for v in problem.variables]
    return [{**dict(zip(names, row.tolist())), **nominal} for row in probe_designs(problem)]


def fix_step(problem, *, progress=False):
    """The problem with its integration step fixed.

    A problem whose ``[simulation]`` gives no ``dt`` runs at the step chosen for its
    ``tolerance`` on :func:`probe_designs` (each at the uncertain parameters' medians),
    by :func:`qzs.workflows.sweeps.step.choose_sweep_step`, the sweeps' choice. A
    problem of linear metrics only needs no step.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    progress : bool
        Show the probes' progress.

    Returns
    -------
    DesignProblem
        With ``sweep.simulation["dt"]`` set (and ``step_note`` saying how).
    """
    from qzs.workflows.sweeps.step import choose_sweep_step

    if problem.sweep.simulation["dt"] is not None or all(
            METRICS[g.metric].source == "linear" for g in problem.goals):
        return problem
    sweep, _ = choose_sweep_step(problem.sweep, _probe_settings(problem), progress=progress)
    return dataclasses.replace(problem, sweep=sweep)


def _algorithm(problem, population):
    require("pymoo", "qzs optimize (multi-objective search)")
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem

    bounds = np.array([v.search_bounds for v in problem.variables])
    search = Problem(n_var=len(problem.variables), n_obj=len(problem.objectives),
                     n_ieq_constr=len(problem.constraints) + 1, xl=bounds[:, 0],
                     xu=bounds[:, 1])
    algorithm = NSGA2(pop_size=population, eliminate_duplicates=True)
    return algorithm, search


def optimize(problem: DesignProblem | str | Path | Mapping[str, Any],
             store: str | Path | None = None, *, resume: bool = False,
             overwrite: bool = False, generations: int | None = None,
             population: int | None = None, seed: int | None = None,
             scheduler: Any = None,
             workers: int | None = None, threads: int | None = None,
             progress: bool = True) -> OptimizationResult:
    """Search a design problem with NSGA-II; every generation is one evaluation task.

    Parameters
    ----------
    problem : DesignProblem, str, Path or dict
        The problem, a TOML file, a shipped problem's name or a parsed document.
    store : str or Path, optional
        Zarr store (``*.zarr``) keeping every evaluated design; default
        ``<problem name>.zarr``. An interrupted run keeps its complete generations.
    resume : bool
        Continue the store: stored generations are replayed, the rest evaluated; the
        result is bit-identical to an uninterrupted run.
    overwrite : bool
        Replace an existing store.
    generations, population : int, optional
        Override ``[optimizer]``'s generations and designs per generation.
    seed : int, optional
        Override ``[optimizer]``'s seed.
    scheduler : str or distributed.Client, optional
        Evaluate each generation on this Dask cluster (same results).
    workers : int, optional
        Start a local Dask cluster of this many single-threaded worker processes.
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a cluster.
    progress : bool
        Show a progress bar over the designs.

    Returns
    -------
    OptimizationResult

    Raises
    ------
    ProblemError
        An invalid problem (before any run).
    OutputPathError
        The store cannot be written, exists without ``resume``/``overwrite``, or holds
        another problem's designs.
    ResumeMismatchError
        ``resume`` with another ``seed`` or ``population`` than the store was started with
        (before any evaluation).
    """
    from qzs.engine.progress import progress_bar
    from qzs._validation import seed as checked_seed
    from qzs.workflows.design_space.problem import _in, _positive_int
    from qzs.workflows.sweeps.cluster import dask_client

    if not isinstance(problem, DesignProblem):
        problem = load_problem(problem)
    settings = dict(problem.optimizer)
    if generations is not None:
        settings["generations"] = _positive_int("optimizer", "generations", generations,
                                                100_000)
    if population is not None:
        settings["population"] = _positive_int("optimizer", "population", population, 100_000)
        if population < MIN_POPULATION:
            raise ProblemError("optimizer", "population", population, "NSGA-II needs at least "
                               f"{MIN_POPULATION} designs per generation")
    if seed is not None:
        settings["seed"] = checked_seed("seed", seed, _in("optimizer"))
    problem = dataclasses.replace(problem, optimizer=settings)
    store = Path(store) if store is not None else Path(f"{problem.name}.zarr")
    check(store, resume=resume, overwrite=overwrite)
    if resume:  # before any work: another seed or population asks for other designs
        check_same_search(store, problem)
    check_run_length(problem, threads=threads)  # certain already at the output period
    require("pymoo", "qzs optimize (multi-objective search)")
    began = time.perf_counter()
    # the cluster before the store or any probe; a store made here and failing before its
    # first generation is stored goes again
    with dask_client(scheduler, workers) as client, removed_on_error(store) as made:
        if not resume:  # the step first: nothing is written until the runs are sure to start
            problem = fix_step(problem, progress=progress)
            check_run_length(problem, threads=threads)
        opened = DesignStore(store, problem, resume=resume, overwrite=overwrite)
        if opened.generations:
            made.keep()
        if opened.step is not None:
            sweep = problem.sweep
            problem = dataclasses.replace(problem, sweep=dataclasses.replace(
                sweep, simulation={**sweep.simulation, "dt": opened.step[0],
                                   "step_note": opened.step[1]}))
        else:
            if resume:
                problem = fix_step(problem, progress=progress)
                check_run_length(problem, threads=threads)
            dt = problem.sweep.simulation["dt"]
            if dt is not None:
                opened.set_step(dt, problem.sweep.simulation.get("step_note", ""))
        total = settings["generations"] * settings["population"] * problem.samples
        with progress_bar(total=total, unit="case", desc=problem.name, disable=not progress,
                          dynamic_ncols=True) as bar:
            evaluated_now, steps = _generations(problem, opened, client, threads, bar,
                                                stored=made.keep)
    return OptimizationResult.from_store(opened, problem, wall=time.perf_counter() - began,
                                         evaluated=evaluated_now, steps=steps)


def _generations(problem, opened, client, threads, bar, stored=lambda: None):
    """Ask NSGA-II for every generation and tell it the designs' objectives.

    A generation the store holds is answered from it (after checking bit for bit that
    the same designs were asked for); the others are evaluated and stored (then
    ``stored()`` is called).

    Returns
    -------
    evaluated : int
        Designs evaluated now.
    steps : int
        Their integration steps.
    """
    from pymoo.core.evaluator import Evaluator
    from pymoo.problems.static import StaticProblem

    settings = problem.optimizer
    algorithm, search = _algorithm(problem, settings["population"])
    algorithm.setup(search, termination=("n_gen", settings["generations"]),
                    seed=settings["seed"], verbose=False)
    evaluated = steps = 0
    for generation in range(settings["generations"]):
        asked = algorithm.ask()
        X = asked.get("X")
        if generation < opened.generations:
            position, values, _ = opened.generation_rows(generation)
            if position.shape != X.shape or not np.array_equal(position, X):
                raise OutputPathError("store", opened.path, "holds designs the optimiser does "
                                      f"not ask for again (generation {generation}); it was "
                                      "written by another qzs or pymoo version. Start again "
                                      "with --overwrite")
            aggregated = goal_values(problem.goals, values, len(X))
            bar.update(len(X) * problem.samples)
        else:
            designs = np.column_stack([v.to_unit(X[:, j])
                                       for j, v in enumerate(problem.variables)])
            evaluation = evaluate(problem, designs, client=client, threads=threads,
                                  progress=bar.update)
            opened.append(generation, X, evaluation)
            stored()
            aggregated = evaluation.goal_values(problem.goals)
            evaluated += len(X)
            steps += evaluation.steps
        F, G = objective_matrix(problem, aggregated)
        Evaluator().eval(StaticProblem(search, F=F, G=G), asked)
        algorithm.tell(infills=asked)
    return evaluated, steps
