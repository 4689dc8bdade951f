"""The net friction law of a compensated guide, and the sliding cycle of over-compensation.

The net law's describing function against Coulomb's closed form and python-control's numerical
one; the predicted cycle against its closed form for Coulomb friction (``A = 4 (a - 1) F/(pi
c)`` at the loop's resonance); and the predicted amplitude and frequency against simulated
limit cycles, within the tolerance docs/model.md §5 states.
"""
import dataclasses
import math

import numpy as np
import pytest

import qzs
from qzs import (FrictionCompensation, InitialState, IsolatorParameters, LinearController,
                 ParameterError, PIDamping)
from qzs.analysis import control_design as cd
from qzs.analysis.linear import loop_constants

#: The accuracy docs/model.md §5 states for the sliding cycle's amplitude and frequency,
#: where the payload slides through its reversals with a margin (breakaway ratio above 1.5)
#: and the loop filters the third harmonic (distortion below 0.03).
TOLERANCE = 0.02


@pytest.mark.parametrize("viscous", [None, 0.0, 40.0])
def test_the_net_law_is_the_plants_less_the_compensators(viscous):
    """The compensator's viscous slope ``a Cv'`` (the plant's Cv with None, 0 by default) is
    linear, in the loop: added back here, so only the deadband shows it."""
    plant = IsolatorParameters()
    law = cd.NetFrictionNonlinearity.of(plant, FrictionCompensation(
        fraction=1.5, viscous_damping=viscous, deadband=2e-3))
    stribeck = cd.FrictionNonlinearity(10.0, 1.0, 100.0)
    slope = 1.5 * (plant.viscous_damping if viscous is None else viscous)
    assert law(0.0) == 0.0
    assert law(1e-3) == pytest.approx(stribeck(1e-3) + slope * 1e-3, rel=1e-14)  # deadband
    assert law(0.01) == pytest.approx(-0.5 * stribeck(0.01), rel=1e-12)
    assert law(-0.01) == -law(0.01)


@pytest.mark.parametrize("fraction", [0.0, 0.6, 1.4])
def test_the_net_describing_function_against_closed_forms_and_python_control(fraction,
                                                                            validation):
    amplitude = np.array([1e-3, 1e-2, 0.3])
    coulomb = IsolatorParameters(stiction_force=2.0, coulomb_force=2.0)
    controller = PIDamping() + FrictionCompensation(fraction=fraction)
    law = cd.NetFrictionNonlinearity.of(coulomb, controller.compensation)
    quadrature = cd.net_describing_function(law, amplitude)
    closed = (1 - fraction) * cd.coulomb_describing_function(2.0, amplitude)
    np.testing.assert_allclose(quadrature, closed, rtol=1e-10, atol=1e-12)
    stribeck = IsolatorParameters()
    law = cd.NetFrictionNonlinearity.of(stribeck, controller.compensation)
    numeric = cd.friction_describing_function(stribeck, amplitude, points=20000,
                                              controller=controller).real
    quadrature = cd.net_describing_function(law, amplitude)
    np.testing.assert_allclose(quadrature, numeric, rtol=1e-3, atol=1e-9)
    validation(f"Net friction law's describing function, fraction {fraction}",
               "(1 - a) 4 F/(pi A) for Coulomb friction (quadrature)",
               float(np.max(np.abs(cd.net_describing_function(
                   cd.NetFrictionNonlinearity.of(coulomb, controller.compensation), amplitude)
                   - closed) / np.abs(cd.coulomb_describing_function(2.0, amplitude)))), 1e-10)


def test_no_sliding_cycle_without_over_compensation():
    for controller in (PIDamping(), PIDamping() + FrictionCompensation(fraction=0.9),
                       PIDamping() + FrictionCompensation(fraction=0.9, viscous_damping=None)):
        prediction = cd.predict_sliding_cycle(None, controller)
        assert not prediction.hunts and prediction.intersections == ()
        assert "does not meet" in prediction.reasons["hunts"]
        assert math.isnan(prediction.amplitude) and "amplitude" in prediction.reasons
    unstable = cd.predict_sliding_cycle(None, PIDamping() + FrictionCompensation(  # the whole law
        fraction=1.5, viscous_damping=None))
    assert not unstable.hunts and not unstable.linear_stable
    assert "linearly unstable" in unstable.reasons["hunts"]


def test_the_sliding_cycle_of_coulomb_friction_is_the_closed_form(validation):
    """``G = s/(m s^2 + c s + K)``, ``c = (1 - a) Cv + Kd``: real, ``1/c``, at ``sqrt(K/m)``;
    ``N(A) = -(a - 1) 4 F/(pi A) = -c`` gives ``A = 4 (a - 1) F/(pi c)``; the whole law
    compensated (``viscous_damping=None``: the compensator's ``Cv' = Cv``)."""
    isolator = IsolatorParameters(stiction_force=2.0, coulomb_force=2.0)
    fraction = 1.4
    controller = PIDamping(pi_kp=2000.0, pi_ki=0.0, damping_gain=60.0,
                           velocity_highpass=0.0) + FrictionCompensation(
        fraction=fraction, viscous_damping=None)
    m, cv, k, kp, _, kd, _ = loop_constants(isolator, controller)
    c = (1 - fraction) * cv + kd
    amplitude = 4 * (fraction - 1) * 2.0 / (math.pi * c)
    frequency = math.sqrt((k + kp) / m) / (2 * math.pi)
    prediction = cd.predict_sliding_cycle(isolator, controller)
    assert prediction.hunts and prediction.in_regime and prediction.linear_stable
    assert prediction.velocity_amplitude == pytest.approx(amplitude, rel=1e-9)
    assert prediction.frequency == pytest.approx(frequency, rel=1e-9)
    assert prediction.amplitude == pytest.approx(amplitude / (2 * math.pi * frequency),
                                                 rel=1e-9)
    assert prediction.intersections == ((prediction.velocity_amplitude, prediction.frequency,
                                         True),)
    validation("Sliding cycle of over-compensated Coulomb friction: amplitude",
               "4 (a - 1) F / (pi c), c = (1 - a) Cv + Kd",
               abs(prediction.velocity_amplitude / amplitude - 1), 1e-9)


def _simulated_cycle(isolator, controller, prediction, duration=30.0):
    """First harmonic of the slip velocity [m/s] and frequency [Hz] of the cycle's second
    half, the run kicked off at 1.5 times the predicted velocity amplitude."""
    run = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                       duration=duration, dt=1e-4, sample_rate=2000.0,
                       initial_state=InitialState(
                           relative_velocity=1.5 * prediction.velocity_amplitude, locked=False))
    late = run.time >= duration / 2
    t, v = run.time[late], run.relative_velocity[late]
    up = np.flatnonzero((v[:-1] < 0) & (v[1:] >= 0))
    crossings = t[up] - v[up] * (t[up + 1] - t[up]) / (v[up + 1] - v[up])
    if crossings.size < 3:
        return 0.0, 0.0, run
    period = (crossings[-1] - crossings[0]) / (crossings.size - 1)
    whole = slice(up[0], up[-1])
    phase = np.exp(-2j * np.pi * t[whole] / period)
    first = 2 * abs(np.trapezoid(v[whole] * phase, t[whole])) / (t[whole][-1] - t[whole][0])
    return first, 1 / period, run


CYCLES = {
    "the whole law, over-compensated by 40 %": (
        IsolatorParameters(stiction_force=2.0),
        PIDamping(pi_kp=2000.0, damping_gain=60.0, velocity_highpass=0.0)
        + FrictionCompensation(fraction=1.4, viscous_damping=None)),
    "the whole law by 50 %": (
        IsolatorParameters(stiction_force=2.0),
        PIDamping(pi_kp=2000.0, damping_gain=60.0, velocity_highpass=0.0)
        + FrictionCompensation(fraction=1.5, viscous_damping=None)),
    "Coulomb and Stribeck only, light viscous friction": (
        IsolatorParameters(stiction_force=2.0, viscous_damping=5.0),
        PIDamping(pi_kp=2000.0, velocity_highpass=0.0)
        + FrictionCompensation(fraction=1.4, viscous_damping=0.0)),
}


@pytest.mark.parametrize("name", list(CYCLES))
def test_the_predicted_sliding_cycle_is_the_simulated_one(name, validation):
    isolator, controller = CYCLES[name]
    prediction = cd.predict_sliding_cycle(isolator, controller)
    assert prediction.hunts and prediction.in_regime
    assert prediction.breakaway_ratio > 1.5 and prediction.distortion < 0.03
    amplitude, frequency, run = _simulated_cycle(isolator, controller, prediction)
    assert not run.locked[run.time > 15.0].any()  # it slides through its reversals
    assert amplitude == pytest.approx(prediction.velocity_amplitude, rel=TOLERANCE)
    assert frequency == pytest.approx(prediction.frequency, rel=TOLERANCE)
    validation(f"Sliding cycle ({name}): velocity amplitude", "describing function of the "
               "net friction law against the simulated cycle",
               abs(amplitude / prediction.velocity_amplitude - 1), TOLERANCE)
    validation(f"Sliding cycle ({name}): frequency", "describing function of the net "
               "friction law against the simulated cycle",
               abs(frequency / prediction.frequency - 1), TOLERANCE)


def test_below_the_breakaway_ratio_the_payload_sticks_and_the_cycle_is_not_the_sliding_one():
    isolator = IsolatorParameters(stiction_force=2.0)
    controller = (PIDamping(pi_kp=2000.0, damping_gain=80.0, velocity_highpass=0.0)
                  + FrictionCompensation(fraction=1.4, viscous_damping=None))  # the whole law
    prediction = cd.predict_sliding_cycle(isolator, controller)
    assert prediction.hunts and not prediction.in_regime and prediction.breakaway_ratio < 1
    assert "sticks at the reversals" in prediction.reasons["in_regime"]
    amplitude, _, run = _simulated_cycle(isolator, controller, prediction)
    assert run.locked[run.time > 15.0].mean() > 0.5
    assert amplitude < 0.5 * prediction.velocity_amplitude


def test_bad_input_names_the_argument():
    with pytest.raises(ParameterError, match="`amplitude` must be positive"):
        cd.net_describing_function(cd.FrictionNonlinearity(1.0, 1.0, 0.0), [0.1, 0.0])
    with pytest.raises(ParameterError, match=r"`controller` has a discrete"):
        cd.predict_sliding_cycle(controller=PIDamping() + LinearController(
            d=[-10.0], inputs="measured_payload_velocity", sample_time=1e-3))
    with pytest.raises(ParameterError, match="`controller` must be a ControllerParameters"):
        cd.predict_sliding_cycle(controller=FrictionCompensation(fraction=1.2))


def test_the_observer_cancels_the_friction_below_its_bandwidth_in_hertz():
    # the observer's estimate follows the friction through w_o/(s + w_o), w_o = 2 pi f_o: the
    # friction left passes s/(s + w_o), down 3 dB and 45 degrees ahead at f_o [Hz]. On a
    # guide without viscous friction the observer has nothing linear to estimate (r' = -w_o r):
    # the loop is the same with and without it but for that factor
    from qzs.analysis.control_design.describing_functions import friction_velocity_loop

    bandwidth = 5.0
    plant = IsolatorParameters(viscous_damping=0.0)
    compensation = FrictionCompensation(fraction=0.5)
    plain = friction_velocity_loop(plant, PIDamping(damping_gain=20.0) + compensation)
    observed = friction_velocity_loop(plant, PIDamping(damping_gain=20.0) + dataclasses.replace(
        compensation, observer_bandwidth=bandwidth))
    s = 2j * np.pi * bandwidth
    ratio = observed(s) / plain(s)
    assert abs(ratio) == pytest.approx(1 / np.sqrt(2), rel=1e-9)
    assert np.degrees(np.angle(ratio)) == pytest.approx(45.0, rel=1e-9)
