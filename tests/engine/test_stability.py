"""The solvers and their linear stability limit (qzs.engine.stability): the textbook real-axis
limits, the largest stable step of a stiff mode in closed form, a run just below it bounded."""
import numpy as np
import pytest
from helpers import linear_controller, linear_isolator

from qzs import (SOLVERS, ControllerParameters, InitialState, IsolatorParameters, Sine,
                 largest_stable_step, simulate)


def test_solver_orders_are_declared():
    assert {name: order for name, (_, order) in SOLVERS.items()} == {"euler": 1, "ode3": 3, "rk4": 4}


# Where each method's stability region |R(z)| <= 1 ends on the negative real axis:
# the real root of R(z) = +-1 closest to 0 (z = 0 itself excluded).
def _real_axis_limit(taylor):
    roots = []
    for level in (1.0, -1.0):
        coefficients = np.array(taylor[::-1], dtype=float)
        coefficients[-1] -= level
        found = np.roots(coefficients)
        roots.extend(found[(np.abs(found.imag) < 1e-9) & (found.real < -1e-9)].real)
    return -max(roots)


REAL_AXIS = {"euler": _real_axis_limit([1, 1]), "ode3": _real_axis_limit([1, 1, 1 / 2, 1 / 6]),
             "rk4": _real_axis_limit([1, 1, 1 / 2, 1 / 6, 1 / 24])}


def test_real_axis_limits_are_the_textbook_values(validation):
    assert REAL_AXIS["euler"] == pytest.approx(2.0, rel=1e-12)
    assert REAL_AXIS["ode3"] == pytest.approx(2.5127, abs=1e-4)
    assert REAL_AXIS["rk4"] == pytest.approx(2.7853, abs=1e-4)
    for solver, textbook in (("ode3", 2.5127), ("rk4", 2.7853)):
        validation(f"{solver}: stability limit h*|lambda| on the negative real axis",
                   f"textbook value {textbook}: the root of the stability polynomial sum z^k/k!",
                   abs(REAL_AXIS[solver] - textbook), 1e-4, measure="absolute error [-]")


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_largest_stable_step_for_a_real_stiff_mode(solver, validation):
    """The charge amplifier's high-pass as the stiffest mode: lambda = -2*pi*f_hp, real."""
    plant = linear_isolator(stiffness=1.0, damping=1.0, stop_model="plastic")
    controller = linear_controller(velocity_highpass=2000.0)
    expected = REAL_AXIS[solver] / (2 * np.pi * 2000.0)
    found = largest_stable_step(plant, controller, solver)
    assert found == pytest.approx(expected, rel=1e-4)
    validation(f"{solver}: largest stable step, a 2 kHz high-pass as the stiffest mode",
               "real-axis limit / (2 pi f_hp)", abs(found / expected - 1), 1e-4)


def test_largest_stable_step_of_euler_for_the_stop_contact_mode(validation):
    """Euler on lambda = s +- i*w is stable for h <= -2*s/|lambda|^2 (closed form)."""
    plant = IsolatorParameters(viscous_damping=100.0, stop_stiffness=1e6, stop_damping=1e3)
    controller = ControllerParameters(velocity_highpass=0.0, damping_gain=0.0)
    m = plant.mass
    k = 1e6 + plant.spring_force * plant.spring_shape + controller.pi_kp
    c = 1e3 + 100.0
    eigenvalue = np.roots([m, c, k])[0]
    assert abs(eigenvalue.imag) > 0
    expected = -2 * eigenvalue.real / abs(eigenvalue) ** 2
    found = largest_stable_step(plant, controller, "euler")
    assert found == pytest.approx(expected, rel=1e-3)
    validation("euler: largest stable step on the compliant stop's mode",
               "h = -2 Re(lambda) / |lambda|^2", abs(found / expected - 1), 1e-3)


def test_run_just_below_the_limit_stays_bounded_on_the_stop():
    """A payload pressed on the compliant stop, at 0.9 of the ode3 limit: no blow-up."""
    plant = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    limit = largest_stable_step(plant, ControllerParameters(pi_kp=0.0, pi_ki=0.0))
    dt = 0.9 * limit
    r = simulate(Sine(amplitude=0.0, frequency=1.0), plant, ControllerParameters(pi_kp=0.0, pi_ki=0.0),
                 duration=200 * dt, dt=dt, sample_rate=1 / dt,
                 initial_state=InitialState(relative_position=-0.139))
    low = r.run["stop_low"]
    assert r.stop_contact[-1]
    static = (plant.mass * plant.gravity - plant.spring_force * np.tanh(-plant.spring_shape * low)) / 1e6
    assert static > 1e-6  # a visible penetration, matched to 0.01 %
    assert np.abs(r.relative_position[-20:] - (low - static)).max() < 1e-4 * static
