"""Harmonic balance of the smooth model (qzs.analysis.harmonic_balance) against independent
references: the linearised closed loop (python-control), the smooth model integrated in time
by scipy (periodic orbit, Floquet multipliers from the monodromy matrix, Liouville's formula),
and the stepped-sine simulation where the response is smooth (a frictionless MagSpring driven
into its softening bend, with folds, an unstable branch and jumps)."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qzs
from qzs import ControllerParameters, IsolatorParameters, ParameterError
from qzs.analysis.harmonic_balance import (SmoothModel, floquet_exponents,
                                           frequency_response_curve, periodic_response,
                                           smooth_right_hand_side)
from qzs.workflows.response import steady_state_response

#: The MagSpring about z = 0, frictionless and lightly damped, no controller, no gravity:
#: a softening oscillator of 4.34 Hz whose resonance leans left and folds.
SOFTENING = dict(isolator=IsolatorParameters(stiction_force=0.0, coulomb_force=0.0,
                                             viscous_damping=3.0, gravity=0.0),
                 controller=ControllerParameters(pi_kp=0.0, pi_ki=0.0, position_setpoint=0.0))
AMPLITUDE = 0.5e-3
#: Harmonics that resolve the softening orbits to 1e-9 m (10 leave 3e-6 m at the peak).
HARMONICS = 20


@pytest.fixture(scope="module")
def softening_curve():
    model = SmoothModel.from_parameters(**SOFTENING, amplitude=AMPLITUDE)
    return frequency_response_curve(model, (3.0, 4.6), harmonics=HARMONICS)


def variational(frequency, model):
    """The smooth ODE with its variational equations, the Jacobian by central differences."""
    def rhs(t, y):
        x, phi = y[:4], y[4:].reshape(4, 4)
        jac = np.empty((4, 4))
        for j in range(4):
            step = np.zeros(4)
            step[j] = 1e-7 * max(1.0, abs(x[j]))
            jac[:, j] = (smooth_right_hand_side(t, x + step, frequency, model)
                         - smooth_right_hand_side(t, x - step, frequency, model)) / (2 * step[j])
        return np.concatenate([smooth_right_hand_side(t, x, frequency, model),
                               (jac @ phi).ravel()])
    return rhs


def monodromy(solution):
    period = 1.0 / solution.frequency
    start = solution.state_at_start()
    sol = solve_ivp(variational(solution.frequency, solution.model), (0, period),
                    np.concatenate([start, np.eye(4).ravel()]), method="DOP853", rtol=1e-11,
                    atol=1e-13)
    return start, sol.y[:4, -1], sol.y[4:, -1].reshape(4, 4)


def test_frictionless_small_motion_is_the_linear_closed_loop(validation):
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    controller = ControllerParameters(damping_gain=30.0)
    # 0.1 mm: the MagSpring's tangent stiffness, steep on its plateau, stays put
    model = SmoothModel.from_parameters(isolator, controller, amplitude=1e-4)
    linear = qzs.linearize(isolator, controller)
    for frequency in (0.2, 1.0, 3.0, 10.0):
        solution = periodic_response(frequency, model, harmonics=5)
        assert solution.converged
        assert solution.transmissibility == pytest.approx(
            float(linear.transmissibility(frequency)), rel=1e-7)
        # the exponents of the orbit are the closed loop's poles (w, I states included)
        exponents = np.sort_complex(floquet_exponents(solution))
        np.testing.assert_allclose(exponents, np.sort_complex(linear.poles), rtol=2e-5)
        validation(f"Harmonic balance, frictionless small motion at {frequency} Hz: T",
                   "the linearised closed loop (python-control)",
                   abs(solution.transmissibility / float(linear.transmissibility(frequency))
                       - 1), 1e-7)
        validation(f"Harmonic balance at {frequency} Hz: Floquet exponents",
                   "the closed loop's poles", np.abs(
                       exponents / np.sort_complex(linear.poles) - 1).max(), 2e-5)


def test_a_solution_is_a_periodic_orbit_of_the_smooth_ode():
    """The paper's default case with Stribeck friction and the PI loop, friction regularised
    over 20 mm/s so that 25 harmonics resolve it: integrated over one period from the
    solution's start, the smooth ODE comes back to it (to the truncation of the harmonics:
    the Stribeck term's |v| leaves a jump in the second derivative at reversal)."""
    model = SmoothModel.from_parameters(amplitude=0.010, friction_velocity=0.02)
    omega = 2 * np.pi * 5.0
    solution = periodic_response(5.0, model)
    assert solution.converged and solution.residual < 1e-9
    start, end, _ = monodromy(solution)
    scale = np.array([model.amplitude, model.amplitude * omega, 1.0, model.amplitude / omega])
    error = np.abs(end - start) / scale
    assert error[0] < 1e-4 and error[1] < 1e-4
    assert error[3] < 1e-3  # the integral sums the small offset of z over the period
    # the integral's mean carries the weight the spring does not: m g - a tanh(b z_ref)
    deficit = model.mass * model.gravity - model.spring(model.position_setpoint)[0]
    assert solution.integral_mean * model.pi_ki == pytest.approx(deficit, rel=1e-2)


def test_steep_friction_needs_more_harmonics_and_gets_better_with_them():
    """At the default 2 mm/s the friction's reversal is steep: the orbit's error falls as
    the harmonics grow, and the fundamental moves less than the orbit does."""
    model = SmoothModel.from_parameters(amplitude=0.010)
    errors, ratios = [], []
    for harmonics in (25, 50):
        solution = periodic_response(5.0, model, harmonics=harmonics)
        start, end, _ = monodromy(solution)
        errors.append(abs(end[1] - start[1]) / (model.amplitude * 2 * np.pi * 5.0))
        ratios.append(solution.transmissibility)
    assert errors[1] < 0.5 * errors[0]
    assert abs(ratios[1] / ratios[0] - 1) < 1e-3


@pytest.mark.parametrize("index", [40, 150, 250])
def test_hill_exponents_are_the_monodromy_matrix_multipliers(softening_curve, index, validation):
    solution = softening_curve.solution(index)
    _, _, phi = monodromy(solution)
    multipliers = np.linalg.eigvals(phi[:2, :2])  # z, v: w and I are not coupled here
    hill = np.exp(floquet_exponents(solution) / solution.frequency)
    np.testing.assert_allclose(np.sort_complex(hill), np.sort_complex(multipliers),
                               rtol=1e-6, atol=1e-8)
    # Liouville: the exponents sum to the period-mean trace, -Cv/m without friction
    assert np.sum(floquet_exponents(solution)).real == pytest.approx(
        -solution.model.viscous_damping / solution.model.mass, rel=1e-8)
    validation(f"Hill's Floquet multipliers, softening orbit at {solution.frequency:.3f} Hz",
               "eigenvalues of the monodromy matrix (scipy DOP853, variational equations)",
               np.abs(np.sort_complex(hill) - np.sort_complex(multipliers)).max(),
               1e-8 + 1e-6 * np.abs(multipliers).max(), measure="absolute error [-]")
    validation(f"Sum of the Floquet exponents at {solution.frequency:.3f} Hz",
               "Liouville's formula: -Cv/m", abs(np.sum(floquet_exponents(solution)).real
                                                 / (-solution.model.viscous_damping
                                                    / solution.model.mass) - 1), 1e-8)


def test_the_softening_resonance_folds_and_is_unstable_between_its_folds(softening_curve):
    curve = softening_curve
    assert len(curve.folds) == 2
    upper, lower = max(curve.folds), min(curve.folds)
    assert 3.3 < lower < 3.5 and 4.0 < upper < 4.1
    # stability changes only at the folds: the middle branch, between them, is unstable
    flips = np.flatnonzero(np.diff(curve.stable.astype(int)))
    assert flips.size == 2
    for i in flips:
        assert min(abs(curve.frequency[i] - f) for f in curve.folds) < 2e-3
    middle = ~curve.stable
    assert np.all(curve.largest_exponent[middle] > 0)
    inside = (curve.frequency > lower - 1e-3) & (curve.frequency < upper + 1e-3)
    assert np.all(inside[middle])
    assert curve.valid.all()


def test_harmonic_balance_is_the_stepped_sine_where_the_response_is_smooth(softening_curve,
                                                                          validation):
    """Every stepped-sine point lies on a stable branch of the harmonic balance (solved at
    its frequency from the nearest point of that branch); the sweeps jump where the
    harmonic balance folds: up just after the upper fold, down just below the lower one."""
    frequencies = np.round(np.arange(3.0, 4.61, 0.1), 10)
    response = steady_state_response(frequencies, AMPLITUDE, **SOFTENING, dt=1e-3,
                                     harmonic_balance=False, workers=2)
    curve = softening_curve
    worst = 0.0
    for direction in ("up", "down"):
        branch = response.branch(direction)
        for f, t in zip(branch["frequency"], branch["transmissibility"]):
            candidates = np.flatnonzero(curve.stable & (np.abs(curve.frequency - f) < 0.05))
            nearest = candidates[np.argmin(np.abs(curve.transmissibility[candidates] - t))]
            exact = periodic_response(f, curve.model, harmonics=HARMONICS,
                                      initial_guess=curve.solution(nearest))
            assert exact.converged
            assert t == pytest.approx(exact.transmissibility, rel=3e-4), (direction, f)
            worst = max(worst, abs(t / exact.transmissibility - 1))
    # each sweep leaves its branch at the fold where the branch ends, or a step before it:
    # close to a fold the branch's basin shrinks below what a 0.1 Hz step disturbs
    lower, upper = min(curve.folds), max(curve.folds)
    jumps = response.jumps()
    ((up_from, up_to),) = jumps["up"]
    ((down_from, down_to),) = jumps["down"]
    assert up_from < upper < up_to + 1e-9
    assert lower < down_from and down_to < lower + 0.1 + 1e-9
    band = response.hysteresis()
    assert band.min() > lower and band.max() < upper
    validation("Stepped sine up and down a folding softening resonance, 3-4.6 Hz",
               "harmonic balance (20 harmonics) on the stable branch",
               worst, 3e-4)


def test_regularised_friction_is_odd_continuous_and_dissipative():
    model = SmoothModel.from_parameters(amplitude=0.01)
    v = np.linspace(-0.2, 0.2, 4001)
    force, slope = model.friction(v)
    np.testing.assert_allclose(force, -model.friction(-v)[0], atol=1e-12)
    assert np.all(force * v <= 0)
    step = 1e-8
    numeric = (model.friction(v + step)[0] - model.friction(v - step)[0]) / (2 * step)
    assert np.max(np.abs(numeric - slope)) < 1e-5 * np.max(np.abs(slope))
    # the level at rest is the stiction; a few v_reg above, the simulator's sliding law
    tiny = 1e-9 * model.friction_velocity
    level = (model.friction(tiny)[0] + model.viscous_damping * tiny) / math.tanh(1e-9)
    assert level == pytest.approx(-model.stiction_force)
    for velocity in (8 * model.friction_velocity, 0.1):
        level = (model.coulomb_force + (model.stiction_force - model.coulomb_force)
                 * math.exp(-model.stribeck_decay * velocity))
        expected = -level - model.viscous_damping * velocity
        assert model.friction(velocity)[0] == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("call, name", [
    (lambda m: periodic_response(0.0, m), "frequency"),
    (lambda m: periodic_response(1.0, m, harmonics=0), "harmonics"),
    (lambda m: periodic_response(1.0, m, harmonics=10, time_points=20), "time_points"),
    (lambda m: periodic_response(1.0, "model"), "model"),
    (lambda m: frequency_response_curve(m, (5.0, 1.0)), "frequency_range"),
    (lambda m: SmoothModel.from_parameters(amplitude=-1.0), "amplitude"),
    (lambda m: SmoothModel.from_parameters(amplitude=0.01, friction_velocity=0.0),
     "friction_velocity"),
])
def test_bad_input_is_refused(call, name):
    model = SmoothModel.from_parameters(amplitude=0.01)
    with pytest.raises(ParameterError, match=name):
        call(model)
