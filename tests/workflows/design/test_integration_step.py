"""The design's steps: the PI search's coarser step."""
import dataclasses

import pytest

from qzs import defaults
from qzs.engine.stability import stability_test
from qzs.workflows.design.integration_step import _stroke_step
from qzs.workflows.design.settings import KP_GRID, STROKE_STEP_MAX


def test_the_stroke_step_is_the_coarsest_stable_output_fraction_up_to_the_limit(design_options):
    from qzs.workflows.design.inputs import _design_settings

    settings = _design_settings(
        None, None, **dict(design_options, cost="rms", controller_rate=None, delay=0.0,
                           gain_margin_min=6.0, phase_margin_min=30.0, workers=1,
                           progress=False))
    step = _stroke_step(settings)
    k = round(1.0 / (settings.sample_rate * step))
    assert step == pytest.approx(1.0 / (settings.sample_rate * k), rel=1e-12)
    assert step <= STROKE_STEP_MAX
    # the next coarser output fraction is too coarse or unstable on the stiffest case
    stiffest = settings.controller_at(max(KP_GRID[True]), settings.damping_gain_max)
    light = dataclasses.replace(settings.isolator, mass=6.4, stiction_force=12.0)
    stable = stability_test(light, stiffest, defaults.SIMULATION["solver"])
    assert stable(step)
    coarser = 1.0 / (settings.sample_rate * (k - 1)) if k > 1 else float("inf")
    assert coarser > STROKE_STEP_MAX or not stable(coarser)


def test_the_accuracy_step_is_chosen_on_the_two_extreme_controllers(design_options,
                                                                     monkeypatch):
    """choose_dt probes the most stiction without damping and the most damping (docs/model.md
    decision 26), one batch, the default request, with the fallback and the cache."""
    import qzs.engine.step_choice as step_choice
    from qzs.engine.step_search import StepChoice
    from qzs.workflows.design.inputs import _design_settings
    from qzs.workflows.design.integration_step import choose_dt

    settings = _design_settings(
        None, None, **dict(design_options, cost="rms", controller_rate=None, delay=0.0,
                           gain_margin_min=6.0, phase_margin_min=30.0, workers=1,
                           progress=False))
    asked = []

    def choose(request, probe, **options):
        asked.append((request, probe, options))
        return StepChoice(dt=2.5e-4, error=0.01, measure="transmissibility_db",
                          tolerance=0.05, reference_dt=6.25e-5, stability_limit=1e-2,
                          sample_rate=settings.sample_rate, solver="ode3", probe=None,
                          probe_duration=20.0, band=None, history=(), notes=(),
                          case_steps=(5e-4, 2.5e-4), case_errors=(0.01, 0.02))

    monkeypatch.setattr(step_choice, "choose", choose)
    dt, note = choose_dt(settings, 300.0)
    (request, probe, options), = asked
    assert dt == 2.5e-4 and request == step_choice.StepRequest()
    assert options == {"fallback": True, "cache": True}
    (sticky, sticky_loop), (damped, damped_loop) = probe.cases
    assert sticky.stiction_force == settings.stiction_range[1]
    assert sticky_loop.damping_gain == 0.0 and sticky_loop.pi_kp == 300.0
    assert damped == settings.isolator and damped_loop.pi_kp == 300.0
    assert damped_loop.damping_gain == settings.damping_gain_max > 0.0
    assert "0.0005 s" in note and "0.00025 s" in note
