"""A validated design problem's types: the decision variables, the uncertain parameters,
the goals (objectives and constraints) and the problem itself.

:func:`qzs.workflows.design_space.problem.load_problem` makes them from a problem file and
re-exports them; the optimiser, the sensitivity analysis and the result read them.
"""
import hashlib
import json
import math
from dataclasses import dataclass, field

import numpy as np

from qzs._format import unit_label, with_unit
from qzs.workflows.sweeps.definition import SweepDefinition, frozen_distribution, unit_draws

__all__ = ["Variable", "Uncertainty", "Goal", "DesignProblem"]


#: The problem document's format, hashed with it (a store made for another format is refused).
_FORMAT = "qzs-problem-1"


@dataclass(frozen=True, kw_only=True)
class Variable:
    """A decision variable: a registry parameter searched between bounds.

    Attributes
    ----------
    name : str
        Registry name (``pi_kp``) or ``excitation.<name>``.
    low : float
        Lower bound, in the parameter's unit (``[N/m]`` for ``pi_kp``).
    high : float
        Upper bound, in the parameter's unit (``[N/m]`` for ``pi_kp``).
    scale : {"linear", "log"}
        ``log``: searched and sampled on ``log10`` (both bounds positive).
    integer : bool
        Rounded to whole numbers.
    units : str
        The parameter's unit (from the registry).
    """

    name: str
    low: float
    high: float
    scale: str = "linear"
    integer: bool = False
    units: str = ""

    def to_unit(self, values):
        """Map values of the search space (``log10`` for a log scale) to the parameter.

        Parameters
        ----------
        values : array_like
            Positions in the search space.

        Returns
        -------
        ndarray
            The parameter's values [its unit], rounded for an integer variable.
        """
        values = np.asarray(values, dtype=float)
        out = 10.0 ** values if self.scale == "log" else values
        return np.round(out) if self.integer else out

    @property
    def search_bounds(self) -> tuple[float, float]:
        """Bounds in the search space (``log10`` of them for a log scale)."""
        if self.scale == "log":
            return math.log10(self.low), math.log10(self.high)
        return self.low, self.high


@dataclass(frozen=True, kw_only=True)
class Uncertainty:
    """An uncertain parameter: a distribution, or a list of equally likely values.

    Attributes
    ----------
    name : str
        Registry name.
    distribution : str
        ``uniform``, ``normal``, ``lognormal``, ``loguniform`` or ``values``.
    settings : dict
        Its keys (``low``/``high``, ``mean``/``std``, ``median``/``sigma`` [the parameter's
        unit; ``sigma`` of ``ln``], or ``values``).
    units : str
        The parameter's unit.
    """

    name: str
    distribution: str
    settings: dict
    units: str = ""

    def quantile(self, u):
        """The parameter at probabilities ``u``: the inverse CDF.

        Parameters
        ----------
        u : array_like
            Probabilities in (0, 1).

        Returns
        -------
        ndarray
            The parameter's values [its unit].
        """
        u = np.asarray(u, dtype=float)
        if self.distribution == "values":
            values = np.asarray(self.settings["values"], dtype=float)
            return values[np.minimum((u * values.size).astype(int), values.size - 1)]
        return frozen_distribution(self.distribution, self.settings).ppf(u)

    @property
    def nominal(self) -> float:
        """The median: the value a design is probed at when one value is needed."""
        return float(self.quantile(0.5))


@dataclass(frozen=True, kw_only=True)
class Goal:
    """An objective or a constraint on one metric.

    Attributes
    ----------
    metric : str
        A name of :data:`~qzs.workflows.design_space.metrics.METRICS`.
    column : str
        The metric with its options, as evaluated (``transmissibility_at_12_hz``).
    options : dict
        The metric's options (``frequency`` [Hz], ``band`` [Hz]).
    statistic : {"mean", "worst", "quantile"}
        How the Monte Carlo draws of a design combine.
    quantile : float or None
        The probability of ``statistic = "quantile"``.
    sense : {"minimize", "maximize"}
        Objectives: which way is better. Constraints: ``minimize`` for an upper bound.
    bound : float or None
        Constraints: the bound [the metric's unit]; None for an objective.
    units : str
        The metric's unit.
    title : str
        The metric with its options for people (``transmissibility at 12 Hz``).
    scale : {"linear", "log"}
        Objectives: ``log`` makes the optimiser compare ``log10`` of the value, so that its
        crowding spreads the Pareto set evenly in ratios (the set itself is the same; the
        metric must stay positive, a value <= 0 counts as undefined).
    """

    metric: str
    column: str
    options: dict
    statistic: str = "mean"
    quantile: float | None = None
    sense: str = "minimize"
    bound: float | None = None
    units: str = ""
    title: str = ""
    scale: str = "linear"

    @property
    def label(self) -> str:
        """Name of the goal's value: the column and its statistic (``peak_stroke_worst``)."""
        if self.statistic == "quantile":
            return f"{self.column}_q{self.quantile:g}"
        return self.column if self.statistic == "mean" else f"{self.column}_{self.statistic}"

    def describe(self) -> str:
        """One line for people: ``peak_stroke (worst case) <= 0.02 m``.

        The mean over the draws, or the one value without draws, is not named.
        """
        stat = (f" (quantile {self.quantile:g})" if self.statistic == "quantile"
                else {"mean": "", "worst": " (worst case)"}[self.statistic])
        if self.bound is None:
            return f"{self.sense} {unit_label(self.column + stat, self.units)}"
        op = "<=" if self.sense == "minimize" else ">="
        return f"{self.column}{stat} {op} {self.bound:g}{_unit(self.units)}"

    def aggregate(self, values):
        """Combine the draws of each design (last axis) into one number per design.

        NaN draws (a metric the run does not define) make the design's value NaN.

        Parameters
        ----------
        values : array_like, shape (..., n_samples)
            The metric per draw [its unit].

        Returns
        -------
        ndarray, shape (...)
            ``mean``: the mean; ``worst``: the largest for a minimised goal (or an upper
            bound), the smallest otherwise; ``quantile``: the quantile ``q`` on the bad
            side (``1 - q`` for a maximised goal).
        """
        values = np.asarray(values, dtype=float)
        if self.statistic == "mean":
            return values.mean(axis=-1)
        if self.statistic == "worst":
            return values.max(axis=-1) if self.sense == "minimize" else values.min(axis=-1)
        q = self.quantile if self.sense == "minimize" else 1.0 - self.quantile
        return np.quantile(values, q, axis=-1)


@dataclass(frozen=True, kw_only=True)
class DesignProblem:
    """A validated design problem (the TOML layout is in :mod:`.problem`).

    Attributes
    ----------
    name, title : str
        Short name (default store ``<name>.zarr``) and title.
    variables : tuple of Variable
        What is searched.
    uncertain : tuple of Uncertainty
        What is uncertain.
    samples : int
        Monte Carlo draws per design (1 without uncertainty).
    seed : int
        Seed of the draws (common random numbers: one set for every design).
    sampling : {"lhs", "random"}
        How the draws are made.
    objectives, constraints : tuple of Goal
        What is minimised (or maximised) and what is bounded.
    optimizer, sensitivity : dict
        Resolved ``[optimizer]`` and ``[sensitivity]`` settings.
    sweep : SweepDefinition
        The evaluation as a sweep: fixed parameters, excitation, simulation, analysis
        and the outputs the metrics need (:func:`qzs.workflows.sweeps.batch.run_batch`
        runs it).
    document : dict
        The parsed TOML file; its hash identifies the problem in a store.
    source : str
        Where it was read from.
    """

    name: str
    title: str
    variables: tuple
    uncertain: tuple
    samples: int
    seed: int
    sampling: str
    objectives: tuple
    constraints: tuple
    optimizer: dict
    sensitivity: dict
    sweep: SweepDefinition = field(repr=False)
    document: dict = field(repr=False)
    source: str = ""

    @property
    def goals(self) -> tuple:
        """Objectives, then constraints."""
        return (*self.objectives, *self.constraints)

    @property
    def columns(self) -> tuple[str, ...]:
        """Every metric column the goals need, in order, each once."""
        return tuple(dict.fromkeys(goal.column for goal in self.goals))

    @property
    def hash(self) -> str:
        """SHA-256 of the canonical problem document (what a store must match to resume)."""
        text = json.dumps({"format": _FORMAT, "document": self.document}, sort_keys=True,
                          default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def draws(self):
        """The Monte Carlo draws: uncertain name -> ndarray of shape (samples,).

        The same for every design and every call (common random numbers), from ``seed``.
        """
        if not self.uncertain:
            return {}
        u = unit_draws(len(self.uncertain), self.samples, self.sampling, self.seed)
        return {p.name: p.quantile(u[:, j]) for j, p in enumerate(self.uncertain)}


def _unit(units):
    """`` m`` for a unit after a number; nothing for a ratio (``1``): :func:`with_unit`."""
    return with_unit("", units)
