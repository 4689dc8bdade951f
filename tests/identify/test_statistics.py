"""Confidence intervals use the two-sided Student-t quantile, checked against closed forms.

A one-sided quantile (``t.ppf(0.95, dof)`` instead of ``t.ppf(0.975, dof)``) makes every
interval about 17 % too narrow; each test here computes the half-width by hand from the
model's analytic Jacobian and ``scipy.stats.t.ppf(0.975, dof)`` and fails on it.
"""
import numpy as np
import pytest
from scipy import stats

import qzs
from qzs.identify import fit_friction, fit_spring
from qzs.identify._statistics import fit_covariance, profile_threshold, student_quantile


def test_two_sided_quantile_exactly():
    for dof in (1, 3, 10, 100, 10_000):
        assert student_quantile(0.95, dof) == stats.t.ppf(0.975, dof)
        assert student_quantile(0.90, dof) == stats.t.ppf(0.95, dof)
        assert profile_threshold(0.95, dof) == pytest.approx(stats.f.ppf(0.95, 1, dof),
                                                             rel=1e-9)
    assert student_quantile(0.95, 10_000) == pytest.approx(1.96, abs=1e-3)


def test_straight_line_interval_by_hand():
    """y = a + b x + noise: covariance s^2 (X^T X)^-1 by hand, half-width t(0.975) * SE."""
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 1.0, 12)
    y = 2.0 + 0.5 * x + rng.normal(0.0, 0.1, x.size)
    design = np.column_stack([np.ones_like(x), x])
    coefficients = np.linalg.solve(design.T @ design, design.T @ y)
    residual = design @ coefficients - y
    dof = x.size - 2
    by_hand = residual @ residual / dof * np.linalg.inv(design.T @ design)
    covariance, got_dof = fit_covariance(design, residual, 2)
    assert got_dof == dof
    np.testing.assert_allclose(covariance, by_hand, rtol=1e-12)
    half = student_quantile(0.95, dof) * np.sqrt(np.diag(covariance))
    np.testing.assert_allclose(half, stats.t.ppf(0.975, dof) * np.sqrt(np.diag(by_hand)),
                               rtol=1e-12)


def test_spring_fit_half_width(validation):
    """tanh law: the analytic Jacobian at the optimum gives the half-widths."""
    rng = np.random.default_rng(1)
    z = np.linspace(-0.1, 0.1, 15)
    force = -60.84 * np.tanh(78.10 * z) + rng.normal(0.0, 0.3, z.size)
    fit = fit_spring(z, force)
    a, b = fit.spring_force, fit.spring_shape
    jacobian = np.column_stack([-np.tanh(b * z), -a * z / np.cosh(b * z) ** 2])
    residual = -a * np.tanh(b * z) - force
    dof = z.size - 2
    covariance = residual @ residual / dof * np.linalg.inv(jacobian.T @ jacobian)
    expected = stats.t.ppf(0.975, dof) * np.sqrt(np.diag(covariance))
    got = [np.diff(fit.intervals["plateau"])[0] / 2, np.diff(fit.intervals["shape"])[0] / 2]
    np.testing.assert_allclose(got, expected, rtol=1e-3)
    validation("MagSpring fit: 95 % half-widths of a and b", "t(0.975, dof) sqrt(diag(s^2 "
               "(J^T J)^-1)), analytic Jacobian of a tanh(b z)",
               np.abs(np.array(got) / expected - 1).max(), 1e-3)


def test_friction_fit_half_width(validation):
    """Eq. (3): the analytic Jacobian of the fitted law at the samples the fit used."""
    truth = qzs.IsolatorParameters()
    rng = np.random.default_rng(0)
    time = np.arange(0.0, 8.0, 1e-3)
    omega = 2 * np.pi * 0.5
    z = -0.060 + 0.030 * np.sin(omega * time)
    v = 0.030 * omega * np.cos(omega * time)
    a = -0.030 * omega ** 2 * np.sin(omega * time)
    force = (truth.mass * a - qzs.spring_force(z, truth) - qzs.friction_force(v, truth) + 3.0
             + rng.normal(0.0, 0.2, time.size))
    fit = fit_friction(time, z, force, spring=truth, mass=truth.mass)
    velocity = fit.velocity[fit.used]
    direction, speed = np.sign(velocity), np.abs(velocity)
    fc, delta, decay = fit.coulomb_force, fit.stiction_force - fit.coulomb_force, \
        fit.stribeck_decay
    jacobian = np.column_stack([direction, np.exp(-decay * speed) * direction,
                                -delta * speed * np.exp(-decay * speed) * direction,
                                velocity, np.ones_like(velocity)])
    residual = fit.residual[fit.used]
    dof = residual.size - 5
    covariance = residual @ residual / dof * np.linalg.inv(jacobian.T @ jacobian)
    t = stats.t.ppf(0.975, dof)
    expected = {"coulomb_force": t * np.sqrt(covariance[0, 0]),
                "viscous_damping": t * np.sqrt(covariance[3, 3]),
                "stribeck_decay": t * np.sqrt(covariance[2, 2]),
                "offset": t * np.sqrt(covariance[4, 4]),
                "stiction_force": t * np.sqrt(covariance[0, 0] + covariance[1, 1]
                                              + 2 * covariance[0, 1])}
    for name, half in expected.items():
        low, high = fit.intervals[name]
        assert (high - low) / 2 == pytest.approx(half, rel=2e-3), name
    validation("Friction fit: 95 % half-widths of Fs, Fc, Cbc, Cv and the offset",
               "t(0.975, dof) sqrt(diag(s^2 (J^T J)^-1)), analytic Jacobian of eq. 3",
               max(abs(np.diff(fit.intervals[name])[0] / 2 / half - 1)
                   for name, half in expected.items()), 2e-3)


def test_transmissibility_local_interval_uses_the_two_sided_quantile(monkeypatch):
    """With ``jitter_samples=0`` the intervals are the linearised Student-t ones: a model
    linear in log(parameter) (a pure gain), so the Jacobian is exact."""
    import qzs.identify.transmissibility as module

    frequency = np.linspace(1.0, 20.0, 40)
    rng = np.random.default_rng(2)
    noise = rng.normal(0.0, 0.05, frequency.size)

    class Estimate:
        def __init__(self, gain):
            self.frequency = np.concatenate([[0.0], frequency])
            self.magnitude = np.concatenate([[1.0], np.full(frequency.size, gain)])

    class Run:  # what the fake simulation returns: the isolator, as both signals
        def __init__(self, isolator):
            self.base_acceleration = self.payload_acceleration = isolator

    monkeypatch.setattr(module, "simulate", lambda excitation, isolator, *a, **k: Run(isolator))
    monkeypatch.setattr(module, "transmissibility",
                        lambda base, payload, *a, **k: Estimate(base.mass))
    measured = 6.4 * np.exp(noise)
    fit = module.fit_transmissibility(frequency, measured, ("mass",), jitter_samples=0,
                                      scan_points=0, excitation=qzs.Chirp(duration=10.0))
    dof = frequency.size - 1
    residual = np.log(fit.parameters["mass"]) - np.log(measured)
    standard_error = np.sqrt(residual @ residual / dof / frequency.size)
    low, high = np.log(fit.intervals["mass"])
    assert (high - low) / 2 == pytest.approx(stats.t.ppf(0.975, dof) * standard_error,
                                             rel=1e-4)
