"""The lockstep driver: every lane gives the one-case driver's numbers, bit for bit."""
import numpy as np
import pytest
from helpers import linear_controller, linear_isolator
from numba import njit

import qzs
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.batch import simulate_batch
from qzs.engine.channels import CHANNELS as CHANNELS_ALL
from qzs.engine.channels import FLAGS

# A shaking hard enough for stick-slip, stop impacts (plastic and compliant) and no-PI
# payloads sinking to the lower stop; a third of the controllers sampled at 1 kHz.
EXCITATION = qzs.Chirp(amplitude=0.02, f0=0.2, f1=8.0, duration=4.0)
CHANNELS = ("payload_acceleration", "relative_position", "friction_force", "motor_force")


def _cases(count, seed=1):
    rng = np.random.default_rng(seed)
    cases = []
    for i in range(count):
        isolator = qzs.IsolatorParameters(stiction_force=float(rng.uniform(2.0, 15.0)),
                                          stop_model=("compliant", "plastic")[i % 2])
        controller = qzs.ControllerParameters(
            pi_kp=float(rng.choice([0.0, 0.0, 20.0, 50.0])), pi_ki=float(rng.choice([0.0, 5.0])),
            damping_gain=float(rng.uniform(0.0, 50.0)), controller_rate=(0.0, 1000.0)[i % 3 == 0])
        cases.append((isolator, controller))
    return cases


CASES = _cases(13)


@pytest.mark.parametrize("solver", ["ode3", "rk4", "euler"])
def test_every_lane_equals_its_single_run(solver):
    batch = simulate_batch(CASES, EXCITATION, sample_rate=1000.0, solver=solver,
                           channels=CHANNELS, workers=1)
    sticks = contacts = 0
    for index, (isolator, controller) in enumerate(CASES):
        single = qzs.simulate(EXCITATION, isolator, controller, sample_rate=1000.0,
                              solver=solver)
        for name in CHANNELS:
            assert np.array_equal(batch.channels[name][index], single[name]), (index, name)
        assert batch.stats["stick_events"][index] == single.run["stick_events"]
        assert batch.stats["stop_contacts"][index] == single.run["stop_contacts"]
        sticks += single.run["stick_events"]
        contacts += single.run["stop_contacts"]
    assert sticks > 0 and contacts > 0  # the event paths (pass 2) were taken


@pytest.fixture(scope="module")
def singles():
    """The single runs of the first seven cases (stick-slip, both stop models, a sampled
    controller among them)."""
    return [qzs.simulate(EXCITATION, isolator, controller, sample_rate=1000.0)
            for isolator, controller in CASES[:7]]


@pytest.mark.parametrize("name", [*CHANNELS_ALL, *FLAGS])
def test_each_channel_asked_for_alone_equals_the_single_run(name, singles):
    """Every channel the batch can keep (and each flag), asked for alone, is the single run's
    bit for bit: the lane pass computes each column itself (:func:`qzs.engine.lanes._keep`),
    so a column swapped or computed from the wrong term shows in that channel only."""
    batch = simulate_batch(CASES[:7], EXCITATION, sample_rate=1000.0, channels=(name,),
                           workers=1)
    assert list(batch.channels) == [name]
    for index, single in enumerate(singles):
        assert np.array_equal(batch.channels[name][index], single[name]), (index, name)
    assert any(np.any(single[name] != 0) for single in singles)  # a comparison that can fail
    assert sum(s.run["stick_events"] for s in singles) > 0
    assert sum(s.run["stop_contacts"] for s in singles) > 0


def test_a_lane_does_not_depend_on_its_neighbours():
    order = np.random.default_rng(7).permutation(len(CASES))
    straight = simulate_batch(CASES, EXCITATION, duration=2.0, sample_rate=500.0,
                              channels=("relative_position",), workers=1)
    shuffled = simulate_batch([CASES[i] for i in order], EXCITATION, duration=2.0,
                              sample_rate=500.0, channels=("relative_position",), workers=1)
    assert np.array_equal(shuffled.channels["relative_position"],
                          straight.channels["relative_position"][order])


@pytest.mark.parametrize("count", [3, 5, 7, 11])
def test_padded_calls_give_every_lane_its_single_run(count):
    """Calls whose lanes are not a multiple of LANE_BLOCK run padded with frozen copies of
    lane 0 (a failed one first, here, so the copies are of a lane that stops early)."""
    assert count % _lanes.LANE_BLOCK >= _lanes.PAD_FROM  # padded
    unstable = (linear_isolator(stiffness=1e-9, damping=100.0, stroke_half=1.0,
                                motor_force_max=1e12),
                linear_controller(pi_kp=1e6, controller_rate=100.0))
    cases = [unstable, *CASES[:count - 1]]
    batch = simulate_batch(cases, EXCITATION, duration=2.0, sample_rate=500.0,
                           channels=("relative_position", "motor_force"), workers=1)
    for index, (isolator, controller) in enumerate(cases[1:], start=1):
        single = qzs.simulate(EXCITATION, isolator, controller, duration=2.0,
                              sample_rate=500.0)
        for name in ("relative_position", "motor_force"):
            assert np.array_equal(batch.channels[name][index], single[name]), (index, name)
        assert batch.stats["stick_events"][index] == single.run["stick_events"]
    assert batch.status[0] != 0 and not batch.status[1:].any()


def test_batches_larger_than_one_call_are_split(monkeypatch):
    whole = simulate_batch(CASES[:7], EXCITATION, duration=1.0, sample_rate=500.0,
                           channels=("relative_position",), workers=1)
    monkeypatch.setattr(_lanes, "MAX_LANES", 3)  # calls of 3, 3 and 1 cases
    split = simulate_batch(CASES[:7], EXCITATION, duration=1.0, sample_rate=500.0,
                           channels=("relative_position",), workers=1)
    assert np.array_equal(split.channels["relative_position"],
                          whole.channels["relative_position"])
    assert np.array_equal(split.stats["stick_events"], whole.stats["stick_events"])


@njit(error_model="numpy")  # as the kernels (x/0 is inf); not cached: it inlines kernel code
def _events(cases):
    """``_any_event`` and ``_first_event``'s kind for rows of (z0, v0, z1, v1, mode,
    direction, margin, margin1, plastic, v_reg)."""
    out = np.empty((cases.shape[0], 2), dtype=np.int64)
    for i in range(cases.shape[0]):
        z0, v0, z1, v1, mode, direction, margin, margin1, plastic, v_reg = cases[i]
        P = (6.4, 9.81, 60.84, 78.1, 10.0, 1.0, 100.0, 100.0, -0.1, 0.1, 1e6, 1e3, plastic,
             44.0, -0.06, 50.0, 20.0, 0.0, 6.28, 0.0, 1e-4, v_reg)
        s = (z0, v0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        s1 = (z1, v1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        out[i, 0] = K._any_event(s, s1, int(mode), direction, margin1, P)
        out[i, 1] = K._first_event(0.0, 1e-4, s, s1, int(mode), direction, margin, margin1,
                                   P)[0]
    return out


def test_the_lane_pass_keeps_a_step_only_when_grid_step_finds_no_transition():
    """Pass 1 tests a step with ``_any_event`` (no division) and hands the rest to pass 2:
    wherever it keeps a step, ``grid_step``'s ``_first_event`` must find none."""
    rng = np.random.default_rng(5)
    n = 20000
    pick = lambda values: rng.choice(np.asarray(values, dtype=float), n)  # noqa: E731
    cases = np.column_stack([
        pick([-0.2, -0.1, -0.05, 0.0, 0.1, 0.2]), pick([-1.0, -1e-9, 0.0, 1e-9, 1.0]),
        pick([-0.2, -0.1, -0.05, 0.0, 0.1, 0.2]), pick([-1.0, -1e-9, 0.0, 1e-9, 1.0]),
        pick([K.MODE_SLIP, K.MODE_SLIP, K.MODE_STICK, K.MODE_WALL_LOW, K.MODE_WALL_HIGH]),
        pick([-1.0, 1.0]), pick([-1.0, 0.0, 1.0, np.nan]), pick([-1.0, 0.0, 1.0, np.nan]),
        pick([0.0, 1.0]), pick([0.0, 0.0, 1e-3])])
    out = _events(cases)
    assert np.all(out[out[:, 0] == 0, 1] == 0)          # kept: no transition in it
    assert np.count_nonzero(out[:, 1] != 0) > 1000      # (there are transitions to find)
    # the regularised model has no zero-crossing events
    smooth = (cases[:, 9] > 0) & (cases[:, 8] == 0) & (cases[:, 4] == K.MODE_SLIP)
    assert np.all(out[smooth] == 0)
