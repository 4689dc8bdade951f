"""Linear analysis: closed forms and agreement with the nonlinear simulator's linear limit."""
import numpy as np
import pytest

import qzs
from qzs.analysis.linear import linearize


def closed_form(frequency, m, k, c, kp, ki, kd, f_hp):
    s = 2j * np.pi * np.asarray(frequency)
    hp = s / (s + 2 * np.pi * f_hp) if f_hp > 0 else 1.0
    coupling = c * s + k + kp + ki / s
    return np.abs(coupling / (m * s ** 2 + coupling + kd * s * hp))


@pytest.mark.parametrize("kp, ki, kd, f_hp", [(50, 20, 0, 1.0), (10, 0, 30, 1.0), (0, 5, 80, 0.0)])
def test_transfer_function_matches_closed_form(kp, ki, kd, f_hp, validation):
    iso = qzs.IsolatorParameters()
    ctrl = qzs.ControllerParameters(pi_kp=kp, pi_ki=ki, damping_gain=kd, velocity_highpass=f_hp)
    model = linearize(iso, ctrl)
    f = np.logspace(-2, 1.5, 40)
    k = float(qzs.spring_stiffness(ctrl.position_setpoint, iso))
    expected = closed_form(f, iso.mass, k, iso.viscous_damping, kp, ki, kd, f_hp)
    np.testing.assert_allclose(model.transmissibility(f), expected, rtol=1e-9)
    # the state-space realisation is the same system
    import control

    response = control.frequency_response(model.state_space, 2 * np.pi * f)
    np.testing.assert_allclose(np.abs(np.squeeze(response.frdata)), expected, rtol=1e-7)
    gains = f"Kp = {kp}, Ki = {ki}, Kd = {kd}, f_hp = {f_hp}"
    closed = "|(c s + k + Kp + Ki/s) / (m s^2 + c s + k + Kp + Ki/s + Kd s HP(s))|, 0.01-30 Hz"
    validation(f"Linearised transmissibility ({gains})", closed,
               np.abs(model.transmissibility(f) / expected - 1).max(), 1e-9)
    validation(f"Its state-space realisation ({gains})", closed + " (python-control)",
               np.abs(np.abs(np.squeeze(response.frdata)) / expected - 1).max(), 1e-7)


def test_natural_frequencies_of_the_paper(validation):
    passive = linearize(controller=qzs.ControllerParameters(pi_kp=0, pi_ki=0))
    assert passive.undamped_natural_frequency == pytest.approx(0.080, abs=0.002)
    closed = linearize(controller=qzs.ControllerParameters(pi_kp=50, pi_ki=0))
    assert closed.undamped_natural_frequency == pytest.approx(0.45, abs=0.01)
    validation("Passive natural frequency of the linearised loop",
               "paper, Section 3.1: resonance at approximately 0.08 Hz",
               abs(passive.undamped_natural_frequency - 0.080), 0.002,
               measure=f"absolute error [Hz], {passive.undamped_natural_frequency:.4f} Hz")
    validation("Natural frequency with the PI loop (Kp = 50 N/m)",
               "paper, Section 3.1: PI moves the resonance within 0.08-0.45 Hz (upper end)",
               abs(closed.undamped_natural_frequency - 0.45), 0.01,
               measure=f"absolute error [Hz], {closed.undamped_natural_frequency:.4f} Hz")


def test_dominant_pole_of_a_light_damped_case(validation):
    """With tiny damping the dominant pair sits at sqrt(k/m) with zeta ~ c/(2 sqrt(k m))."""
    iso = qzs.IsolatorParameters(viscous_damping=0.5)
    ctrl = qzs.ControllerParameters(pi_kp=50, pi_ki=0, velocity_highpass=0)
    model = linearize(iso, ctrl)
    k = model.stiffness
    assert model.natural_frequency == pytest.approx(np.sqrt(k / iso.mass) / (2 * np.pi), rel=1e-3)
    assert model.damping_ratio == pytest.approx(0.5 / (2 * np.sqrt(k * iso.mass)), rel=1e-3)
    validation("Dominant pole, lightly damped: natural frequency", "sqrt(k/m) / 2 pi",
               abs(model.natural_frequency / (np.sqrt(k / iso.mass) / (2 * np.pi)) - 1), 1e-3)
    validation("Dominant pole, lightly damped: damping ratio", "c / (2 sqrt(k m))",
               abs(model.damping_ratio / (0.5 / (2 * np.sqrt(k * iso.mass))) - 1), 1e-3)
