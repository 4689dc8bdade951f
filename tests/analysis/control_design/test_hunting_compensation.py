"""Hunting at rest with friction compensation: the slip jump, the relay, the re-stick level.

Compensation does nothing while the payload sticks, so the breakaway stays at Fs; it pushes
along the slip, which carries the payload further: the slip jump ``J = 2 a Fs`` of a
Coulomb guide (closed form), a larger plateau in the simulation as in the prediction, and no
re-stick at all once ``a >= 1``.
"""
import dataclasses
import math

import numpy as np
import pytest

import qzs
from qzs import (ControllerParameters, Dither, FrictionCompensation, InitialState,
                 IsolatorParameters, ParameterError, PIDamping)
from qzs.analysis import control_design as cd

NOTHING = FrictionCompensation(fraction=0.0)  # a block that adds nothing


def test_compensation_of_fraction_zero_changes_no_prediction():
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    assert cd.predict_hunting(None, controller + NOTHING) == cd.predict_hunting(None, controller)
    with_dither = cd.predict_hunting(None, controller + Dither(amplitude=1.0))
    assert with_dither.slip_jump == cd.predict_hunting(None, controller).slip_jump
    assert "dither" in with_dither.reasons


@pytest.mark.parametrize("fraction", [0.0, 0.3, 0.8, 1.2])
def test_the_slip_jump_of_a_compensated_coulomb_guide_is_two_a_fs(fraction, validation):
    """Fs = Fc = F, no viscous friction, no damping: ``m v' = F - (1 - a) Fs``, ``F' = -K v``
    from ``F = Fs``; the slip ends half a period later at ``F = Fs - 2 a Fs``."""
    isolator = IsolatorParameters(stiction_force=5.0, coulomb_force=5.0, viscous_damping=0.0)
    controller = PIDamping(pi_kp=200.0, pi_ki=80.0)
    if fraction:
        controller = controller + FrictionCompensation(fraction=fraction)
    jump, duration = cd.slip_jump(isolator, controller)
    expected = 2 * fraction * 5.0 * (1 + 1e-6) if fraction else 0.0  # the 1e-6 start kick
    k_total = cd.predict_hunting(isolator, controller).stiffness
    assert jump == pytest.approx(expected, rel=2e-6, abs=1e-9)
    if fraction:
        assert duration == pytest.approx(math.pi * math.sqrt(isolator.mass / k_total), rel=1e-6)
        validation(f"Slip jump of a compensated Coulomb guide, fraction {fraction}",
                   "2 a Fs (half a period of m v' = F - (1 - a) Fs, F' = -K v)",
                   abs(jump / expected - 1), 2e-6)
    prediction = cd.predict_hunting(isolator, controller)
    if fraction >= 1:  # it does not re-stick: no relay, no plateau
        assert not prediction.hunts and "does not re-stick" in prediction.reasons["hunts"]
        assert math.isnan(prediction.amplitude) and math.isnan(prediction.relay_period)
        assert math.isnan(prediction.switching_force)
        assert math.isnan(prediction.steady_restick_force)


def test_the_restick_level_scales_with_the_fraction_left():
    """The net steady force is ``(1 - a)`` times the law when the compensator's is the plant's
    (``viscous_damping=None``); with the default compensator (``Cv' = 0``) it is the law of a
    guide with ``(1 - a) Fs``, ``(1 - a) Fc`` and the whole ``Cv`` (closed form)."""
    isolator = IsolatorParameters()
    for fraction in (0.3, 0.9):
        controller = PIDamping() + FrictionCompensation(fraction=fraction, viscous_damping=None)
        assert cd.restick_force(isolator, controller) == pytest.approx(
            (1 - fraction) * cd.restick_force(isolator), rel=1e-9)
        controller = PIDamping() + FrictionCompensation(fraction=fraction)
        left = dataclasses.replace(
            isolator, stiction_force=(1 - fraction) * isolator.stiction_force,
            coulomb_force=(1 - fraction) * isolator.coulomb_force)
        assert cd.restick_force(isolator, controller) == pytest.approx(
            cd.restick_force(left), rel=1e-9)
    assert math.isnan(cd.restick_force(isolator, PIDamping() + FrictionCompensation(
        fraction=1.1)))


def _stuck_positions(isolator, controller, start, duration=400.0):
    run = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                       duration=duration, dt=1e-3, sample_rate=100.0,
                       initial_state=InitialState(relative_position=-0.06 + start))
    sticks = np.flatnonzero(~run.locked[:-1] & run.locked[1:]) + 1
    late = run.time[sticks] > duration / 2
    return run.relative_position[sticks][late] - controller.position_setpoint


def test_compensation_enlarges_the_hunting_plateau_as_predicted(validation):
    """Kp = 200 N/m, Ki = 80 N/(m s): the relay's plateau ``d/K`` against the simulated
    stuck positions, without compensation, with 30 % of the Coulomb and Stribeck terms (the
    default compensator, ``Cv' = 0``) and with 30 % of the whole law (``Cv' = Cv``:
    ``viscous_damping=None``), each plateau larger than the one before."""
    isolator = IsolatorParameters()
    base = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    plateaus = []
    for controller in (base + NOTHING, base + FrictionCompensation(fraction=0.3),
                       base + FrictionCompensation(fraction=0.3, viscous_damping=None)):
        prediction = cd.predict_hunting(isolator, controller)
        assert prediction.hunts and prediction.in_regime
        stuck = _stuck_positions(isolator, controller, prediction.amplitude)
        assert stuck.size >= 8 and np.all(np.sign(stuck[1:]) != np.sign(stuck[:-1]))
        simulated = float(np.mean(np.abs(stuck)))
        assert simulated == pytest.approx(prediction.amplitude, rel=0.05)
        plateaus.append((prediction.amplitude, simulated))
    (predicted_0, simulated_0), (predicted_c, simulated_c), (predicted_3, simulated_3) = plateaus
    assert predicted_0 < predicted_c < predicted_3 and simulated_0 < simulated_c < simulated_3
    assert predicted_3 > 1.15 * predicted_0 and simulated_3 > 1.15 * simulated_0
    validation("Hunting plateau with 30 % friction compensation (Kp = 200, Ki = 80)",
               "stick-slip relay's d/K with the compensated slip against the simulation",
               abs(simulated_3 / predicted_3 - 1), 0.05)


def test_what_the_relay_cannot_hold_is_refused():
    with pytest.raises(ParameterError, match=r"`controller` has a LinearController"):
        cd.predict_hunting(controller=PIDamping() + qzs.LinearController(
            d=[-10.0], inputs="measured_payload_velocity"))
    with pytest.raises(ParameterError, match=r"`controller` has a friction observer"):
        cd.slip_jump(controller=PIDamping() + FrictionCompensation(observer_bandwidth=5.0))


def test_a_compensated_viscous_friction_is_a_guide_with_less_of_it():
    # the compensation's viscous part fraction*Cv' is linear: to the relay it is the guide's
    # Cv lowered by it (docs/model.md §5.1), in the slip and in the integral loop alike
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    fraction, plant = 0.3, IsolatorParameters()
    viscous = cd.predict_hunting(plant, controller + FrictionCompensation(
        fraction=fraction, viscous_damping=plant.viscous_damping))
    lowered = dataclasses.replace(plant, viscous_damping=(1 - fraction) * plant.viscous_damping)
    reference = cd.predict_hunting(lowered, controller + FrictionCompensation(
        fraction=fraction, viscous_damping=0.0))
    assert reference.hunts
    assert viscous.slip_jump == pytest.approx(reference.slip_jump, rel=1e-6)
    assert viscous.frequency == pytest.approx(reference.frequency, rel=1e-6)
    assert viscous.amplitude == pytest.approx(reference.amplitude, rel=1e-6)
