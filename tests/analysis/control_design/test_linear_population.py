"""Linear metrics of a population against python-control, design by design.

python-control is the reference: its transfer functions evaluated, its closed-loop poles,
and the scalar path's margin routine on its loop. The scalar path's loop passes through
``control.minreal``, which rebuilds the polynomials from their roots and moves the response
by up to about 1e-7 relative; against the same loop without ``minreal`` the population's
numbers agree to 1e-10.

Designs drawn at random (seeded) are compared one by one too: across the shipped problem's
bounds, and across the tuning page's ranges of every parameter the linear loop reads (in the
problem's bounds, a loop without its high-pass is stable with or without its damping,
``Cv (k + Kp) > m Ki`` there, so that only the page's ranges hold a design whose stability the
damping decides); half of each without the high-pass (``velocity_highpass = 0``).
"""
import itertools

import control
import numpy as np
import pytest
from helpers import shipped_designs

from qzs import ControllerParameters, IsolatorParameters
from qzs.analysis.control_design import linear_population as lp
from qzs.analysis.control_design.linear_stability import closed_loop_poles
from qzs.analysis.control_design.stability_margins import loop_margins, stability_margins_of
from qzs.analysis.linear import linear_transmissibility, loop_constants

FIELDS = ("gain_margin", "phase_margin", "gain_crossover_frequency",
          "phase_crossover_frequency")


def _table():
    cases = [(IsolatorParameters(spring_force=sf, stiction_force=fs),
              ControllerParameters(pi_kp=kp, pi_ki=ki, damping_gain=kd))
             for sf, kp, ki, kd, fs in itertools.product((58.0, 68.0), (10.0, 3000.0),
                                                         (0.1, 100.0), (0.0, 400.0),
                                                         (10.0,))]
    rng = np.random.default_rng(34)
    for _ in range(24):  # beyond the bounds: gains up to 8000, high-pass off, 1 or 5 Hz
        cases.append((IsolatorParameters(spring_force=float(rng.uniform(50.0, 70.0))),
                      ControllerParameters(
                          pi_kp=float(np.exp(rng.uniform(0.0, 9.0))),
                          pi_ki=float(rng.choice([0.0, np.exp(rng.uniform(-3.0, 6.0))])),
                          damping_gain=float(rng.choice([0.0, rng.uniform(0.0, 3000.0)])),
                          velocity_highpass=float(rng.choice([0.0, 1.0, 5.0])))))
    cases += [(IsolatorParameters(), ControllerParameters(pi_kp=0.1, pi_ki=0.0)),  # |L| < 1
              (IsolatorParameters(), ControllerParameters(pi_kp=1.0, pi_ki=50.0)),  # unstable
              (IsolatorParameters(), ControllerParameters(pi_kp=5.0, pi_ki=40.0,
                                                          damping_gain=3000.0))]
    return cases


@pytest.fixture(scope="module")
def table():
    cases = _table()
    isolators, controllers = [c[0] for c in cases], [c[1] for c in cases]
    return cases, lp.population_margins(isolators, controllers), isolators, controllers


def _raw_loop(isolator, controller):
    """The scalar path's loop (loop_transfers.loop_transfer) without ``minreal``."""
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller)
    s = control.tf("s")
    plant = 1 / (m * s ** 2 + cv * s + k)
    highpass = s / (s + w) if w > 0 else 1
    return (kp + (ki / s if ki > 0 else 0)) * plant + kd * s * highpass * plant


def _same(ours, theirs, rtol):
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    assert np.array_equal(np.isnan(ours), np.isnan(theirs))
    assert np.array_equal(np.isinf(ours), np.isinf(theirs))
    finite = np.isfinite(theirs)
    np.testing.assert_allclose(ours[finite], theirs[finite], rtol=rtol, atol=0)


def _raw_transmissibility(isolator, controller):
    """The scalar path's ``X/Y`` (linear.linearize) without ``minreal``."""
    m, c, k, kp, ki, kd, w = loop_constants(isolator, controller)
    s = control.tf("s")
    highpass = s / (s + w) if w > 0 else 1
    coupling = c * s + k + kp + (ki / s if ki > 0 else 0)
    return coupling / (m * s ** 2 + coupling + kd * s * highpass)


def test_transmissibility_is_python_controls(table):
    cases, _, isolators, controllers = table
    frequency = np.array([0.05, 1.0, 12.0, 200.0])
    ours = lp.population_transmissibility(frequency, isolators, controllers)
    raw = np.array([np.abs(_raw_transmissibility(i, c)(2j * np.pi * frequency))
                    for i, c in cases])
    np.testing.assert_allclose(ours, raw, rtol=1e-10)
    scalar = np.array([linear_transmissibility(frequency, i, c) for i, c in cases])
    np.testing.assert_allclose(ours, scalar, rtol=1e-6)  # its minreal's share
    one = lp.population_transmissibility(12.0, isolators, controllers)
    np.testing.assert_array_equal(one, ours[:, 2])


def test_stability_is_that_of_python_controls_poles(table):
    cases, margins, *_ = table
    poles = [closed_loop_poles(i, c) for i, c in cases]
    assert margins.stable.tolist() == [bool(np.all(p.real < 0)) for p in poles]
    assert 0 < (~margins.stable).sum() < len(cases)


def test_margins_are_python_controls_on_the_same_loop(table):
    """Within 1e-10 of the margin routine on python-control's loop (no minreal)."""
    cases, margins, *_ = table
    reference = [stability_margins_of(_raw_loop(i, c)) for i, c in cases]
    assert margins.stable.tolist() == [r.stable for r in reference]
    for name in FIELDS:
        _same(getattr(margins, name), [getattr(r, name) for r in reference], 1e-10)
    # the conventions' cases are in the table: no crossover (NaN), no -180 deg (inf)
    assert np.isnan(margins.phase_margin).any() and np.isinf(margins.gain_margin).any()


def test_margins_are_the_scalar_paths_to_its_minreal(table):
    cases, margins, *_ = table
    reference = [loop_margins(i, c) for i, c in cases]
    assert margins.stable.tolist() == [r.stable for r in reference]
    for name in FIELDS:
        _same(getattr(margins, name), [getattr(r, name) for r in reference], 1e-6)


#: Random designs per range (the shipped problem's, the page's): python-control's poles take
#: about 7 ms a design.
RANDOM_DESIGNS = 500
#: The parameters of the linear loop, drawn over the page's ranges in the second half.
LOOP_PARAMETERS = ("mass", "viscous_damping", "spring_force", "pi_kp", "pi_ki", "damping_gain",
                   "velocity_highpass")


@pytest.fixture(scope="module")
def drawn():
    problem = shipped_designs(RANDOM_DESIGNS, seed=39, highpass_off=True)
    page = shipped_designs(RANDOM_DESIGNS, seed=40, highpass_off=True, page=LOOP_PARAMETERS)
    return problem[0] + page[0], problem[1] + page[1]


def test_random_designs_are_stable_where_python_controls_poles_say_so(drawn):
    """Routh-Hurwitz on the population against the closed loop's poles from python-control
    (:func:`closed_loop_poles`: the loop transfer closed by ``control.feedback``, no closed
    form shared), design by design, with and without the high-pass. A design whose largest
    real part is within round-off of zero could go either way: none may decide the test."""
    isolators, controllers = drawn
    stable = lp.population_stable(isolators, controllers)
    poles = [closed_loop_poles(i, c) for i, c in zip(isolators, controllers)]
    largest = np.array([p.real.max() for p in poles])
    size = np.array([np.abs(p).max() for p in poles])
    marginal = np.abs(largest) <= 1e-9 * size
    assert marginal.sum() <= 2
    wrong = np.flatnonzero((stable != (largest < 0)) & ~marginal)
    assert wrong.size == 0, f"{wrong.size} designs differ from python-control's poles: {wrong}"
    assert 0 < stable.sum() < len(stable)
    # without the high-pass, the damping decides some: stable, but not without it
    off = np.array([c.velocity_highpass == 0 for c in controllers])
    without = lp.population_stable(constants={**lp.population_constants(isolators, controllers),
                                              "damping_gain": np.zeros(len(isolators))})
    assert np.any(stable & ~without & off)


def test_random_designs_transmissibility_is_the_scalar_paths(drawn):
    """``|X/Y|`` of every design against :func:`linear_transmissibility` (python-control,
    within its ``minreal``'s 1e-6)."""
    isolators, controllers = drawn
    frequency = np.array([0.1, 2.0, 12.0, 50.0])
    ours = lp.population_transmissibility(frequency, isolators, controllers)
    scalar = np.array([linear_transmissibility(frequency, i, c)
                       for i, c in zip(isolators, controllers)])
    np.testing.assert_allclose(ours, scalar, rtol=1e-6)


def test_a_sampled_controller_goes_through_the_scalar_path():
    isolator = IsolatorParameters()
    controllers = [ControllerParameters(controller_rate=200.0, damping_gain=50.0),
                   ControllerParameters(damping_gain=50.0)]
    margins = lp.population_margins([isolator] * 2, controllers)
    sampled = loop_margins(isolator, controllers[0])
    assert margins.gain_margin[0] == sampled.gain_margin
    assert margins.phase_margin[0] == sampled.phase_margin
    assert margins.stable[0] == sampled.stable
    assert margins.phase_margin[0] != margins.phase_margin[1]  # the sampled loop's own
