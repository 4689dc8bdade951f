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


def test_the_margins_stage_advances_its_bar_after_every_loop_analysis(monkeypatch):
    """Never silent: one bar step per analysis (each can take seconds), as many as announced."""
    from types import SimpleNamespace

    from qzs.workflows.design import margins as M

    events = []

    class Margins:
        gain_margin = phase_margin = 1.0

        def to_dict(self):
            return {}

        def meets(self, *_):
            return True

    def analysis(kind, result):
        def run(*_, **__):
            events.append(kind)
            return result
        return run

    class Bar:
        def update(self, n):
            events.append(("step", n))

    monkeypatch.setattr(M.cd, "loop_margins", analysis("margins", Margins()))
    monkeypatch.setattr(M.cd, "required_controller_rate", analysis("rate", (100.0, "")))
    settings = SimpleNamespace(controller_at=lambda kp, kd: None, isolator=None,
                               controller_rate=1000.0, delay=1e-3, gain_margin_min=6.0,
                               phase_margin_min=30.0)
    M._margins(settings, 1.0, 2.0, Bar())
    steps = [e for e in events if e == ("step", 1)]
    assert len(steps) == M.margin_steps(settings)
    assert events[-1] == ("step", 1)
    gaps, run = [], 0  # analyses between two steps: at most two (a delay's rate and margins)
    for event in events:
        run = 0 if event == ("step", 1) else run + 1
        gaps.append(run)
    assert max(gaps) <= 2
