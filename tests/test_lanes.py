"""The lockstep driver: every lane gives the one-case driver's numbers, bit for bit."""
import numpy as np
import pytest

import qzs
from qzs.engine import lanes as _lanes
from qzs.engine.batch import simulate_batch

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


def test_a_lane_does_not_depend_on_its_neighbours():
    order = np.random.default_rng(7).permutation(len(CASES))
    straight = simulate_batch(CASES, EXCITATION, duration=2.0, sample_rate=500.0,
                              channels=("relative_position",), workers=1)
    shuffled = simulate_batch([CASES[i] for i in order], EXCITATION, duration=2.0,
                              sample_rate=500.0, channels=("relative_position",), workers=1)
    assert np.array_equal(shuffled.channels["relative_position"],
                          straight.channels["relative_position"][order])


def test_batches_larger_than_one_call_are_split(monkeypatch):
    whole = simulate_batch(CASES[:7], EXCITATION, duration=1.0, sample_rate=500.0,
                           channels=("relative_position",), workers=1)
    monkeypatch.setattr(_lanes, "MAX_LANES", 3)  # calls of 3, 3 and 1 cases
    split = simulate_batch(CASES[:7], EXCITATION, duration=1.0, sample_rate=500.0,
                           channels=("relative_position",), workers=1)
    assert np.array_equal(split.channels["relative_position"],
                          whole.channels["relative_position"])
    assert np.array_equal(split.stats["stick_events"], whole.stats["stick_events"])
