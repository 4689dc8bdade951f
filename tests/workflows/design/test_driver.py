"""``design_controller`` end to end: the final gains pass every case and are linearly stable."""
import math

import pytest

import qzs
from qzs.analysis import control_design as cd


def test_the_final_gains_pass_and_are_linearly_stable(design):
    assert design.verification["summary"]["passes"]
    g = design.gains
    assert g["pi_ki"] == pytest.approx(0.4 * g["pi_kp"])
    assert design.stability.stable and design.stability.agrees
    low, high = design.stability.damping_gain_limits
    assert low <= g["damping_gain"] < high
    assert design.margins["meets"]


def test_the_result_records_every_stage_and_the_stability_of_the_final_gains(design):
    assert list(design.seconds)[:4] == ["choose_step", "pi_search", "damping_search",
                                        "verification"]
    assert list(design.seconds)[-4:] == ["hunting", "margins", "why", "total"]
    assert design.seconds["total"] >= sum(v for k, v in design.seconds.items() if k != "total")
    g = design.gains
    final = qzs.ControllerParameters(pi_kp=g["pi_kp"], pi_ki=g["pi_ki"],
                                     damping_gain=g["damping_gain"])
    expected = cd.integral_gain_limit(controller=final)
    assert design.stability.integral_gain_limit == pytest.approx(expected, rel=1e-12)
    assert design.static.mass_range == (6.4, 6.4)
    assert math.isfinite(design.pi_search["pi_kp"])


def test_the_lazy_exports_are_this_function_and_class():
    from qzs.workflows.design import DesignResult, design_controller

    assert qzs.design_controller is design_controller
    assert qzs.DesignResult is DesignResult
