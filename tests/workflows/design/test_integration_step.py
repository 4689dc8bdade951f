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
