"""Periodic stepping (qzs.engine.periodic) against the exact steady state and an uncut run.

* a linear plant (the PI loop's proportional gain as the only spring, viscous damping, no
  friction events) under a sine: the state at the period boundaries converges to the
  closed-form steady state, at the closed-form decay rate of the transient;
* one period per call is one uncut :func:`qzs.simulate` to the last bit;
* a run continued from a carried state is one uninterrupted run to the last bit.
"""
import math

import numpy as np
import pytest
from helpers import LINEAR_SHAPE, linear_controller, linear_isolator

import qzs
from qzs import ControllerParameters, IsolatorParameters, ParameterError, Sine
from qzs.engine.periodic import STATE_VARIABLES, CarriedState, PeriodicRun
from qzs.engine.channels import CHANNELS, FLAGS

MASS = 6.4
#: Names of the energy ledger's channels: integrals that a continued run starts from zero.
LEDGER = ("base_work", "friction_dissipation", "motor_work", "stop_dissipation")


def advance(run, periods):
    """``periods`` periods of ``run``: its output rows and marks, shape (periods, samples, .)."""
    rows, marks = run.output_buffers(periods)
    for i in range(periods):
        assert not run.advance(rows[i], marks[i]), run.divergence()
    return rows, marks


def test_a_linear_plant_converges_to_its_closed_form_steady_state(validation):
    """``m z'' + c z' + k z = -m y''`` with ``y = A cos(w t)``: the steady state is
    ``z = Re(Z e^{iwt})``, ``Z = m A w^2 / (k - m w^2 + i c w)``; at every period boundary
    (t = nT) ``z = Re Z`` and ``v = Re(i w Z)``. The transient decays as
    ``exp(-zeta wn t)``: per period by ``exp(-zeta wn T)``."""
    natural, zeta, frequency, amplitude = 2.0, 0.3, 3.0, 0.005
    wn, w, period = 2 * math.pi * natural, 2 * math.pi * frequency, 1.0 / frequency
    k, c = MASS * wn ** 2, 2 * zeta * MASS * wn
    # the loop's Kp*(z_ref - z) is the spring: linear exactly; no stick-slip events
    isolator = linear_isolator(stiffness=0.0, damping=c, mass=MASS,
                               friction_regularisation=1e-3)
    controller = linear_controller(pi_kp=k)
    steady = MASS * amplitude * w ** 2 / (k - MASS * w ** 2 + 1j * c * w)
    excitation = Sine(amplitude=amplitude, frequency=frequency, phase=0.5 * math.pi,
                      fade_in=0.0)
    run = PeriodicRun(excitation, isolator, controller, period=period, dt=period / 512,
                      sample_rate=256 * frequency, solver="rk4")
    assert (run.steps_per_period, run.samples_per_period, run.decimation) == (512, 256, 2)
    rows, marks = run.output_buffers()
    distance = []
    for _ in range(40):
        assert not run.advance(rows[0], marks[0])
        z, v = run.state_of(["relative_position", "relative_velocity"])
        distance.append(max(abs(z - steady.real) / abs(steady),
                            abs(v - (1j * w * steady).real) / (w * abs(steady))))
    assert distance[-1] < 1e-9
    slope = np.polyfit(np.arange(1, 16), np.log(distance[:15]), 1)[0]
    assert slope == pytest.approx(-zeta * wn * period, rel=0.01)
    # the last row is the period's end, the boundary state
    assert rows[0][-1, CHANNELS["relative_position"][0]] == z
    assert rows[0][-1, CHANNELS["base_displacement"][0]] == pytest.approx(amplitude, rel=1e-12)
    assert run.mode == 0 and run.stop_contacts == 0 and not marks.any()
    validation("Periodic stepping of a linear plant: period-boundary state after 40 periods",
               "the closed-form steady state Z = m A w^2 / (k - m w^2 + i c w)",
               distance[-1], 1e-9)
    validation("Periodic stepping of a linear plant: decay per period of the transient",
               "exp(-zeta wn T)", abs(slope / (-zeta * wn * period) - 1), 0.01)


def test_one_period_per_call_is_one_uncut_run():
    """Periods of 1024 steps (a multiple of the kernels' 256-step exact-sine period) change
    no bit: every channel and flag equals one :func:`qzs.simulate` of the same sine."""
    frequency, periods = 2.0, 5
    period = 1.0 / frequency
    excitation = Sine(amplitude=0.01, frequency=frequency, phase=0.5 * math.pi, fade_in=0.5)
    options = dict(dt=period / 1024, sample_rate=256 * frequency)
    rows, marks = advance(PeriodicRun(excitation, period=period, **options), periods)
    result = qzs.simulate(excitation, duration=periods * period, **options)
    n = periods * 256  # simulate also records t = 0
    for name, (column, *_) in CHANNELS.items():
        np.testing.assert_array_equal(rows[..., column].ravel(), result[name][-n:], name)
    for name, (column, _) in FLAGS.items():
        np.testing.assert_array_equal(marks[..., column].ravel(), result[name][-n:], name)


def sliding_oscillator():
    """A spring (linear to 1e-10), stiction and Coulomb friction, compliant stops 12 mm away."""
    k = MASS * (2 * math.pi * 2.0) ** 2
    return IsolatorParameters(mass=MASS, gravity=0.0, spring_force=k / LINEAR_SHAPE,
                              spring_shape=LINEAR_SHAPE, stiction_force=1.0,
                              coulomb_force=0.8, viscous_damping=0.5, stroke_half=0.012,
                              stop_stiffness=2e4, stop_damping=50.0)


def test_a_run_continued_from_its_carried_state_is_one_uninterrupted_run():
    """A sine throws the payload onto a stop; then, the base at rest, it slides back and
    forth (a reversal every half period) and sticks in the fourth period. Handed over
    from run to run at every period, that motion is the uninterrupted one to the last bit:
    every channel, flag and the boundary state, the stick/slip mode too. Only what a
    continued run starts afresh differs: its time and its energy ledger (each period's
    work the uninterrupted ledger's increment over that period)."""
    isolator = sliding_oscillator()
    controller = ControllerParameters(pi_kp=0.0, pi_ki=0.0, position_setpoint=0.0)
    frequency = 2.0
    options = dict(period=1.0 / frequency, dt=1.0 / (1024 * frequency),
                   sample_rate=256 * frequency)
    thrown = PeriodicRun(Sine(amplitude=0.004, frequency=frequency, phase=0.5 * math.pi,
                              fade_in=0.5), isolator, controller, **options)
    advance(thrown, 3)
    assert thrown.stop_contacts > 0
    start = thrown.carry()
    # the time restarts with every run: only a base at rest moves the same at any time
    rest = Sine(amplitude=0.0, frequency=frequency, fade_in=0.0)
    periods = 6
    whole = PeriodicRun(rest, isolator, controller, carried=start, **options)
    rows, marks = advance(whole, periods)
    locked = marks[..., FLAGS["locked"][0]].mean(axis=1)
    assert locked[0] == 0.0 and 0.0 < locked[3] < 1.0 and locked[-1] == 1.0
    carried = start
    for i in range(periods):
        run = PeriodicRun(rest, isolator, controller, carried=carried, **options)
        piece, piece_marks = advance(run, 1)
        for name, (column, *_) in CHANNELS.items():
            if name == "time":
                np.testing.assert_array_equal(piece[0, :, column], rows[0, :, column])
            elif name in LEDGER:
                before = rows[i - 1, -1, column] if i else 0.0
                np.testing.assert_allclose(piece[0, :, column], rows[i, :, column] - before,
                                           rtol=1e-9, atol=1e-15)
            else:
                np.testing.assert_array_equal(piece[0, :, column], rows[i, :, column], name)
        np.testing.assert_array_equal(piece_marks[0], marks[i])
        carried = run.carry()
    assert isinstance(carried, CarriedState)
    names = list(STATE_VARIABLES)
    np.testing.assert_array_equal(run.state_of(names), whole.state_of(names))
    assert run.mode == whole.mode == 1  # stuck
    assert run.stop_contacts == 0  # a continued run counts from zero


def test_carry_hands_over_copies():
    period = 0.5
    run = PeriodicRun(Sine(amplitude=0.01, frequency=2.0, fade_in=0.0), period=period,
                      dt=period / 256, sample_rate=512.0)
    carried = run.carry()
    advance(run, 1)
    assert not np.array_equal(run.carry().state, carried.state)


@pytest.mark.parametrize("steps, decimation", [(300.5, 1), (300, 7)])
def test_a_period_of_no_whole_number_of_samples_is_refused(steps, decimation):
    period = 0.5
    dt = period / steps
    with pytest.raises(ParameterError, match="`period`"):
        PeriodicRun(Sine(amplitude=0.01, frequency=2.0, fade_in=0.0), period=period, dt=dt,
                    sample_rate=1.0 / (decimation * dt))
