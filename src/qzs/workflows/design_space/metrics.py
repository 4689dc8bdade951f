"""What a design is judged by: the metrics, and how a design's draws combine.

A metric is a number per simulated case: a statistic of the run (peak stroke, RMS motor
force, saturated and locked shares), a number of the transmissibility estimate (RMS or
mean over a band, the value at a frequency, the isolation onset; trusted bins only,
docs/model.md §10), or a number of the linear analysis at the setpoint, which needs no
simulation (hunting amplitude at rest, stability margins, the linear transmissibility).

A population is evaluated by :mod:`qzs.workflows.design_space.evaluation`.
"""
from dataclasses import dataclass

import numpy as np

from qzs.analysis.statistics import STATISTICS as RUN_STATISTICS
from qzs.engine.batch import STATS

__all__ = ["MetricDefinition", "METRICS", "STATISTICS", "metric_column", "sweep_outputs",
           "goal_values"]

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
