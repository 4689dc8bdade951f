"""The design's result: strict JSON, frozen, and its files written atomically."""
import dataclasses
import json

import pytest


def test_to_dict_is_strict_json_and_the_result_is_frozen(design):
    text = json.dumps(design.to_dict(), allow_nan=False)
    assert json.loads(text)["gains"]["pi_kp"] == pytest.approx(design.gains["pi_kp"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        design.gains = {}


def test_save_writes_report_json_and_every_figure_atomically(design, tmp_path):
    written = design.save(tmp_path / "out")
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert "report.html" in names and "design.json" in names
    for figure in ("static_design", "pi_search", "hunting", "damping", "margins",
                   "damping_effect"):
        assert f"{figure}.png" in names and f"{figure}.svg" in names
    assert not [n for n in names if n.startswith(".")]  # no temporary file left
    record = json.loads(written["json"].read_text())
    assert record["gains"]["damping_gain"] == pytest.approx(design.gains["damping_gain"])
    html = written["report"].read_text()
    assert "Why active damping did not help much" in html and "pi_search.png" in html
