"""What a design is judged by: the metrics, and a population's evaluation in lockstep.

A metric is a number per simulated case: a statistic of the run (peak stroke, RMS motor
force, saturated and locked shares), a number of the transmissibility estimate (RMS or
mean over a band, the value at a frequency, the isolation onset; trusted bins only,
docs/model.md §10), or a number of the linear analysis at the setpoint, which needs no
simulation (hunting amplitude at rest, stability margins, the linear transmissibility).

:func:`evaluate` runs a population: every design crossed with every Monte Carlo draw
(common random numbers), in batches through
:func:`qzs.workflows.sweeps.batch.run_batch`, the task of every sweep, so a design
gives exactly the numbers of a sweep's case and of :func:`qzs.simulate`. Cases that share
their excitation and step run as one lockstep batch of the lane kernel.
:func:`evaluate_cases` is that path for any list of cases (a sensitivity analysis sets
variables and uncertain parameters together, so it cannot cross designs with draws).
"""
import math
import time
from dataclasses import dataclass, field

import numpy as np

from qzs.analysis.statistics import STATISTICS as RUN_STATISTICS
from qzs.engine.batch import STATS

__all__ = ["MetricDefinition", "METRICS", "STATISTICS", "metric_column", "sweep_outputs",
           "Evaluation", "evaluate", "evaluate_cases", "case_settings", "goal_values"]

#: How the Monte Carlo draws of a design combine.
STATISTICS = ("mean", "worst", "quantile")


@dataclass(frozen=True, kw_only=True)
class MetricDefinition:
    """One metric a goal can name.

    Attributes
    ----------
    name : str
        The metric's name in problem files.
    units : str
        Its unit.
    description : str
        One line.
    source : {"run", "spectrum", "linear"}
        A statistic of the simulated run, a number of its transmissibility estimate, or of
        the linear analysis (no simulation).
    options : tuple of str
        Keys a goal gives with it: ``frequency`` [Hz] or ``band`` [Hz].
    lowest, highest : float or None
        Bounds the metric can never pass (a constraint beyond them is infeasible).
    label : str
        A short name for axes and tables ('' : the name with spaces).
    """

    name: str
    units: str
    description: str
    source: str
    options: tuple = ()
    lowest: float | None = None
    highest: float | None = None
    label: str = ""

    def title(self, options):
        """The metric with its options for people: ``RMS transmissibility 1-5 Hz``.

        Parameters
        ----------
        options : dict
            The goal's ``frequency`` [Hz] or ``band`` [Hz], as the metric takes.

        Returns
        -------
        str
        """
        text = self.label or self.name.replace("_", " ")
        if "frequency" in options:
            return f"{text} {options['frequency']:g} Hz"
        if "band" in options:
            return f"{text} {options['band'][0]:g}-{options['band'][1]:g} Hz"
        return text


def _run(name, lowest=0.0, highest=None):
    unit, doc = STATS[name]
    return MetricDefinition(name=name, units=unit, description=doc, source="run",
                            lowest=lowest, highest=highest, label=doc)


#: Metrics by name.
METRICS = {m.name: m for m in (
    MetricDefinition(name="rms_transmissibility", units="1", label="RMS transmissibility",
                     source="spectrum",
                     options=("band",), lowest=0.0,
                     description="RMS transmissibility (amplitude ratio) over `band` "
                                 "(default the analysis band), trusted bins"),
    MetricDefinition(name="mean_transmissibility", units="1", label="mean transmissibility",
                     source="spectrum",
                     options=("band",), lowest=0.0,
                     description="mean transmissibility (amplitude ratio) over `band`, "
                                 "trusted bins"),
    MetricDefinition(name="transmissibility_at", units="1", label="transmissibility at",
                     source="spectrum",
                     options=("frequency",), lowest=0.0,
                     description="transmissibility (amplitude ratio) at `frequency`, "
                                 "interpolated between trusted bins"),
    MetricDefinition(name="resonance_peak", units="1", source="spectrum", lowest=0.0,
                     description="largest transmissibility in the analysis band"),
    MetricDefinition(name="resonance_frequency", units="Hz", source="spectrum", lowest=0.0,
                     description="frequency of the largest transmissibility"),
    MetricDefinition(name="isolation_onset", units="Hz", source="spectrum", lowest=0.0,
                     description="lowest frequency above which the transmissibility stays "
                                 "below 1"),
    MetricDefinition(name="minus_3db_frequency", units="Hz", source="spectrum", lowest=0.0,
                     description="frequency where the transmissibility falls below -3 dB"),
    _run("peak_stroke"),
    _run("motor_force_rms"),
    _run("saturated_fraction", highest=1.0),
    _run("locked_fraction", highest=1.0),
    _run("stop_contacts"),
    _run("stick_events"),
    MetricDefinition(name="hunting_amplitude", units="m", source="linear", lowest=0.0,
                     description="predicted plateau of the stick-slip limit cycle at rest "
                                 "(describing function; 0 where the loop does not hunt)"),
    MetricDefinition(name="gain_margin", units="dB", source="linear",
                     description="gain margin of the control loop at the setpoint "
                                 "(undefined where the closed loop is unstable)"),
    MetricDefinition(name="phase_margin", units="deg", source="linear",
                     description="phase margin of the control loop at the setpoint (inf "
                                 "where |L| never crosses 1; undefined where the closed "
                                 "loop is unstable)"),
    MetricDefinition(name="linear_transmissibility_at", units="1", label="linear transmissibility at",
                     source="linear",
                     options=("frequency",), lowest=0.0,
                     description="transmissibility of the linearised loop at `frequency` "
                                 "(no friction, no stops)"),
)}
assert set(RUN_STATISTICS) <= set(STATS)


def _band_label(band):
    return f"from_{band[0]:g}_to_{band[1]:g}_hz".replace(".", "p")


def metric_column(metric, options):
    """The name of a metric with its options, as evaluated and stored.

    Parameters
    ----------
    metric : str
        A name of :data:`METRICS`.
    options : dict
        ``frequency`` [Hz] or ``band`` [Hz], as the metric takes.

    Returns
    -------
    str
        ``transmissibility_at_12_hz``, ``rms_transmissibility_from_1_to_3_hz``, or ``metric``.
    """
    if "frequency" in options:
        return f"{metric}_{options['frequency']:g}_hz"
    if "band" in options:
        return f"{metric}_{_band_label(options['band'])}"
    return metric


def sweep_outputs(goals, analysis):
    """What the sweep behind a problem records for these goals.

    Parameters
    ----------
    goals : sequence of Goal
        The problem's objectives and constraints.
    analysis : dict
        The resolved analysis settings.

    Returns
    -------
    analysis : dict
        ``at_frequencies`` [Hz] the goals need.
    outputs : dict
        The sweep's ``[outputs]`` table (no curve).
    """
    stats, metrics, bands, rms, at = [], [], {}, {}, []
    for goal in goals:
        source = METRICS[goal.metric].source
        if source == "run":
            stats.append(goal.metric)
        elif goal.metric == "transmissibility_at":
            at.append(goal.options["frequency"])
            metrics.append(goal.column)
        elif goal.metric in ("rms_transmissibility", "mean_transmissibility"):
            table = rms if goal.metric.startswith("rms") else bands
            table[_band_label(goal.options["band"])] = goal.options["band"]
        elif source == "spectrum":
            metrics.append(goal.metric)
    outputs = {"stats": list(dict.fromkeys(stats)), "metrics": list(dict.fromkeys(metrics)),
               "transmissibility": False, "coherence": False, "bands": bands,
               "rms_bands": rms}
    return {"at_frequencies": list(dict.fromkeys(at))}, outputs


def goal_values(goals, values, n_designs):
    """Each goal's value per design: its column's draws combined by its statistic.

    Parameters
    ----------
    goals : sequence of Goal
        The goals, in the order of the columns returned.
    values : mapping of str to ndarray, shape (n_designs, n_samples)
        Metric column -> value per design and draw [the metric's unit].
    n_designs : int
        Designs (the shape when there is no goal).

    Returns
    -------
    ndarray, shape (n_designs, n_goals)
        [each goal's unit]; NaN where a draw's value is undefined.
    """
    columns = [goal.aggregate(values[goal.column]) for goal in goals]
    return np.column_stack(columns) if columns else np.empty((n_designs, 0))


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


def _linear(problem, settings, goals, values, status, messages, progress=None):
    """The linear metrics ``goals`` of every case at once (closed forms; no simulation).

    One vectorised evaluation of the population (:mod:`~qzs.analysis.control_design.
    hunting_population`, :mod:`~qzs.analysis.control_design.linear_population`), equal to
    python-control's numbers to their tests' bounds. ``progress`` is called with the number
    of cases, once, when they are done.
    """
    from qzs.analysis.control_design.hunting_population import (population_constants,
                                                                predict_hunting_population)
    from qzs.analysis.control_design.linear_population import (population_margins,
                                                               population_transmissibility)
    from qzs.errors import ParameterError
    from qzs.workflows.sweeps.cases import build_model

    built, models = [], []
    for c, case in enumerate(settings):
        try:  # the model only: the linear analysis needs no excitation
            models.append(build_model(problem.sweep, case))
            built.append(c)
        except (ParameterError, TypeError) as error:
            status[c], messages[c] = 2, str(error)
    isolators, controllers = [m[0] for m in models], [m[1] for m in models]
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
    if progress is not None:
        progress(len(settings))


def evaluate_cases(problem, settings, *, columns=None, client=None, threads=None,
                   batch_size=None, progress=None):
    """Evaluate cases, each a dict of parameter values, in lockstep batches.

    The one path of every evaluation: :func:`evaluate` crosses designs with draws into
    cases, a sensitivity analysis samples variables and uncertain parameters together;
    each case runs through :func:`qzs.workflows.sweeps.batch.run_batch` with
    ``problem.sweep`` (simulated metrics) or the linear analysis (linear metrics).

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
        Cases per batch; default all of them locally (one lockstep batch), about two
        batches per worker thread on a cluster.
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
    from qzs.workflows.sweeps.batch import run_local, run_on_dask

    total = len(settings)
    columns = problem.columns if columns is None else tuple(columns)
    goals = [g for g in problem.goals if g.column in columns]
    values = {column: np.full(total, np.nan) for column in columns}
    status = np.ones(total, dtype=np.int8)
    messages = [""] * total
    steps = 0
    simulated = [g for g in goals if METRICS[g.metric].source != "linear"]
    if simulated and total:
        definition = problem.sweep
        if definition.simulation["dt"] is None:
            raise ValueError("the problem's step is not fixed yet: choose it first "
                             "(qzs.workflows.design_space.optimizer.fix_step)")
        if batch_size is None:
            batch_size = total if client is None else max(
                1, -(-total // (2 * sum(client.nthreads().values()))))
        batches = [(a, min(a + batch_size, total)) for a in range(0, total, batch_size)]
        if client is not None:
            results = run_on_dask(client, definition, batches, settings, 0,
                            1 if threads is None else threads)
        else:
            results = run_local(definition, batches, settings, 0, threads)
        try:
            for result in results:
                start, arrays = result["start"], result["arrays"]
                stop = start + len(arrays["status"])
                status[start:stop] = arrays["status"]
                messages[start:stop] = [str(m) for m in arrays["message"]]
                for goal in simulated:
                    # the sweep stores each metric under the goal's column name
                    values[goal.column][start:stop] = np.asarray(arrays[goal.column],
                                                                 dtype=float)
                steps += int(result["steps"])
                if progress is not None:
                    progress(stop - start)
        finally:
            results.close()
        for column in values:  # a failed case defines no metric
            values[column][status != 1] = np.nan
    linear = [g for g in goals if METRICS[g.metric].source == "linear"]
    if linear:
        _linear(problem, settings, linear, values, status, messages,
                None if simulated else progress)
    return values, status, messages, steps


def evaluate(problem, designs, *, client=None, threads=None, batch_size=None,
             progress=None):
    """Evaluate designs: every design under every draw, in lockstep batches.

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
        Cases per batch; default all of them locally (one lockstep batch), about two
        batches per worker thread on a cluster.
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
