"""The findings as tables: metric rows with the reason beside each undefined value, the run
settings, the claims' record, a document's head, a table cell with its footnote; shared by the
paper's report and the six-axis study."""
import math

import numpy as np

from qzs._format import footnoted, number
from qzs._version import __version__

__all__ = ["with_reasons", "metric_rows", "case_row", "study_record", "case_text",
           "claims_record", "run_settings", "document_head", "metric_cell", "significant"]


def with_reasons(metrics, reasons, prefix=""):
    """Metric values with ``<name>_reason`` beside each NaN one.

    Parameters
    ----------
    metrics : dict
        Name -> value.
    reasons : dict
        Name -> why the value is undefined.
    prefix : str
        Put before every name.

    Returns
    -------
    dict
    """
    row = {}
    for name, value in metrics.items():
        row[prefix + name] = value
        if name in reasons and not (isinstance(value, float) and math.isfinite(value)):
            row[f"{prefix}{name}_reason"] = reasons[name]
    return row


def metric_rows(study_results):
    """The rows of ``metrics.csv``: one per study and case, a reason beside each NaN metric.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.

    Returns
    -------
    list of dict
    """
    return [{"study": result.study.name, **case_row(case)} for result in study_results
            for case in result.cases]


def case_row(case):
    """One case's row of ``metrics.csv`` without its study: label, parameters, metrics
    with reasons, statistics, run settings, the linear model's frequency, time.

    Parameters
    ----------
    case : CaseResult
        The case.

    Returns
    -------
    dict
    """
    row = {"case": case.label}
    row.update({f"param.{k}": v for k, v in case.settings.items()})
    row.update(with_reasons(case.metrics, case.reasons))
    if "metrics" in case.extra:
        row.update(with_reasons(case.extra["metrics"], case.extra.get("reasons", {}),
                                prefix="processed."))
    row.update(case.stats)
    row.update({f"run.{k}": v for k, v in case.run.items()})
    if case.linear:
        row["linear_undamped_natural_frequency"] = case.linear["undamped_natural_frequency"]
    row["seconds"] = case.seconds
    return row


def study_record(result):
    """A study as ``metrics.json`` holds it: title, time [s], run settings, case rows.

    Parameters
    ----------
    result : StudyResult
        The study.

    Returns
    -------
    dict
    """
    return {"title": result.study.title, "seconds": result.seconds,
            "settings": run_settings(result), "cases": metric_rows([result])}


def case_text(case, unit):
    """A case's curve, metrics and statistics as text (a paper study's case, a question's).

    Parameters
    ----------
    case : CaseResult or CaseCurve
        The case (``label``, ``frequency`` [Hz] or None, ``magnitude``, ``trusted``,
        ``metrics``, ``reasons``, ``stats``).
    unit : callable
        Metric or statistic name -> its unit ("1" or "" shown as none).

    Returns
    -------
    str
    """
    from qzs._format import decibels

    def shown(name, value):
        return number(value, 4, "" if unit(name) in ("1", None) else unit(name))

    f = case.frequency
    if f is None:
        lines = [f"{case.label}: no transmissibility curve"]
    else:
        trusted = np.flatnonzero(case.trusted)
        lines = [f"{case.label}: transmissibility over {f.size} bins "
                 f"{f[0]:.4g}-{f[-1]:.4g} Hz, {trusted.size} trusted"]
        if trusted.size:
            k = trusted[np.argmax(case.magnitude[trusted])]
            lines.append(f"  trusted peak |T| {case.magnitude[k]:.4g} "
                         f"({decibels(case.magnitude[k]):.3g} dB) at {f[k]:.4g} Hz")
    for name, value in case.metrics.items():
        why = f" ({case.reasons[name]})" if name in case.reasons else ""
        lines.append(f"  {name} = {shown(name, value)}{why}")
    if case.stats:
        lines.append("  run: " + ", ".join(f"{name} {shown(name, value)}"
                                           for name, value in case.stats.items()))
    return "\n".join(lines)


def claims_record(verdicts):
    """The claims' verdicts as data (``metrics.json``, ``--json``).

    Parameters
    ----------
    verdicts : sequence of Verdict
        The claims decided.

    Returns
    -------
    list of dict
    """
    return [{"claim": v.claim, "study": v.study, "statement": v.statement, "verdict": v.label,
             "evidence": v.evidence} for v in verdicts]


def run_settings(result):
    """The run settings shared by a study's cases: name -> value (values joined if they differ).

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    dict
    """
    out = {}
    for case in result.cases:
        for key, value in case.run.items():
            out.setdefault(key, [])
            if value not in out[key]:
                out[key].append(value)
    return {k: v[0] if len(v) == 1 else v for k, v in out.items()}


def significant(value):
    """``value`` with three significant digits (:func:`qzs._format.number`), "—" if undefined.

    Parameters
    ----------
    value : float, int, bool or None
        The number.

    Returns
    -------
    str
    """
    return number(value, undefined="—")


def metric_cell(value, reason, notes, *, dash="—", text=significant):
    """A table cell of a metric: ``text(value)``, or the dash with a footnote saying why not.

    Parameters
    ----------
    value : float
        The metric; NaN (or not a number) where the trusted bins do not define it.
    reason : str
        Why it is undefined (the footnote).
    notes : dict
        The table's footnotes so far, reason -> number (:func:`qzs._format.footnoted`).
    dash : str
        The undefined cell's text ("—", or "&mdash;" in HTML).
    text : callable
        How a defined value is shown.

    Returns
    -------
    str
    """
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
            and math.isfinite(value):
        return text(value)
    return footnoted(dash, reason, notes)


def document_head(quick, wall_seconds):
    """The head of a findings document (``metrics.json``): version, runs, wall time.

    Parameters
    ----------
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float or None
        Wall time of the runs [s].

    Returns
    -------
    dict
        ``qzs_version``, ``quick``, ``wall_seconds``.
    """
    return {"qzs_version": __version__, "quick": quick, "wall_seconds": wall_seconds}
