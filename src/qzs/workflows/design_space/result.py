"""The result of ``qzs optimize``: every evaluated design, the Pareto set, the chosen design.

:class:`OptimizationResult` holds the store's designs and derives the rest: which
designs meet every constraint, the Pareto set among those (non-dominated in the
objectives), and the chosen design, the member of the Pareto set nearest the ideal
point once each objective is scaled to the front's range (a compromise; with one
objective, the best feasible design). It only delegates: ``.to_xarray()`` and
``.save()`` to the file layer, ``.plot()`` to :mod:`qzs.viz.design_space`.
"""
from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from qzs._format import with_unit
from qzs._version import __version__
from qzs.iotools.result_files import DATASET_SUFFIXES
from qzs.errors import HelperProcessError, ParameterError
from qzs.workflows.design_space.metrics import goal_values
from qzs.workflows.design_space.problem import DesignProblem, _spread_text, _unit

if TYPE_CHECKING:
    from collections.abc import Iterator

    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from qzs.workflows.design_space.store import DesignStore

__all__ = ["OptimizationResult", "objective_matrix", "pareto_front", "write_files",
           "file_writer", "draw_figure", "OUTPUT_FILES"]


def pareto_front(F):
    """Indices of the non-dominated rows of ``F`` (minimised), each distinct row once.

    Parameters
    ----------
    F : array_like, shape (n, n_objectives)
        The objectives of ``n`` designs, each minimised.

    Returns
    -------
    ndarray of int
        Sorted indices.
    """
    F = np.asarray(F, dtype=float)
    if F.size == 0:
        return np.zeros(0, dtype=int)
    _, first = np.unique(F, axis=0, return_index=True)
    keep = []
    for i in np.sort(first):
        dominated = np.all(F <= F[i], axis=1) & np.any(F < F[i], axis=1)
        if not dominated.any():
            keep.append(i)
    return np.asarray(keep, dtype=int)


def objective_matrix(problem, goal_values):
    """What the optimiser minimises and what it keeps <= 0.

    Parameters
    ----------
    problem : DesignProblem
        The problem.
    goal_values : ndarray, shape (n_designs, n_goals)
        :meth:`~qzs.workflows.design_space.evaluation.Evaluation.goal_values` of
        ``problem.goals``.

    Returns
    -------
    F : ndarray, shape (n_designs, n_objectives)
        The objectives (``log10`` of those on a log scale), negated where maximised. An
        undefined objective (NaN, or a value <= 0 on a log scale) takes the worst defined
        value of its column.
    G : ndarray, shape (n_designs, n_constraints + 1)
        Each constraint as ``value - max`` or ``min - value`` [its unit]; the last column
        is 1 for a design with any undefined goal (a failed run, a metric its trusted bins
        do not define) and -1 otherwise, so such a design is infeasible.
    """
    goal_values = np.asarray(goal_values, dtype=float)
    n_obj = len(problem.objectives)
    sign = np.array([-1.0 if g.sense == "maximize" else 1.0 for g in problem.objectives])
    F = goal_values[:, :n_obj].copy()
    for j, goal in enumerate(problem.objectives):
        if goal.scale == "log":
            with np.errstate(divide="ignore", invalid="ignore"):
                F[:, j] = np.where(F[:, j] > 0, np.log10(np.abs(F[:, j])), np.nan)
    undefined = np.isnan(F).any(axis=1)
    F *= sign
    for j in range(n_obj):
        bad = ~np.isfinite(F[:, j])
        if bad.any():
            F[bad, j] = np.max(F[~bad, j]) if (~bad).any() else 0.0
    G = np.empty((len(goal_values), len(problem.constraints) + 1))
    for j, goal in enumerate(problem.constraints):
        value = goal_values[:, n_obj + j]
        G[:, j] = value - goal.bound if goal.sense == "minimize" else goal.bound - value
    G[:, :-1] = np.where(np.isnan(G[:, :-1]), 0.0, G[:, :-1])
    G[:, -1] = np.where(np.isnan(goal_values).any(axis=1) | undefined, 1.0, -1.0)
    return F, G


@dataclass(frozen=True, kw_only=True)
class OptimizationResult:
    """What ``qzs optimize`` found.

    Attributes
    ----------
    problem : DesignProblem
        The problem (its step fixed).
    designs : ndarray, shape (n, n_variables)
        Every evaluated design [the variables' units].
    generation : ndarray of int, shape (n,)
        The generation that evaluated it.
    values : dict of str to ndarray, shape (n, n_samples)
        Metric column -> value per design and draw [its unit].
    status : ndarray of int8, shape (n, n_samples)
        Sweep status per case (1 ok).
    goal_values : ndarray, shape (n, n_goals)
        Each objective and constraint per design, its draws combined [its unit].
    feasible : ndarray of bool, shape (n,)
        Every constraint met and every goal defined.
    pareto : ndarray of int
        Indices of the Pareto set among the feasible designs.
    messages : dict of int to str
        Why a design's run failed.
    store : Path
        The store.
    wall : float
        Wall time of this call [s].
    evaluated : int
        Designs evaluated by this call (the others came from the store).
    steps : int
        Integration steps of this call.
    """

    problem: DesignProblem = field(repr=False)
    designs: np.ndarray
    generation: np.ndarray
    values: dict = field(repr=False)
    status: np.ndarray = field(repr=False)
    goal_values: np.ndarray
    feasible: np.ndarray
    pareto: np.ndarray
    messages: dict = field(repr=False, default_factory=dict)
    store: Path | None = None
    wall: float = 0.0
    evaluated: int = 0
    steps: int = 0

    @classmethod
    def from_store(cls, store: DesignStore, problem: DesignProblem, *, wall: float = 0.0,
                   evaluated: int = 0, steps: int = 0) -> OptimizationResult:
        """The result of every design a :class:`~.store.DesignStore` holds.

        Parameters
        ----------
        store : DesignStore
            The store.
        problem : DesignProblem
            Its problem, with the step fixed.
        wall : float
            Wall time of the search [s].
        evaluated : int
            Designs the search evaluated (the others were read from the store).
        steps : int
            Integration steps of the search.

        Returns
        -------
        OptimizationResult
        """
        data = store.read()
        values = goal_values(problem.goals, data["values"], len(data["generation"]))
        F, G = objective_matrix(problem, values)
        feasible = np.all(G <= 0.0, axis=1)
        members = np.flatnonzero(feasible)
        pareto = members[pareto_front(F[members])] if members.size else members
        return cls(problem=problem, designs=data["design_variables"],
                   generation=data["generation"], values=data["values"],
                   status=data["status"], goal_values=values, feasible=feasible,
                   pareto=pareto, messages=data["messages"], store=store.path, wall=wall,
                   evaluated=evaluated, steps=steps)

    # ------------------------------------------------------------ derived
    @property
    def step(self) -> float | None:
        """The integration step [s] (None for a problem of linear metrics only)."""
        return self.problem.sweep.simulation["dt"]

    @property
    def chosen(self) -> int | None:
        """Index of the chosen design: the Pareto member nearest the ideal point.

        Each objective is scaled to the Pareto set's range (0 best, 1 worst); the member
        with the smallest Euclidean distance to the origin is chosen. None if no design
        is feasible.
        """
        if self.pareto.size == 0:
            return None
        n_obj = len(self.problem.objectives)
        sign = np.array([-1.0 if g.sense == "maximize" else 1.0 for g in self.problem.objectives])
        F = self.goal_values[self.pareto, :n_obj] * sign
        span = F.max(axis=0) - F.min(axis=0)
        scaled = (F - F.min(axis=0)) / np.where(span > 0, span, 1.0)
        return int(self.pareto[np.argmin(np.sqrt((scaled ** 2).sum(axis=1)))])

    def design(self, index: int | None = None) -> dict[str, float]:
        """A design's variables by name.

        Parameters
        ----------
        index : int, optional
            The design's index; default the chosen design.

        Returns
        -------
        dict of str to float
            Variable -> value [its unit].
        """
        index = self._index(index)
        return {v.name: float(self.designs[index, j])
                for j, v in enumerate(self.problem.variables)}

    def _index(self, index):
        if index is None:
            index = self.chosen
            if index is None:
                raise ParameterError("no design meets every constraint, so none is chosen; "
                                     "relax the constraints or widen the bounds, or give "
                                     "`index` to pick one of the designs anyway.")
        index = int(index)
        if not 0 <= index < len(self.designs):
            raise ParameterError(f"`index` must be a design index in 0..{len(self.designs) - 1},"
                                 f" got {index}.")
        return index

    # ------------------------------------------------------------ files
    def to_xarray(self, *, pareto_only: bool = False) -> xr.Dataset:
        """The designs as an ``xarray.Dataset`` on a ``design`` dimension, with units.

        Parameters
        ----------
        pareto_only : bool
            Only the Pareto set.

        Returns
        -------
        xarray.Dataset
            The variables [their units], each goal's value (draws combined), ``feasible``,
            ``pareto`` and ``generation``; the problem and the step as attributes.
        """
        import xarray as xr

        p = self.problem
        rows = self.pareto if pareto_only else np.arange(len(self.designs))
        chosen = self.chosen
        data = {}
        for j, v in enumerate(p.variables):
            data[v.name] = ("design", self.designs[rows, j],
                            {"units": v.units, "long_name": f"decision variable {v.name}",
                             "valid_min": v.low, "valid_max": v.high, "scale": v.scale})
        for j, goal in enumerate(p.goals):
            role = "objective" if goal.bound is None else "constraint"
            attrs = {"units": goal.units, "long_name": f"{role}: {goal.describe()}",
                     "metric": goal.metric, "statistic": goal.statistic}
            if goal.bound is not None:
                attrs["bound"] = goal.bound
            data[goal.label] = ("design", self.goal_values[rows, j], attrs)
        in_pareto = np.isin(rows, self.pareto)
        data["feasible"] = ("design", self.feasible[rows].astype(np.int8),
                            {"units": "1", "long_name": "every constraint met (1) or not (0)"})
        data["pareto"] = ("design", in_pareto.astype(np.int8),
                          {"units": "1", "long_name": "in the Pareto set (1) or not (0)"})
        data["chosen"] = ("design", (rows == chosen).astype(np.int8),
                          {"units": "1", "long_name": "the chosen design (1)"})
        data["generation"] = ("design", self.generation[rows].astype(np.int32),
                              {"units": "1", "long_name": "generation that evaluated it"})
        attrs = {"title": f"qzs optimize: {p.title}", "problem": p.name,
                 "objectives": "; ".join(g.describe() for g in p.objectives),
                 "constraints": "; ".join(g.describe() for g in p.constraints) or "none",
                 "uncertain": "; ".join(f"{u.name} {_spread_text(u)}"
                                        for u in p.uncertain) or "none",
                 "monte_carlo_samples": p.samples, "evaluated_designs": len(self.designs),
                 "algorithm": "NSGA-II (pymoo)", "population": p.optimizer["population"],
                 "generations": p.optimizer["generations"], "seed": p.optimizer["seed"],
                 "qzs_version": __version__, "Conventions": "CF-1.10"}
        if self.step is not None:
            attrs["dt"] = self.step
            attrs["step_note"] = p.sweep.simulation.get("step_note", "")
        return xr.Dataset(data, coords={"design": ("design", rows.astype(np.int64),
                                                   {"long_name": "index of the evaluated "
                                                                 "design in the store"})},
                          attrs=attrs)

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def save(self, path: str | Path, *, pareto_only: bool = True) -> Path:
        """Write the Pareto set (or every design) to NetCDF, CSV or MATLAB, atomically.

        Parameters
        ----------
        path : str or Path
            ``.nc``, ``.csv`` (with a units row) or ``.mat``.
        pareto_only : bool
            Only the Pareto set (default), or every evaluated design.

        Returns
        -------
        Path
        """
        from qzs.iotools.result_files import save_by_extension

        return save_by_extension(path, dataset=lambda: self.to_xarray(pareto_only=pareto_only))

    def config_text(self, index: int | None = None) -> str:
        """The chosen design (or design ``index``) as a run configuration's TOML text.

        Uncertain parameters take their medians; the excitation and step are the
        problem's. ``qzs simulate --config FILE`` runs it.

        Parameters
        ----------
        index : int, optional
            The design's index; default the chosen design.

        Returns
        -------
        str
        """
        from qzs.iotools.config import config_text
        from qzs.workflows.sweeps.cases import build_case

        index = self._index(index)
        p = self.problem
        case = {**self.design(index), **{u.name: u.nominal for u in p.uncertain}}
        isolator, controller, (_, duration), _ = build_case(p.sweep, case)
        excitation = {"kind": p.sweep.excitation_kind, **p.sweep.excitation}
        excitation.update({k.split(".", 1)[1]: v for k, v in case.items()
                           if k.startswith("excitation.")})
        excitation.setdefault("duration", duration)
        simulation = {"solver": p.sweep.simulation["solver"],
                      "sample_rate": p.sweep.analysis["sample_rate"]}
        if self.step is not None:
            simulation["dt"] = self.step
        values = ", ".join(f"{g.label} = {with_unit(f'{self.goal_values[index, j]:.4g}', g.units)}"
                           for j, g in enumerate(p.goals))
        return config_text(isolator, controller, excitation, simulation,
                           note=f"design {index} of `qzs optimize` {p.name!r}: {values}")

    def write_config(self, path: str | Path, index: int | None = None) -> Path:
        """Write :meth:`config_text` to a TOML file, atomically.

        Parameters
        ----------
        path : str or Path
            The file.
        index : int, optional
            The design's index; default the chosen design.

        Returns
        -------
        Path
        """
        from qzs.iotools.files import atomic_path

        text = self.config_text(index)
        with atomic_path(Path(path)) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
        return Path(path)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             ax: Axes | None = None) -> Figure:
        """The Pareto figure (:func:`qzs.viz.design_space.plot_pareto`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there too (format from the suffix).
        title : str, optional
            Figure title; default the problem's.
        ax : matplotlib.axes.Axes, optional
            Draw into this axes (two objectives only).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.design_space import plot_pareto

        return plot_pareto(self, ax=ax, path=path, title=title)

    # ------------------------------------------------------------ text
    def summary(self) -> str:
        """A few lines: evaluations, feasible designs, the Pareto set and the chosen design."""
        p = self.problem
        lines = [f"{p.name}: {len(self.designs)} designs evaluated in "
                 f"{int(self.generation.max()) + 1 if len(self.generation) else 0} generations "
                 f"({self.evaluated} now, {self.wall:.1f} s), x {p.samples} draws each",
                 f"  feasible {int(self.feasible.sum())}, Pareto set {self.pareto.size}"]
        if self.step is not None:
            lines.append(f"  step dt = {self.step:g} s")
        chosen = self.chosen
        if chosen is None:
            lines.append("  no design meets every constraint: nothing chosen")
        else:
            design = ", ".join(f"{v.name} = {with_unit(f'{self.designs[chosen, j]:.4g}', v.units)}"
                               for j, v in enumerate(p.variables))
            goals = ", ".join(
                f"{g.label} = {with_unit(_fmt(self.goal_values[chosen, j]), g.units)}"
                for j, g in enumerate(p.goals))
            lines += [f"  chosen design {chosen}: {design}", f"    {goals}"]
        return "\n".join(lines)

    def report(self) -> str:
        """A Markdown report: the problem, the search, the Pareto set, the chosen design."""
        p = self.problem
        out = [f"# Design search: {p.title}", "",
               f"Problem `{p.name}` ({p.source}); qzs {__version__}; NSGA-II (pymoo), "
               f"{p.optimizer['population']} designs per generation, "
               f"{p.optimizer['generations']} generations, seed {p.optimizer['seed']}.", "",
               "## Decision variables", "", "| variable | low | high | scale | unit |",
               "|---|---|---|---|---|"]
        out += [f"| {v.name} | {v.low:g} | {v.high:g} | {v.scale}"
                f"{' (integer)' if v.integer else ''} | {v.units or '-'} |" for v in p.variables]
        out += ["", "## Goals", ""]
        out += [f"- objective: {g.describe()}" for g in p.objectives]
        out += [f"- constraint: {g.describe()}" for g in p.constraints]
        if p.uncertain:
            out += ["", f"## Uncertainty ({p.samples} draws, {p.sampling}, seed {p.seed}, the "
                        "same draws for every design)", ""]
            out += [f"- {u.name}: {_spread_text(u)}" for u in p.uncertain]
        out += ["", "## Search", "",
                f"- {len(self.designs)} designs evaluated ({self.evaluated} by this call, the "
                f"rest read from the store), {int(self.feasible.sum())} feasible, "
                f"{self.pareto.size} in the Pareto set.",
                f"- Integration step: {self._step_text()}."]
        failed = int(np.count_nonzero(self.status != 1))
        if failed:
            out.append(f"- {failed} runs failed or were invalid; their designs count as "
                       "infeasible (first reasons: " + "; ".join(
                           f"design {k}: {v}" for k, v in list(self.messages.items())[:3]) + ").")
        out += ["", "## Pareto set", ""]
        if self.pareto.size:
            labels = [v.name for v in p.variables] + [g.label for g in p.goals]
            units = [v.units for v in p.variables] + [g.units for g in p.goals]
            out += ["| design | " + " | ".join(f"{l} [{u}]" for l, u in zip(labels, units))
                    + " |", "|---" * (len(labels) + 1) + "|"]
            order = self.pareto[np.argsort(self.goal_values[self.pareto, 0])]
            for i in order:
                row = [*self.designs[i], *self.goal_values[i]]
                mark = " (chosen)" if i == self.chosen else ""
                out.append(f"| {i}{mark} | " + " | ".join(_fmt(x) for x in row) + " |")
        else:
            out.append("No design meets every constraint. Relax the constraints or widen the "
                       "bounds; `feasible` in the designs file shows how close each came.")
        out += ["", "## Chosen design", ""]
        chosen = self.chosen
        if chosen is None:
            out.append("None (no feasible design).")
        else:
            units = {v.name: v.units for v in p.variables}
            out.append(f"Design {chosen}, the Pareto member nearest the ideal point, each "
                       "objective scaled to the front's range: " + ", ".join(
                           f"{k} = {_fmt(v)} {units[k]}" for k, v in self.design(chosen).items())
                       + "; " + ", ".join(f"{g.label} = {_fmt(self.goal_values[chosen, j])}"
                                          f"{_unit(g.units)}" for j, g in enumerate(p.goals))
                       + ". `chosen.toml` holds it as a run configuration.")
        return "\n".join(out) + "\n"

    def _step_text(self):
        if self.step is None:
            return "none (linear metrics only)"
        note = self.problem.sweep.simulation.get("step_note")
        return f"dt = {self.step:g} s" + (f" ({note})" if note else "")


def _fmt(value):
    value = float(value)
    if math.isnan(value):
        return "undefined"
    return f"{value:.4g}"


#: What :func:`write_files` writes into its folder, beside the store.
OUTPUT_FILES = ("pareto.nc", "pareto.csv", "pareto.mat", "designs.nc", "pareto.png",
                "chosen.toml", "report.md")


def write_files(result: OptimizationResult, folder: str | Path, *,
                progress: bool = False) -> list[Path]:
    """Write a search's outputs into ``folder``, each file atomically.

    ``pareto.nc``/``.csv``/``.mat`` (the Pareto set with units), ``designs.nc`` (every
    evaluated design, with ``feasible``, ``pareto`` and ``chosen`` flags), ``pareto.png``
    (:func:`qzs.viz.design_space.plot_pareto`), ``chosen.toml`` (the chosen design as a run
    configuration ``qzs simulate --config`` reads; left out if no design is feasible) and
    ``report.md``. Where processes fork (Linux, two cores) the figure is drawn in one beside
    this process (:mod:`qzs.workflows.forked`) while it writes the rest (matplotlib holds
    the GIL: only a process draws in parallel); elsewhere it is drawn here, first.

    Parameters
    ----------
    result : OptimizationResult
        The search.
    folder : str or Path
        Where to write; created if missing.
    progress : bool
        Show a progress bar, one step per file.

    Returns
    -------
    list of Path
        The files written.
    """
    from qzs.engine.progress import progress_bar
    from qzs.iotools.files import atomic_path
    from qzs.iotools.writer import write_dataset
    from qzs.workflows import forked

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    # forked, the process has this one's modules and data at once (nothing is pickled but
    # the path); a fresh interpreter would import qzs again, which takes longer than the figure
    with progress_bar(total=6 + (result.chosen is not None), unit="file", desc="writing",
                      disable=not progress, leave=False) as bar, \
            forked.start(partial(draw_figure, result), grace=None, name="qzs-pareto") as figure:
        figure.send(folder / "pareto.png")
        written = []
        pareto = result.to_xarray(pareto_only=True)  # one dataset for its three files
        for name in ("pareto.nc", "pareto.csv", "pareto.mat"):
            written.append(write_dataset(pareto, folder / name))
            bar.update(1)
        written.append(result.save(folder / "designs.nc", pareto_only=False))
        bar.update(1)
        if result.chosen is not None:
            written.append(result.write_config(folder / "chosen.toml"))
            bar.update(1)
        with atomic_path(folder / "report.md") as tmp:
            Path(tmp).write_text(result.report(), encoding="utf-8")
        written.append(folder / "report.md")
        bar.update(1)
        try:
            written.append(figure.result())  # last: drawn meanwhile
        except HelperProcessError:  # the process is gone (killed): drawn here instead
            written.append(draw_figure(result, folder / "pareto.png"))
        bar.update(1)
    return written


def draw_figure(result: OptimizationResult, path: str | Path) -> Path:
    """Draw the Pareto figure into a file and close it (the job :func:`write_files` forks).

    Parameters
    ----------
    result : OptimizationResult
        The search.
    path : str or Path
        The figure file (format from the suffix).

    Returns
    -------
    Path
        ``path``.
    """
    import matplotlib.pyplot as plt

    plt.close(result.plot(path=path))
    return Path(path)


@contextlib.contextmanager
def file_writer(folder: str | Path, *, progress: bool = False) -> Iterator[_Writer]:
    """A writer of a search's files, started before the search (a forked process).

    The process (a :class:`~qzs.workflows.forked.Forked` helper) imports what the files
    need (matplotlib; xarray, h5netcdf and what xarray imports when it writes, Dask's hooks
    where Dask is installed) while this one searches, in a thread of lower priority, so
    that the imports take the CPU time the search leaves idle rather than the search's
    own; then it waits for the result and writes the files (:func:`write_files`); about a
    second of imports off the end of ``qzs optimize``. Where no process forks (or one core
    is usable), or if the process is gone, the files are written here. The context ends
    the process, whatever happened (a writing under way gets 5 s to finish).

    Parameters
    ----------
    folder : str or Path
        Where to write.
    progress : bool
        Show a progress bar, one step per file.

    Yields
    ------
    _Writer
        Its ``write(result)`` writes the files of an :class:`OptimizationResult` and returns
        their paths, as :func:`write_files` does (raising what it raises).
    """
    from qzs.workflows import forked

    job = partial(_write_files_into, folder, progress)
    with forked.start(job, prepare=_warm, nice=5, grace=5.0, name="qzs-files") as helper:
        yield _Writer(helper, job)


def _write_files_into(folder, progress, result):
    """:func:`write_files` with the result last (the job :func:`file_writer` is sent)."""
    return write_files(result, folder, progress=progress)


class _Writer:
    """:func:`file_writer`'s writer: its helper writes, or this process if the helper died."""

    def __init__(self, helper, job):
        self.helper, self.job = helper, job

    def write(self, result):
        self.helper.send(result)
        try:
            return self.helper.result()
        except HelperProcessError:  # the process is gone (killed): written here instead
            return self.job(result)


def _warm():
    """Import what :func:`write_files` needs, as writing would, before it is needed."""
    import importlib
    import importlib.util

    import matplotlib.pyplot  # noqa: F401
    import xarray

    import qzs.iotools.writer  # noqa: F401
    import qzs.viz.design_space  # noqa: F401

    xarray.Variable("design", np.zeros(1))  # xarray's test for Dask arrays imports Dask
    for name in ("h5netcdf", "distributed", "scipy.io"):  # what writing a file imports
        if importlib.util.find_spec(name) is not None:
            importlib.import_module(name)
