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
