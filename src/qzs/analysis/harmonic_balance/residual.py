"""The harmonic-balance residual of the smooth model and its Jacobian.

``R_k = [m s^2 + Kd HP(s) s] (z_k + y_k) + (Kp + Ki/s) z_k - N_k`` for each harmonic
``k >= 1`` (``s = i k omega``) and ``R_0 = m g - N_0 - Kp (z_ref - z_0) - Ki I_0``: the
linear parts (mass, PI, damping through the high-pass) exact per harmonic, the spring and
friction forces ``N`` evaluated on a time grid and transformed back (alternating
frequency-time, AFT). The unknowns are the real Fourier coefficients of ``z``; with
``pi_ki > 0`` the mean of ``z`` is the setpoint (the integral of a periodic error is periodic
only if the error has zero mean) and the mean of the PI integral takes the mean's slot.

References
----------
Cameron, T. M., Griffin, J. H. (1989). An alternating frequency/time domain method for
calculating the steady-state response of nonlinear dynamic systems. J. Appl. Mech. 56, 149-154.
"""
import numpy as np

from qzs.analysis.harmonic_balance.fourier import _block

__all__ = []


def _linear_terms(omega, model, harmonics):
    """Per-harmonic complex operators: on z (``G_k``), on y (``B_k``) and their d/domega."""
    k = np.arange(1, harmonics + 1)
    s = 1j * k * omega
    wh = model.highpass_omega
    if wh > 0:
        hp_s = s * s / (s + wh)
        hp_s_ds = (s * s + 2 * s * wh) / (s + wh) ** 2
    else:
        hp_s, hp_s_ds = s, np.ones_like(s)
    m, kp, ki, kd = model.mass, model.pi_kp, model.pi_ki, model.damping_gain
    base = m * s * s + kd * hp_s
    base_ds = 2 * m * s + kd * hp_s_ds
    on_z = base + kp + ki / s
    on_z_ds = base_ds - ki / (s * s)
    return on_z, base, on_z_ds * 1j * k, base_ds * 1j * k


def _relative_coefficients(q, model):
    """Fourier coefficients of z from the unknowns (the mean is z_ref when Ki > 0)."""
    zq = np.array(q, dtype=float)
    if model.pi_ki > 0:
        zq[0] = model.position_setpoint
    return zq


def _residual(q, omega, model, basis, jacobian=True):
    """The balance ``R(q, omega)`` and, if asked, ``dR/dq`` and ``dR/domega``.

    ``R_k = [m s^2 + Kd HP(s) s] (z_k + y_k) + (Kp + Ki/s) z_k - N_k`` for k >= 1
    (``s = i k omega``), ``R_0 = m g - N_0 - Kp (z_ref - z_0) - Ki I_0``, with ``N`` the
    spring and friction forces by AFT; the unknown of slot 0 is ``I_0`` when Ki > 0, else
    ``z_0``. Units: [N].
    """
    zq = _relative_coefficients(q, model)
    z = basis.synthesis @ zq
    dz = basis.synthesis_derivative @ zq
    spring, spring_slope = model.spring(z)
    friction, friction_slope = model.friction(omega * dz)
    nonlinear = basis.analysis @ (spring + friction)
    on_z, on_y, on_z_dw, on_y_dw = _linear_terms(omega, model, basis.harmonics)
    linear = _block(on_z)
    y = np.zeros(2 * basis.harmonics)
    y[0] = model.amplitude
    residual = np.empty(basis.size)
    residual[1:] = linear @ zq[1:] + _block(on_y) @ y - nonlinear[1:]
    mean_motor = model.pi_kp * (model.position_setpoint - zq[0])
    if model.pi_ki > 0:
        mean_motor += model.pi_ki * q[0]
    residual[0] = model.mass * model.gravity - nonlinear[0] - mean_motor
    if not jacobian:
        return residual, None, None
    local = (basis.synthesis * spring_slope[:, None]
             + basis.synthesis_derivative * (omega * friction_slope)[:, None])
    d_q = -basis.analysis @ local
    d_q[1:, 1:] += linear
    if model.pi_ki > 0:
        d_q[:, 0] = 0.0
        d_q[0, 0] = -model.pi_ki
    else:
        d_q[0, 0] += model.pi_kp
    d_omega = -basis.analysis @ (friction_slope * dz)
    d_omega[1:] += _block(on_z_dw) @ zq[1:] + _block(on_y_dw) @ y
    return residual, d_q, d_omega


def _scales(model, omega, size):
    """Scales of the unknowns [m, or m*s for the integral's mean] for norms and arclength."""
    scale = np.full(size, model.amplitude)
    if model.pi_ki > 0:
        scale[0] = _force_scale(model, omega, 1.0) / model.pi_ki
    return scale


def _force_scale(model, omega, floor):
    """Force scale of the balance [N]: the largest of the weight, the stiction and the base's
    inertial force ``m A omega^2``, and ``floor``."""
    return max(model.mass * model.gravity, model.stiction_force,
               model.mass * model.amplitude * omega ** 2, floor)
