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


def test_each_legs_block_costs_are_what_its_columns_give():
    """Per leg, the RMS of each of its blocks' forces and the platform's acceleration at its
    dither's frequency (the norm of the translation's three Fourier amplitudes), over blocks
    of rows in any cut; a leg without blocks reports none."""
    from qzs.engine.hexapod.layout import C_ACC, C_FCO, C_FDI, C_FOB, C_TIME
    from qzs.model.controller import ControllerParameters, Dither, FrictionCompensation

    rng = np.random.default_rng(11)
    rows = 400
    data = rng.normal(size=(rows, N_CHANNELS))
    data[:, C_TIME] = np.arange(rows) * 1e-3
    flags = rng.random((rows, N_FLAGS)) < 0.4
    plain = ControllerParameters()
    controllers = [plain, plain + Dither(amplitude=1.0, frequency=37.0),
                   plain + FrictionCompensation(fraction=0.5, observer_bandwidth=4.0), plain,
                   plain + Dither(amplitude=2.0, frequency=55.0)
                   + FrictionCompensation(fraction=1.0), plain]
    statistics = _Statistics(np.zeros(6), controllers)
    for cut in (slice(0, 1), slice(1, 250), slice(250, 250), slice(250, rows)):
        statistics.add(data[cut], flags[cut])
    blocks = statistics.result()["blocks"]

    def rms(column, leg):
        return np.sqrt(np.mean(data[:, column + leg] ** 2))

    def amplitude(frequency):
        phase = np.exp(-2j * np.pi * frequency * data[:, C_TIME])
        return 2 * np.linalg.norm(data[:, C_ACC:C_ACC + 3].T @ phase) / rows

    assert blocks[0] == blocks[3] == blocks[5] == {}
    assert set(blocks[1]) == {"dither_force_rms", "dither_payload_acceleration"}
    assert set(blocks[2]) == {"compensation_force_rms", "friction_estimate_rms"}
    assert set(blocks[4]) == {"compensation_force_rms", "dither_force_rms",
                              "dither_payload_acceleration"}
    assert blocks[1]["dither_force_rms"] == pytest.approx(rms(C_FDI, 1), rel=1e-14)
    assert blocks[1]["dither_payload_acceleration"] == pytest.approx(amplitude(37.0), rel=1e-12)
    assert blocks[2]["compensation_force_rms"] == pytest.approx(rms(C_FCO, 2), rel=1e-14)
    assert blocks[2]["friction_estimate_rms"] == pytest.approx(rms(C_FOB, 2), rel=1e-14)
    assert blocks[4]["dither_force_rms"] == pytest.approx(rms(C_FDI, 4), rel=1e-14)
    assert blocks[4]["dither_payload_acceleration"] == pytest.approx(amplitude(55.0), rel=1e-12)
    # without blocks on any leg: no block statistics at all
    plain_run = _Statistics(np.zeros(6), [plain] * 6)
    plain_run.add(data, flags)
    assert "blocks" not in plain_run.result()


def test_six_vertical_legs_report_the_block_costs_a_single_axis_reports():
    """Six vertical legs under a z sine are six single axes (docs/hexapod.md §9.5a): each
    leg's block costs in the run's statistics and summary equal the single run's with the
    same controller (its dither's payload acceleration is the platform's, in z)."""
    from helpers import vertical_legs

    from qzs import Dither, FrictionCompensation, IsolatorParameters, PIDamping, Sine, simulate
    from qzs.analysis.summary import block_lines
    from qzs.engine.hexapod import simulate_hexapod
    from qzs.model.hexapod import PlatformParameters

    isolator = IsolatorParameters(stiction_force=4.0, coulomb_force=2.0)
    controller = PIDamping() + FrictionCompensation(fraction=0.6, observer_bandwidth=5.0) + \
        Dither(amplitude=1.0, frequency=25.0)
    sine = Sine(amplitude=0.01, frequency=4.0)
    options = dict(duration=1.0, sample_rate=2000.0)
    single = simulate(sine, isolator, controller, **options)
    result = simulate_hexapod(vertical_legs(),
                              PlatformParameters(mass=6 * isolator.mass,
                                                 inertia=np.diag([1.0, 1.0, 1.5])),
                              isolator, controller, excitation={"z": sine}, **options)
    text = result.summary()
    for leg in range(6):
        costs = result.statistics["blocks"][leg]
        assert set(costs) == {"compensation_force_rms", "friction_estimate_rms",
                              "dither_force_rms", "dither_payload_acceleration"}
        for name, value in costs.items():
            assert value == pytest.approx(single.statistics[name], rel=1e-5, abs=1e-9), name
        lines = block_lines(controller, {**costs,
                                         "motor_force_rms": result.statistics["motor_rms_N"][leg]},
                            payload="platform acceleration")
        assert f"Leg {leg + 1}:\n" + "\n".join(lines) in text
    assert single.statistics["dither_payload_acceleration"] > 0.01
