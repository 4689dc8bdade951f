"""The exported controller.c: one C file, no dependency, the simulated controller's commands."""
import ctypes

import numpy as np
import pytest
from helpers import Controller, Parameters
from helpers import build_controller as build

import qzs
from qzs.engine import kernels as K
from qzs.engine.prepare import prepare_run
from qzs.errors import CompilerError, ParameterError
from qzs.export import controller as exported
from qzs.export.csource import find_compiler

try:
    find_compiler()
except CompilerError:  # pragma: no cover
    pytest.skip("no C compiler", allow_module_level=True)


def test_the_commands_are_the_simulated_controllers_sample_for_sample(tmp_path):
    """Fed the z and measured velocity a sampled qzs run recorded at each sample, the
    exported code returns the command the run held over the next period, bit for bit
    (a random record: its base motion has no rotated phase, so the recorded velocity is
    the very one the run's controller read)."""
    controller = qzs.ControllerParameters(controller_rate=1000.0, damping_gain=400.0)
    excitation = qzs.RandomExcitation(amplitude=0.004, f_high=30.0, duration=4.0, seed=5)
    result = qzs.simulate(excitation, None, controller, duration=4.0, dt=1e-4,
                          sample_rate=1000.0)
    lib = build(tmp_path, exported.controller_source(controller, dt=1e-4))
    state = Controller()
    lib.qzs_controller_init(ctypes.byref(state),
                            Parameters.in_dll(lib, exported.PARAMETERS_NAME),
                            ctypes.c_double.in_dll(lib, exported.PRELOAD_NAME).value)
    z = np.asarray(result.relative_position)
    measured = np.asarray(result.measured_payload_velocity)
    commands = np.array([[out.pi, out.damping, out.motor] for out in (
        lib.qzs_controller_step(ctypes.byref(state), z[k], measured[k])
        for k in range(z.size - 1))])
    simulated = np.column_stack([np.asarray(result.pi_force), np.asarray(result.damping_force),
                                 np.asarray(result.motor_force)])[1:]
    np.testing.assert_array_equal(commands, simulated)
    assert np.ptp(simulated[:, 2]) > 1.0  # the commands move: a real check


def test_the_preload_is_the_runs(tmp_path):
    controller = qzs.ControllerParameters(controller_rate=500.0)
    run = prepare_run(qzs.Chirp(duration=10.0), None, controller, dt=1e-4)
    parameters, preload = exported.exported_parameters(controller, dt=1e-4)
    assert preload == run.state[K.S_INT] != 0.0
    assert parameters["period_steps"] == 20 and parameters["pi_kp"] == controller.pi_kp


def test_saturation_and_anti_windup_in_the_exported_code(tmp_path):
    """Far from the setpoint the command is clipped at the motor's limit and the integral
    stops growing into the saturation (docs/model.md §5)."""
    controller = qzs.ControllerParameters(controller_rate=1000.0)
    lib = build(tmp_path, exported.controller_source(controller))
    state = Controller()
    lib.qzs_controller_init(ctypes.byref(state), Parameters.in_dll(lib, exported.PARAMETERS_NAME),
                            0.0)
    out = lib.qzs_controller_step(ctypes.byref(state), controller.position_setpoint - 1.0, 0.0)
    assert out.motor == qzs.IsolatorParameters().motor_force_max and out.integral_rate == 0.0
    assert state.integral == 0.0
    out = lib.qzs_controller_step(ctypes.byref(state), controller.position_setpoint - 1e-4, 0.0)
    assert out.integral_rate == pytest.approx(1e-4) and state.integral > 0.0


def test_a_continuous_controller_is_refused():
    with pytest.raises(ParameterError, match="controller_rate"):
        exported.controller_source(qzs.ControllerParameters(controller_rate=0.0))


def test_the_file_is_written_atomically_with_its_suffix(tmp_path):
    with pytest.raises(ParameterError, match="--out"):
        exported.export_controller(tmp_path / "controller.txt", argument="--out")
    path = exported.export_controller(tmp_path / "controller.c")
    assert path.read_text().count("qzs_controller_step(QzsController") == 2
    assert [p.name for p in tmp_path.iterdir()] == ["controller.c"]
