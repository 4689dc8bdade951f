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
