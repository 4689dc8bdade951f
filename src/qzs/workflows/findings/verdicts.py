"""The paper's claims decided from the numbers: one :class:`Verdict` per claim and study.

A claim (docs/model.md §13) is decided from the cases of the studies that name it
(:data:`qzs.workflows.paper.studies.CLAIMS`), from their trusted bins only; a trend claim (a
quantity rising with a swept parameter) over every case, ordered by that parameter, and
needs at least :data:`TREND_CASES` cases, else it is "not decidable".
"""
from dataclasses import dataclass

import numpy as np

from qzs._format import number
from qzs.analysis.damping import damping_change
from qzs.analysis.spectral import band_mask, rolloff_slope, transmissibility_at
from qzs.defaults import DAMPING_CLAIM
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, passive_natural_frequency
from qzs.model.registry import ALL_PARAMETERS, format_value, unit_of, update_parameters
from qzs.workflows.paper.studies import CLAIMS as STATEMENTS

__all__ = ["CLAIMS", "TREND_CASES", "TREND_CLAIMS", "Verdict", "case_value", "decide_claims",
           "damping_changes"]

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
def case_value(case, name):
    """A case's value of model parameter ``name``: its override, else the default.

    Parameters
    ----------
    case : CaseResult
        The case.
    name : str
        A model parameter's registry name.

    Returns
    -------
    float
    """
    return case.settings.get(name, ALL_PARAMETERS[name].default)


def _ordered(result, name, needed=TREND_CASES):
    """The study's cases ordered by parameter ``name``; a trend needs ``needed`` distinct values."""
    cases = sorted(result.cases, key=lambda c: case_value(c, name))
    values = sorted({case_value(c, name) for c in cases})
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
    strong = [c for c in cases if case_value(c, "stiction_force") >= 5.0]
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
    cases = [c for c in result.cases if case_value(c, "pi_kp") <= 50]
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
    without = [c for c in result.cases if case_value(c, "pi_kp") == 0 and case_value(c, "pi_ki") == 0]
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
    reference = next((c for c in result.cases if case_value(c, "damping_gain") == 0), None)
    damped = [c for c in result.cases if case_value(c, "damping_gain") > 0]
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
