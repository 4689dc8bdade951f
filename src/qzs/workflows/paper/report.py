"""``qzs paper``: run the paper's studies, draw its figures, decide its claims from the data.

Writes to an output folder: one figure per paper figure (PNG and SVG), the curves behind
each study's figures as data (``<study>_curves.nc`` and ``<study>_curves.csv``,
:mod:`qzs.workflows.paper.curves`), ``metrics.json`` and ``metrics.csv`` (per study and case,
with a units row), and ``report.html``,
which states how every curve was computed, puts each figure beside the paper's claims
the study names (docs/model.md §13, "What the paper reports") and says, from the numbers,
whether each claim is reproduced.

Every number comes from the trusted bins of a curve (docs/model.md §10); a metric those
bins do not define is NaN in the data (empty in the CSV, null in the JSON) with its
reason in the column ``<metric>_reason`` beside it, and a dash with a footnote in the
report. A trend claim (a quantity rising with a swept parameter) is decided over every
case, ordered by that parameter, and needs at least three cases; with fewer it is
"not decidable".
"""
import html
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from qzs._format import (footnoted, html_figure, html_head, html_table, json_ready, json_text,
                         number)
from qzs._validation import worker_count
from qzs._version import __version__
from qzs.analysis.damping import damping_change
from qzs.analysis.spectral import (METRIC_NAMES, band_mask, metric_unit, rolloff_slope,
                                   transmissibility_at)
from qzs.defaults import DAMPING_CLAIM
from qzs.iotools.files import atomic_path
from qzs.iotools.writer import write_table
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, passive_natural_frequency
from qzs.model.registry import ALL_PARAMETERS, format_value, unit_of, update_parameters
from qzs.model.springs import SpringLaw
from qzs.viz.figures import check_frequency_scale
from qzs.viz.transmissibility import overlap_notes, plot_transmissibility
from qzs.workflows.paper.curves import CURVE_SUFFIXES, curves_dataset, write_curves
from qzs.workflows.paper.report_spring import (draw_spring, spring_curves, spring_fit_html,
                                               spring_record, spring_statement)
from qzs.workflows.paper.studies import CLAIMS as STATEMENTS
from qzs.workflows.paper.report_step import step_record, step_statement
from qzs.workflows.paper.studies import column_unit  # noqa: F401 (the metrics table's units)
from qzs.workflows.paper.studies import (RUN_UNITS, STATS_UNITS, StudyResult, load_study,
                                         run_studies, shipped_studies)

__all__ = ["CLAIMS", "TREND_CLAIMS", "Verdict", "decide_claims", "damping_changes",
           "curves_of", "paper_summary", "write_paper_outputs", "run_paper"]

#: Free space [bytes] the output folder must have before the studies run: a generous bound
#: of the report, its figures (PNG) and metrics.
PAPER_BYTES = 20_000_000
#: Least number of cases, with different values of the swept parameter, a trend needs.
TREND_CASES = 3
#: Trend claims -> the parameter they are a trend in (cases are ordered by it).
TREND_CLAIMS = {"stiction_low_frequency": "stiction_force",
                "viscous_high_frequency": "viscous_damping",
                "pi_low_frequency": "pi_kp"}


@dataclass(frozen=True)
class Verdict:
    """Whether a claim is reproduced by one study's cases, with the numbers.

    Attributes
    ----------
    claim : str
        The claim's id, a key of :data:`CLAIMS`.
    statement : str
        What the paper states.
    reproduced : bool or None
        True if reproduced, False if not, None if partly (or not decidable).
    evidence : str
        The numbers the decision rests on, or why it cannot be decided.
    study : str
        Name of the study whose cases decided it.
    decidable : bool
        False when the cases cannot decide the claim (a trend from fewer than three
        cases, a quantity undefined on the trusted bins, a case missing).
    """

    claim: str
    statement: str
    reproduced: bool | None
    evidence: str
    study: str = ""
    decidable: bool = True

    @property
    def label(self) -> str:
        """``"reproduced"``, ``"not reproduced"``, ``"partly reproduced"`` or ``"not decidable"``."""
        if not self.decidable:
            return "not decidable"
        return {True: "reproduced", False: "not reproduced", None: "partly reproduced"}[
            self.reproduced]


class _Undecidable(Exception):
    """The cases cannot decide a claim; the message says why."""


# ---------------------------------------------------------------- reading cases
def _value(case, name):
    """A case's value of model parameter ``name``: its override, else the default."""
    return case.settings.get(name, ALL_PARAMETERS[name].default)


def _ordered(result, name, needed=TREND_CASES):
    """The study's cases ordered by parameter ``name``; a trend needs ``needed`` distinct values."""
    cases = sorted(result.cases, key=lambda c: _value(c, name))
    values = sorted({_value(c, name) for c in cases})
    if len(values) < needed:
        raise _Undecidable(f"a trend in {name} needs at least {needed} cases with different "
                           f"values; study {result.study.name!r} has {len(values)} "
                           f"({', '.join(format_value(v) for v in values)} "
                           f"{unit_of(name)}), so the claim is not decidable from it")
    return cases


def _band_mean(case, low, high):
    keep = band_mask(case.frequency, low, high, trusted=case.trusted)
    return float(np.mean(case.magnitude[keep])) if keep.any() else float("nan")


def _at(case, frequency):
    return float(transmissibility_at(case.frequency, case.magnitude, frequency,
                                     trusted=case.trusted)[0])


def _defined(values, what, cases):
    """Raise :class:`_Undecidable` naming the cases where ``values`` are NaN."""
    missing = [c.label for v, c in zip(values, cases) if not np.isfinite(v)]
    if missing:
        raise _Undecidable(f"{what} is undefined on the trusted bins of {', '.join(missing)}")


def _non_decreasing(values):
    return all(b >= a for a, b in zip(values, values[1:]))


def _increasing(values):
    return all(b > a for a, b in zip(values, values[1:]))


def _fmt(values):
    return ", ".join(number(v) for v in values)


def _labels(cases):
    return "; ".join(c.label for c in cases)


# ---------------------------------------------------------------- the claims
def _resonance_masked(result):
    cases = result.cases
    strong = [c for c in cases if _value(c, "stiction_force") >= 5.0]
    if not strong:
        raise _Undecidable("needs a case with stiction_force >= 5 N")
    fns = []
    for case in cases:
        isolator, controller = update_parameters(IsolatorParameters(spring=result.spring),
                                                 ControllerParameters(), case.settings)
        fns.append(passive_natural_frequency(isolator, controller.position_setpoint))
    locked = [c.stats["locked_fraction_below_half_hz"] for c in strong]
    _defined(locked, "the fraction of time locked below 0.5 Hz (the chirp never went there)",
             strong)
    peaks = [c.metrics.get("resonance_frequency", float("nan")) for c in strong]
    onsets = [c.metrics.get("isolation_onset", float("nan")) for c in strong]
    masked = all(f >= 0.9 for f in locked)
    low_peak = any(p < 1.0 for p in peaks if np.isfinite(p))
    ok = all(0.07 <= f <= 0.09 for f in fns) and masked and not low_peak
    starts = [c.metrics.get("trusted_from", float("nan")) for c in strong]
    return ok, (f"linearised passive natural frequency {_fmt(sorted(set(fns)))} Hz (paper: about "
                f"0.08 Hz); fraction of the time locked while the chirp is below 0.5 Hz "
                f"({_labels(strong)}): {_fmt(locked)} (masked if >= 0.9 for every case with "
                f"Fs >= 5 N: a locked payload moves with the base, T = 1, no resonance). "
                f"Resonance peak over the trusted bins: {_fmt(peaks)} Hz (none may lie below "
                f"1 Hz; a peak just below the isolation onset, {_fmt(onsets)} Hz, is the "
                f"break-away from stiction). The trusted bins start at {_fmt(starts)} Hz: "
                "below, the coherence is under the threshold (the chirp puts almost no base "
                "acceleration there while stick-slip adds broadband payload motion), so those "
                "bins are left out of every number")


def _pi_resonance_range(result):
    cases = [c for c in result.cases if _value(c, "pi_kp") <= 50]
    if len(cases) < 2:
        raise _Undecidable(f"needs at least two cases with Kp <= 50 N/m; study "
                           f"{result.study.name!r} has {len(cases)}")
    fns = [c.linear["undamped_natural_frequency"] for c in cases]
    ok = all(0.075 <= f <= 0.46 for f in fns)
    return ok, (f"undamped natural frequency sqrt((k + Kp)/m)/2pi for Kp <= 50 N/m "
                f"({_labels(cases)}): {_fmt(fns)} Hz; paper: 0.08-0.45 Hz")


def _stiction_low_frequency(result):
    cases = _ordered(result, "stiction_force")
    low = [_band_mean(c, 1.0, 3.0) for c in cases]
    _defined(low, "the mean T over 1-3 Hz", cases)
    onset = [c.metrics["isolation_onset"] for c in cases]
    _defined(onset, "the isolation onset", cases)
    ok = _non_decreasing(low) and _non_decreasing(onset)
    return ok, (f"mean T over the trusted bins of 1-3 Hz for {_labels(cases)}: {_fmt(low)} "
                f"(must not fall as Fs rises); isolation onset: {_fmt(onset)} Hz (must not fall)")


def _viscous_high_frequency(result):
    cases = _ordered(result, "viscous_damping")
    rows = {f: [_at(c, f) for c in cases] for f in (8.0, 12.0, 16.0)}
    for f, values in rows.items():
        _defined(values, f"T({f:g} Hz)", cases)
    ok = all(_increasing(v) for v in rows.values())
    text = "; ".join(f"T({f:g} Hz) = {_fmt(v)}" for f, v in rows.items())
    return ok, f"{text} for {_labels(cases)} (must rise with Cv)"


def _pi_low_frequency(result):
    cases = _ordered(result, "pi_kp")
    low = [_band_mean(c, 0.5, 4.0) for c in cases]
    _defined(low, "the mean T over 0.5-4 Hz", cases)
    high = [_at(c, 12.0) for c in cases]
    _defined(high, "T(12 Hz)", cases)
    spread = (max(high) - min(high)) / min(high)
    spoiled = low[-1] > 1.1 * low[0]
    barely = all(value <= 1.05 * low[0] for value in low[:-1])
    lowest = cases[0]
    held = lowest.stats["stop_contacts"] == 0
    ok = spoiled and barely and held and spread < 0.1
    return ok, (f"mean T over the trusted bins of 0.5-4 Hz for {_labels(cases)}: {_fmt(low)} "
                f"(the highest gains must exceed the lowest by > 10 %, every other set stay "
                f"within 5 % of the lowest); T(12 Hz): {_fmt(high)} (spread "
                f"{100 * spread:.1f} %, must stay < 10 %); lowest gains hold z: "
                f"{lowest.stats['stop_contacts']} stop contacts, z in "
                f"[{lowest.stats['z_min'] * 1e3:.1f}, {lowest.stats['z_max'] * 1e3:.1f}] mm")


def _no_pi_stops(result):
    without = [c for c in result.cases if _value(c, "pi_kp") == 0 and _value(c, "pi_ki") == 0]
    with_pi = [c for c in result.cases if c not in without]
    if not without or not with_pi:
        raise _Undecidable(f"needs a case without PI (Kp = Ki = 0) and one with it; study "
                           f"{result.study.name!r} has {len(without)} and {len(with_pi)}")
    ok = (all(c.stats["stop_contacts"] > 0 for c in without)
          and all(c.stats["stop_contacts"] == 0 for c in with_pi))

    def describe(cases):
        return "; ".join(f"{c.label}: {c.stats['stop_contacts']} (z in "
                         f"[{c.stats['z_min'] * 1e3:.1f}, {c.stats['z_max'] * 1e3:.1f}] mm)"
                         for c in cases)

    return ok, f"stop contacts without PI: {describe(without)}; with PI: {describe(with_pi)}"


#: The band of the damping claim [Hz] and the change below which damping "did not help
#: much" [dB] (:data:`qzs.defaults.DAMPING_CLAIM`).
DAMPING_BAND, DAMPING_SMALL_DB = DAMPING_CLAIM["band"], DAMPING_CLAIM["small_db"]
#: Where the design analysis explains the damping claim (``qzs design``).
DAMPING_EXPLAINED = ("docs/design.md section 7, \"Why active damping did not help much\" "
                     "(qzs design)")


def damping_changes(result, band=DAMPING_BAND):
    """What damping changes in each damped case of a study, against its case with Kd = 0.

    The two metrics of :func:`qzs.analysis.damping.damping_change` (largest per-bin
    reduction, band-RMS change), from each curve's trusted bins: what the damping claim is
    decided from, and what ``qzs design`` reports for every gain it tries.

    Parameters
    ----------
    result : StudyResult
        A study with a case at ``damping_gain`` 0 (the first is the reference).
    band : tuple of float
        The band [Hz, Hz]; default the claim's (:data:`qzs.defaults.DAMPING_CLAIM`).

    Returns
    -------
    reference : CaseResult or None
        The case with Kd = 0; None if there is none.
    changes : list of (CaseResult, DampingChange)
        Each case with Kd > 0, in the study's order.
    """
    reference = next((c for c in result.cases if _value(c, "damping_gain") == 0), None)
    damped = [c for c in result.cases if _value(c, "damping_gain") > 0]
    if reference is None:
        return None, [(case, None) for case in damped]
    return reference, [(case, damping_change(reference.frequency, reference.magnitude,
                                             case.magnitude, band=band,
                                             reference_trusted=_trusted(reference),
                                             damped_trusted=_trusted(case)))
                       for case in damped]


def _damping_small_effect(result):
    reference, pairs = damping_changes(result)
    damped = [case for case, _ in pairs]
    if reference is None or not damped:
        raise _Undecidable(f"needs a case with Kd = 0 and one with Kd > 0; study "
                           f"{result.study.name!r} has {int(reference is not None)} and "
                           f"{len(damped)}")
    changes = [change for _, change in pairs]
    largest = [c.largest_reduction_db for c in changes]
    rms = [c.band_rms_change_db for c in changes]
    low, high = DAMPING_BAND
    _defined(largest, f"the reduction over {low:g}-{high:g} Hz", damped)
    _defined(rms, f"the band RMS over {low:g}-{high:g} Hz", damped)
    linear = []
    if reference.linear.get("magnitude") is not None:
        linear = [damping_change(reference.frequency, reference.linear["magnitude"],
                                 case.linear["magnitude"], band=DAMPING_BAND).band_rms_change_db
                  for case in damped if case.linear.get("magnitude") is not None]
    per_bin = all(v < DAMPING_SMALL_DB for v in largest)
    band = all(-v < DAMPING_SMALL_DB for v in rms)
    ok = True if per_bin and band else (False if not (per_bin or band) else None)
    said = {True: "small", False: "not small"}
    text = (f"against {reference.label}, over the trusted bins of {low:g}-{high:g} Hz, for "
            f"{_labels(damped)}: largest per-bin reduction of T {_fmt(largest)} dB (at "
            f"{_fmt([c.largest_reduction_frequency for c in changes])} Hz); change of the band "
            f"RMS of T {_fmt(rms)} dB")
    if len(linear) == len(damped):
        text += f" (linearised model: {_fmt(linear)} dB)"
    text += (f". \"Did not help much\" if both stay under {DAMPING_SMALL_DB:g} dB: per bin "
             f"{said[per_bin]}, over the band {said[band]}. Why damping helps little, and "
             f"which factor limits it (the guide's viscous friction Cv, the high-pass, the "
             f"controller rate, a delay), is analysed in {DAMPING_EXPLAINED}, which reports "
             "the same two metrics (qzs.analysis.damping) for every gain it tries")
    return ok, text


def _trusted(case):
    return (np.ones(case.frequency.shape, bool) if case.trusted is None
            else np.asarray(case.trusted, dtype=bool))


def _experiment_shape(result):
    case = result.cases[0]
    processed = case.extra
    if "frequency" not in processed:
        raise _Undecidable("needs the experiment-style processing (a study of kind 'processing')")
    f, t = processed["frequency"], processed["magnitude"]
    trusted = processed.get("trusted")
    trusted = np.ones(f.shape, bool) if trusted is None else np.asarray(trusted, bool)
    trusted = trusted & (f >= 1.5 * processed["highpass"])
    if not trusted.any():
        raise _Undecidable("the experiment-style curve has no trusted bin")
    peak_f = float(f[trusted][np.argmax(t[trusted])])
    rolloff = band_mask(f, 4.0, np.inf, trusted=trusted)
    if np.count_nonzero(rolloff) < 3:
        raise _Undecidable("fewer than 3 trusted bins above 4 Hz for the roll-off")
    slope = rolloff_slope(f[rolloff], t[rolloff])
    t12 = float(transmissibility_at(f, t, 12.0, trusted=trusted)[0])
    if not np.isfinite(t12):
        raise _Undecidable("T(12 Hz) lies in untrusted bins")
    checks = [peak_f < 3.5, slope < 0, abs(t12 - 0.3) <= 0.1]
    ok = True if all(checks) else (False if not any(checks) else None)
    return ok, (f"processed like the experiment ({processed['n_averages']} averages, "
                f"{processed['highpass']:g} Hz high-pass): highest T over the trusted bins "
                f"(from {1.5 * processed['highpass']:g} Hz) at {peak_f:.2f} Hz (paper: below "
                f"3.5 Hz); slope above 4 Hz {slope:.1f} dB/decade (paper: rolls off); "
                f"T(12 Hz) = {t12:.3f} (paper: 0.3, accepted 0.2-0.4)")


_DECIDERS = {
    "resonance_masked": _resonance_masked,
    "pi_resonance_range": _pi_resonance_range,
    "stiction_low_frequency": _stiction_low_frequency,
    "viscous_high_frequency": _viscous_high_frequency,
    "pi_low_frequency": _pi_low_frequency,
    "no_pi_stops": _no_pi_stops,
    "damping_small_effect": _damping_small_effect,
    "experiment_shape": _experiment_shape,
}
if set(_DECIDERS) != set(STATEMENTS):  # pragma: no cover - a programming error
    raise RuntimeError(f"claims without a decision: {sorted(set(STATEMENTS) ^ set(_DECIDERS))}")

#: claim id -> (the paper's statement (docs/model.md §13), decision function of a StudyResult).
#: The ids a study may name are :data:`qzs.workflows.paper.studies.CLAIMS`.
CLAIMS = {claim: (statement, _DECIDERS[claim]) for claim, statement in STATEMENTS.items()}


def decide_claims(study_results):
    """Decide every claim from the cases of each study that names it.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run; each decides the claims its ``[study] claims`` names.

    Returns
    -------
    list of Verdict
        In the order of :data:`CLAIMS`, then of the studies; a claim no study names is
        left out.
    """
    verdicts = []
    for claim, (statement, decide) in CLAIMS.items():
        for result in study_results:
            if claim not in result.study.claims:
                continue
            try:
                ok, evidence = decide(result)
            except _Undecidable as reason:
                verdicts.append(Verdict(claim, statement, None, f"not decidable: {reason}",
                                        result.study.name, decidable=False))
            else:
                verdicts.append(Verdict(claim, statement, ok, evidence, result.study.name))
    return verdicts


# ---------------------------------------------------------------- figures
def _curves(result):
    """The curves a study's figures draw, each with its case's ``parameters`` and ``phase``."""
    cases = result.cases
    names = list(dict.fromkeys(k for c in cases for k in c.settings))

    def parameters(case):
        return {name: _value(case, name) for name in names}

    if result.study.kind == "processing":
        case = cases[0]
        return [dict(label=f"ideal: accelerations, {case.stats['n_averages']} averages",
                     frequency=case.frequency, magnitude=case.magnitude, trusted=case.trusted,
                     coherence=case.coherence, linear=case.linear.get("magnitude"),
                     phase=case.phase, parameters=parameters(case)),
                dict(label=f"experiment-style: velocities through the "
                           f"{case.extra['highpass']:g} Hz high-pass, "
                           f"{case.extra['n_averages']} averages",
                     frequency=case.extra["frequency"], magnitude=case.extra["magnitude"],
                     trusted=case.extra.get("trusted"), coherence=case.extra.get("coherence"),
                     phase=case.extra.get("phase"), parameters=parameters(case))]
    return [dict(label=c.label, frequency=c.frequency, magnitude=c.magnitude, trusted=c.trusted,
                 coherence=c.coherence, linear=c.linear.get("magnitude"), phase=c.phase,
                 parameters=parameters(c)) for c in cases]


def curves_of(result, *, quick=False):
    """A study's curves as a dataset (:func:`qzs.workflows.paper.curves.curves_dataset`).

    The curves its figures draw, on ``case`` and ``frequency``, with each case's
    parameters as coordinates and the run settings, study and definition as attributes;
    for the spring's characteristic, its points and fitted law
    (:func:`qzs.workflows.paper.curves.spring_dataset`).

    Parameters
    ----------
    result : StudyResult
        A study.
    quick : bool
        Whether the runs were the quick ones (an attribute).

    Returns
    -------
    xarray.Dataset
    """
    attrs = {"title": result.study.title, "study": result.study.name,
             "definition": Path(result.study.source).name if result.study.source else "",
             "quick": int(bool(quick)), "source": f"qzs {__version__} (qzs paper / qzs study)"}
    if result.study.kind == "spring_characteristic":
        return spring_curves(result, attrs)
    for key, value in _settings(result).items():
        attrs[key] = (", ".join(format_value(v) for v in value) if isinstance(value, list)
                      else value)
        if RUN_UNITS.get(key):
            attrs[f"{key}_units"] = RUN_UNITS[key]
    return curves_dataset(_curves(result), attrs)


def _figures(result, folder, frequency_scale=None):
    """Draw a study's views; returns ``[(figure name, png path, caption notes)]``.

    ``frequency_scale`` (``--frequency-axis``) overrides the views' own; else a view's
    ``frequency_scale`` or the default (log) is used."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    study = result.study
    if study.kind == "spring_characteristic":
        path = folder / "fig05_spring.png"
        plt.close(draw_spring(result, path))
        return [("fig05_spring", path, [])]
    drawn = []
    curves = _curves(result)
    coherence_min = result.cases[0].run.get("coherence_min") if result.cases[0].run else None
    for view in study.views:
        untrusted = None
        if study.kind == "processing":
            untrusted = result.cases[0].extra.get("untrusted_below",
                                                  1.5 * result.cases[0].extra["highpass"])
        span = tuple(view["frequency_range"])
        path = folder / f"{view['figure']}.png"
        options = {} if coherence_min is None else {"coherence_min": coherence_min}
        fig = plot_transmissibility(curves, frequency_range=span,
                                    frequency_scale=frequency_scale or view.get(
                                        "frequency_scale"),
                                    title=study.title, path=path, untrusted_below=untrusted,
                                    **options)
        plt.close(fig)
        drawn.append((view["figure"], path, overlap_notes(curves, frequency_range=span)))
    return drawn


def _curve_files(result, folder):
    """The data files of a study's curves."""
    return [Path(folder) / f"{result.study.name}_curves{suffix}" for suffix in CURVE_SUFFIXES]


def _figure_names(result):
    if result.study.kind == "spring_characteristic":
        return ["fig05_spring"]
    return [view["figure"] for view in result.study.views]


# ---------------------------------------------------------------- tables
def _with_reasons(metrics, reasons, prefix=""):
    """Metric values with ``<name>_reason`` beside each NaN one."""
    row = {}
    for name, value in metrics.items():
        row[prefix + name] = value
        if name in reasons and not (isinstance(value, float) and math.isfinite(value)):
            row[f"{prefix}{name}_reason"] = reasons[name]
    return row


def _metric_rows(study_results):
    rows = []
    for result in study_results:
        for case in result.cases:
            row = {"study": result.study.name, "case": case.label}
            row.update({f"param.{k}": v for k, v in case.settings.items()})
            row.update(_with_reasons(case.metrics, case.reasons))
            if "metrics" in case.extra:
                row.update(_with_reasons(case.extra["metrics"], case.extra.get("reasons", {}),
                                         prefix="processed."))
            row.update(case.stats)
            row.update({f"run.{k}": v for k, v in case.run.items()})
            if case.linear:
                row["linear_undamped_natural_frequency"] = case.linear[
                    "undamped_natural_frequency"]
            row["seconds"] = case.seconds
            rows.append(row)
    return rows


#: Columns of ``metrics.csv`` that are not one of a case's metrics, statistics or run
#: settings, with their units ("" for text).


def _claims_record(verdicts):
    return [{"claim": v.claim, "study": v.study, "statement": v.statement, "verdict": v.label,
             "evidence": v.evidence} for v in verdicts]


def _settings(result):
    """The run settings shared by a study's cases: name -> value (values joined if they differ)."""
    out = {}
    for case in result.cases:
        for key, value in case.run.items():
            out.setdefault(key, [])
            if value not in out[key]:
                out[key].append(value)
    return {k: v[0] if len(v) == 1 else v for k, v in out.items()}


def _draw(study_results, folder, workers, frequency_scale=None, bar=None, meanwhile=None):
    """Every study's figures (:func:`_figures`), in ``workers`` processes if more than one.

    Matplotlib holds the GIL, so figures draw in parallel only in processes; 0.3-0.7 s
    a figure, 5 s for the paper's on one core. ``bar`` (a progress bar, optional) advances
    by one as each study's figures are drawn. ``meanwhile`` (optional, no arguments) runs
    in this process while the others draw (after the figures with one worker): the
    paper's tables and curves (1.3 s) fill the time in which one drawing process has no
    study left. Returns ``{study name: drawn}``.
    """
    step = (lambda: None) if bar is None else (lambda: bar.update(1))
    if workers <= 1:
        drawn = {}
        for r in study_results:
            drawn[r.study.name] = _figures(r, folder, frequency_scale)
            step()
        if meanwhile is not None:
            meanwhile()
        return drawn
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # the studies with most views first, so that no process is left with two at the end
    order = sorted(study_results, key=lambda r: -len(r.study.views or [None]))
    with ProcessPoolExecutor(max_workers=workers) as pool:
        drawn = {r.study.name: pool.submit(_figures, r, folder, frequency_scale)
                 for r in order}
        if meanwhile is not None:
            meanwhile()
        for _ in as_completed(drawn.values()):
            step()
        return {r.study.name: drawn[r.study.name].result() for r in study_results}


def write_paper_outputs(study_results, folder, *, quick=False, wall_seconds=None,
                        workers=None, frequency_scale=None, progress=False):
    """Write figures, curves, ``metrics.json``, ``metrics.csv`` and ``report.html`` into ``folder``.

    The curves of each transmissibility study go to ``<study>_curves.nc`` and
    ``<study>_curves.csv`` (:func:`curves_of`); ``metrics.csv`` has a units row under its
    column names (:func:`column_unit`).

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    folder : str or Path
        Output folder, created if missing.
    quick : bool
        Whether the runs were the quick ones (recorded in the metrics and the report).
    wall_seconds : float, optional
        Wall time of the runs [s], recorded in the metrics and the report.
    workers : int, optional
        Processes drawing the figures; default all cores. 1 draws them in-process.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of every figure; default each view's own, else
        ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    progress : bool
        Show a progress bar: one step per study's figures, per study's curves, and per
        file of metrics and report.

    Returns
    -------
    list of Verdict
        As :func:`decide_claims` gives them.

    Raises
    ------
    ParameterError
        ``workers`` not a positive integer.
    """
    workers = worker_count(workers, len(study_results))  # checked before anything is written
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    from qzs.engine.progress import progress_bar

    with progress_bar(total=2 * len(study_results) + 3, unit="part",
                      desc="figures and report", disable=not progress, leave=False) as bar:
        return _write_outputs(study_results, folder, quick, wall_seconds, workers,
                              frequency_scale, bar)


def _write_outputs(study_results, folder, quick, wall_seconds, workers, frequency_scale, bar):
    """:func:`write_paper_outputs` once its arguments are checked, advancing ``bar``."""
    verdicts = decide_claims(study_results)
    figures = _draw(study_results, folder, workers, frequency_scale, bar,
                    meanwhile=lambda: _write_tables(study_results, folder, quick,
                                                    wall_seconds, verdicts, bar))
    with atomic_path(folder / "report.html") as tmp:
        tmp.write_text(_html(study_results, figures, verdicts, quick, wall_seconds),
                       encoding="utf-8")
    bar.update(1)
    return verdicts


def _write_tables(study_results, folder, quick, wall_seconds, verdicts, bar):
    """``metrics.json``, ``metrics.csv`` and each study's curves, advancing ``bar``."""
    rows = _metric_rows(study_results)
    document = {"qzs_version": __version__, "quick": quick, "wall_seconds": wall_seconds,
                "studies": {r.study.name: {"title": r.study.title, "seconds": r.seconds,
                                           "settings": _settings(r),
                                           "cases": [row for row in rows
                                                     if row["study"] == r.study.name]}
                            for r in study_results},
                "claims": _claims_record(verdicts), "step": step_record(study_results),
                "spring": spring_record(study_results)}
    with atomic_path(folder / "metrics.json") as tmp:
        tmp.write_text(json_text(document), encoding="utf-8")
    bar.update(1)
    write_table(rows, folder / "metrics.csv", units=column_unit)
    bar.update(1)
    for result in study_results:
        write_curves(curves_of(result, quick=quick), folder, result.study.name)
        bar.update(1)


def paper_summary(study_results: Sequence[StudyResult], verdicts: Sequence[Verdict],
                  folder: str | Path, *, quick: bool = False,
                  wall_seconds: float | None = None) -> dict[str, Any]:
    """What ``qzs paper --json`` prints: claims, per-case metrics, output paths.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    verdicts : sequence of Verdict
        Their claims, decided (:func:`decide_claims`).
    folder : str or Path
        The output folder the report was written to.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float, optional
        Wall time of the runs [s].

    Returns
    -------
    dict
        JSON-ready (NaN as None, the reason beside it as ``<metric>_reason``):
        ``qzs_version``, ``quick``, ``wall_seconds``, ``claims`` (claim, study,
        statement, verdict, evidence), ``studies`` (name -> title, seconds, settings,
        cases with their metrics), ``step`` (:func:`~qzs.workflows.paper.report_step.step_record`), ``outputs`` (report,
        metrics_json, metrics_csv, figures: PNG and SVG paths, curves: the
        ``<study>_curves.nc`` and ``.csv`` files).
    """
    folder = Path(folder)
    studies = {}
    for result in study_results:
        cases = []
        for case in result.cases:
            entry = {"case": case.label, "parameters": dict(case.settings)}
            entry.update(_with_reasons(case.metrics, case.reasons))
            if "metrics" in case.extra:
                entry.update(_with_reasons(case.extra["metrics"], case.extra.get("reasons", {}),
                                           prefix="processed."))
            for key in ("stop_contacts", "locked_fraction", "locked_fraction_below_half_hz"):
                if key in case.stats:
                    entry[key] = case.stats[key]
            cases.append(entry)
        studies[result.study.name] = {"title": result.study.title, "seconds": result.seconds,
                                      "settings": _settings(result), "cases": cases}
    figures = [str(folder / f"{name}{suffix}") for result in study_results
               for name in _figure_names(result) for suffix in (".png", ".svg")]
    return json_ready({
        "qzs_version": __version__, "quick": quick, "wall_seconds": wall_seconds,
        "claims": _claims_record(verdicts), "studies": studies,
        "step": step_record(study_results), "spring": spring_record(study_results),
        "outputs": {"report": str(folder / "report.html"),
                    "metrics_json": str(folder / "metrics.json"),
                    "metrics_csv": str(folder / "metrics.csv"), "figures": figures,
                    "curves": [str(path) for result in study_results
                               for path in _curve_files(result, folder)]}})


# ---------------------------------------------------------------- report.html
_STYLE = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;
color:#222}section{border-top:1px solid #ccc;padding-top:1em;margin-top:2em}
figure{margin:1em 0}figure img{width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#444}
.claim{padding:.6em 1em;margin:.6em 0;border-left:6px solid #999;background:#f7f7f7}
.reproduced{border-color:#2a8a2a}.not{border-color:#c0392b}.partly{border-color:#d4a017}
.undecidable{border-color:#777}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0}td,th{border:1px solid #ddd;
padding:.2em .5em;text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}
.notes{font-size:.85em;color:#444}"""

_CSS = {"reproduced": "reproduced", "not reproduced": "not", "partly reproduced": "partly",
        "not decidable": "undecidable"}

#: The run settings a study's section lists: key of :attr:`CaseResult.run
#: <qzs.workflows.paper.studies.CaseResult>` -> name (units from
#: :data:`qzs.workflows.paper.studies.RUN_UNITS`).
#: The chirp length the paper states [s] (a report that differs says why).
PAPER_CHIRP_DURATION = 2000.0
_RUN_ROWS = (("solver", "solver"), ("dt", "time step"), ("sample_rate", "sample rate"),
             ("chirp_amplitude", "chirp amplitude"), ("chirp_f0", "chirp from"),
             ("chirp_f1", "chirp to"), ("chirp_duration", "chirp duration"),
             ("window", "window"), ("fft_length", "FFT length [samples]"),
             ("n_averages", "averages"), ("overlap", "overlap"),
             ("coherence_min", "trusted: coherence at least"),
             ("base_share_min", "trusted: base power share at least"))


def _html(study_results, figures, verdicts, quick, wall_seconds):
    e = html.escape
    parts = [html_head("qzs paper report", _STYLE),
             "<h1>Semi-active QZS isolator: the paper's studies, reproduced</h1>",
             f"<p>qzs {e(__version__)}; {'quick' if quick else 'full-length'} runs"
             + (f"; wall time {wall_seconds:.1f} s" if wall_seconds else "") +
             f". <b>Spring</b>: {e(spring_statement(study_results))}"
             f". <b>Integration step</b>: {e(step_statement(study_results))}</p><p>"
             "Transmissibility is the amplitude ratio sqrt(S_payload/S_base) of the "
             "accelerations (Welch averages of Hann-windowed segments), shown in dB. Dashed: the "
             "linearised model (frictionless guide, viscous damping only). Each study's run "
             "settings are listed in its section.</p>",
             "<p><b>Trusted bins</b> (docs/model.md §10): a frequency bin is used only where "
             "the magnitude-squared coherence of base and payload reaches the threshold given "
             "in each study's settings (there the PSD ratio exceeds the coherent response by at "
             "most 1/sqrt(threshold)), where the base put a non-negligible share of its own "
             "power, above 0 Hz, and above 1.5 times a measurement high-pass corner. Untrusted "
             "bins are drawn faint and never enter a metric or a claim: a metric they would "
             "decide is shown as a dash, with the reason in the notes below the table.</p>",
             "<h2>Claims</h2><ul>"]
    for v in verdicts:
        parts.append(f"<li><b>{e(v.label)}</b>: {e(v.statement)} "
                     f"(<a href='#{e(v.study)}'>{e(v.study)}</a>)</li>")
    parts.append("</ul>")
    for result in study_results:
        study = result.study
        parts.append(f"<section id='{e(study.name)}'><h2>{e(study.title)}</h2>"
                     f"<p>{len(result.cases)} case(s), {result.seconds:.1f} s of simulation "
                     f"and analysis; definition <code>{e(Path(study.source).name)}</code>.</p>")
        if study.kind != "spring_characteristic":
            parts.append(_settings_table(result))
        for name, path, notes in figures.get(study.name, []):
            caption = [f"<b>{e(name)}</b>."]
            if study.kind != "spring_characteristic":
                caption.append("Solid: trusted bins; faint: untrusted bins. Lower panel: "
                               "coherence of base and payload.")
            caption.extend(e(note) for note in notes)
            parts.append(html_figure(path, name, " ".join(caption)))
        files = [p.name for p in _curve_files(result, ".")]
        if files:
            links = " and ".join(f"<a href='{e(f)}'>{e(f)}</a>" for f in files)
            what = ("the measured points and the fitted law at them"
                    if study.kind == "spring_characteristic" else
                    "per case and frequency the transmissibility, its phase, the coherence, "
                    "the trusted flag and the linearised model, the case's parameters beside it")
            parts.append(f"<p class='notes'>The curves of these figures as data: {links} "
                         f"(NetCDF CF-1.10; CSV with a units row under the column names): "
                         f"{e(what)}.</p>")
        for verdict in verdicts:
            if verdict.study != study.name:
                continue
            parts.append(f"<div class='claim {_CSS[verdict.label]}'><b>Paper:</b> "
                         f"{e(verdict.statement)}<br><b>Here: {e(verdict.label)}</b>: "
                         f"{e(verdict.evidence)}</div>")
        parts.append(_case_table(result))
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _duration_note(settings):
    """Why the chirp is not the paper's 2000 s: it lasts what its Welch averages need."""
    keys = ("chirp_duration", "n_averages", "fft_length", "sample_rate", "overlap")
    if any(isinstance(settings.get(k), (list, type(None))) for k in keys) \
            or settings["chirp_duration"] == PAPER_CHIRP_DURATION:
        return ""
    return (f"<p class='notes'>Chirp duration {settings['chirp_duration']:.6g} s, not the "
            f"paper's {PAPER_CHIRP_DURATION:g} s: the record lasts what "
            f"{settings['n_averages']} complete Welch averages of {settings['fft_length']} "
            f"samples at {settings['sample_rate']:g} Hz with overlap {settings['overlap']:g} "
            "need (qzs.analysis.spectral.required_duration).</p>")


def _settings_table(result):
    settings = _settings(result)
    head, cells = [], []
    for key, name in _RUN_ROWS:
        if key not in settings:
            continue
        unit = RUN_UNITS[key] if RUN_UNITS[key] != "1" else ""
        value = settings[key]
        text = ", ".join(format_value(v) for v in value) if isinstance(value, list) \
            else format_value(value)
        head.append(f"{name} [{unit}]" if unit else name)
        cells.append(text)
    names = list(dict.fromkeys(k for c in result.cases for k in c.settings))
    parameters = html_table(["case", *(f"{n} [{unit_of(n)}]" for n in names)],
                            ([case.label, *(format_value(_value(case, n)) for n in names)]
                             for case in result.cases))
    return "\n".join(["<p>Run settings (every case):</p>",
                      html_table(head, [cells], separator="") + _duration_note(settings),
                      parameters + "<p class='notes'>Every other parameter at its default "
                      "(Table 1, docs/model.md §11; <code>qzs params</code>).</p>"])


_TABLE = (("trusted_from", "trusted from [Hz]"), ("resonance_frequency", "peak of T at [Hz]"),
          ("resonance_peak", "T at peak [-]"), ("isolation_onset", "isolation onset [Hz]"),
          ("minus_3db_frequency", "-3 dB [Hz]"), ("rolloff_db_per_decade", "roll-off [dB/decade]"),
          ("transmissibility_at_1_hz", "T(1 Hz) [-]"), ("transmissibility_at_4_hz", "T(4 Hz) [-]"),
          ("transmissibility_at_12_hz", "T(12 Hz) [-]"))


def _case_table(result):
    e = html.escape
    if result.study.kind == "spring_characteristic":
        return spring_fit_html(result)
    notes = {}

    def cell(metrics, reasons, name):
        value = metrics.get(name, float("nan"))
        if isinstance(value, (float, np.floating)) and np.isfinite(value):
            return f"{value:.3g}"
        return footnoted("&mdash;", reasons.get(name, "not computed"), notes)

    head = ["case", *(title for _, title in _TABLE), "stop contacts", "locked [%]",
            "f_n with PI [Hz]"]
    entries = [(case.label, case.metrics, case.reasons, case) for case in result.cases]
    if result.study.kind == "processing":
        case = result.cases[0]
        entries.append((f"{case.label}, experiment-style", case.extra["metrics"],
                        case.extra.get("reasons", {}), case))
    table = []
    for label, metrics, reasons, case in entries:
        s = case.stats
        table.append([e(label), *(cell(metrics, reasons, name) for name, _ in _TABLE),
                      e(f"{s['stop_contacts']}"), e(f"{100 * s['locked_fraction']:.1f}"),
                      e(f"{case.linear['undamped_natural_frequency']:.3g}")])
    isolator, controller = update_parameters(IsolatorParameters(spring=result.spring),
                                             ControllerParameters(), result.cases[0].settings)
    rows = [html_table(head, table, cells_html=True)]
    if notes:
        rows.append("<ol class='notes'>" + "".join(f"<li>{e(reason)}</li>" for reason in notes)
                    + "</ol>")
    rows.append("<p class='notes'>f_n with PI: sqrt((k + Kp)/m)/2pi, the linearised loop's undamped "
            "natural frequency, the PI's proportional gain Kp acting as a spring; the paper's "
            "\"about 0.08 Hz\" is the passive isolator's (Kp = 0): "
            f"{passive_natural_frequency(isolator, controller.position_setpoint):.3g} Hz for "
            f"{e(result.cases[0].label)}.</p>")
    return "\n".join(rows)


def run_paper(definitions: Sequence[str | Path] | None = None,
              folder: str | Path = "results/paper", *, quick: bool = False,
              workers: int | None = None, progress: bool = True,
              argument: str = "folder", dt: float | None = None,
              tolerance: float | None = None,
              frequency_scale: str | None = None, spring: SpringLaw | None = None,
              tolerance_db: float | None = None
              ) -> tuple[list[StudyResult], list[Verdict], float]:
    """Run studies and write their report (``qzs paper``, ``qzs study``).

    Parameters
    ----------
    definitions : sequence of str or Path, optional
        Study files or shipped study names; default every shipped study (the paper).
    folder : str or Path
        Output folder of the figures, metrics and ``report.html``.
    quick : bool
        Shorter runs (fewer, shorter Welch segments).
    workers : int, optional
        Cores: threads of the lockstep kernel, worker processes of the other cases and of
        the figures; default all cores.
    progress : bool
        Show a progress bar over cases.
    argument : str
        How the caller names ``folder`` in messages (``"--out"`` on the command line).
    dt : float, optional
        Integration step [s] of every case, as given (the paper's: 1e-4); default chosen
        for ``tolerance`` (a study file's ``[simulation] dt`` is kept).
    tolerance : float, optional
        Tolerance on the transmissibility [dB] the chosen step meets; default
        :data:`qzs.defaults.ACCURACY`. Not with ``dt``.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of every figure (``--frequency-axis``); default each view's own,
        else ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    spring : SpringLaw, optional
        The spring law of every case (docs/model.md §3.1; ``--spring``); default the
        MagSpring's tanh, the paper's.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    results : list of StudyResult
    verdicts : list of Verdict
    wall_seconds : float
        Wall time of the whole [s]: the runs, the figures, the curves and the report (the
        metrics and the report record the runs' alone).

    Raises
    ------
    OutputPathError
        ``folder`` is a file, or cannot be created or written (checked before any study
        runs: on a cold cache they take minutes).
    ParameterError
        A study file is invalid, or both ``dt`` and ``tolerance`` are given.
    """
    import time

    from qzs._validation import renamed_keyword
    from qzs.iotools.paths import check_output_path

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)

    check_output_path(folder, argument=argument, suffixes=None, directory=True,
                      estimated_bytes=PAPER_BYTES)
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale, argument="frequency_scale")
    paths = shipped_studies() if definitions is None else definitions
    studies = [load_study(p) for p in paths]
    start = time.perf_counter()
    results = run_studies(studies, quick=quick, workers=workers, progress=progress, dt=dt,
                          tolerance=tolerance, spring=spring)
    wall = time.perf_counter() - start
    verdicts = write_paper_outputs(results, folder, quick=quick, wall_seconds=wall,
                                   workers=workers, frequency_scale=frequency_scale,
                                   progress=progress)
    return results, verdicts, time.perf_counter() - start
