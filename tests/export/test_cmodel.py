"""The C model (qzs/export/csrc) computes what the numba kernels compute, bit for bit.

Each case runs through :func:`qzs.simulate` and through the C closed loop at the same step
and solver; every recorded channel must agree within 1e-12 of its range, and, since the C
takes the very operations of the kernels in the same order (no fast-math, explicit fused
multiply-adds, the same libm), the numbers are identical: a change to the kernels not made
in the C too fails here.
"""
import numpy as np
import pytest
from helpers import EXPORT_CASES as CASES
from helpers import run_both
from helpers import export_settings as settings

import qzs
from qzs.engine import kernels as K
from qzs.engine.channels import CHANNELS
from qzs.errors import CompilerError
from qzs.export.cmodel import simulate_c

try:
    from qzs.export.csource import load_model
    load_model()
except CompilerError as error:  # pragma: no cover - the machines have one
    pytest.skip(f"no C compiler: {error}", allow_module_level=True)

#: What each case must go through, so that it checks the code it is meant to.
EXPECTED_EVENTS = {"plastic stops": ("stop_contacts", 2), "compliant stops": ("stop_contacts", 2),
                   "high stiction": ("stick_events", 2), "passive": ("stick_events", 1),
                   "paper chirp shortened": ("stick_events", 1)}


@pytest.fixture(scope="module", params=list(CASES))
def both(request):
    return run_both(CASES, settings, request.param)


def test_every_channel_is_the_kernels(both):
    name, ours, theirs = both
    assert not theirs.diverged
    assert theirs.data.shape == (len(ours.time), K.N_CHANNELS)
    for channel, (column, _, _) in CHANNELS.items():
        expected = np.asarray(ours[channel])
        got = theirs.data[:, column]
        scale = max(np.ptp(expected), np.abs(expected).max(), 1e-300)
        assert np.abs(got - expected).max() <= 1e-12 * scale, (name, channel)
        np.testing.assert_array_equal(got, expected, err_msg=f"{name}: {channel}")
    np.testing.assert_array_equal(theirs.flags[:, K.O_LOCKED], np.asarray(ours.locked))
    np.testing.assert_array_equal(theirs.flags[:, K.O_CONTACT], np.asarray(ours.stop_contact))


def test_counters_and_end_state_are_the_kernels(both):
    name, ours, theirs = both
    assert theirs.steps == ours.run["steps"]
    assert theirs.run_flags[K.I_N_STICKS] == ours.run["stick_events"]
    assert theirs.run_flags[K.I_N_CONTACTS] == ours.run["stop_contacts"]
    if name in EXPECTED_EVENTS:
        counter, least = EXPECTED_EVENTS[name]
        assert ours.run[counter] >= least, f"{name} no longer exercises {counter}"


def test_sampled_case_holds_its_command_between_samples():
    """The sampled controller's command changes only on its samples (every 10th row here)."""
    excitation, isolator, _, _ = CASES["sampled damping"]
    controller = qzs.ControllerParameters(controller_rate=100.0)
    run = simulate_c(excitation, isolator, controller, **settings("sampled damping"))
    motor = run.data[:, K.C_F_MOTOR]
    changes = np.flatnonzero(np.diff(motor) != 0.0) + 1
    assert changes.size > 10 and np.all(changes % 10 == 1)


def test_a_diverging_case_stops_where_the_kernels_stop():
    """A stop far too stiff for the step diverges at its first contact, in C as in the
    kernels: flagged at the same step, with the same last finite state."""
    from qzs.engine import lanes
    from qzs.engine.prepare import prepare_run
    from qzs.export.cmodel import run_prepared

    excitation, isolator, controller, _ = CASES["compliant stops"]
    run = prepare_run(excitation, isolator, controller, **settings("compliant stops"))
    run.params[K.P_STOP_K] = 1e11  # the contact mode far beyond the stable step
    run.params[K.P_STOP_C] = 0.0
    result = run_prepared(run)
    state, flags = run.state.copy(), run.flags.copy()
    steps = int(round(run.duration / run.dt))
    out = np.zeros((steps // run.decimation + 1, K.N_CHANNELS))
    marks = np.zeros((out.shape[0], 2), dtype=bool)
    status, _ = lanes.run_single(run.solver_code, steps, run.decimation, state, flags,
                                 run.params, run.model, *run.packed, out, marks, 1)
    assert result.diverged and status == K.STATUS_DIVERGED
    assert 0 < result.steps == flags[K.I_STEP] < steps
    np.testing.assert_array_equal(result.state[:K.N_ODE], state[:K.N_ODE])
    assert np.all(np.isfinite(result.state[:K.N_ODE]))


def test_a_buffer_of_the_wrong_shape_is_refused_not_overrun():
    """The C writes K.N_CHANNELS doubles a row: a (rows, 24) buffer (the channels before the
    controller's blocks existed) or too few rows is refused with the shape it needs, before the
    C runs (it overran such a buffer and the benchmark's process died with SIGSEGV)."""
    from qzs.engine.prepare import prepare_run
    from qzs.export.cmodel import run_prepared

    run = prepare_run(qzs.Chirp(duration=0.5), duration=0.5, dt=1e-4, sample_rate=1000.0)
    samples = 501
    for out, flags, name in ((np.zeros((samples, 24)), None, "out"),
                             (np.zeros((samples - 1, K.N_CHANNELS)), None, "out"),
                             (np.zeros((samples, K.N_CHANNELS), dtype=np.float32), None, "out"),
                             (np.zeros((samples, K.N_CHANNELS))[:, ::1][::2], None, "out"),
                             (None, np.zeros((samples, 3), dtype=np.uint8), "out_flags"),
                             (None, np.zeros((samples, 2), dtype=bool), "out_flags")):
        with pytest.raises(qzs.ParameterError) as error:
            run_prepared(run, out=out, out_flags=flags)
        assert f"`{name}`" in str(error.value) and name in error.value.options
    good = run_prepared(run, out=np.zeros((samples, K.N_CHANNELS)),
                        out_flags=np.zeros((samples, 2), dtype=np.uint8))
    assert len(good.data) == samples and not good.diverged
