"""The general kernel's spring laws in runs: the energy ledger, a table's convergence to the
law it samples, and an oblique-spring QZS's free oscillation (docs/model.md §3.1)."""
import numpy as np
import pytest

import qzs
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Sine
from qzs.model.isolator import InitialState, IsolatorParameters
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring

SINE = Sine(amplitude=5e-3, frequency=5.0)  # base 4.9 m/s^2: stick-slip
LAWS = {"oblique": ObliqueSpringQZS(),
        "polynomial": PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -2e5), center=-0.06),
        "table": TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.15, 0.03, 181))}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_energy_ledger_closes_for_every_law(name, validation):
    """dE = W_base + W_motor - D_friction - D_stop, as the tanh's test (test_kernels.py)."""
    r = qzs.simulate(SINE, IsolatorParameters(spring=LAWS[name]), duration=2.0)
    assert r.run["stick_events"] > 0  # the stick-slip events run through the law too
    throughput = np.abs(r.base_work).max()
    assert throughput > 0.05  # J: the ledger is exercised
    # the stored energy is the law's: the ledger would not close with another
    np.testing.assert_allclose(r.spring_energy, LAWS[name].energy(r.relative_position),
                               rtol=1e-12, atol=1e-12)
    residual = np.abs(r.energy_residual()).max() / throughput
    assert residual < 1e-8  # the tanh's run: 1.8e-10
    validation(f"Energy ledger closes ({name} spring)",
               "dE = W_base + W_motor - D_friction - D_stop (docs/model.md §8)", residual, 1e-8,
               measure="largest residual / largest base work")


def test_a_table_of_the_tanh_converges_to_the_tanh_run_at_the_interpolants_order(validation):
    """Sampled at h, h/2, h/4 (2, 1, 0.5 mm; PCHIP's force error O(h^3)), the run's largest
    difference in z to the tanh's falls by about 8 each halving. Horizontal, frictionless, about
    the tanh's centre (its stiffness a b there: the slope errors' M2^2/mu term is small)."""
    plant = dict(stiction_force=0.0, coulomb_force=0.0, gravity=0.0)
    controller = ControllerParameters(position_setpoint=0.0)
    excitation = Sine(amplitude=10e-3, frequency=3.0)  # z over -3..2 mm
    tanh = qzs.simulate(excitation, IsolatorParameters(**plant), controller, duration=1.0)
    errors = []
    for intervals in (100, 200, 400):
        table = TabulatedSpring.from_law(TanhSpring(), np.linspace(-0.1, 0.1, intervals + 1))
        run = qzs.simulate(excitation, IsolatorParameters(spring=table, **plant), controller,
                           duration=1.0)
        errors.append(np.abs(run.relative_position - tanh.relative_position).max())
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 1e-7  # m
    assert np.all((orders > 2.7) & (orders < 3.5)), (errors, orders)
    validation("Table of the tanh: the run converges at the interpolant's order (3)",
               f"the tanh run; orders observed {np.round(orders, 2).tolist()}",
               float(np.abs(orders - 3.0).max()), 0.5, measure="largest |order - 3|")


def test_an_oblique_spring_qzs_oscillates_at_its_stiffness_at_the_centre(validation):
    """PI off, no friction: a 0.5 mm release about the centre oscillates at sqrt(k/m)/2 pi with
    k = k_v + 2 k_o (1 - L0/d) (20 N/m above the quasi-zero vertical stiffness)."""
    qzs_law = ObliqueSpringQZS.quasi_zero()
    law = ObliqueSpringQZS(vertical_stiffness=qzs_law.vertical_stiffness + 20.0,
                           preload=6.4 * 9.81)  # carries the payload at the centre
    k = float(law.stiffness(law.center))
    assert k == pytest.approx(20.0, rel=1e-12)
    plant = IsolatorParameters(spring=law, stiction_force=0.0, coulomb_force=0.0,
                               viscous_damping=0.0)
    off = ControllerParameters(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0)
    start = InitialState(relative_position=law.center + 5e-4, locked=False)
    r = qzs.simulate(Sine(amplitude=0.0, frequency=1.0), plant, off, duration=20.0, dt=1e-3,
                     sample_rate=1000.0, initial_state=start)
    u = r.relative_position - law.center
    up = np.flatnonzero((u[:-1] < 0) & (u[1:] >= 0))
    crossings = r.time[up] - u[up] * (r.time[up + 1] - r.time[up]) / (u[up + 1] - u[up])
    measured = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    expected = np.sqrt(k / plant.mass) / (2 * np.pi)
    assert len(crossings) >= 4
    assert measured == pytest.approx(expected, rel=1e-3)
    validation("Oblique-spring QZS: free oscillation at the centre",
               "sqrt(k/m)/2 pi with k = k_v + 2 k_o (1 - L0/d) = 20 N/m",
               abs(measured / expected - 1), 1e-3)


def test_a_payload_stuck_on_a_law_holding_its_weight_stays_stuck_below_the_breakaway():
    """A 10 kg payload on a law that alone holds its weight at the setpoint (98.1 N, where the
    MagSpring's tanh of ``P`` holds 61 N), the base shaking it by ``m |y''| = 5 N`` < Fs = 10 N:
    friction holds it throughout (docs/model.md §3), z never moves. The holding margin is the
    law's: with the tanh's the 37 N it lacks would break the payload away at once."""
    mass = 10.0
    law = PolynomialSpring(coefficients=(mass * 9.81, -300.0, 0.0, -2e5), center=-0.06)
    isolator = IsolatorParameters(mass=mass, gravity=9.81, stiction_force=10.0, spring=law)
    frequency = 2.0
    gentle = Sine(amplitude=0.5 / (2 * np.pi * frequency) ** 2, frequency=frequency,
                  fade_in=0.0)
    r = qzs.simulate(gentle, isolator, duration=1.0)
    assert mass * np.abs(r.base_acceleration).max() == pytest.approx(5.0, rel=1e-3)
    assert r.locked.all()
    assert r.run["stick_events"] == 0
    np.testing.assert_array_equal(r.relative_position, r.relative_position[0])
