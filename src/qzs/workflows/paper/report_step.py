"""The integration step of the paper's studies, as the report states it (docs/workflows/paper.md).

How each study's step was set (chosen for a tolerance, given, from the study file, or the
paper's own as a fallback), the cases whose response depends on the step, and the agreement
with the paper's own step that :data:`AGREEMENT_TEST` checks: as a record
(:func:`step_record`, for ``metrics.json`` and ``--json``) and as one paragraph
(:func:`step_statement`, for ``report.html`` and the console).
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from qzs.defaults import ACCURACY, SIMULATION

if TYPE_CHECKING:
    from qzs.workflows.paper.studies import StudyResult

__all__ = ["AGREEMENT_TEST", "step_record", "step_statement"]

#: The test that runs a shortened paper at the chosen step and at the paper's own, and
#: checks every verdict and tabulated number against the criteria of docs/workflows/paper.md.
AGREEMENT_TEST = "tests/workflows/paper/test_report_step.py"


def step_record(study_results: Sequence[StudyResult]) -> dict[str, Any]:
    """How the studies' integration steps were set, with the agreement the test checks.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.

    Returns
    -------
    dict
        ``steps``: one entry per distinct step (``dt`` [s], ``source``: ``"chosen"``,
        ``"given"``, ``"file"`` or ``"fallback"`` (no step met the tolerance: the paper's),
        ``studies``, and for a chosen step ``tolerance_db``,
        ``estimated_error_db`` (the largest over its studies' cases that met it),
        ``reference_dt`` [s], ``probe_duration`` [s], ``seconds`` [s], ``cached`` (read
        from the step cache, :mod:`qzs.engine.step_cache`) and ``notes``);
        ``step_dependent``: the cases no step met (study, case); ``paper_dt`` [s];
        ``agreement``: what :data:`AGREEMENT_TEST` checks; ``statement``:
        :func:`step_statement`.
    """
    steps: dict[tuple[float, str], dict[str, Any]] = {}
    dependent: list[dict[str, str]] = []
    for result in study_results:
        step = result.step
        if not step:
            continue
        entry = steps.setdefault((step["dt"], step["source"]),
                                 {"dt": step["dt"], "source": step["source"], "studies": []})
        entry["studies"].append(result.study.name)
        if step["source"] == "fallback":
            entry.update(tolerance_db=step["tolerance_db"], notes=step["notes"])
            dependent += [{"study": result.study.name, "case": label} for label in step["unmet"]]
        elif step["source"] == "chosen":
            for key in ("tolerance_db", "reference_dt", "probe_duration"):
                entry[key] = step[key]
            entry["estimated_error_db"] = max(entry.get("estimated_error_db", 0.0),
                                              step["estimated_error_db"])
            groups = entry.setdefault("groups", {})
            groups[step["group"]] = step["seconds"]
            entry["seconds"] = sum(groups.values())
            entry["cached"] = entry.get("cached", True) and step.get("cached", False)
            entry.setdefault("notes", [])
            entry["notes"] += [n for n in step["notes"] if n not in entry["notes"]]
            dependent += [{"study": result.study.name, "case": label} for label in step["unmet"]]
    for entry in steps.values():
        entry.pop("groups", None)
    record = {"steps": list(steps.values()), "step_dependent": dependent,
              "paper_dt": SIMULATION["dt"],
              "agreement": (f"every claim's verdict and every tabulated number agrees with the "
                            f"paper's own step dt = {SIMULATION['dt']:g} s within the tolerance "
                            f"(criteria: docs/workflows/paper.md; checked by {AGREEMENT_TEST} "
                            "on the quick paper at the default tolerance); the numbers of the "
                            "step-dependent cases differ between any two steps")}
    record["statement"] = step_statement(study_results, record)
    return record


def step_statement(study_results: Sequence[StudyResult],
                   record: dict[str, Any] | None = None) -> str:
    """The integration step in one paragraph, for the report and the console.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    record : dict, optional
        Their :func:`step_record` (computed if omitted).

    Returns
    -------
    str
    """
    record = step_record(study_results) if record is None else record
    if not record["steps"]:
        return "no simulation."
    parts = []
    for step in record["steps"]:
        where = "" if len(record["steps"]) == 1 else f" ({', '.join(step['studies'])})"
        if step["source"] == "chosen":
            parts.append(f"dt = {step['dt']:g} s{where}, chosen for the transmissibility within "
                         f"{step['tolerance_db']:g} dB: estimated error "
                         f"{step['estimated_error_db']:.2g} dB (against dt = "
                         f"{step['reference_dt']:g} s on a {step['probe_duration']:g} s probe, "
                         + ("read from the step cache)" if step.get("cached") else
                            f"{step['seconds']:.1f} s to choose)"))
        elif step["source"] == "fallback":
            parts.append(f"dt = {step['dt']:g} s{where}, the paper's own: no step met "
                         f"{step['tolerance_db']:g} dB for any case ({'; '.join(step['notes'])})")
        else:
            mark = " (the paper's own)" if step["dt"] == record["paper_dt"] else ""
            how = "as given" if step["source"] == "given" else "from the study file"
            parts.append(f"dt = {step['dt']:g} s{mark}{where}, {how}")
    text = "; ".join(parts) + "."
    if record["step_dependent"]:
        text += (" No step met the tolerance for " + "; ".join(
            f"{d['case']} ({d['study']})" for d in record["step_dependent"])
            + ": its response depends on the step (stop contacts), so its numbers differ "
            "between any two steps, the paper's own included.")
    chosen = [step for step in record["steps"] if step["source"] == "chosen"]
    if chosen and all(step["tolerance_db"] == ACCURACY["tolerance_db"] for step in chosen):
        text += " " + record["agreement"][0].upper() + record["agreement"][1:] + "."
    elif chosen:
        text += (f" The agreement of verdicts and tabulated numbers with the paper's own step is "
                 f"checked ({AGREEMENT_TEST}) at the default {ACCURACY['tolerance_db']:g} dB only.")
    return text
