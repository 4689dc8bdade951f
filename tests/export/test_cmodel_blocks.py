"""The C model runs a controller with blocks as the numba kernels do, bit for bit (issue 40).

Friction compensation with its observer (continuous and sampled, with a deadband), a dither,
a continuous 2-state lead-lag and a discrete 2-state controller reading the payload's
acceleration: every channel of :func:`qzs.simulate`, the blocks' own among them, equals the C
closed loop's (:func:`qzs.export.cmodel.simulate_c`) to the bit, with the same stick events.
"""
import numpy as np
import pytest
from helpers import EXPORT_BLOCK_CASES as CASES
from helpers import run_both
from helpers import export_block_settings as settings

import qzs
from qzs.engine import kernels as K
from qzs.engine.channels import BLOCK_CHANNELS, CHANNELS
from qzs.errors import CompilerError
from qzs.export.cmodel import simulate_c

try:
    from qzs.export.csource import load_model
    load_model()
except CompilerError as error:  # pragma: no cover - the machines have one
    pytest.skip(f"no C compiler: {error}", allow_module_level=True)

#: The block channel each case must move, so that it checks the code it is meant to.
MOVES = {"compensation with observer": ("compensation_force", "friction_estimate"),
         "sampled compensation with observer": ("compensation_force", "friction_estimate"),
         "dither": ("dither_force",), "continuous lead-lag": ("linear_force",),
         "discrete controller": ("linear_force",)}


@pytest.fixture(scope="module", params=list(CASES))
def both(request):
    return run_both(CASES, settings, request.param)


def test_every_channel_with_blocks_is_the_kernels(both):
    name, ours, theirs = both
    assert not theirs.diverged
    names = [channel for channel in (*CHANNELS, *BLOCK_CHANNELS) if channel in ours.channels]
    assert set(MOVES[name]) <= set(names)
    for channel in names:
        column = {**CHANNELS, **BLOCK_CHANNELS}[channel][0]
        np.testing.assert_array_equal(theirs.data[:, column], np.asarray(ours[channel]),
                                      err_msg=f"{name}: {channel}")
    for channel in MOVES[name]:
        assert np.ptp(np.asarray(ours[channel])) > 1e-3, (name, channel)  # the block acts
    np.testing.assert_array_equal(theirs.flags[:, K.O_LOCKED], np.asarray(ours.locked))
    assert theirs.run_flags[K.I_N_STICKS] == ours.run["stick_events"] >= 1
    assert theirs.steps == ours.run["steps"]


def test_the_blocks_change_the_run():
    """The same case without its blocks gives another motion: the comparison above is not one
    of two runs that ignore the blocks."""
    excitation, isolator, controller, _ = CASES["compensation with observer"]
    kwargs = settings("compensation with observer")
    plain = simulate_c(excitation, isolator, qzs.PIDamping(), **kwargs)
    blocks = simulate_c(excitation, isolator, controller, **kwargs)
    assert np.abs(plain.data[:, K.C_Z] - blocks.data[:, K.C_Z]).max() > 1e-4


def test_a_saturated_linear_controller_settles_where_back_calculation_puts_it_in_c():
    """The C model's back-calculation, row by row: a 2-state controller held beyond the motor's
    limit settles at the closed form (tests/engine/test_kernels_blocks.py), as the kernels."""
    from engine.test_kernels_blocks import (HELD_ERROR, HELD_PLANT, NO_LOOPS, WINDUP,
                                            saturated_command)
    from qzs.model.isolator import InitialState

    settled, _ = saturated_command(WINDUP, HELD_PLANT, HELD_ERROR)
    start = InitialState(relative_position=NO_LOOPS.position_setpoint - HELD_ERROR)
    run = simulate_c(qzs.Sine(amplitude=0.0, frequency=1.0), HELD_PLANT, NO_LOOPS + WINDUP,
                     duration=6.0, dt=1e-4, sample_rate=100.0, initial_state=start)
    assert run.data[-1, K.C_F_LINEAR] == pytest.approx(settled, rel=1e-5)


def test_a_discrete_integral_carrying_the_static_load_starts_as_the_kernels():
    """Without the PI's integral a discrete linear controller's integrator carries the static
    load from t = 0 (docs/model.md §5.1): its output held at the start is not 0, and a payload
    slipping at t = 0 feels it in the acceleration the first sample reads; the C model starts
    from the same held output."""
    from qzs.model.isolator import InitialState

    sampled = qzs.LinearController(a=[[1.0]], b=[[1e-3, 0.0, 0.0]], c=[20.0],
                                   d=[50.0, -20.0, 0.5],
                                   inputs=("position_error", "measured_payload_velocity",
                                           "payload_acceleration"), sample_time=1e-3)
    controller = qzs.PIDamping(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0, linear=sampled)
    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    options = dict(duration=1.0, dt=1e-4, sample_rate=1000.0,
                   initial_state=InitialState(relative_velocity=0.02))
    ours = qzs.simulate(excitation, None, controller, **options)
    theirs = simulate_c(excitation, None, controller, **options)
    assert abs(ours["linear_force"][0]) > 1.0  # the static load, held from the start
    for channel in ("linear_force", "relative_position", "motor_force"):
        np.testing.assert_array_equal(theirs.data[:, {**CHANNELS, **BLOCK_CHANNELS}[channel][0]],
                                      np.asarray(ours[channel]), err_msg=channel)


def test_the_observer_measures_the_stop_force_as_the_kernels():
    """Without the PI the payload sinks onto the lower stop (docs/model.md §5): the observer
    measures the friction left with the stop's force in it (r_meas = F_friction + F_stop +
    F_ff), in the C model as in the kernels."""
    controller = qzs.PIDamping(pi_kp=0.0, pi_ki=0.0, compensation=qzs.FrictionCompensation(
        fraction=0.5, observer_bandwidth=5.0))
    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    options = dict(duration=2.0, dt=1e-4, sample_rate=1000.0)
    ours = qzs.simulate(excitation, None, controller, **options)
    theirs = simulate_c(excitation, None, controller, **options)
    assert np.max(np.abs(ours["stop_force"])) > 100.0  # on the stop: the path is checked
    for channel in ("friction_estimate", "compensation_force", "relative_position"):
        np.testing.assert_array_equal(theirs.data[:, {**CHANNELS, **BLOCK_CHANNELS}[channel][0]],
                                      np.asarray(ours[channel]), err_msg=channel)
