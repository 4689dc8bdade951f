"""A six-axis run's statistics (qzs.engine.hexapod.statistics): over blocks of output rows in
any cut, what numpy computes from the whole run's columns at once."""
import numpy as np
import pytest

from qzs.engine.hexapod.layout import (C_BASE_POSE, C_DF, C_DS, C_EG, C_EK, C_ESP, C_EST, C_FMO,
                                       C_POSE, C_WB, C_WM, C_Z, N_CHANNELS, N_FLAGS, O_LOCKED)
from qzs.engine.hexapod.statistics import _Statistics


def test_blocks_give_the_statistics_of_the_whole_run():
    rng = np.random.default_rng(7)
    rows = 300
    data = rng.normal(size=(rows, N_CHANNELS))
    flags = rng.random((rows, N_FLAGS)) < 0.4
    centers = np.linspace(-0.06, -0.05, 6)
    statistics = _Statistics(centers)
    for cut in (slice(0, 1), slice(1, 170), slice(170, 170), slice(170, rows)):
        statistics.add(data[cut], flags[cut])
    result = statistics.result()
    z, motor = data[:, C_Z:C_Z + 6], data[:, C_FMO:C_FMO + 6]
    relative = data[:, C_POSE:C_POSE + 6] - data[:, C_BASE_POSE:C_BASE_POSE + 6]
    energy = data[:, C_EK] + data[:, C_ESP] + data[:, C_EG] + data[:, C_EST]
    net = data[:, C_WB] + data[:, C_WM] - data[:, C_DF] - data[:, C_DS]
    assert result["samples"] == rows
    np.testing.assert_array_equal(result["stroke_used_m"], np.abs(z - centers).max(axis=0))
    np.testing.assert_array_equal(result["locked_share"],
                                  flags[:, O_LOCKED:O_LOCKED + 6].mean(axis=0))
    np.testing.assert_allclose(result["motor_rms_N"], np.sqrt((motor ** 2).mean(axis=0)),
                               rtol=1e-14)
    np.testing.assert_array_equal(result["motor_max_N"], np.abs(motor).max(axis=0))
    assert result["relative_translation_max_m"] == np.abs(relative[:, :3]).max()
    assert result["relative_rotation_max_rad"] == np.abs(relative[:, 3:]).max()
    assert result["energy_residual_max_J"] == pytest.approx(
        np.abs(energy - energy[0] - net).max(), rel=1e-14)
    assert result["base_work_max_J"] == np.abs(data[:, C_WB]).max()
