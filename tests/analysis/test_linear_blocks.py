"""The linearised loop with a user's controller: plant, controller, closed loop, simulation.

Every sensor of the plant and every block of the controller against their transfer functions
written by hand; a controller whose blocks add nothing against today's closed form; the
compensation's linear part as less viscous damping (and, with its observer, none at low
frequency); and the simulated steady-state transmissibility of a frictionless isolator with a
user's lead-lag damping loop against python-control's closed loop.
"""
import math

import control
import numpy as np
import pytest
from helpers import LEAD_LAG, lead_lag, linear_isolator, steady_transmissibility

import qzs
from qzs import (Dither, FrictionCompensation, IsolatorParameters, LinearController,
                 ParameterError, PIDamping)
from qzs.analysis.linear import controller_system, linearize, loop_constants, plant_system
from qzs.model.controller import SENSORS

S = 1j * np.array([0.05, 0.7, 3.0, 20.0, 150.0])  # Laplace points [rad/s]
def lead_value(s):
    return -LEAD_LAG["gain"] * (1 + s / LEAD_LAG["zero"]) / (1 + s / LEAD_LAG["pole"])


def response(system, s):
    """``(N, outputs, inputs)`` response of a python-control system at Laplace points."""
    return np.moveaxis(np.asarray(system(s)).reshape(system.noutputs, system.ninputs, -1), -1, 0)


def test_the_plant_reads_every_sensor_as_its_transfer_function():
    """Base acceleration a and motor force F in: z = (F - m a)/D, D = m s^2 + Cv s + k."""
    isolator = IsolatorParameters()
    controller = PIDamping()
    m, c, k, _, _, _, w = loop_constants(isolator, controller)
    plant = plant_system(isolator, controller)
    assert list(plant.output_labels) == list(SENSORS)
    assert list(plant.input_labels) == ["base_acceleration", "motor_force"]
    d = m * S ** 2 + c * S + k
    highpass = S / (S + w)
    z_base, z_force = -m / d, 1 / d
    expected = np.stack([
        np.stack([-z_base, -z_force], -1),                                   # z_ref - z
        np.stack([highpass * (1 / S + S * z_base), highpass * S * z_force], -1),  # HP (y' + z')
        np.stack([1 + S ** 2 * z_base, S ** 2 * z_force], -1),              # y'' + z''
        np.stack([np.ones_like(S), np.zeros_like(S)], -1),                  # y''
        np.stack([S * z_base, S * z_force], -1),                            # z'
    ], 1)
    np.testing.assert_allclose(response(plant, S), expected, rtol=1e-12, atol=1e-15)
    at_rest = plant_system(isolator, controller, base=False)
    np.testing.assert_allclose(response(at_rest, S)[:, :, 0], expected[:, :, 1], rtol=1e-12,
                               atol=1e-15)


def test_the_controller_is_the_sum_of_its_blocks():
    """PI + damping + the compensation's viscous slope and observer + a user's lead-lag."""
    isolator = IsolatorParameters()
    compensation = FrictionCompensation(fraction=0.6, viscous_damping=80.0,
                                        observer_bandwidth=3.0)
    controller = (PIDamping(pi_kp=50.0, pi_ki=20.0, damping_gain=30.0) + compensation
                  + lead_lag() + Dither(amplitude=2.0))
    gains = response(controller_system(isolator, controller), S)[:, 0, :]
    slope, cv, wo = 0.6 * 80.0, isolator.viscous_damping, 2 * math.pi * 3.0
    expected = np.zeros((S.size, len(SENSORS)), dtype=complex)
    expected[:, 0] = 50.0 + 20.0 / S
    expected[:, 1] = -30.0 + lead_value(S)
    expected[:, 4] = slope - wo / (S + wo) * (slope - cv)
    np.testing.assert_allclose(gains, expected, rtol=1e-12)


@pytest.mark.parametrize("adds, what", [
    (FrictionCompensation(fraction=0.0), "compensation of fraction 0"),
    (Dither(amplitude=3.0), "a dither (no feedback)"),
    ("as-linear", "PI + damping as a LinearController"),
])
def test_blocks_that_add_nothing_leave_the_closed_form(adds, what, validation):
    """T(s) = (Cv s + k + Kp + Ki/s)/(m s^2 + Cv s + k + Kp + Ki/s + Kd s HP(s))."""
    isolator = IsolatorParameters()
    base = PIDamping(damping_gain=100.0)
    if adds == "as-linear":
        as_linear = LinearController(a=[[0.0]], b=[[1.0, 0.0]], c=[base.pi_ki],
                                     d=[base.pi_kp, -base.damping_gain],
                                     inputs=("position_error", "measured_payload_velocity"))
        controller = PIDamping(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0) + as_linear
    else:
        controller = base + adds
    f = np.logspace(-2, 1.5, 30)
    expected = linearize(isolator, base)
    model = linearize(isolator, controller)
    error = np.max(np.abs(model.transmissibility(f) / expected.transmissibility(f) - 1))
    assert error < 1e-9
    np.testing.assert_allclose(np.sort_complex(model.poles), np.sort_complex(expected.poles),
                               rtol=1e-8)
    validation(f"Linearised loop with {what}", "PI + damping's closed-form T(s), 0.01-30 Hz",
               error, 1e-9)


@pytest.mark.parametrize("observer", [0.0, 2.0])
@pytest.mark.parametrize("viscous", [None, 0.0], ids=["Cv'=Cv", "Cv'=0"])
def test_compensating_the_viscous_friction_takes_it_out_of_the_loop(observer, viscous,
                                                                    validation):
    """The compensation's linear part: ``Cv`` becomes ``Cv - a Cv'``; with an observer of the
    friction left, ``(Cv - a Cv') s/(s + w_o)`` (it cancels the rest at low frequency). The
    whole law (``viscous_damping=None``, ``Cv' = Cv``) leaves ``(1 - a) Cv``; the default
    compensator (``Cv' = 0``) leaves ``Cv``, which the observer still takes out."""
    isolator = IsolatorParameters()
    fraction = 0.7
    controller = PIDamping(damping_gain=20.0) + FrictionCompensation(
        fraction=fraction, viscous_damping=viscous, observer_bandwidth=observer)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller)
    compensated = fraction * (cv if viscous is None else viscous)
    s = 2j * np.pi * np.logspace(-2, 1.5, 30)
    damping = (cv - compensated) * (s / (s + 2 * np.pi * observer) if observer else 1.0)
    coupling = damping * s + k + kp + ki / s
    expected = np.abs(coupling / (m * s ** 2 + coupling + kd * s * s / (s + w)))
    found = linearize(isolator, controller).transmissibility(s.imag / (2 * np.pi))
    error = np.max(np.abs(found / expected - 1))
    assert error < 1e-9
    validation(f"Compensation's linear part, fraction {fraction}, "
               f"Cv' = {'Cv' if viscous is None else viscous}, observer {observer} Hz",
               "T(s) with Cv -> Cv - a Cv'" + (" s/(s + w_o)" if observer else ""), error, 1e-9)


@pytest.mark.parametrize("frequency", [0.5, 2.0, 5.0, 10.0])
def test_simulated_transmissibility_with_a_lead_lag_loop_is_the_linear_loops(frequency,
                                                                             validation):
    """Frictionless, no stop, linear spring: the run's steady state against ``feedback``."""
    isolator = linear_isolator()
    controller = PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0, damping_gain=0.0,
                           velocity_highpass=1.0) + lead_lag()
    plant = plant_system(isolator, controller)
    gains = controller_system(isolator, controller)  # sensors -> motor force; none to the base
    both = control.ss(gains.A, gains.B, np.vstack([np.zeros_like(gains.C), gains.C]),
                      np.vstack([np.zeros_like(gains.D), gains.D]))
    closed = control.feedback(plant, both, sign=1)
    expected = abs(closed(2j * np.pi * frequency)[list(SENSORS).index("payload_acceleration"),
                                                  0])
    simulated = steady_transmissibility(frequency, isolator, controller)
    assert simulated == pytest.approx(expected, rel=1e-4)
    assert linearize(isolator, controller).transmissibility(frequency) == pytest.approx(
        expected, rel=1e-10)
    validation(f"Simulated steady state with a lead-lag damping loop, {frequency:g} Hz",
               "python-control's feedback of the linearised plant and the controller",
               abs(simulated / expected - 1), 1e-4)


@pytest.mark.parametrize("frequency", [2.0, 5.0, 10.0])
def test_simulated_transmissibility_with_a_friction_observer_is_the_linear_loops(frequency,
                                                                                validation):
    """Half the viscous friction compensated and the rest observed (10 Hz): the run's steady
    state against ``c(s) = (1 - a) Cv s/(s + w_o)`` in the closed loop (docs/model.md §10)."""
    isolator = linear_isolator()
    controller = PIDamping(position_setpoint=0.0, pi_kp=50.0, pi_ki=200.0, damping_gain=100.0,
                           velocity_highpass=0.0) + FrictionCompensation(
        fraction=0.5, viscous_damping=None, observer_bandwidth=10.0)
    expected = float(linearize(isolator, controller).transmissibility(frequency))
    simulated = steady_transmissibility(frequency, isolator, controller)
    assert simulated == pytest.approx(expected, rel=1e-4)
    validation(f"Simulated steady state with friction compensation and its observer, "
               f"{frequency:g} Hz", "the linearised loop with the compensation's linear part",
               abs(simulated / expected - 1), 1e-4)


def test_bad_input_names_the_argument_and_the_fix():
    block = lead_lag()
    with pytest.raises(ParameterError, match=r"`controller`.*PIDamping\(\) \+ LinearController"):
        linearize(controller=block)
    discrete = PIDamping() + lead_lag(sample_time=1e-3)
    for call in (linearize, controller_system):
        with pytest.raises(ParameterError, match=r"`controller` has a discrete.*sampled_loop"):
            call(controller=discrete)
    with pytest.raises(ParameterError, match="`isolator`"):
        plant_system(isolator=PIDamping())
    assert qzs.linearize(controller=PIDamping() + lead_lag()).damping_ratio > 0


def test_a_loop_with_direct_feedthrough_both_ways_is_solved_for_the_force():
    # F = u + K y and y = C x + D F: F = (u + K C x) / (1 - K D), the algebraic loop solved
    # (a discrete controller may feed the payload's acceleration straight through)
    from qzs.analysis.linear import close_loop

    plant = (np.array([[-1.0]]), np.array([[1.0]]), np.array([[2.0]]), np.array([[0.5]]))
    gain = 0.4
    controller = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[gain]]))
    a, b, c, d = close_loop(plant, controller)
    loop = 1.0 / (1.0 - gain * 0.5)
    np.testing.assert_allclose(d, [[0.5 * loop], [loop]], rtol=1e-15)
    np.testing.assert_allclose(c, [[2.0 * loop], [gain * 2.0 * loop]], rtol=1e-15)
    np.testing.assert_allclose(a, [[-1.0 + gain * 2.0 * loop]], rtol=1e-15)
