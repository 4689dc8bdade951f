"""Hunting at rest: the stick-slip relay's prediction against simulation and closed forms.

The memoryless friction law predicts no limit cycle, the stick-slip relay in the integral loop
does; its plateau and exact period against the simulator; the re-stick level against the
minimum of the steady friction curve.
"""
import control
import numpy as np
import pytest

import qzs
from qzs import ControllerParameters, InitialState, IsolatorParameters, ParameterError
from qzs.analysis import control_design as cd


def test_the_stiction_relay_is_python_controls_hysteresis_relay():
    """Its analytic describing function against python-control's numerical first harmonic."""
    element = control.relay_hysteresis_nonlinearity(2.9, 7.1)
    amplitude = np.array([7.2, 9.0, 15.0])
    analytic = control.describing_function(element, amplitude)
    numeric = control.describing_function(element, amplitude, num_points=20000,
                                          try_method=False)
    np.testing.assert_allclose(numeric, analytic, rtol=2e-3)


def test_the_memoryless_friction_law_predicts_no_limit_cycle_the_stick_slip_relay_does():
    prediction = cd.predict_hunting()
    assert prediction.friction_intersections == ()
    assert prediction.hunts and prediction.in_regime
    assert prediction.slip_jump > prediction.stiffness * 0  # a jump exists
    # inertia carries the slip past the quasi-static re-stick level
    fs = IsolatorParameters().stiction_force
    assert prediction.slip_jump > fs - prediction.steady_restick_force


def test_restick_force_is_the_minimum_of_the_steady_friction_curve():
    isolator = IsolatorParameters()
    v = np.linspace(0, 0.2, 200001)
    curve = (isolator.coulomb_force + (isolator.stiction_force - isolator.coulomb_force)
             * np.exp(-isolator.stribeck_decay * v) + isolator.viscous_damping * v)
    assert cd.restick_force(isolator) == pytest.approx(curve.min(), abs=1e-6)
    flat = IsolatorParameters(stribeck_decay=5.0)  # Cbc*(Fs - Fc) = 45 < Cv: no dip
    assert cd.restick_force(flat) == flat.stiction_force


def test_no_stribeck_dip_no_jump_no_hunting_predicted_and_none_simulated():
    isolator = IsolatorParameters(stribeck_decay=5.0)
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    prediction = cd.predict_hunting(isolator, controller)
    assert prediction.slip_jump == 0.0 and not prediction.hunts
    result = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                          duration=300.0, dt=1e-3, sample_rate=50.0,
                          initial_state=InitialState(relative_position=-0.05))
    late = result.time > 150.0
    assert np.ptp(result.relative_position[late]) < 1e-4  # it settled, no cycle


def test_predicted_hunting_matches_the_simulated_cycle(validation):
    """The relay's plateau d/K and its exact period against the simulator, at rest."""
    isolator = IsolatorParameters()
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    prediction = cd.predict_hunting(isolator, controller)
    result = qzs.simulate(qzs.Sine(amplitude=0.0, fade_in=0.0), isolator, controller,
                          duration=400.0, dt=1e-3, sample_rate=100.0,
                          initial_state=InitialState(relative_position=-0.06
                                                     + prediction.amplitude))
    late = result.time > 200.0
    zeta = result.relative_position[late] - controller.position_setpoint
    assert 0.5 * np.ptp(zeta) == pytest.approx(prediction.amplitude, rel=0.1)
    locked = result.locked
    breaks = result.time[1:][locked[:-1] & ~locked[1:]]
    period = 2 * np.median(np.diff(breaks[breaks > 200.0]))
    assert period == pytest.approx(prediction.relay_period, rel=0.1)
    validation("Hunting cycle at rest (Kp = 200 N/m, Ki = 80 N/(m s)): plateau",
               "stick-slip relay's plateau d/K against a 400 s simulation",
               abs(0.5 * np.ptp(zeta) / prediction.amplitude - 1), 0.1)
    validation("Hunting cycle at rest: period", "the relay's exact period 4 h K / (Ki d) "
               "against the simulated one", abs(period / prediction.relay_period - 1), 0.1)
    # the describing function's own frequency is the usual square-wave approximation
    assert prediction.period == pytest.approx(period, rel=0.35)


def test_hunting_stiffness_keeps_the_plateau_inside_the_half_width():
    isolator = IsolatorParameters(stiction_force=15.0)
    kp = cd.hunting_stiffness(isolator, ControllerParameters(), 0.02)
    inside = cd.predict_hunting(isolator, ControllerParameters(pi_kp=kp * 1.01))
    outside = cd.predict_hunting(isolator, ControllerParameters(pi_kp=kp * 0.97))
    assert inside.amplitude <= 0.02 < outside.amplitude


def test_bad_input_names_the_argument():
    with pytest.raises(ParameterError, match="`half_width`"):
        cd.hunting_stiffness(half_width=0.0)
