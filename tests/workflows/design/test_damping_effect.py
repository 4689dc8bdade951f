"""Why damping did not help much: the experiments and the answer built from them."""
import math

import numpy as np
import pytest


def test_more_damping_helps_more_on_the_papers_set_up(design):
    sweep = sorted((r for r in design.why["rows"] if r["factor"] == "baseline"),
                   key=lambda r: r["damping_gain"])
    changes = [r["change_db"] for r in sweep]
    assert len(changes) >= 4 and all(np.diff(changes) < 0)
    factors = {r["factor"] for r in design.why["rows"]}
    assert {"viscous friction", "high-pass", "controller rate"} <= factors
    assert "viscous friction" in design.why["answer"]


def test_each_change_is_the_ratio_of_the_two_costs_in_decibels(design):
    rows = [r for r in design.why["rows"] if math.isfinite(r["change_db"])]
    assert rows
    for row in rows:
        expected = 20 * math.log10(row["cost_damped"] / row["cost_undamped"])
        assert row["change_db"] == pytest.approx(expected, rel=1e-12)


def test_both_damping_metrics_are_shown_beside_the_change_of_the_cost(design):
    """On the bins trusted in both curves the band's reduction never exceeds the largest
    per-bin one; where the two curves trust nearly the same bins (the baseline) the band RMS
    change is the change of the cost."""
    assert design.settings["cost"] == "rms"
    rows = [r for r in design.why["rows"] if math.isfinite(r["change_db"])]
    assert rows
    for row in rows:
        assert row["largest_reduction_db"] >= -row["band_rms_change_db"]
    for row in (r for r in rows if r["factor"] == "baseline"):
        assert row["band_rms_change_db"] == pytest.approx(row["change_db"], abs=0.3)
    assert "largest per-bin reduction" in design.why["answer"]


def test_report_and_design_give_the_same_damping_metrics_on_the_same_runs(design):
    """The paper report's damping_changes on the design's own curves gives the design's rows."""
    from qzs.workflows.paper.report import damping_changes
    from qzs.workflows.paper.studies import CaseResult, Study, StudyResult

    estimates = design.series["damping_estimates"]
    cases = [CaseResult(f"Kd = {kd:g}", {"damping_gain": kd}, e.frequency, e.magnitude,
                        e.coherence, e.trusted) for kd, e in sorted(estimates.items())]
    result = StudyResult(Study(name="d", title="d", kind="transmissibility",
                               cases=tuple({} for _ in cases)), cases, quick=True)
    reference, changes = damping_changes(result, band=tuple(design.settings["band"]))
    assert reference.settings["damping_gain"] == 0.0 and changes
    rows = {r["damping_gain"]: r for r in design.damping["rows"]}
    compared = 0
    for case, change in changes:
        row = rows[case.settings["damping_gain"]]
        if math.isfinite(row["band_rms_change_db"]):
            assert change.band_rms_change_db == row["band_rms_change_db"]
            assert change.largest_reduction_db == row["largest_reduction_db"]
            compared += 1
    assert compared >= 2
