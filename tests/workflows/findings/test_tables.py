"""The findings' tables (qzs.workflows.findings.tables): cells, reasons, documents."""
import math

import numpy as np

from qzs._version import __version__
from qzs.iotools.files import write_text
from qzs.workflows.findings.tables import (document_head, metric_cell, significant,
                                           with_reasons)


def test_a_defined_metric_is_its_text_and_an_undefined_one_a_numbered_note():
    """Both reports' cells: a finite number shown, NaN (or None) a dash with its reason as a
    footnote, one number per distinct reason in order of first use."""
    notes = {}
    assert metric_cell(0.123456, "unused", notes) == "0.123" and notes == {}
    assert metric_cell(np.float64(2.0), "unused", notes, text=lambda v: f"{v:.1f}") == "2.0"
    assert metric_cell(7, "unused", notes) == "7"
    assert metric_cell(math.nan, "no peak", notes) == "—<sup>1</sup>"
    assert metric_cell(None, "not computed", notes, dash="&mdash;") == "&mdash;<sup>2</sup>"
    assert metric_cell(np.inf, "no peak", notes) == "—<sup>1</sup>"
    assert notes == {"no peak": 1, "not computed": 2}
    assert significant(math.nan) == "—" and significant(1234.5) == "1.23e+03"


def test_reasons_sit_beside_the_undefined_values_only():
    row = with_reasons({"a": 1.0, "b": math.nan, "c": math.nan}, {"a": "x", "b": "why"}, "p.")
    assert list(row) == ["p.a", "p.b", "p.b_reason", "p.c"]
    assert row["p.b_reason"] == "why"


def test_a_document_s_head_and_its_text_file(tmp_path):
    assert document_head(True, 2.5) == {"qzs_version": __version__, "quick": True,
                                        "wall_seconds": 2.5}
    path = write_text(tmp_path / "report.md", "µ — text\n")
    assert path == tmp_path / "report.md"
    assert path.read_text(encoding="utf-8") == "µ — text\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.md"]  # nothing left behind


def test_a_flag_is_no_metric_and_a_setting_the_cases_differ_in_lists_their_values():
    """A bool is not a number to show (the dash and its note); the run settings give a
    setting's one value where the cases share it, every distinct value where they differ."""
    import types

    from qzs.workflows.findings.tables import run_settings

    notes = {}
    assert metric_cell(True, "a flag, not a metric", notes) == "—<sup>1</sup>"
    result = types.SimpleNamespace(cases=[
        types.SimpleNamespace(run={"dt": 1e-4, "solver": "ode3"}),
        types.SimpleNamespace(run={"dt": 2e-4, "solver": "ode3"}),
        types.SimpleNamespace(run={"dt": 1e-4, "solver": "ode3"})])
    assert run_settings(result) == {"dt": [1e-4, 2e-4], "solver": "ode3"}
