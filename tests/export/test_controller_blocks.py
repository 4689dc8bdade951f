"""The exported controller.c with the controller's blocks (issue 40): every block carried,
its forces the simulated blocks' sample for sample."""
import ctypes

import numpy as np
import pytest
from helpers import (EXPORT_DISCRETE, BlockController, BlockOutput, BlockParameters, Blocks,
                     Controller, Parameters, Sensors)
from helpers import build_controller as build

import qzs
from qzs.errors import CompilerError, ParameterError
from qzs.export import controller as exported
from qzs.export.csource import find_compiler

try:
    find_compiler()
except CompilerError:  # pragma: no cover
    pytest.skip("no C compiler", allow_module_level=True)

SAMPLED = qzs.PIDamping(controller_rate=1000.0)
#: A 2-state discrete controller at the PI's 1 kHz on four of the rig's sensors (not the
#: payload's acceleration: a sampled run reads it after the PI's new command at the same
#: instant, which no recorded channel holds; docs/fmu.md).
LINEAR = qzs.LinearController(
    a=[[0.9, 0.05], [0.0, 0.8]], b=[[1e-3, 0.0, 0.0, 2e-3], [0.0, 0.01, 1e-3, 0.0]],
    c=[30.0, -2.0], d=[10.0, -20.0, 0.0, 5.0],
    inputs=("position_error", "measured_payload_velocity", "base_acceleration",
            "relative_velocity"), sample_time=1e-3)
#: Every block at once: compensation with deadband and observer, dither, the linear controller.
EVERY_BLOCK = qzs.PIDamping(
    controller_rate=1000.0, damping_gain=50.0,
    compensation=qzs.FrictionCompensation(fraction=0.8, deadband=1e-4, observer_bandwidth=5.0),
    dither=qzs.Dither(amplitude=2.0, frequency=40.0), linear=LINEAR)
#: The forces compared: the C output's field and the run's channel.
FORCES = (("pi", "pi_force"), ("damping", "damping_force"),
          ("compensation", "compensation_force"), ("dither", "dither_force"),
          ("linear", "linear_force"), ("motor", "motor_force"),
          ("friction_estimate", "friction_estimate"))


@pytest.mark.parametrize("block", [
    qzs.FrictionCompensation(fraction=0.5), qzs.Dither(amplitude=1.0, frequency=50.0),
    EXPORT_DISCRETE], ids=["compensation", "dither", "linear"])
def test_a_block_is_not_dropped_from_the_export(block):
    """A controller with a block is not exported as its PI + damping alone (it was, silently)."""
    assert exported.controller_source(SAMPLED + block) != exported.controller_source(SAMPLED)


def _exported(tmp_path, controller):
    """The compiled export of ``controller`` and its controller, initialised as exported."""
    lib = build(tmp_path, exported.controller_source(controller, dt=1e-4))
    state = BlockController()
    lib.qzs_block_controller_init(
        ctypes.byref(state), BlockParameters.in_dll(lib, exported.BLOCK_PARAMETERS_NAME),
        ctypes.c_double.in_dll(lib, exported.PRELOAD_NAME).value,
        Blocks.in_dll(lib, exported.BLOCK_STATES_NAME),
        BlockOutput.in_dll(lib, exported.BLOCK_HELD_NAME))
    return lib, state


def _sensors(result, k):
    """What the rig measures at row ``k`` of a run sampled at its controller's rate: the row
    is recorded at the sample instant, before the sample (docs/model.md §5.1)."""
    channel = {name: np.asarray(result[name]) for name in (
        "time", "relative_position", "measured_payload_velocity", "relative_velocity",
        "payload_acceleration", "base_acceleration", "friction_force", "stop_force")}
    return Sensors(channel["time"][k], channel["relative_position"][k],
                   channel["measured_payload_velocity"][k], channel["relative_velocity"][k],
                   channel["payload_acceleration"][k], channel["base_acceleration"][k],
                   channel["friction_force"][k] + channel["stop_force"][k])


def test_every_block_equals_the_simulated_one_sample_for_sample(tmp_path):
    """Fed what a sampled run's controller read at each sample, the exported step returns
    the forces the run held over the next period, every block's and the motor's, bit for bit:
    the C runs the C model's laws (qzs_controller.h), which are the kernels' operations in
    their order (tests/export/test_cmodel_blocks.py). A random record: its base motion has no
    rotated phase, so the recorded velocities are the very ones the run's controller read."""
    excitation = qzs.RandomExcitation(amplitude=0.004, f_high=30.0, duration=4.0, seed=5)
    result = qzs.simulate(excitation, None, EVERY_BLOCK, duration=4.0, dt=1e-4,
                          sample_rate=1000.0)
    lib, state = _exported(tmp_path, EVERY_BLOCK)
    rows = np.asarray(result.time).size
    outputs = [lib.qzs_block_controller_step(ctypes.byref(state), _sensors(result, k))
               for k in range(rows - 1)]
    locked = np.asarray(result.locked)[:-1]
    assert min(locked.sum(), (~locked).sum()) > 100  # it sticks and slips: both branches
    for field, channel in FORCES:
        ours = np.array([getattr(out, field) for out in outputs])
        simulated = np.asarray(result[channel])[1:]
        np.testing.assert_array_equal(ours, simulated, err_msg=channel)
        assert np.ptp(simulated) > 1e-3, channel  # each block acts: a real check
    assert state.integral != exported.exported_parameters(EVERY_BLOCK, dt=1e-4)[1]


def test_a_continuous_linear_controller_is_refused_naming_the_fix(tmp_path):
    """Its zero-order-hold discretisation is not the controller qzs simulates (integrated with
    the plant): refused, nothing written, the error naming `linear` and how to discretise it."""
    controller = SAMPLED + qzs.LinearController(a=[[-10.0]], b=[[1.0]], c=[5.0], d=[0.0])
    with pytest.raises(ParameterError, match=r"c2d\(linear.to_system\(\), 0.001, 'zoh'\)") as error:
        exported.export_controller(tmp_path / "controller.c", controller)
    assert error.value.options == ("linear",)
    assert list(tmp_path.iterdir()) == []


def test_a_linear_controller_at_another_period_is_refused_naming_the_fix():
    """The exported step samples every block at once: a discrete linear controller at 2 ms
    under a 1 kHz PI is refused, naming both ways out."""
    slow = qzs.LinearController(a=[[0.5]], b=[[1.0]], c=[5.0], d=[0.0], sample_time=2e-3)
    with pytest.raises(ParameterError, match=r"sample_time=0\.001.*controller_rate=500\.0") as error:
        exported.controller_source(SAMPLED + slow, dt=1e-4)
    assert error.value.options == ("sample_time",)


def test_without_blocks_both_steps_are_exported_and_agree(tmp_path):
    """A controller without blocks keeps the PI + damping's own step, and the block step with
    no block gives the same forces (its blocks add exact zeros)."""
    lib, state = _exported(tmp_path, SAMPLED)
    alone = Controller()
    lib.qzs_controller_init(ctypes.byref(alone), Parameters.in_dll(lib, exported.PARAMETERS_NAME),
                            ctypes.c_double.in_dll(lib, exported.PRELOAD_NAME).value)
    for k, z in enumerate(np.linspace(-0.01, 0.01, 50)):
        sensors = Sensors(k * 1e-3, z, 0.1 * z, 0.0, 0.0, 0.0, 0.0)
        ours = lib.qzs_block_controller_step(ctypes.byref(state), ctypes.byref(sensors))
        theirs = lib.qzs_controller_step(ctypes.byref(alone), z, 0.1 * z)
        assert (ours.pi, ours.damping, ours.motor) == (theirs.pi, theirs.damping, theirs.motor)
    assert state.integral == alone.integral != 0.0
    declaration = f"QzsControllerParameters {exported.PARAMETERS_NAME} ="
    assert declaration in exported.controller_source(SAMPLED)  # with blocks the PI-alone set
    assert declaration not in exported.controller_source(EVERY_BLOCK)  # is not written


def test_the_c_files_labels_name_the_entries_they_stand_by():
    """The exported C file labels each packed entry: the value beside ``A[i][j]``,
    ``B[i][sensor]``, ``C[i]``, ``D[sensor]`` is that entry of the controller's matrices (0-based,
    a sensor by its name), so that a reader of the file edits the entry they mean."""
    from qzs.model.sensors import SENSORS

    values = {}
    for line in exported.controller_source(EVERY_BLOCK, dt=1e-4).splitlines():
        value, _, label = line.strip().partition(",  /* ")
        if label.endswith(" */"):
            values.setdefault(label[:-3], float(value))
    a, b, c, d = (np.atleast_2d(m) for m in (LINEAR.a, LINEAR.b, LINEAR.c, LINEAR.d))
    for k, sensor in enumerate(LINEAR.inputs):
        assert values[f"D[{sensor}]"] == d[0, k], sensor
        for i in range(2):
            assert values[f"B[{i}][{sensor}]"] == b[i, k], (i, sensor)
    unread = set(SENSORS) - set(LINEAR.inputs)
    assert all(values[f"D[{sensor}]"] == 0.0 for sensor in unread)
    for i in range(2):
        assert values[f"C[{i}]"] == c[0, i]
        for j in range(2):
            assert values[f"A[{i}][{j}]"] == a[i, j]
