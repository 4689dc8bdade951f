"""The design's margins: the rate it reports as needed keeps the margins, a slower one not."""
import math

from qzs import ControllerParameters
from qzs.analysis import control_design as cd


def final_controller(design):
    g = design.gains
    return ControllerParameters(pi_kp=g["pi_kp"], pi_ki=g["pi_ki"],
                                damping_gain=g["damping_gain"])


def test_the_needed_rate_keeps_the_margins_and_a_slower_one_does_not(design):
    margins, s = design.margins, design.settings
    rate = margins["required_rate_without_delay"]
    assert math.isfinite(rate)
    controller = final_controller(design)
    assert cd.loop_margins(controller=controller, rate=rate).meets(s["gain_margin_min"],
                                                                   s["phase_margin_min"])
    assert not cd.loop_margins(controller=controller, rate=0.97 * rate).meets(
        s["gain_margin_min"], s["phase_margin_min"])


def test_every_delays_needed_rate_keeps_the_margins_with_that_delay(design):
    rows = sorted(design.margins["by_delay"], key=lambda r: r["delay"])
    assert [r["delay"] for r in rows] == [0.0, 0.001, 0.002, 0.005]
    assert rows[0]["required_rate"] == design.margins["required_rate_without_delay"]
    controller, s = final_controller(design), design.settings
    for row in rows:
        continuous = cd.loop_margins(controller=controller, rate=0.0, delay=row["delay"])
        assert row["continuous_phase_margin"] == continuous.phase_margin
        if math.isfinite(row["required_rate"]):
            assert cd.loop_margins(controller=controller, rate=row["required_rate"],
                                   delay=row["delay"]).meets(s["gain_margin_min"],
                                                             s["phase_margin_min"])
