"""A population's evaluation: each batch one task, its runs, estimates and linear metrics.

:func:`evaluate` runs a population: every design crossed with every Monte Carlo draw
(common random numbers); :func:`evaluate_cases` is that path for any list of cases (a
sensitivity analysis sets variables and uncertain parameters together, so it cannot
cross designs with draws). The cases go in batches, each one task.

:func:`evaluate_batch` is what every backend runs for a batch of cases (stumpy style: the
same task in this process and on a Dask worker): the simulations and their reductions
through the sweeps' task :func:`qzs.workflows.sweeps.batch.run_batch` (statistics,
transmissibility estimates, their metrics), and the linear metrics of the same cases
(hunting at rest, margins, linear transmissibility: one vectorised evaluation of the
closed forms). So a Dask cluster or ``--workers N`` shares all of a batch's work, and
nothing of it is left for the main process but collecting the numbers.

With more than one core a batch's work is shared over a thread per core: the linear
metrics of all its cases in one vectorised call, and its simulations in shares, each
share's runs on one core (in the kernel, which releases the GIL) followed by its
estimates, so that one thread's Python work overlaps another's integration instead of
waiting for the whole batch. Every case's numbers are the same whatever the share it runs
in (the kernel's lanes and the columns of the vectorised closed forms are independent),
so the result is bit-identical to one share on one thread.
:func:`run_tasks` runs a list of batches here or on a cluster and yields their results.
"""
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from qzs.workflows.design_space.metrics import METRICS, goal_values

__all__ = ["Evaluation", "evaluate", "evaluate_cases", "cases_per_batch", "case_settings",
           "evaluate_batch", "run_tasks", "linear_metrics", "shares"]


def shares(n, parts):
    """Contiguous shares of ``n`` cases, at most ``parts`` of them, as equal as can be.

    Parameters
    ----------
    n : int
        Cases [-].
    parts : int
        Shares wanted [-].

    Returns
    -------
    list of (int, int)
        Each share's first and past-the-last case; none empty.
    """
    parts = max(1, min(int(parts), n))
    edges = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def linear_metrics(problem, settings, goals, values, status, messages):
    """The linear metrics ``goals`` of every case at once (closed forms; no simulation).

    One vectorised evaluation of the cases (:mod:`~qzs.analysis.control_design.
    hunting_population`, :mod:`~qzs.analysis.control_design.linear_population`), equal to
    python-control's numbers to their tests' bounds; each case's number depends on that
    case alone.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    settings : list of dict
        One dict of parameter values per case.
    goals : sequence of Goal
        The linear goals wanted.
    values : dict of str to ndarray, shape (n_cases,)
        Filled in place at each goal's column [the metric's unit].
    status : ndarray of int8, shape (n_cases,)
        Set to 2 (invalid) where a case's model cannot be built.
    messages : list of str
        Why, for those cases.
    """
    from qzs.analysis.control_design.hunting_population import (population_constants,
                                                                predict_hunting_population)
    from qzs.analysis.control_design.linear_population import (population_margins,
                                                               population_transmissibility)
    from qzs.errors import ParameterError
    from qzs.workflows.sweeps.cases import build_model

    built, isolators, controllers = [], [], []
    for c, case in enumerate(settings):
        try:  # the model only: the linear analysis needs no excitation
            model = build_model(problem.sweep, case)
        except (ParameterError, TypeError) as error:
            status[c], messages[c] = 2, str(error)
            continue
        built.append(c)
        isolators.append(model[0])
        controllers.append(model[1])
    if not built:
        return
    constants = population_constants(isolators, controllers)
    margins = hunting = None
    for goal in goals:
        if goal.metric == "hunting_amplitude":
            hunting = hunting or predict_hunting_population(isolators, controllers,
                                                            constants=constants)
            value = hunting.hunting_amplitude
        elif goal.metric in ("gain_margin", "phase_margin"):
            margins = margins or population_margins(isolators, controllers,
                                                    constants=constants)
            value = np.where(margins.stable, getattr(margins, goal.metric), math.nan)
            if goal.metric == "phase_margin":  # |L| < 1 everywhere: no crossover to lose
                value = np.where(margins.stable & np.isnan(value), math.inf, value)
        else:
            value = population_transmissibility(goal.options["frequency"],
                                                constants=constants)
        values[goal.column][built] = value


def _simulate_share(definition, settings, columns, threads):
    """Simulate and reduce cases: (values of ``columns``, status, messages, steps)."""
    from qzs.workflows.sweeps.batch import run_batch

    result = run_batch(definition, 0, settings, 0, threads)
    arrays = result["arrays"]
    status = np.asarray(arrays["status"], dtype=np.int8)
    values = {}
    for column in columns:  # the sweep stores each metric under the goal's column name
        values[column] = np.asarray(arrays[column], dtype=float).copy()
        values[column][status != 1] = np.nan  # a failed case defines no metric
    return values, status, [str(m) for m in arrays["message"]], int(result["steps"])


def _linear_job(problem, settings, linear):
    """The linear metrics of all the cases: (values, status, messages)."""
    n = len(settings)
    values = {g.column: np.full(n, np.nan) for g in linear}
    status, messages = np.ones(n, dtype=np.int8), [""] * n
    linear_metrics(problem, settings, linear, values, status, messages)
    return values, status, messages


def evaluate_batch(problem, start, settings, columns, threads=None):
    """Evaluate one batch of cases: simulations, estimates and linear metrics together.

    The task of every backend (this process, a Dask worker). With more than one core the
    work runs on a thread per core: the linear metrics of all the cases in one
    vectorised call (its cost is mostly per call), and the simulations in shares, two
    per core, each share's runs on one core and then its estimates.

    Parameters
    ----------
    problem : DesignProblem
        The problem; its ``sweep`` must have its step fixed when a column needs a
        simulation.
    start : int
        Index of the batch's first case.
    settings : list of dict
        One dict of parameter values per case.
    columns : sequence of str
        The metric columns wanted.
    threads : int, optional
        Cores to use; default all.

    Returns
    -------
    dict
        ``start``; ``values`` (column -> ndarray, shape (n,), NaN where undefined);
        ``status`` (int8, 1 ok, see :data:`qzs.workflows.sweeps.store.STATUS`);
        ``messages`` (list of str, '' if ok); ``steps`` (integration steps); ``elapsed``
        [s].
    """
    began = time.perf_counter()
    goals = [g for g in problem.goals if g.column in columns]
    simulated = [g.column for g in goals if METRICS[g.metric].source != "linear"]
    linear = [g for g in goals if METRICS[g.metric].source == "linear"]
    n = len(settings)
    cores = threads or os.cpu_count() or 1
    parts = (shares(n, 2 * cores) if cores > 1 else [(0, n)]) if simulated and n else []
    one_core = 1 if len(parts) > 1 else threads
    jobs = ([lambda: _linear_job(problem, settings, linear)] if linear and n else []) + [
        lambda a=a, b=b: _simulate_share(problem.sweep, settings[a:b], simulated, one_core)
        for a, b in parts]
    if cores > 1 and len(jobs) > 1:  # the linear job first: it overlaps the integrations
        with ThreadPoolExecutor(min(cores, len(jobs))) as pool:
            done = list(pool.map(lambda job: job(), jobs))
    else:
        done = [job() for job in jobs]
    values = {g.column: np.full(n, np.nan) for g in goals}
    status, messages, steps = np.ones(n, dtype=np.int8), [""] * n, 0
    for (a, b), (share, share_status, share_messages, share_steps) in zip(
            parts, done[len(done) - len(parts):]):
        for column in simulated:
            values[column][a:b] = share[column]
        status[a:b], messages[a:b] = share_status, share_messages
        steps += share_steps
    if linear and n:
        linear_values, linear_status, linear_messages = done[0]
        values.update(linear_values)
        for c in np.flatnonzero(linear_status != 1):  # no model: the reason the linear
            status[c], messages[c] = linear_status[c], linear_messages[c]  # analysis gives
    return {"start": start, "values": values, "status": status, "messages": messages,
            "steps": steps, "elapsed": time.perf_counter() - began}


def run_tasks(problem, batches, settings, columns, *, client=None, threads=None):
    """Run :func:`evaluate_batch` on batches, here one after the other or on a Dask cluster.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    batches : list of (int, int)
        Each batch's first and past-the-last case index into ``settings``.
    settings : list of dict
        One dict of parameter values per case.
    columns : sequence of str
        The metric columns wanted.
    client : distributed.Client, optional
        Run the batches on this cluster, at most two per worker thread in flight (a failed
        task is tried twice more).
    threads : int, optional
        Threads per batch (:func:`evaluate_batch`); default all cores here, 1 on a cluster.

    Returns
    -------
    generator of dict
        Each batch's :func:`evaluate_batch` result: in order here, as they finish on a
        cluster (:func:`qzs.workflows.sweeps.batch.run_on_dask`). Closing it cancels the
        tasks still pending.
    """
    from qzs.workflows.sweeps.batch import run_on_dask

    columns = tuple(columns)
    if client is None:
        return (evaluate_batch(problem, start, settings[start:stop], columns, threads)
                for start, stop in batches)
    return run_on_dask(client, problem, batches, settings, columns,
                       1 if threads is None else threads, task=evaluate_batch)


@dataclass(frozen=True, kw_only=True)
class Evaluation:
    """The metrics of a population, every design under every draw.

    Attributes
    ----------
    designs : ndarray, shape (n_designs, n_variables)
        The decision variables [their units].
    values : dict of str to ndarray, shape (n_designs, n_samples)
        Metric column -> its value per design and draw [the metric's unit]; NaN where the
        run failed or the metric is undefined.
    status : ndarray of int8, shape (n_designs, n_samples)
        Sweep status per case (1 ok; see :data:`qzs.workflows.sweeps.store.STATUS`).
    messages : list of list of str
        Why a case failed ('' if ok).
    steps : int
        Integration steps done.
    elapsed : float
        Wall time [s].
    """

    designs: np.ndarray
    values: dict
    status: np.ndarray
    messages: list = field(repr=False)
    steps: int = 0
    elapsed: float = 0.0

    def goal_values(self, goals):
        """Each goal's value per design: the draws combined by its statistic.

        Parameters
        ----------
        goals : sequence of Goal
            The goals, in the order of the columns returned.

        Returns
        -------
        ndarray, shape (n_designs, n_goals)
            [each goal's unit]; NaN where a draw's value is undefined.
        """
        return goal_values(goals, self.values, len(self.designs))


def case_settings(problem, designs):
    """One dict of parameter values per case: each design crossed with each draw.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    designs : ndarray, shape (n_designs, n_variables)
        The decision variables [their units].

    Returns
    -------
    list of dict
        Design-major, draws fastest: case ``i * samples + k`` is design ``i`` under draw
        ``k``.
    """
    draws = problem.draws()
    names = [v.name for v in problem.variables]
    settings = []
    for row in np.asarray(designs, dtype=float):
        design = dict(zip(names, row.tolist()))
        for k in range(problem.samples):
            settings.append({**design, **{name: float(v[k]) for name, v in draws.items()}})
    return settings


def cases_per_batch(total, client=None, batch_size=None, simulated=True):
    """Cases :func:`evaluate_cases` evaluates in one task [-].

    Parameters
    ----------
    total : int
        Cases to evaluate [-].
    client : distributed.Client, optional
        The Dask cluster they go to (None: this process).
    batch_size : int, optional
        Cases per task asked for.
    simulated : bool
        Whether any metric needs a simulation.

    Returns
    -------
    int
        Here, ``batch_size`` if given for a simulated problem, else every case in one
        call (the linear metrics cost mostly per call); on a cluster, ``batch_size`` or
        one task per worker thread.
    """
    if client is None and (batch_size is None or not simulated):
        return total
    if batch_size is None:
        return max(1, -(-total // sum(client.nthreads().values())))
    return batch_size


def evaluate_cases(problem, settings, *, columns=None, client=None, threads=None,
                   batch_size=None, progress=None):
    """Evaluate cases, each a dict of parameter values, in batches (one task each).

    The one path of every evaluation: :func:`evaluate` crosses designs with draws into
    cases, a sensitivity analysis samples variables and uncertain parameters together;
    each batch is one task, :func:`qzs.workflows.design_space.evaluation.evaluate_batch`,
    here or on a Dask worker: its cases' runs through
    :func:`qzs.workflows.sweeps.batch.run_batch` with ``problem.sweep`` (simulated
    metrics) and their linear analysis (linear metrics).

    Parameters
    ----------
    problem : DesignProblem
        The problem; its ``sweep`` must have its step fixed (``simulation["dt"]``) when a
        metric of ``columns`` needs a simulation.
    settings : list of dict
        One dict per case: parameter name -> value [the parameter's unit].
    columns : sequence of str, optional
        The metric columns wanted; default every column of the problem's goals. No
        simulation runs when none of them needs one.
    client : distributed.Client, optional
        Run the batches on this Dask cluster (results are the same).
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a cluster.
    batch_size : int, optional
        Cases per batch (one task); default all of them locally (one task, its cases
        shared over the cores), one batch per worker thread on a cluster (the linear
        metrics cost mostly per call: fewer, larger batches cost less). Locally
        the linear metrics alone are one batch whatever it says.
    progress : callable, optional
        Called with the number of cases each finished batch held.

    Returns
    -------
    values : dict of str to ndarray, shape (n_cases,)
        Metric column -> its value per case [the metric's unit]; NaN where the run failed
        or the metric is undefined.
    status : ndarray of int8, shape (n_cases,)
        Sweep status per case (1 ok; see :data:`qzs.workflows.sweeps.store.STATUS`).
    messages : list of str
        Why a case failed ('' if ok).
    steps : int
        Integration steps done.

    Raises
    ------
    ValueError
        A simulated metric is wanted and the problem's step is not fixed yet.
    """
    total = len(settings)
    columns = problem.columns if columns is None else tuple(columns)
    goals = [g for g in problem.goals if g.column in columns]
    values = {column: np.full(total, np.nan) for column in columns}
    status = np.ones(total, dtype=np.int8)
    messages = [""] * total
    steps = 0
    if not total or not goals:
        return values, status, messages, steps
    simulated = any(METRICS[g.metric].source != "linear" for g in goals)
    if simulated and problem.sweep.simulation["dt"] is None:
        raise ValueError("the problem's step is not fixed yet: choose it first "
                         "(qzs.workflows.design_space.optimizer.fix_step)")
    batch_size = cases_per_batch(total, client, batch_size, simulated)
    batches = [(a, min(a + batch_size, total)) for a in range(0, total, batch_size)]
    results = run_tasks(problem, batches, settings, [g.column for g in goals], client=client,
                        threads=threads)
    try:
        for result in results:
            start = result["start"]
            stop = start + len(result["status"])
            status[start:stop] = result["status"]
            messages[start:stop] = result["messages"]
            for column, value in result["values"].items():
                values[column][start:stop] = value
            steps += int(result["steps"])
            if progress is not None:
                progress(stop - start)
    finally:
        results.close()
    return values, status, messages, steps


def evaluate(problem, designs, *, client=None, threads=None, batch_size=None,
             progress=None):
    """Evaluate designs: every design under every draw, in batches (one task each).

    Parameters
    ----------
    problem : DesignProblem
        The problem; its ``sweep`` must have its step fixed (``simulation["dt"]``) when
        any goal needs a simulation.
    designs : array_like, shape (n_designs, n_variables)
        The decision variables [their units], in the order of ``problem.variables``.
    client : distributed.Client, optional
        Run the batches on this Dask cluster (results are the same).
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a cluster.
    batch_size : int, optional
        Cases per batch (one task); default all of them locally, one batch per worker
        thread on a cluster (:func:`evaluate_cases`).
    progress : callable, optional
        Called with the number of cases each finished batch held.

    Returns
    -------
    Evaluation
    """
    began = time.perf_counter()
    designs = np.atleast_2d(np.asarray(designs, dtype=float))
    n, samples = designs.shape[0], problem.samples
    settings = case_settings(problem, designs)
    values, status, messages, steps = evaluate_cases(
        problem, settings, client=client, threads=threads, batch_size=batch_size,
        progress=progress)
    return Evaluation(designs=designs,
                      values={c: v.reshape(n, samples) for c, v in values.items()},
                      status=status.reshape(n, samples),
                      messages=[messages[i * samples:(i + 1) * samples] for i in range(n)],
                      steps=steps, elapsed=time.perf_counter() - began)
