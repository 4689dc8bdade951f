"""Hunting of a population against the scalar path (python-control) and a tight integration.

The table spans the shipped problem's bounds (``isolation_vs_effort``: spring force 58-68 N,
Kp 10-3000 N/m, Ki 0.1-100 N/(m*s), Kd 0-400 N*s/m, stiction 5-15 N) at its corners, plus the
cases where the scalar path gives each of its "no cycle" reasons; designs drawn at random
across those bounds (seeded) are compared with the scalar path one by one, verdicts and
numbers.
"""
import itertools
import math

import control
import numpy as np
import pytest
from helpers import shipped_designs
from scipy.integrate import solve_ivp

from qzs import ControllerParameters, IsolatorParameters, ParameterError
from qzs.analysis.control_design import hunting_population as hp
from qzs.analysis.control_design.hunting import integral_loop, predict_hunting
from qzs.analysis.linear import loop_constants


def _table():
    cases = [(IsolatorParameters(spring_force=sf, stiction_force=fs),
              ControllerParameters(pi_kp=kp, pi_ki=ki, damping_gain=kd))
             for sf, kp, ki, kd, fs in itertools.product((58.0, 68.0), (10.0, 3000.0),
                                                         (0.1, 100.0), (0.0, 400.0),
                                                         (5.0, 15.0))]
    cases += [(IsolatorParameters(), ControllerParameters()),
              (IsolatorParameters(), ControllerParameters(velocity_highpass=0.0)),
              (IsolatorParameters(), ControllerParameters(pi_ki=0.0)),  # no integral
              (IsolatorParameters(stribeck_decay=5.0),  # no Stribeck dip: creeps
               ControllerParameters(pi_kp=200.0, pi_ki=80.0)),
              (IsolatorParameters(stiction_force=0.0, coulomb_force=0.0),
               ControllerParameters()),
              (IsolatorParameters(stiction_force=12.0, spring_force=63.0),
               ControllerParameters(pi_kp=300.0, pi_ki=3.0, damping_gain=50.0))]
    return cases


@pytest.fixture(scope="module")
def compared():
    cases = _table()
    population = hp.predict_hunting_population([c[0] for c in cases], [c[1] for c in cases])
    scalar = [predict_hunting(i, c, memoryless=False) for i, c in cases]
    return cases, population, scalar


def test_the_verdicts_are_the_scalar_paths(compared):
    cases, population, scalar = compared
    assert [p.hunts for p in scalar] == population.hunts.tolist()
    assert [p.in_regime for p in scalar] == population.in_regime.tolist()
    # every kind of verdict is in the table: cycles, no crossing, no jump, no integral, ...
    reasons = {p.reasons.get("hunts", "")[:12] for p in scalar}
    assert len(reasons) >= 5 and 0 < population.hunts.sum() < len(cases)


def test_the_slip_jump_and_plateau_are_the_scalar_paths(compared):
    """Within 1e-6 relative, or 1e-6 of the stiction force where the jump is a small difference."""
    cases, population, scalar = compared
    stiction = np.array([i.stiction_force for i, _ in cases])
    reference = np.array([p.slip_jump for p in scalar])
    assert np.all(np.abs(population.slip_jump - reference) <= 1e-6 * stiction)
    large = reference > 0.1 * stiction
    assert large.sum() > 20
    np.testing.assert_allclose(population.slip_jump[large], reference[large], rtol=1e-6)
    plateau = np.array([p.amplitude for p in scalar])
    np.testing.assert_allclose(population.amplitude[large], plateau[large], rtol=1e-6)
    assert np.array_equal(np.isnan(population.amplitude), np.isnan(plateau))
    np.testing.assert_allclose(population.relay_period, [p.relay_period for p in scalar],
                               rtol=1e-6)
    hunting = population.hunting_amplitude
    assert np.all(hunting[~population.hunts] == 0)
    assert np.all(hunting[population.hunts] == population.amplitude[population.hunts])


def test_the_intersection_solves_python_controls_equation_to_round_off(compared):
    """``1 + G(jw) N(A) = 0`` with python-control's loop and describing function.

    The scalar path's point comes from ``scipy.optimize.minimize`` on ``|1 + G N|^2`` with
    its default tolerance: about 1e-4 relative. The direct solution is exact to round-off,
    and within that refinement's reach of the scalar point.
    """
    cases, population, scalar = compared
    for k in np.flatnonzero(population.hunts):
        isolator, controller = cases[k]
        loop = integral_loop(isolator, controller)
        relay = control.relay_hysteresis_nonlinearity(population.relay_output[k],
                                                      population.switching_force[k])

        def residual(amplitude, omega):
            return abs(1 + loop(1j * omega) * relay.describing_function(amplitude))

        omega = 2 * np.pi * population.frequency[k]
        ours = residual(population.integral_force_amplitude[k], omega)
        theirs = residual(scalar[k].integral_force_amplitude, 2 * np.pi * scalar[k].frequency)
        assert ours < 1e-9 and ours <= theirs
        assert population.frequency[k] == pytest.approx(scalar[k].frequency, rel=1e-3)
        assert population.integral_force_amplitude[k] == pytest.approx(
            scalar[k].integral_force_amplitude, rel=1e-3)
        assert population.first_harmonic_amplitude[k] == pytest.approx(
            scalar[k].first_harmonic_amplitude, rel=1e-3)
        assert population.period[k] == pytest.approx(1 / population.frequency[k], rel=1e-15)
    assert np.all(np.isnan(population.frequency[~population.hunts]))


#: Designs drawn at random across the shipped problem's bounds: the scalar path takes about
#: 0.1 s each. A wrong regime bound (``h + d`` for ``h + 2d``) flips 3.5 % of such designs.
RANDOM_DESIGNS = 240


@pytest.fixture(scope="module")
def drawn():
    isolators, controllers = shipped_designs(RANDOM_DESIGNS, seed=39)
    population = hp.predict_hunting_population(isolators, controllers)
    scalar = [predict_hunting(i, c, memoryless=False) for i, c in zip(isolators, controllers)]
    return isolators, population, scalar


def test_random_shipped_designs_get_the_scalar_paths_verdicts_one_by_one(drawn):
    """Whether each design hunts, and whether its cycle is in the relay's regime (the
    intersection's amplitude below ``h + 2d``), as the scalar path says, design by design;
    the designs lie on both sides of both verdicts. A design whose scalar amplitude lies
    within the two paths' 1e-3 agreement of the bound could go either way: none may decide
    the test (they are counted)."""
    isolators, population, scalar = drawn
    hunts = np.array([p.hunts for p in scalar])
    in_regime = np.array([p.in_regime for p in scalar])
    assert np.array_equal(population.hunts, hunts), np.flatnonzero(population.hunts != hunts)
    bound = np.array([p.switching_force + 2 * p.relay_output for p in scalar])
    amplitude = np.array([p.integral_force_amplitude for p in scalar])
    with np.errstate(invalid="ignore"):
        undecided = np.abs(amplitude / bound - 1) < 1e-3
    assert undecided.sum() <= 2
    flipped = np.flatnonzero((population.in_regime != in_regime) & ~undecided)
    assert flipped.size == 0, f"{flipped.size} designs leave the scalar path's regime: {flipped}"
    assert 0 < in_regime.sum() < hunts.sum() < len(scalar)  # every verdict is drawn
    stiction = np.array([i.stiction_force for i in isolators])
    assert len(set(stiction)) == 3  # the uncertain stiction's three values


def test_random_shipped_designs_get_the_scalar_paths_numbers_one_by_one(drawn):
    """The slip jump within 1e-6 of the stiction force; where the loop hunts, the cycle's
    frequency, integral force amplitude and first harmonic within the scalar path's own
    refinement (1e-3), and the plateau ``d/K`` from the same jump."""
    isolators, population, scalar = drawn
    stiction = np.array([i.stiction_force for i in isolators])
    jump = np.array([p.slip_jump for p in scalar])
    assert np.all(np.abs(population.slip_jump - jump) <= 1e-6 * stiction)
    hunts = population.hunts
    for name in ("frequency", "integral_force_amplitude", "first_harmonic_amplitude"):
        theirs = np.array([getattr(p, name) for p in scalar])
        np.testing.assert_allclose(getattr(population, name)[hunts], theirs[hunts], rtol=1e-3)
        assert np.all(np.isnan(getattr(population, name)[~hunts]))
    plateau = np.array([p.amplitude for p in scalar])
    large = jump > 0.1 * stiction
    np.testing.assert_allclose(population.amplitude[large], plateau[large], rtol=1e-5)


def _tight_jump(isolator, controller):
    """The slip of the scalar path integrated at rtol 1e-13 (DOP853): the jump's truth."""
    m, cv, k, kp, _, kd, w = loop_constants(isolator, controller)
    fs, fc, cbc = isolator.stiction_force, isolator.coulomb_force, isolator.stribeck_decay

    def rates(_, y):
        v, force, lagged = y
        friction = fc + (fs - fc) * math.exp(-cbc * max(v, 0.0))
        return [(force - friction - cv * v - kd * (v - lagged)) / m, -(k + kp) * v,
                w * (v - lagged)]

    def stopped(_, y):
        return y[0] + 1e-15
    stopped.terminal, stopped.direction = True, -1
    solution = solve_ivp(rates, (0.0, 1e4), [0.0, fs * (1 + 1e-6), 0.0], method="DOP853",
                         events=stopped, rtol=1e-13, atol=[1e-16, 1e-14, 1e-16])
    return fs - solution.y[1, -1], solution.t[-1]


def test_slip_jumps_against_a_tight_integration():
    """Closer to the truth than the scalar path's LSODA (rtol 1e-8), small jumps included."""
    cases = [(IsolatorParameters(stiction_force=fs), ControllerParameters(
        pi_kp=kp, damping_gain=kd)) for fs, kp, kd in ((10.0, 50.0, 0.0), (5.0, 3000.0, 0.0),
                                                       (15.0, 10.0, 400.0),
                                                       (5.0, 1483.5, 188.8),
                                                       (10.0, 2000.0, 330.0))]
    jump, duration = hp.slip_jumps([c[0] for c in cases], [c[1] for c in cases])
    for k, (isolator, controller) in enumerate(cases):
        truth, length = _tight_jump(isolator, controller)
        assert abs(jump[k] - truth) <= max(1e-6 * truth, 1e-7 * isolator.stiction_force)
        assert duration[k] == pytest.approx(length, rel=1e-5)


def test_an_empty_population_and_bad_input():
    empty = hp.predict_hunting_population([], [])
    assert empty.hunts.shape == (0,)
    with pytest.raises(ParameterError, match="controllers"):
        hp.predict_hunting_population([IsolatorParameters()], [])


def test_stiff_slips_are_the_scalar_paths_integration(monkeypatch):
    """A large damping gain on a soft loop, and any slip still going after the step budget,
    go through the scalar path's LSODA: its numbers, bit for bit."""
    from qzs.analysis.control_design.hunting import slip_jump

    stiff = [(IsolatorParameters(), ControllerParameters(pi_kp=1.0, damping_gain=4000.0)),
             (IsolatorParameters(), ControllerParameters(pi_kp=20.0, damping_gain=4000.0))]
    jump, duration = hp.slip_jumps([c[0] for c in stiff], [c[1] for c in stiff])
    assert [(j, d) for j, d in zip(jump, duration)] == [slip_jump(*c) for c in stiff]
    plain = [(IsolatorParameters(), ControllerParameters()),
             (IsolatorParameters(stiction_force=15.0), ControllerParameters(pi_kp=900.0))]
    monkeypatch.setattr(hp, "_MAX_STEPS", 5)
    jump, duration = hp.slip_jumps([c[0] for c in plain], [c[1] for c in plain])
    assert [(j, d) for j, d in zip(jump, duration)] == [slip_jump(*c) for c in plain]
