"""The six-axis study's text (qzs.workflows.findings.markdown): its console summary."""
import math
import types
from pathlib import Path

from qzs.workflows.findings.markdown import study_summary


def test_the_summary_shows_each_row_with_a_dash_where_a_metric_is_undefined():
    row = {"case": "PI", "axis": "z", "T_at_4_hz": 0.98412, "T_at_8_hz": math.nan,
           "T_at_16_hz": 0.104, "locked_percent": 26.34, "stop_contacts": 3,
           "ledger_closure": 3.2e-9}
    study = types.SimpleNamespace(quick=True, wall_seconds=12.34, rows=[row],
                                  findings=["a finding"], cases={}, folder=Path("out"))
    lines = study_summary(study).splitlines()
    assert lines[0] == "qzs hexapod study: quick runs, wall 12.3 s"
    assert lines[2].split() == ["PI", "z", "0.984", "—", "0.104", "26.3", "3", "3e-09"]
    assert lines[3] == "  - a finding"
    assert lines[-1] == f"wrote {Path('out') / 'report.md'}, metrics.csv, metrics.json, " \
                        "figures and matrices"
