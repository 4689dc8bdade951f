"""The one step search: the largest fixed step meeting a tolerance, for any model (docs/model.md §7).

Every accuracy-driven step of qzs comes from :func:`search_step`: one axis
(:func:`qzs.engine.accuracy.choose_step`), a lockstep batch of cases
(:func:`qzs.engine.accuracy_batch.choose_batch_step`) and the six-leg platform
(:func:`qzs.engine.hexapod.accuracy.choose_hexapod_step`) give it only what differs: how to
integrate a candidate step on the probe, and how to measure the difference of two runs. The
halving, its memo, its progress bar, the Richardson estimate, the one fallback policy and the
one record (:class:`StepChoice`) are written here once.

The method: candidates ``dt_j = dt_0 / 2**j`` from the largest admissible step ``dt_0``
(:func:`qzs.engine.step_choice.admissible_step`); each is integrated on the probe and compared with the next finer
one: the difference ``d_j`` is measured, and the observed ratio ``r_j = d_j/d_{j+1}``
(``2**order`` in the asymptotic range; stick-slip events lower it), capped at ``2**order``,
extrapolates the error of ``dt_j`` as ``d_j r_j/(r_j - 1)``. The chosen step is the coarsest
whose estimate times the safety factor meets the tolerance; for several cases, the finest of
the cases' chosen steps.

The fallback (one policy, docs/model.md §7): where no candidate meets the tolerance (the
differences do not shrink: stop contacts or a stick-slip pattern each refinement redraws),
or no bin of the band is trusted on the probe, a caller that must run anyway gets the
``finest`` step it allows (default the paper's ``defaults.SIMULATION["dt"]``), with ``met``
False, ``error`` NaN (no estimate holds for it) and a note that says why.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs import defaults
from qzs._format import STEP_RECORD_UNITS as RECORD_UNITS
from qzs._format import step_line as record_line
from qzs.errors import ParameterError, ToleranceNotMetError

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["StepChoice", "search_step", "halving_search", "fallback_step", "unmet_sentence",
           "record_line", "RECORD_UNITS", "MEASURE_UNITS", "SAFETY", "MAX_HALVINGS"]

#: The measures of a step's accuracy and their units: the transmissibility [dB], the state [m].
MEASURE_UNITS = {"transmissibility_db": "dB", "state_m": "m"}
#: Factor between the estimated error and the tolerance (docs/model.md §7).
SAFETY = 2.0
#: Halvings below the largest admissible step tried at most before giving up.
MAX_HALVINGS = 8


# ---------------------------------------------------------------- the one unmet meaning
# (changing the fallback step or the sentence every caller shows is an edit here)
def fallback_step(finest=None):
    """The step [s] a run that must go on gets where no step tried meets its tolerance.

    Parameters
    ----------
    finest : float, optional
        The finest step the caller allows [s]; default the paper's ``SIMULATION["dt"]``.

    Returns
    -------
    float
    """
    return float(finest if finest is not None else defaults.SIMULATION["dt"])


def unmet_sentence(reason, dt):
    """The one sentence every caller shows for an unmet tolerance (the record's last note).

    Parameters
    ----------
    reason : str
        Why no step met it (from :func:`~qzs.engine.step_search.search_step`).
    dt : float
        The fallback step the run goes on at [s] (:func:`fallback_step`).

    Returns
    -------
    str
    """
    return f"{reason}; running at dt = {dt:.3g} s, whose error is not estimated"


@dataclass(frozen=True, kw_only=True)
class StepChoice:
    """The step of a run and how it was chosen: the one step record of qzs.

    The console (:meth:`summary`), the JSON record (:meth:`to_dict`), the file attributes
    (:meth:`attributes`, the ``run.step_*`` entries of NetCDF and MAT files) and the reports
    all show this record. A literal step (:meth:`literal`) is a record too, with ``chosen``
    False.

    Attributes
    ----------
    dt : float
        The integration step [s].
    error : float
        Estimated error of a run at ``dt`` in the requested measure ([dB] or [m]); NaN for
        a literal step and for the fallback (no estimate holds for it).
    measure : str
        ``"transmissibility_db"`` (max ``|20 log10(T_dt/T_ref)|`` over the trusted bins of
        ``band``) or ``"state_m"`` (max ``|z_dt - z_ref|`` over the output samples); empty
        for a literal step.
    tolerance : float
        The tolerance asked for, in the unit of ``measure`` (NaN for a literal step).
    reference_dt : float
        The finest step integrated on the probe [s] (the estimate's reference; NaN if none
        was).
    stability_limit : float
        The solver's largest stable step for this model [s].
    sample_rate : float
        Output rate [Hz]; ``dt`` divides its period.
    solver : str
        The integrator.
    probe : object
        The excitation integrated to choose the step (None for a literal step).
    probe_duration : float
        Length of the probe [s].
    band : tuple of float
        Frequency band [Hz] of the transmissibility measure (None for the state).
    history : tuple
        ``(dt, difference to the next finer step, estimated error)`` per step tried,
        coarsest first, in the unit of ``measure``; for several cases the largest over the
        cases still searched.
    notes : tuple of str
        What the caller should know (the limit that bound the step, caveats, the fallback).
    met : bool
        Whether ``dt`` meets the tolerance; False for the fallback.
    cached : bool
        Whether the choice was read from the step cache (:mod:`qzs.engine.step_cache`).
    chosen : bool
        False for a literal step (:meth:`literal`).
    case_errors : tuple of float
        Several cases: each case's estimated error at the coarsest step that met the
        tolerance for it (inf: none did; NaN: no trusted bin on the probe).
    case_steps : tuple of float
        Several cases: that coarsest step [s] per case (NaN: none).
    unmet : tuple of int
        Several cases: those no candidate met, or without a trusted bin; ``dt`` comes from
        the others.
    """

    dt: float
    error: float
    measure: str
    tolerance: float
    reference_dt: float
    stability_limit: float
    sample_rate: float
    solver: str
    probe: object
    probe_duration: float
    band: tuple | None
    history: tuple
    notes: tuple
    met: bool = True
    cached: bool = False
    chosen: bool = True
    case_errors: tuple = ()
    case_steps: tuple = ()
    unmet: tuple = ()

    @classmethod
    def literal(cls, dt: float, *, sample_rate: float = defaults.SIMULATION["sample_rate"],
                solver: str = defaults.SIMULATION["solver"]) -> StepChoice:
        """The record of a step given literally (``dt`` [s]): nothing chosen, no estimate.

        Parameters
        ----------
        dt : float
            The step [s].
        sample_rate : float
            Output rate [Hz].
        solver : str
            The integrator.

        Returns
        -------
        StepChoice
        """
        return cls(dt=float(dt), error=math.nan, measure="", tolerance=math.nan,
                   reference_dt=math.nan, stability_limit=math.nan,
                   sample_rate=float(sample_rate), solver=str(solver), probe=None,
                   probe_duration=math.nan, band=None, history=(), notes=(), met=True,
                   chosen=False)

    @property
    def unit(self) -> str:
        """The unit of ``error`` and ``tolerance``: ``"dB"``, ``"m"`` or ``""`` (literal)."""
        return MEASURE_UNITS.get(self.measure, "")

    @property
    def unmet_note(self) -> str:
        """The one sentence every caller shows for an unmet tolerance; '' where it was met.

        Made by :func:`unmet_sentence` (the fallback's reason and step); a literal step has
        no tolerance to miss.
        """
        return "" if self.met or not self.chosen else (self.notes[-1] if self.notes else "")

    @property
    def steps_per_sample(self) -> int:
        """Integration steps per output sample [-]."""
        return int(round(1.0 / (self.sample_rate * self.dt)))

    def summary(self) -> str:
        """One paragraph for people: the step, its error and why (the console's form).

        Returns
        -------
        str
        """
        if not self.chosen:
            return f"dt = {self.dt:.6g} s ({self.solver}): given literally; its error is not estimated"
        unit = self.unit
        if not self.met:
            return "\n".join([f"dt = {self.dt:.6g} s ({self.solver}): no step tried meets the "
                              f"tolerance {self.tolerance:g} {unit}"]
                             + [f"  note: {note}" for note in self.notes])
        lines = [f"dt = {self.dt:.6g} s ({self.solver}, {self.steps_per_sample} step(s) per "
                 f"{self.sample_rate:g} Hz sample): estimated error {self.error:.3g} {unit} "
                 f"(tolerance {self.tolerance:g} {unit}, reference dt = {self.reference_dt:.3g} s, "
                 f"probe {self.probe_duration:g} s, stability limit {self.stability_limit:.3g} s)"
                 + (", from the step cache" if self.cached else "")]
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)

    def line(self) -> str:
        """The step in one line, as summaries and reports quote it (:func:`record_line`).

        Returns
        -------
        str
        """
        return record_line({"dt": self.dt, **self.attributes()})

    def to_dict(self) -> dict[str, Any]:
        """The record as JSON gives it (``qzs ... --json``'s ``step``).

        Returns
        -------
        dict
            ``dt`` [s], ``chosen``; for a chosen step also ``measure``, ``unit``,
            ``tolerance`` and ``error`` (in ``unit``), ``met``, ``reference_dt`` [s],
            ``cached``, ``band`` [Hz] and ``notes``.
        """
        if not self.chosen:
            return {"dt": self.dt, "chosen": False}
        record = {"dt": self.dt, "chosen": True, "measure": self.measure, "unit": self.unit,
                  "tolerance": self.tolerance, "error": self.error, "met": self.met,
                  "reference_dt": self.reference_dt, "cached": self.cached,
                  "band": None if self.band is None else list(self.band),
                  "notes": list(self.notes)}
        if self.case_steps:
            record.update(case_steps=list(self.case_steps), case_errors=list(self.case_errors),
                          unmet=list(self.unmet))
        return record

    #: The extensions :meth:`save` accepts: the candidates (.nc, .csv, .mat), the record (.json).
    save_suffixes = (".nc", ".csv", ".mat", ".json")

    def to_xarray(self) -> xr.Dataset:
        """The candidates tried, with the record as attributes
        (:func:`qzs.engine.step_views.step_dataset`).

        Returns
        -------
        xarray.Dataset
            ``step`` [s], ``difference`` and ``estimated_error`` (in the measure's unit) per
            candidate, coarsest first.
        """
        from qzs.engine.step_views import step_dataset

        return step_dataset(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> Figure:
        """Each candidate's estimated error against its step, the tolerance and the chosen
        step (:func:`qzs.viz.step.plot_step_choice`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (format from the suffix).
        title : str, optional
            Figure title; default the step and how it was chosen.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.step import plot_step_choice

        return plot_step_choice(self, path=path, title=title)

    def save(self, path: str | Path) -> Path:
        """Write the choice by the extension of ``path``, atomically: the candidates as .nc,
        .csv or .mat (:meth:`to_xarray`), the record as .json (:meth:`to_dict`).

        Parameters
        ----------
        path : str or Path
            The file; its extension is one of ``save_suffixes``.

        Returns
        -------
        Path
            ``path``.
        """
        from qzs.iotools.result_files import save_by_extension

        return save_by_extension(path, dataset=self.to_xarray, record=self.to_dict)

    def attributes(self) -> dict[str, Any]:
        """The record as a run's entries and file attributes give it (``run.step*``).

        Returns
        -------
        dict
            ``step``: ``"given"`` (a literal step: nothing more), ``"accuracy-driven"`` (the
            step met the tolerance) or ``"fallback"`` (no step tried met it); for the last
            two also ``step_tolerance_db`` and ``step_error_db`` [dB] (or ``_m`` [m] for the
            state measure; the error NaN for the fallback), ``step_band_low`` and
            ``step_band_high`` [Hz] (the transmissibility's band), ``step_reference_dt`` [s],
            ``step_probe_duration`` [s] and ``step_reason`` (why this step, in words).
        """
        if not self.chosen:
            return {"step": "given"}
        suffix = self.unit.lower()
        if self.met:
            reason = (f"estimated error {self.error:.2g} {self.unit} <= {self.tolerance:g} "
                      f"{self.unit} / safety on a {self.probe_duration:g} s probe")
        else:
            reason = self.unmet_note or "no step tried met the tolerance"
        band = {} if self.band is None else {"step_band_low": float(self.band[0]),
                                             "step_band_high": float(self.band[1])}
        return {"step": "accuracy-driven" if self.met else "fallback",
                f"step_tolerance_{suffix}": float(self.tolerance), **band,
                f"step_error_{suffix}": float(self.error),
                "step_reference_dt": float(self.reference_dt),
                "step_probe_duration": float(self.probe_duration), "step_reason": reason}


# ---------------------------------------------------------------- the search
def _estimate(d, d_next, order):
    """The Richardson estimate of the error of ``dt_j`` from ``d_j`` and ``d_{j+1}``:
    0 where ``d_j = 0``, inf where the differences do not shrink."""
    ratio = d / d_next if d_next > 0 else math.inf
    if d == 0.0:
        return 0.0
    if ratio <= 1.0:  # not converging yet: no estimate
        return math.inf
    r = min(ratio, 2.0 ** order)
    return d * r / (r - 1)


def _order_notes(d, d_next, order):
    """A note when the observed order of the chosen step lies below the scheme's."""
    if d > 0 and d_next > 0:
        observed = math.log2(d / d_next)
        if observed < order - 0.5:
            return [f"observed order {observed:.2f} below the scheme's {order} (stick-slip "
                    "events lower it): the estimate extrapolates with the observed ratio"]
    return []


def _loop(difference, n, order, tolerance, dt0, max_halvings, safety, give_up_early,
          before=None, after=None):
    """The halving loop over ``n`` cases; returns ``(met, best, history, untrusted, failed)``.

    ``difference(j, c)`` is case ``c``'s difference between ``dt_j`` and ``dt_{j+1}`` (NaN:
    no measure: the case leaves the search untrusted); ``before(j, cases)`` integrates what
    the comparisons at ``j`` need, ``after(j)`` frees what no later comparison needs.
    """
    searched, met, best, history, untrusted, hopeless = list(range(n)), {}, {}, [], [], []
    for j in range(max_halvings - 1):
        if not searched:
            break
        if before is not None:
            before(j, searched)
        pairs = {c: (difference(j, c), difference(j + 1, c)) for c in searched}
        untrusted += [c for c, (d, d_next) in pairs.items()
                      if not (np.isfinite(d) and np.isfinite(d_next))]
        estimates = {c: _estimate(d, d_next, order) for c, (d, d_next) in pairs.items()
                     if c not in untrusted}
        if estimates:
            history.append((dt0 / 2 ** j, max(pairs[c][0] for c in estimates),
                            max(estimates.values())))
        left = max_halvings - 2 - j  # candidates finer than dt_j still to compare
        for c, estimate in estimates.items():
            best[c] = min(best.get(c, math.inf), estimate)
            if safety * estimate <= tolerance:
                met[c] = (j, estimate)
            elif give_up_early and safety * estimate > tolerance * 2.0 ** (order * left):
                hopeless.append(c)  # even at the scheme's order no candidate left meets it
        searched = [c for c in searched
                    if c not in met and c not in untrusted and c not in hopeless]
        if after is not None:
            after(j)
    return met, best, history, sorted(set(untrusted)), sorted(searched + hopeless)


def halving_search(difference, order, tolerance, dt0, max_halvings, safety=SAFETY):
    """The search of :func:`search_step` on one case given its differences directly.

    Parameters
    ----------
    difference : callable
        ``difference(j)``: the measured difference between the runs at ``dt_j`` and
        ``dt_{j+1}`` (in the tolerance's unit; NaN: no measure, the search stops).
    order : int
        The scheme's order of accuracy [-]; the observed ratio ``d_j/d_{j+1}`` is capped at
        ``2**order``.
    tolerance : float
        What the error estimate times ``safety`` must not exceed (its unit).
    dt0 : float
        The coarsest candidate [s].
    max_halvings : int
        Candidates ``dt_0 .. dt_{max_halvings}`` [-].
    safety : float
        Factor [-] between the estimate and the tolerance.

    Returns
    -------
    chosen : int or None
        ``j`` of the chosen step, None if no candidate met the tolerance.
    history : list of tuple
        ``(dt_j [s], d_j, estimate_j)`` per candidate compared.
    """
    memo = {}

    def measured(j, c):
        if j not in memo:
            memo[j] = difference(j)
        return memo[j]

    met, _, history, _, _ = _loop(measured, 1, order, tolerance, dt0, max_halvings, safety,
                                  False)
    return (met[0][0] if met else None), history


def search_step(probe, *, tolerance, dt0, stability_limit, notes=(), finest=None,
                fallback=False, progress=False):
    """The coarsest candidate ``dt_0 / 2**j`` whose estimated error meets a tolerance.

    The one search of qzs (module docstring), on a built probe: the probe says what differs
    between the models (how to run a candidate and compare two, the cases, the measure).

    Parameters
    ----------
    probe : Probe
        The built probe (:class:`qzs.engine.step_choice.Probe`): ``run(dt, cases)`` (one
        probe run per listed case at step ``dt`` [s]), ``compare(coarse, fine)`` (their
        difference in the measure's unit; NaN: none), ``cases`` [-] and their ``labels``,
        the scheme's ``order`` [-], the ``measure``, ``sample_rate`` [Hz], ``solver``, the
        probe's ``excitation``, ``duration`` [s] and ``band`` [Hz] (for the record),
        ``max_halvings`` [-], ``safety`` [-] (>= 1, between the estimate and the tolerance),
        and ``search``: ``give_up_early`` (a case leaves, unmet, once its estimate exceeds
        the tolerance by more than the order could close), ``per_case`` (the record's
        per-case entries even for one case), ``unit_name`` (a probe run on the bar).
    tolerance : float
        The tolerance, in the measure's unit.
    dt0 : float
        The coarsest candidate [s] (:func:`~qzs.engine.step_choice.admissible_step`).
    stability_limit : float
        The largest stable step [s] (for the record).
    notes : sequence of str
        What bounds ``dt0`` (:func:`~qzs.engine.step_choice.bound_notes`).
    finest : float, optional
        The finest candidate [s]: halvings stop above it; also the fallback step.
    fallback : bool
        Where no candidate meets the tolerance, or no bin of the band is trusted: return
        the fallback (``finest``, default the paper's step) with ``met`` False instead of
        raising.
    progress : bool
        Show a progress bar over the probe runs.

    Returns
    -------
    StepChoice

    Raises
    ------
    ToleranceNotMetError
        No candidate meets the tolerance for any case (without ``fallback``).
    ParameterError
        No bin of the band is trusted on the probe for any case (without ``fallback``).
    """
    cases, max_halvings = probe.cases, probe.max_halvings
    if finest is not None:
        count = sum(1 for j in range(64) if dt0 / 2 ** j >= finest * (1 - 1e-9))
        max_halvings = min(max_halvings, count - 1)
    labels = ([f"case {c}" for c in range(cases)] if probe.labels is None
              else [str(x) for x in probe.labels])
    if len(labels) != cases:
        raise ParameterError(f"`labels` must name each of the {cases} cases, got {len(labels)}.")
    notes = list(notes)
    bar = _progress_bar(progress, max_halvings + 1, probe.search.get("unit_name", "run"))
    differences, integrated = {}, []
    before, after, difference = _probe_runs(probe.run, probe.compare, dt0, bar, differences,
                                            integrated)
    try:
        met, best, history, untrusted, failed = _loop(
            difference, cases, probe.order, tolerance, dt0, max_halvings, probe.safety,
            probe.search.get("give_up_early", False), before=before, after=after)
    finally:
        if bar is not None:
            bar.close()
    record = dict(measure=probe.measure, tolerance=float(tolerance),
                  stability_limit=float(stability_limit), sample_rate=float(probe.sample_rate),
                  solver=probe.solver, probe=probe.excitation,
                  probe_duration=float(probe.duration), band=probe.band, history=tuple(history))
    outcome = dict(met=met, best=best, untrusted=untrusted, failed=failed,
                   differences=differences, integrated=integrated)
    return _choice(probe, outcome, record, notes, labels, dt0, max_halvings, finest, fallback)


def _choice(probe, outcome, record, notes, labels, dt0, max_halvings, finest, fallback):
    """The record of a finished search: the chosen step and each case's, or the fallback."""
    cases, order, safety = probe.cases, probe.order, probe.safety
    several = cases > 1 or probe.search.get("per_case", False)
    met, best, untrusted, failed, differences, integrated = (
        outcome[key] for key in ("met", "best", "untrusted", "failed", "differences",
                                 "integrated"))
    if not met:
        reason = _unmet_reason(best, untrusted, cases, fallback, dt0, max_halvings, safety,
                               record)
        dt = fallback_step(finest)
        return StepChoice(dt=dt, error=math.nan,
                          reference_dt=min(integrated, default=math.nan),
                          notes=tuple(notes + [unmet_sentence(reason, dt)]), met=False,
                          case_errors=(math.nan,) * cases if several else (),
                          case_steps=(math.nan,) * cases if several else (),
                          unmet=tuple(range(cases)) if several else (), **record)
    j = max(level for level, _ in met.values())
    deciding = min(c for c, (level, _) in met.items() if level == j)
    notes += _order_notes(differences[j, deciding], differences[j + 1, deciding], order)
    notes += _case_notes(labels, failed, untrusted, best, dt0 / 2 ** (max_halvings - 2), record)
    entries = {}
    if several:
        entries = dict(
            case_errors=tuple(float(met[c][1]) if c in met else
                              (math.nan if c in untrusted else math.inf) for c in range(cases)),
            case_steps=tuple(dt0 / 2 ** met[c][0] if c in met else math.nan
                             for c in range(cases)),
            unmet=tuple(sorted(set(range(cases)) - set(met))))
    return StepChoice(dt=dt0 / 2 ** j, error=float(max(e for _, e in met.values())),
                      reference_dt=dt0 / 2 ** (j + 2), notes=tuple(notes), **entries, **record)


def _progress_bar(progress, total, unit_name):
    """The search's progress bar over probe runs (None without ``progress``)."""
    if not progress:
        return None
    from qzs.engine.progress import progress_bar

    # shown after half a second: a cached or quick choice draws nothing, and a first run's
    # compile notice (qzs.engine.compiling) comes before the bar
    return progress_bar(total=total, unit=unit_name, desc="choosing dt", leave=False, delay=0.5)


def _probe_runs(run, compare, dt0, bar, differences, integrated):
    """The loop's ``before``, ``after`` and ``difference`` over the probe's runs: each
    candidate integrated once per case, kept while a comparison needs it; ``differences``
    memoises the comparisons and ``integrated`` lists the steps run."""
    runs = {}

    def integrate(j, members):
        kept = runs.setdefault(j, {})
        missing = [c for c in members if c not in kept]
        if missing:
            kept.update(zip(missing, run(dt0 / 2 ** j, missing)))
            integrated.append(dt0 / 2 ** j)
            if bar is not None:
                bar.update(1)

    def before(j, members):
        for level in (j, j + 1, j + 2):
            integrate(level, members)

    def difference(j, c):
        if (j, c) not in differences:
            differences[j, c] = compare(runs[j][c], runs[j + 1][c])
        return differences[j, c]

    return before, lambda j: runs.pop(j, None), difference


def _unmet_reason(best, untrusted, cases, fallback, dt0, max_halvings, safety, record):
    """Why no candidate met the tolerance, for the fallback's sentence; without
    ``fallback`` the error that says so is raised instead."""
    tolerance, band, length = record["tolerance"], record["band"], record["probe_duration"]
    unit = MEASURE_UNITS[record["measure"]]
    # the finest candidate whose error was estimated (compared with two finer ones)
    finest_tried = dt0 / 2 ** max(max_halvings - 2, 0)
    if untrusted and len(untrusted) == cases:
        reason = (f"no bin of the band ({band[0]:g}, {band[1]:g}) Hz is trusted on the "
                  f"{length:g} s probe, so no error is measured")
        if not fallback:
            raise ParameterError(reason.replace(", so no error is measured", "")
                                 + "; lengthen `probe_duration` or narrow the band.")
        return reason
    smallest = min(best.values(), default=math.inf)
    if not fallback:
        raise ToleranceNotMetError(tolerance, unit, finest_tried, smallest, safety)
    return (f"no step down to {finest_tried:.3g} s met {tolerance:g} {unit} "
            f"(smallest estimate {smallest:.3g} {unit}: stick-slip or stop contacts "
            "redraw the response at every step)")


def _case_notes(labels, failed, untrusted, best, finest_tried, record):
    """The notes on the cases that did not set the step: none met it, or none was measured."""
    tolerance, band, length = record["tolerance"], record["band"], record["probe_duration"]
    unit = MEASURE_UNITS[record["measure"]]
    notes = []
    if failed:
        notes.append(
            f"{'; '.join(labels[c] for c in failed)}: no step down to "
            f"{finest_tried:.3g} s meets {tolerance:g} {unit} (best estimate "
            + ", ".join(f"{best.get(c, math.inf):.2g} {unit}" for c in failed)
            + "; an estimate that even the scheme's order could not bring within the tolerance "
            "by the finest candidate ends the search early): their response depends on the step "
            "(stop contacts or a stick-slip pattern each refinement redraws); the step is the "
            "other cases'")
    if untrusted:
        notes.append(f"{'; '.join(labels[c] for c in untrusted)}: no bin of "
                     f"the band ({band[0]:g}, {band[1]:g}) Hz is trusted on the "
                     f"{length:g} s probe, so no error is measured; the step is the "
                     "other cases'")
    return notes
