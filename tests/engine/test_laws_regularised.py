"""The regularised friction option (``friction_regularisation`` > 0, docs/model.md §3).

``tanh(v/v_reg)`` in place of the slip direction, no stick-slip events: the model a solver
without events (JAX, solve_ivp) can integrate, kept beside the exact one for comparisons.
"""
import numpy as np
import pytest
from helpers import SHORT_CHIRP, stick_rises

import qzs
from qzs import ControllerParameters, InitialState, IsolatorParameters, Sine, simulate
from qzs.engine import laws
from qzs.engine.batch import simulate_batch
from qzs.errors import ParameterError, StabilityError
from qzs.model.isolator import friction_force
from qzs.model.registry import parameter_info

V_REG = 1e-3  # [m/s]
REGULARISED = IsolatorParameters(friction_regularisation=V_REG)


@pytest.fixture(scope="module")
def chirp_runs():
    """The default case on 20 s of the paper's chirp, exact and regularised, every step."""
    return (simulate(SHORT_CHIRP, dt=1e-4, sample_rate=1e4),
            simulate(SHORT_CHIRP, REGULARISED, dt=1e-4, sample_rate=1e4))


def test_the_regularised_payload_never_locks_where_the_exact_one_sticks(chirp_runs):
    exact, regularised = chirp_runs
    assert exact.run["stick_events"] > 0 and exact.locked.any()  # the case does stick-slip
    assert regularised.run["stick_events"] == 0
    assert not regularised.locked.any() and stick_rises(regularised.locked) == 0
    # it creeps instead: slow, but never held at exactly zero for long
    assert np.count_nonzero(regularised.relative_velocity == 0.0) <= 1


def test_the_energy_ledger_closes_with_regularised_friction(chirp_runs):
    r = chirp_runs[1]
    throughput = np.abs(r.base_work).max()
    assert throughput > 1.0
    assert np.abs(r.energy_residual()).max() < 1e-4 * throughput
    # friction only dissipates: tanh(v/v_reg) has the sign of v
    assert (r.friction_force * r.relative_velocity).max() <= 1e-12
    assert np.diff(r.friction_dissipation).min() >= -1e-12


def test_regularised_run_approaches_the_exact_one_as_v_reg_shrinks(validation):
    """A payload that slips all the time (it reverses but never sticks): tanh(v/v_reg) -> sign(v).

    The payload starts at absolute rest, so slipping (v = -A*omega), and a 15 Hz base
    motion reverses it 30 times a second with more force than friction can hold.
    """
    amplitude, frequency = 0.010, 15.0
    excitation = Sine(amplitude=amplitude, frequency=frequency, fade_in=0.0)
    start = InitialState(relative_velocity=-amplitude * 2 * np.pi * frequency)
    run = dict(duration=1.0, dt=1e-4, sample_rate=1e4, initial_state=start)
    exact = simulate(excitation, **run)
    assert exact.run["stick_events"] == 0 and not exact.locked.any()
    signs = np.sign(exact.relative_velocity[exact.relative_velocity != 0])
    assert np.count_nonzero(np.diff(signs)) >= 20  # it does pass v = 0, many times
    size = np.sqrt(np.mean(exact.payload_acceleration**2))
    errors = []
    for v_reg in (1e-2, 1e-3, 1e-4):
        r = simulate(excitation, IsolatorParameters(friction_regularisation=v_reg), **run)
        difference = r.payload_acceleration - exact.payload_acceleration
        errors.append(np.sqrt(np.mean(difference**2)) / size)
    assert errors[0] > 2 * errors[1] > 4 * errors[2]  # shrinks with v_reg ...
    assert errors[0] > 1e-3 and errors[2] < 2e-4      # ... from visible to negligible
    validation("Regularised friction, v_reg = 1e-4 m/s, against the exact stick-slip model",
               "tanh(v/v_reg) -> sign(v): the exact model's payload acceleration",
               errors[2], 2e-4, measure="rms difference / rms acceleration")


def test_every_lane_equals_its_single_run_with_regularised_friction():
    """Regularised and exact cases in one batch: each gives its single run's bits."""
    excitation = qzs.Chirp(amplitude=0.02, f0=0.2, f1=8.0, duration=3.0)
    rng = np.random.default_rng(3)
    cases = []
    for i in range(9):
        isolator = IsolatorParameters(stiction_force=float(rng.uniform(2.0, 15.0)),
                                      friction_regularisation=(0.0, 1e-3, 1e-2)[i % 3])
        controller = ControllerParameters(pi_kp=float(rng.choice([0.0, 20.0, 50.0])),
                                          pi_ki=float(rng.choice([0.0, 5.0])),
                                          damping_gain=float(rng.uniform(0.0, 50.0)),
                                          controller_rate=(0.0, 1000.0)[i % 4 == 0])
        cases.append((isolator, controller))
    channels = ("payload_acceleration", "relative_position", "friction_force", "motor_force")
    for subset in (cases, [c for c in cases if c[0].friction_regularisation > 0]):
        batch = simulate_batch(subset, excitation, sample_rate=1000.0, channels=channels,
                               workers=1)
        for index, (isolator, controller) in enumerate(subset):
            single = simulate(excitation, isolator, controller, sample_rate=1000.0)
            for name in channels:
                assert np.array_equal(batch.channels[name][index], single[name]), (index, name)
            assert batch.stats["stick_events"][index] == single.run["stick_events"]
            if isolator.friction_regularisation > 0:
                assert single.run["stick_events"] == 0 and not single.locked.any()


def test_regularised_law_equals_the_numpy_law():
    v = np.concatenate([-np.logspace(-9, 1, 300), [0.0], np.logspace(-9, 1, 300)])
    p = IsolatorParameters(stiction_force=12.0, coulomb_force=2.5, stribeck_decay=40.0,
                           viscous_damping=80.0, friction_regularisation=2e-3)
    numba = np.array([laws.sliding_friction_law(x, 1.0, 12.0, 2.5, 40.0, 80.0, 2e-3) for x in v])
    np.testing.assert_allclose(numba, friction_force(v, p), rtol=1e-14, atol=1e-14)
    assert numba[300] == 0.0 and np.all(numba * v <= 0)
    # far beyond v_reg it is the exact law
    exact = np.array([laws.sliding_friction_law(x, np.sign(x), 12.0, 2.5, 40.0, 80.0, 0.0)
                      for x in v])
    far = np.abs(v) > 40 * 2e-3
    np.testing.assert_allclose(numba[far], exact[far], rtol=1e-15)


@pytest.mark.parametrize("kwargs, match", [
    (dict(friction_regularisation=-1e-3), "`friction_regularisation` must be non-negative"),
    (dict(friction_regularisation=float("nan")), "`friction_regularisation` must be finite"),
    (dict(friction_regularisation="small"), "`friction_regularisation` must be a number"),
    (dict(friction_regularisation=1e-3, stop_model="plastic"),
     "`friction_regularisation` .* needs `stop_model='compliant'`"),
])
def test_a_bad_value_is_named(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        IsolatorParameters(**kwargs)


def test_a_locked_start_is_refused_and_a_too_small_v_reg_is_unstable():
    with pytest.raises(ParameterError, match="`locked` must not be True with "
                                             "`friction_regularisation`"):
        simulate(SHORT_CHIRP, REGULARISED, duration=0.1, initial_state=InitialState(locked=True))
    with pytest.raises(StabilityError, match="raise `friction_regularisation`"):
        simulate(SHORT_CHIRP, IsolatorParameters(friction_regularisation=1e-5), duration=0.1)
    assert qzs.largest_stable_step(IsolatorParameters(friction_regularisation=1e-5)) < \
        qzs.largest_stable_step(REGULARISED) <= qzs.largest_stable_step()


def test_the_default_is_the_exact_model():
    assert IsolatorParameters().friction_regularisation == 0.0
    assert parameter_info("friction_regularisation").unit == "m/s"
