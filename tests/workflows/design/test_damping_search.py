"""The damping search: the least cost of the gains tried, inside the stability bound."""
import math

import pytest

from qzs import ControllerParameters
from qzs.analysis import control_design as cd


def test_the_damping_gain_has_the_least_cost_of_those_tried(design):
    rows = [r for r in design.damping["rows"] if math.isfinite(r["cost"])]
    best = min(rows, key=lambda r: r["cost"])
    assert design.gains["damping_gain"] == best["damping_gain"]
    assert design.gains["damping_gain"] <= design.damping["bound"] + 1e-9
    costs = [r["cost"] for r in sorted(rows, key=lambda r: r["damping_gain"])]
    assert costs[-1] < costs[0]  # damping lowers the band RMS on the 60 s chirp


def test_the_bound_is_the_routh_hurwitz_limit_or_the_cap(design):
    kp = design.gains["pi_kp"]
    controller = ControllerParameters(pi_kp=kp, pi_ki=design.settings["integral_ratio"] * kp)
    low, high = cd.damping_gain_limits(controller=controller)
    assert list(design.damping["routh_limits"]) == pytest.approx([low, high], rel=1e-12)
    assert design.damping["bound"] <= min(high, design.settings["damping_gain_max"])
