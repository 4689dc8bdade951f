"""The design's settings: the gain grid and the gains a stage tries."""
import numpy as np
import pytest

from qzs.workflows.design.settings import KP_GRID


def test_the_gain_grids_are_geometric_from_1_to_1000_n_per_m():
    for quick, count in ((True, 7), (False, 10)):
        grid = np.array(KP_GRID[quick])
        assert len(grid) == count and grid[0] == 1.0 and grid[-1] == pytest.approx(1000.0)
        np.testing.assert_allclose(grid[1:] / grid[:-1], 1000 ** (1 / (count - 1)), rtol=1e-12)


def test_the_gains_a_stage_tries_keep_the_ratio_and_the_rate(design_options):
    from qzs.workflows.design.inputs import _design_settings

    arguments = dict(design_options, stiction_range=(8.0, 12.0), cost="rms",
                     controller_rate=500.0, delay=0.0, gain_margin_min=6.0,
                     phase_margin_min=30.0, workers=1, progress=False)
    settings = _design_settings(None, None, **arguments)
    trial = settings.controller_at(300.0, kd=25.0)
    assert (trial.pi_kp, trial.damping_gain, trial.controller_rate) == (300.0, 25.0, 500.0)
    assert trial.pi_ki == pytest.approx(0.4 * 300.0, rel=1e-15)
    assert settings.controller_at(10.0).damping_gain == settings.controller.damping_gain


def test_the_plan_is_resolved_once_with_its_steps_and_never_changed(design_options):
    """The settings are a frozen plan: the steps are in it when it is made (a given dt is
    the cost's step and the PI search's), and a stage cannot write a step into it."""
    import dataclasses

    from qzs.workflows.design.inputs import _design_settings

    arguments = dict(design_options, stiction_range=(8.0, 12.0), cost="rms",
                     controller_rate=None, delay=0.0, gain_margin_min=6.0,
                     phase_margin_min=30.0, workers=1, progress=False, dt=5e-4)
    settings = _design_settings(None, None, **arguments)
    assert (settings.dt, settings.stroke_dt, settings.dt_note) == (5e-4, 5e-4, "given")
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.dt = 1e-3
