"""The harmonic-balance residual and its Jacobian (qzs.analysis.harmonic_balance.residual): zero
at the closed-form response of a linear model, and the Jacobian the residual's derivative."""
import dataclasses

import numpy as np
import pytest

from qzs import ControllerParameters
from qzs.analysis.harmonic_balance import SmoothModel
from qzs.analysis.harmonic_balance.fourier import _basis
from qzs.analysis.harmonic_balance.residual import _force_scale, _residual, _scales


def linear_unknowns(frequency, model, transmissibility, size):
    """The unknowns of the exact linear response: ``Z_1 = (T - 1) A`` as ``a cos + b sin``
    (``Z = a - i b``), and the mean slot (the integral's mean, or z0)."""
    q = np.zeros(size)
    z1 = (transmissibility - 1) * model.amplitude
    q[1], q[2] = z1.real, -z1.imag
    k = model.spring_force * model.spring_shape
    if model.pi_ki > 0:  # the integral's mean carries the weight: m g + k z_ref = Ki I0
        q[0] = (model.mass * model.gravity + k * model.position_setpoint) / model.pi_ki
    else:  # the spring and Kp carry it at z0: m g + k z0 = Kp (z_ref - z0)
        q[0] = ((model.pi_kp * model.position_setpoint - model.mass * model.gravity)
                / (k + model.pi_kp))
    return q


@pytest.mark.parametrize("options", [
    dict(),                                            # PI, damping through the high-pass
    dict(pi_ki=0.0),                                   # no integral: the mean is z0
    dict(velocity_highpass=0.0),                       # damping on the velocity itself
    dict(damping_gain=0.0, pi_kp=0.0, pi_ki=0.0),      # passive
])
@pytest.mark.parametrize("frequency", [0.3, 1.7, 12.0])
def test_the_linear_limit_balances_at_the_linear_transmissibility(
        options, frequency, linear_model, linear_transmissibility, validation):
    model = linear_model(**options)
    basis = _basis(5, 64)
    transmissibility = complex(linear_transmissibility(frequency, model))
    q = linear_unknowns(frequency, model, transmissibility, basis.size)
    residual = _residual(q, 2 * np.pi * frequency, model, basis, False)[0]
    force = _force_scale(model, 2 * np.pi * frequency, 1e-12)
    # a tanh(b z) is a b z to (b z)^2/3 < 1e-12 relative
    assert np.max(np.abs(residual)) / force < 1e-9
    validation(f"Harmonic-balance residual of a linear model at {frequency} Hz, {options}",
               "zero at the closed-form response (m s^2 X + Kd HP(s) s X + (c s + k + Kp + "
               "Ki/s)(X - Y) = 0)", np.max(np.abs(residual)) / force, 1e-9,
               measure="largest residual over the force scale [-]")
    # and not zero anywhere else: a 1 % error in the fundamental shows
    wrong = q.copy()
    wrong[1] += 0.01 * abs(transmissibility - 1) * model.amplitude
    assert np.max(np.abs(_residual(wrong, 2 * np.pi * frequency, model, basis, False)[0])) > (
        1e3 * np.max(np.abs(residual)))


@pytest.mark.parametrize("controller", [ControllerParameters(),
                                        ControllerParameters(pi_ki=0.0, damping_gain=40.0)])
def test_the_jacobian_is_the_derivative_of_the_residual(controller):
    """Central differences of the residual in every unknown and in omega: the AFT of the
    spring's and friction's slopes, and the linear operators' d/domega."""
    model = SmoothModel.from_parameters(controller=controller, amplitude=0.01,
                                        friction_velocity=0.02)
    basis = _basis(6, 64)
    rng = np.random.default_rng(11)
    q = rng.normal(scale=0.3 * model.amplitude, size=basis.size)
    q[0] = 2.0 if model.pi_ki > 0 else model.position_setpoint + 0.002
    omega = 2 * np.pi * 3.0
    _, d_q, d_omega = _residual(q, omega, model, basis)
    numeric = np.empty_like(d_q)
    for j in range(basis.size):
        h = 1e-6 * (1.0 if (j == 0 and model.pi_ki > 0) else model.amplitude)
        step = np.zeros(basis.size)
        step[j] = h
        numeric[:, j] = (_residual(q + step, omega, model, basis, False)[0]
                         - _residual(q - step, omega, model, basis, False)[0]) / (2 * h)
    np.testing.assert_allclose(d_q, numeric, rtol=1e-6, atol=1e-7 * np.abs(d_q).max())
    h = 1e-6 * omega
    numeric = (_residual(q, omega + h, model, basis, False)[0]
               - _residual(q, omega - h, model, basis, False)[0]) / (2 * h)
    np.testing.assert_allclose(d_omega, numeric, rtol=1e-6, atol=1e-7 * np.abs(d_omega).max())


def test_scales_are_the_amplitude_and_a_force_over_the_integral_gain():
    model = SmoothModel.from_parameters(amplitude=0.004)
    omega = 2 * np.pi * 8.0
    scale = _scales(model, omega, 9)
    assert np.all(scale[1:] == 0.004)
    force = max(model.mass * model.gravity, model.stiction_force,
                model.mass * model.amplitude * omega ** 2)
    assert scale[0] == pytest.approx(force / model.pi_ki, rel=1e-15)
    assert np.all(_scales(dataclasses.replace(model, pi_ki=0.0), omega, 9) == 0.004)
