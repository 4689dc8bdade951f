"""Physics of qzs.simulate: closed forms, convergence order, energy, stick-slip, hard stops.

Runs are short; the shared ones are session fixtures in conftest.py.
"""
from typing import NamedTuple

import numpy as np
import pytest
from helpers import PASSIVE, SHORT_CHIRP, linear_controller, linear_isolator, stick_rises

from qzs import (
    ControllerParameters,
    InitialState,
    IsolatorParameters,
    Sine,
    friction_force,
    simulate,
    spring_force,
)
from qzs.model import spring_energy

DEFAULT_PLANT = IsolatorParameters()


# ====================================================================== 1. linear limit
MASS, STIFFNESS, DAMPING = 6.4, 100.0, 100.0
# PI gains placing the PI-only loop's three poles near -5.2 1/s: m*(s + 5.2)^3 has
# s^2-coefficient 15.6*m = 99.8 ~ c, so Kp = 3*5.2^2*m - k and Ki = 5.2^3*m.
KP = 3 * 5.2**2 * MASS - STIFFNESS
KI = 5.2**3 * MASS
CASES = {
    "pi": dict(pi_kp=KP, pi_ki=KI),
    "pi+damping+highpass": dict(pi_kp=KP, pi_ki=KI, damping_gain=50.0, velocity_highpass=1.0),
}


def _closed_loop(controller):
    """Transmissibility X/Y(s) and the closed-loop characteristic polynomial (in s)."""
    kd, wh = controller.damping_gain, 2 * np.pi * controller.velocity_highpass
    kp, ki = controller.pi_kp, controller.pi_ki

    def transmissibility(s):
        highpass = s / (s + wh) if wh > 0 else 1.0
        numerator = STIFFNESS + DAMPING * s + kp + ki / s
        return numerator / (MASS * s**2 + numerator + kd * s * highpass)

    loop = np.array([MASS, DAMPING, STIFFNESS + kp, ki])  # s * (m s^2 + c s + k + Kp + Ki/s)
    if wh > 0:  # times (s + wh), plus Kd s^3
        characteristic = np.polyadd(np.polymul(loop, [1.0, wh]), [kd, 0.0, 0.0, 0.0])
    else:
        characteristic = np.polyadd(loop, [kd, 0.0, 0.0])
    return transmissibility, characteristic


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("frequency", [0.3, 1.0, 3.0, 10.0])
def test_frictionless_linear_limit_matches_closed_form_transmissibility(case, frequency, validation):
    """X/Y(s) = (k + c s + Kp + Ki/s) / (m s^2 + k + c s + Kp + Ki/s + Kd s HP(s)).

    The run is long enough for the slowest closed-loop pole to decay by 1e-9 (with a
    margin of 1.5 for repeated poles), then amplitude and phase of the payload
    displacement are fitted by least squares over the following whole cycles.
    """
    controller = linear_controller(**CASES[case])
    transmissibility, characteristic = _closed_loop(controller)
    poles = np.roots(characteristic)
    slowest = -poles.real.max()
    assert slowest > 2.0  # well damped: every transient decays faster than exp(-2 t)
    period = 1 / frequency
    settle = np.ceil(1.5 * np.log(1e9) / slowest / period) * period
    cycles = max(2, int(np.ceil(2 * frequency)))
    amplitude = 0.010
    r = simulate(Sine(amplitude=amplitude, frequency=frequency, fade_in=0.0), linear_isolator(STIFFNESS, DAMPING, MASS),
                 controller, duration=settle + cycles * period, dt=1e-4, sample_rate=1000.0)
    assert r.run["stop_contacts"] == 0
    steady = r.time >= settle - 1e-9
    t, x = r.time[steady][:-1], r.payload_displacement[steady][:-1]
    w = 2 * np.pi * frequency
    design = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
    (in_phase, quadrature, offset), residual, *_ = np.linalg.lstsq(design, x, rcond=None)
    measured = (in_phase + 1j * quadrature) / amplitude  # x = Im(X e^{jwt}) for y = Im(A e^{jwt})
    expected = transmissibility(1j * w)
    assert abs(measured) == pytest.approx(abs(expected), rel=1e-5)
    assert np.angle(measured / expected) == pytest.approx(0.0, abs=1e-5)
    assert np.sqrt(residual[0] / len(t)) < 1e-6 * amplitude  # nothing but the sine is left
    reference = ("X/Y = (k + c s + Kp + Ki/s) / (m s^2 + k + c s + Kp + Ki/s + Kd s HP(s)) at "
                 "s = jw, frictionless linear plant")
    validation(f"Linear limit ({case}): |X/Y| at {frequency} Hz", reference,
               abs(abs(measured) / abs(expected) - 1), 1e-5)
    validation(f"Linear limit ({case}): phase of X/Y at {frequency} Hz", reference,
               abs(np.angle(measured / expected)), 1e-5, measure="absolute error [rad]")
    if case == "pi+damping+highpass":  # the damping term matters: without it the answer differs
        without, _ = _closed_loop(linear_controller(**CASES["pi"]))
        assert abs(without(1j * w) - expected) > 1e-3 * abs(expected)


# ====================================================================== 2. convergence order
class Case(NamedTuple):
    plant: IsolatorParameters
    controller: ControllerParameters
    excitation: Sine
    initial: InitialState
    end: float  # [s]

    def run(self, solver, dt, sample_rate):
        return simulate(self.excitation, self.plant, self.controller, duration=self.end, dt=dt,
                        sample_rate=sample_rate, solver=solver, initial_state=self.initial)


def _final_state(case, solver, k):
    """State at ``case.end`` with dt = 2**-k: z, v, PI command / Kp, measured payload velocity."""
    r = case.run(solver, 2.0**-k, 1 / case.end)
    assert len(r) == 2
    return np.array([r.relative_position[-1], r.relative_velocity[-1], r.pi_force[-1] / case.controller.pi_kp,
                     r.measured_payload_velocity[-1]])


# Frictionless, nonlinear MagSpring, PI + damping + high-pass, no stop in reach; a payload
# thrown upwards at 3 m/s so that its slip velocity never reaches zero in the 0.25 s.
SMOOTH = Case(IsolatorParameters(gravity=0.0, stiction_force=0.0, coulomb_force=0.0, spring_force=10.0,
                                 viscous_damping=10.0, stop_center=0.0, stroke_half=10.0, motor_force_max=1e9,
                                 stop_model="plastic"),
              ControllerParameters(position_setpoint=0.0, pi_kp=50.0, pi_ki=20.0, damping_gain=5.0,
                                   velocity_highpass=1.0),
              Sine(amplitude=0.001, frequency=10.0, fade_in=0.0), InitialState(relative_velocity=3.0), 0.25)
# The same frictionless plant with a slower, larger base motion: the slip velocity now changes
# sign twice in the 1 s. The equations are just as smooth (no friction: Fs = Fc = 0).
OSCILLATING = SMOOTH._replace(excitation=Sine(amplitude=0.010, frequency=2.0, fade_in=0.0),
                              initial=InitialState(relative_velocity=0.3), end=1.0)
STEPS = {"euler": range(10, 17), "ode3": range(10, 15), "rk4": range(8, 12)}
ORDERS = {"euler": 1, "ode3": 3, "rk4": 4}


def _observed_order(case, solver):
    """Slope of log(error) against log(dt), error against rk4 at dt = 2**-20 (diffrax style)."""
    reference = _final_state(case, "rk4", 20)
    ks = STEPS[solver]
    errors = np.array([np.abs(_final_state(case, solver, k) - reference).max() for k in ks])
    assert errors.min() > 1e-13  # above rounding: the slope measures truncation error
    return np.polyfit(np.log(2.0 ** -np.array(ks)), np.log(errors), 1)[0]


def test_smooth_case_never_reaches_zero_slip():
    r = SMOOTH.run("rk4", 2.0**-12, 2.0**12)
    assert r.relative_velocity.min() > 0.3 and not r.locked.any()
    assert r.run["stick_events"] == 0 and r.run["stop_contacts"] == 0


def test_oscillating_case_reverses_without_sticking():
    r = OSCILLATING.run("rk4", 2.0**-12, 2.0**12)
    signs = np.sign(r.relative_velocity)
    signs = signs[signs != 0]  # a sample may land exactly on a located reversal (v = 0)
    assert np.count_nonzero(np.diff(signs)) >= 2  # it reverses, and never sticks:
    assert r.run["stick_events"] == 0 and r.locked.sum() == 0


def _record_order(validation, solver, slope, what):
    order = ORDERS[solver]
    validation(f"{solver}: observed convergence order, {what}",
               f"order {order}: log-log slope of the final-state error over dt = 2^-k "
               "(reference: rk4 at dt = 2^-20)", abs(slope - order), 0.3,
               measure=f"|slope - {order}|, slope {slope:.3f}")


@pytest.mark.parametrize("solver", list(ORDERS))
def test_integrator_converges_at_its_order(solver, validation):
    slope = _observed_order(SMOOTH, solver)
    assert slope == pytest.approx(ORDERS[solver], abs=0.3)
    _record_order(validation, solver, slope, "smooth run (frictionless MagSpring, PI + damping)")


@pytest.mark.parametrize("solver", ["ode3", "rk4"])
def test_integrator_keeps_its_order_through_velocity_reversals(solver, validation):
    slope = _observed_order(OSCILLATING, solver)
    assert slope == pytest.approx(ORDERS[solver], abs=0.3)
    _record_order(validation, solver, slope, "through located velocity reversals")


# ====================================================================== 3. energy
RUNS = ["default_chirp_run", "passive_chirp_run", "plastic_sine_run", "sampled_chirp_run"]


@pytest.mark.parametrize("run", RUNS)
def test_friction_power_is_never_positive(run, request):
    r = request.getfixturevalue(run)
    power = r.friction_force * r.relative_velocity
    assert power.max() <= 1e-12
    assert (~r.locked).sum() > 0.05 * len(r)  # the run does slip


@pytest.mark.parametrize("run", RUNS)
def test_energy_ledger_balances(run, request, validation):
    """dE = W_base + W_motor - D_friction - D_stop, up to the integrator's truncation error."""
    r = request.getfixturevalue(run)
    throughput = np.abs(r.base_work).max()
    assert throughput > 1.0  # J: the ledger is exercised
    assert np.abs(r.energy_residual()).max() < 1e-4 * throughput
    validation(f"Energy ledger closes ({run.replace('_', ' ')})",
               "dE = W_base + W_motor - D_friction - D_stop (docs/model.md §8)",
               np.abs(r.energy_residual()).max() / throughput, 1e-4,
               measure="largest residual / largest base work")


def test_compliant_stop_dissipation_never_decreases(passive_chirp_run):
    r = passive_chirp_run
    assert r.run["stop_contacts"] > 0 and r.stop_dissipation[-1] > 0
    assert np.diff(r.stop_dissipation).min() >= -1e-12


def test_friction_dissipation_never_decreases(default_chirp_run):
    r = default_chirp_run
    assert r.run["stick_events"] > 0
    assert np.diff(r.friction_dissipation).min() >= -1e-10


def test_plastic_stop_dissipation_never_decreases(plastic_sine_run):
    r = plastic_sine_run
    assert r.run["stop_contacts"] > 0
    # tolerance: room for booking the O(h^2) position snap onto the stop, 1e5 below the bug
    assert np.diff(r.stop_dissipation).min() >= -1e-6


def test_plastic_impact_dissipates_the_relative_kinetic_energy_on_a_still_base(validation):
    """A still base (amplitude 0): the impact absorbs m*v^2/2 and the ledger shows it as stop loss."""
    plant = IsolatorParameters(stop_model="plastic", stiction_force=0.0, coulomb_force=0.0,
                               viscous_damping=0.0)
    low = -0.140
    r = simulate(Sine(amplitude=0.0, frequency=1.0), plant, PASSIVE, duration=0.05, dt=1e-4, sample_rate=1e4,
                 initial_state=InitialState(relative_position=low + 0.01, relative_velocity=-1.0))
    assert r.run["stop_contacts"] == 1
    hit = np.argmax(r.stop_dissipation > 0)
    m, g = plant.mass, plant.gravity
    deficit = m * g - spring_force(r.relative_position[hit - 1], plant)  # net downward force, ~2 N
    v_before = r.relative_velocity[hit - 1]
    dz = r.relative_position[hit - 1] - low
    v_impact = -np.sqrt(v_before**2 + 2 * deficit / m * dz)  # energy, over the last 0.1 mm
    assert r.stop_dissipation[hit] == pytest.approx(0.5 * m * v_impact**2, rel=1e-4)
    validation("Plastic impact on a still base: energy booked as stop loss",
               "m v^2 / 2 at the impact velocity (energy balance over the last 0.1 mm)",
               abs(r.stop_dissipation[hit] / (0.5 * m * v_impact**2) - 1), 1e-4)
    assert np.all(r.relative_position >= low) and r.locked[hit:].all()


# ====================================================================== 4. stuck payload
def test_large_stiction_moves_the_payload_exactly_with_the_base(validation):
    plant = IsolatorParameters(stiction_force=1e6, coulomb_force=1.0)
    r = simulate(SHORT_CHIRP, plant, duration=20.0, dt=1e-4, sample_rate=1000.0)
    assert r.locked.all()
    assert np.all(r.relative_position == r.relative_position[0])
    assert np.all(r.relative_velocity == 0.0)
    np.testing.assert_array_equal(r.payload_acceleration, r.base_acceleration)
    assert r.run["stick_events"] == 0
    assert np.abs(r.friction_force).max() > 100.0  # friction is really holding (m*ydd up to 1000 N)
    validation("Huge stiction: the payload moves exactly with the base", "x'' = y'' (locked)",
               np.abs(r.payload_acceleration - r.base_acceleration).max(), 0.0,
               measure="absolute error [m/s^2]")


def test_breakaway_happens_when_the_holding_force_reaches_stiction(validation):
    """Stuck at rest on a sine base with the motor carrying the weight deficit (bumpless start):
    friction must supply ``m*A*w^2*sin(w t)``, which reaches Fs at ``t* = asin(Fs/(m A w^2))/w``."""
    amplitude, frequency, dt = 0.010, 2.5, 1e-5
    w = 2 * np.pi * frequency
    m, fs = DEFAULT_PLANT.mass, DEFAULT_PLANT.stiction_force
    assert m * amplitude * w**2 > fs
    breakaway = np.arcsin(fs / (m * amplitude * w**2)) / w
    r = simulate(Sine(amplitude=amplitude, frequency=frequency, fade_in=0.0), duration=0.1, dt=dt, sample_rate=1 / dt)
    first_slip = np.argmin(r.locked)
    assert r.time[first_slip - 1] <= breakaway < r.time[first_slip]
    np.testing.assert_allclose(r.friction_force[:first_slip],
                               -m * amplitude * w**2 * np.sin(w * r.time[:first_slip]), rtol=0, atol=1e-9)
    validation("Holding force of a stuck payload until breakaway", "-m A w^2 sin(w t), breaking "
               "away at t* = asin(Fs / (m A w^2)) / w", np.abs(
                   r.friction_force[:first_slip]
                   + m * amplitude * w**2 * np.sin(w * r.time[:first_slip])).max(), 1e-9,
               measure="absolute error [N]")


# ====================================================================== 5. hard stops
def _penetration(r):
    z = r.relative_position
    return max((r.run["stop_low"] - z).max(), (z - r.run["stop_high"]).max())


def _penetration_bound(r):
    """Kinetic energy into the contact spring plus the largest quasi-static push [m]."""
    p, c = r.isolator, r.controller
    push = (p.mass * p.gravity + p.motor_force_max + p.spring_force + p.stiction_force
            + p.mass * np.abs(r.base_acceleration).max())
    v_impact = np.abs(r.relative_velocity).max()
    return v_impact * np.sqrt(p.mass / p.stop_stiffness) + push / p.stop_stiffness


def test_compliant_stop_penetration_stays_within_the_energy_bound(passive_chirp_run, validation):
    r = passive_chirp_run
    assert r.run["stop_contacts"] > 0 and r.stop_contact.any()
    assert 0 < _penetration(r) <= _penetration_bound(r)
    validation("Compliant stop: penetration of the passive chirp run",
               "bound v sqrt(m/k_stop) + F_push/k_stop (impact energy + quasi-static push)",
               _penetration(r) / _penetration_bound(r), 1.0, measure="penetration / bound")


def test_fast_head_on_impact_on_the_compliant_stop():
    plant = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0, viscous_damping=0.0)
    r = simulate(Sine(amplitude=0.0, frequency=1.0), plant, PASSIVE, duration=0.1, dt=1e-5, sample_rate=1e5,
                 initial_state=InitialState(relative_velocity=-2.0))  # (0.19 s: the upper stop)
    assert r.run["stop_contacts"] == 1
    undamped = 2.0 * np.sqrt(plant.mass / plant.stop_stiffness)  # 5 mm
    assert 0.5 * undamped < _penetration(r) <= _penetration_bound(r)
    assert r.relative_velocity[-1] > 0.5  # it bounced back
    assert r.stop_dissipation[-1] > 0


@pytest.mark.parametrize("run", ["passive_chirp_run", "default_chirp_run"])
def test_compliant_stop_pushes_and_never_pulls(run, request):
    r = request.getfixturevalue(run)
    z, force = r.relative_position, r.stop_force
    below, above = z < r.run["stop_low"], z > r.run["stop_high"]
    assert np.all(force[below] >= 0) and np.all(force[above] <= 0)
    assert np.all(force[~below & ~above] == 0)
    np.testing.assert_array_equal(r.stop_contact, below | above)


def test_plastic_stop_is_never_passed(plastic_sine_run):
    r = plastic_sine_run
    assert r.run["stop_contacts"] > 0 and r.stop_contact.any()
    assert np.all(r.relative_position >= r.run["stop_low"])
    assert np.all(r.relative_position <= r.run["stop_high"])
    on_wall = r.relative_position == r.run["stop_low"]
    assert on_wall.any() and np.all(r.relative_velocity[on_wall] == 0)


# ====================================================================== 6. gravity: passive sinks
@pytest.fixture(scope="module")
def sine_3hz_runs():
    excitation = Sine(amplitude=0.010, frequency=3.0, fade_in=0.0)
    return (simulate(excitation, controller=PASSIVE, duration=10.0, sample_rate=1000.0),
            simulate(excitation, duration=10.0, sample_rate=1000.0))


def test_passive_isolator_sinks_to_the_lower_stop(sine_3hz_runs):
    """docs/model.md §5 (gravity): m*g exceeds the spring plateau; once stiction breaks it drifts down."""
    passive, _ = sine_3hz_runs
    low = passive.run["stop_low"]
    assert low == pytest.approx(-0.060 - 0.080)
    assert passive.run["stop_contacts"] > 0
    last = passive.time > 8.0  # it rattles on the stop: within the lowest sixth of the stroke
    assert np.all(passive.relative_position[last] < low + 0.16 / 6)
    assert passive.relative_position[last].mean() < low + 0.015


def test_pi_loop_holds_the_payload_near_the_setpoint(sine_3hz_runs):
    _, controlled = sine_3hz_runs
    assert controlled.run["stop_contacts"] == 0
    assert np.abs(controlled.relative_position + 0.060).max() < 0.03
    last = controlled.time > 8.0
    assert abs(controlled.relative_position[last].mean() + 0.060) < 0.005
    assert (~controlled.locked).any()  # it did slip


# ====================================================================== stick-slip logic
def test_locked_samples_hold_within_stiction(default_chirp_run, passive_chirp_run):
    for r in (default_chirp_run, passive_chirp_run):
        assert np.all(r.relative_velocity[r.locked] == 0.0)
        np.testing.assert_array_equal(r.payload_acceleration[r.locked], r.base_acceleration[r.locked])
        assert np.abs(r.friction_force[r.locked]).max() <= r.isolator.stiction_force * (1 + 1e-12)
        assert np.all(r.relative_velocity[~r.locked] != 0.0)


def test_plastic_impact_with_the_base_pulling_away_releases_at_once():
    low = -0.140
    r = simulate(Sine(amplitude=0.010, frequency=10.0, phase=np.pi / 2, fade_in=0.0),  # ydd(0) = -39.5 m/s^2
                 IsolatorParameters(stop_model="plastic"), PASSIVE, duration=0.002, dt=1e-4, sample_rate=1e4,
                 initial_state=InitialState(relative_position=low + 1e-4, relative_velocity=-0.5))
    assert r.run["stop_contacts"] == 1
    held = r.locked
    assert np.abs(r.friction_force[held]).max(initial=0.0) <= 10.0 * (1 + 1e-12)


def test_no_chatter_and_plausible_stick_events(default_chirp_run):
    r = default_chirp_run
    locked = r.locked
    isolated = (locked[1:-1] != locked[:-2]) & (locked[1:-1] != locked[2:])
    transitions = np.count_nonzero(np.diff(locked.astype(np.int8)))
    assert transitions >= 3
    assert isolated.sum() <= 0.01 * transitions
    cycles = 0.5 * (SHORT_CHIRP.f0 + SHORT_CHIRP.f1) * 20.0  # 200 cycles of the chirp
    assert 1 <= r.run["stick_events"] <= 2 * cycles
    assert r.run["stick_events"] == stick_rises(locked)


def test_payload_sticks_at_every_velocity_reversal_of_a_slow_sine():
    """2 Hz, 10 mm: friction breaks each half cycle and holds the payload at each reversal."""
    r = simulate(Sine(amplitude=0.010, frequency=2.0, fade_in=0.0), duration=10.0, dt=1e-4, sample_rate=1e4)
    cycles = 20
    sticks = r.run["stick_events"]
    assert 2 * cycles - 2 <= sticks <= 2 * cycles
    assert sticks == stick_rises(r.locked)
    runs = np.diff(np.flatnonzero(np.diff(r.locked.astype(np.int8))))
    assert runs.min() >= 10  # every stick and every slip phase lasts at least 1 ms


def test_a_single_stick_is_counted_once():
    """Started slipping at zero velocity where friction can hold: it sticks once and stays."""
    r = simulate(Sine(amplitude=0.001, frequency=1.0, fade_in=0.0), duration=0.01, dt=1e-4, sample_rate=1e4,
                 initial_state=InitialState(locked=False))
    assert r.locked[1:].all()
    assert r.run["stick_events"] == 1


def test_frictionless_start_stuck_or_slipping_is_the_same_motion():
    excitation = Sine(amplitude=0.010, frequency=1.0, fade_in=0.0)
    plant, controller = linear_isolator(), linear_controller(pi_kp=100.0)
    stuck = simulate(excitation, plant, controller, duration=1.0, sample_rate=1000.0)
    slipping = simulate(excitation, plant, controller, duration=1.0, sample_rate=1000.0,
                        initial_state=InitialState(locked=False))
    assert stuck.locked[0] and not slipping.locked[0]
    scale = np.abs(slipping.relative_position).max()
    np.testing.assert_allclose(stuck.relative_position, slipping.relative_position, rtol=0, atol=1e-12 * scale)


# ====================================================================== plain-numpy reference
@pytest.mark.parametrize("run", RUNS)
def test_every_sample_obeys_the_equation_of_motion_and_force_laws(run, request, validation):
    r = request.getfixturevalue(run)
    p = r.isolator
    forces = r.spring_force + r.friction_force + r.stop_force + r.motor_force - p.mass * p.gravity
    np.testing.assert_allclose(p.mass * r.payload_acceleration, forces, rtol=0, atol=1e-9)
    validation(f"Equation of motion in every sample ({run.replace('_', ' ')})",
               "m x'' = F_spring + F_friction + F_stop + F_motor - m g (docs/model.md §2)",
               np.abs(p.mass * r.payload_acceleration - forces).max(), 1e-9,
               measure="absolute error [N]")
    np.testing.assert_allclose(r.spring_force, spring_force(r.relative_position, p), rtol=0, atol=1e-11)
    np.testing.assert_allclose(r.spring_energy, spring_energy(r.relative_position, p), rtol=0, atol=1e-12)
    slipping = ~r.locked
    np.testing.assert_allclose(r.friction_force[slipping], friction_force(r.relative_velocity[slipping], p),
                               rtol=0, atol=1e-11)  # kernel exp/tanh: ~1e-13 relative
    np.testing.assert_allclose(r.kinetic_energy, 0.5 * p.mass * r.payload_velocity**2, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r.gravity_energy, p.mass * p.gravity * r.payload_displacement, rtol=0,
                               atol=1e-12)
