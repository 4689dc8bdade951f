"""One run's column: the Welch estimate of every platform axis per the excited base axis."""
import dataclasses
import types

import numpy as np
import pytest

from qzs.workflows.hexapod.transmissibility.runs import _estimate


def test_a_platform_moving_half_the_base_gives_half_on_every_trusted_bin():
    """H1 of y = 0.5 x is exactly 0.5 (phase 0) wherever the base has power; other platform
    axes, at rest, give 0."""
    rng = np.random.default_rng(3)
    n, rate = 2 ** 15, 1000.0
    base = np.zeros((n, 6))
    base[:, 2] = rng.normal(size=n)
    twist = np.zeros((n, 6))
    twist[:, 2] = 0.5 * base[:, 2]
    twist[:, 0] = 1e-3 * rng.normal(size=n)  # uncorrelated with the base
    run = types.SimpleNamespace(sample_rate=rate, fft_length=4096, overlap=0.5, estimator="h1",
                                coherence_min=0.9, base_share_min=1e-10)
    estimates = _estimate({"base_velocity": base, "platform_twist": twist}, "z", run)
    z = estimates[2]
    assert np.any(z.trusted)
    np.testing.assert_allclose(z.magnitude[z.trusted], 0.5, rtol=1e-12)
    np.testing.assert_allclose(z.phase[z.trusted], 0.0, atol=1e-12)
    assert not np.any(estimates[0].trusted)  # no coherence with the base


def test_the_plan_gives_one_frozen_run_per_axis_with_the_common_settings():
    """Each excited axis is one AxisRun, in the order of AXES, carrying its own chirp and the
    runs' common settings; nothing can be written into it (a chosen step is returned by
    axis_step, not stored); the centralised controller keyword only where there is one."""
    from qzs.workflows.hexapod.setups import hexapod_setup
    from qzs.workflows.hexapod.transmissibility import plan
    from qzs.workflows.hexapod.transmissibility.runs import AxisRun

    setup = hexapod_setup()
    _, amplitudes, common, runs, _ = plan._plan(
        setup, ("x", "z"), None, 0.0, 20.0, 60.0, None, None, None, None, "h1", -100.0, 1,
        False)
    assert [run.axis for run in runs] == ["x", "z"]  # the order of AXES, not the argument's
    for run in runs:
        assert isinstance(run, AxisRun)
        assert run.excitation.amplitude == amplitudes[run.axis]
        assert run.dt is None and run.tolerance_db == common["tolerance_db"]
        for name in ("f0", "f1", "duration", "sample_rate", "solver", "fft_length",
                     "setup_dt"):
            assert getattr(run, name) == common[name]
        assert run.control == {}
    with pytest.raises(dataclasses.FrozenInstanceError):
        runs[0].dt = 1e-3
    assert dataclasses.replace(runs[0], cartesian="c").control == {"cartesian": "c"}


def test_axis_step_asks_the_one_call_for_the_run_s_tolerance_band_and_finest_step(monkeypatch):
    """The six-leg probe of the run's chirp, measured over its band (from f0, or from the
    lower of 1 Hz and f1/2 for a chirp from rest), halving down to the set-up's dt and
    falling back to it; the record's history is each step and its difference [dB]."""
    import qzs.engine.step_choice as step_choice
    from qzs.engine.step_search import StepChoice
    from qzs.workflows.hexapod.setups import hexapod_setup
    from qzs.workflows.hexapod.transmissibility import plan
    from qzs.workflows.hexapod.transmissibility.runs import axis_step

    asked = []

    def choose(request, probe, **options):
        asked.append((request, probe, options))
        return StepChoice(dt=5e-4, error=0.01, measure="transmissibility_db", tolerance=0.05,
                          reference_dt=1.25e-4, stability_limit=1e-2, sample_rate=1000.0,
                          solver="ode3", probe=None, probe_duration=20.0, band=probe.band,
                          history=((1e-3, 0.5, 0.8), (5e-4, 0.006, 0.007)), notes=())

    monkeypatch.setattr(step_choice, "choose", choose)
    _, _, _, runs, _ = plan._plan(hexapod_setup(), ("z",), None, 0.0, 20.0, 60.0, None, None,
                                  None, None, "h1", -100.0, 1, False)
    run, = runs
    for f0, f1, band in ((0.0, 20.0, (1.0, 20.0)), (0.0, 1.5, (0.75, 1.5)),
                         (2.0, 20.0, (2.0, 20.0))):
        asked.clear()
        dt, record = axis_step(dataclasses.replace(run, f0=f0, f1=f1))
        (request, probe, options), = asked
        assert dt == 5e-4 and probe.band == band
        assert request == step_choice.StepRequest(tolerance=run.tolerance_db)
        assert options == {"finest": run.setup_dt, "fallback": True}
        assert record["step_history"] == ((1e-3, 0.5), (5e-4, 0.006))
        assert record["step"] == "accuracy-driven"
