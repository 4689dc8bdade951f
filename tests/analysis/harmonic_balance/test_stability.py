"""Floquet exponents by Hill's method (qzs.analysis.harmonic_balance.stability) against the
closed loop's poles, the monodromy matrix of the smooth ODE integrated by scipy, and
Liouville's formula."""
import numpy as np
import pytest

from qzs.analysis.harmonic_balance import floquet_exponents, periodic_response
from qzs.analysis.harmonic_balance.stability import STABILITY_MARGIN, _is_stable


def test_a_linear_orbit_has_the_closed_loops_poles(linear_model):
    """Linear: the exponents are the roots of the characteristic polynomial, whatever the
    orbit: ``m s^2 + c s + k + Kp + Ki/s + Kd s HP(s)``, ``HP(s) = s/(s + w_hp)``, times
    ``s (s + w_hp)``."""
    model = linear_model()
    solution = periodic_response(2.0, model, harmonics=4)
    k = model.spring_force * model.spring_shape
    m, c, kp, ki, kd, wh = (model.mass, model.viscous_damping, model.pi_kp, model.pi_ki,
                            model.damping_gain, model.highpass_omega)
    # (m s^3 + c s^2 + (k + Kp) s + Ki)(s + wh) + Kd s^3 = 0
    polynomial = np.polyadd(np.polymul([m, c, k + kp, ki], [1, wh]), [kd, 0, 0, 0])
    poles = np.roots(polynomial)
    exponents = floquet_exponents(solution)
    # an exponent is defined up to i k omega: the multipliers exp(lambda T) are the same
    multipliers = np.exp(exponents / solution.frequency)
    for pole in np.exp(poles / solution.frequency):
        assert np.min(np.abs(multipliers - pole)) < 1e-9 * abs(pole)
    assert np.sum(exponents).real == pytest.approx(np.sum(poles).real, rel=1e-9)


def test_frictionless_small_motion_has_the_closed_loops_poles(frictionless_small_motion,
                                                              validation):
    solutions, linear = frictionless_small_motion
    for frequency, solution in solutions.items():
        # the exponents of the orbit are the closed loop's poles (w, I states included)
        exponents = np.sort_complex(floquet_exponents(solution))
        np.testing.assert_allclose(exponents, np.sort_complex(linear.poles), rtol=2e-5)
        validation(f"Harmonic balance at {frequency} Hz: Floquet exponents",
                   "the closed loop's poles", np.abs(
                       exponents / np.sort_complex(linear.poles) - 1).max(), 2e-5)


@pytest.mark.parametrize("index", [40, 150, 250])
def test_hill_exponents_are_the_monodromy_matrix_multipliers(softening_curve, monodromy, index,
                                                             validation):
    solution = softening_curve.solution(index)
    _, _, phi = monodromy(solution)
    multipliers = np.linalg.eigvals(phi[:2, :2])  # z, v: w and I are not coupled here
    hill = np.exp(floquet_exponents(solution) / solution.frequency)
    np.testing.assert_allclose(np.sort_complex(hill), np.sort_complex(multipliers),
                               rtol=1e-6, atol=1e-8)
    # Liouville: the exponents sum to the period-mean trace, -Cv/m without friction
    assert np.sum(floquet_exponents(solution)).real == pytest.approx(
        -solution.model.viscous_damping / solution.model.mass, rel=1e-8)
    validation(f"Hill's Floquet multipliers, softening orbit at {solution.frequency:.3f} Hz",
               "eigenvalues of the monodromy matrix (scipy DOP853, variational equations)",
               np.abs(np.sort_complex(hill) - np.sort_complex(multipliers)).max(),
               1e-8 + 1e-6 * np.abs(multipliers).max(), measure="absolute error [-]")
    validation(f"Sum of the Floquet exponents at {solution.frequency:.3f} Hz",
               "Liouville's formula: -Cv/m", abs(np.sum(floquet_exponents(solution)).real
                                                 / (-solution.model.viscous_damping
                                                    / solution.model.mass) - 1), 1e-8)


def test_stable_means_every_real_part_below_a_margin_of_omega():
    omega = 2 * np.pi * 3.0
    assert _is_stable(np.array([-1.0 + 2j, -1.0 - 2j, -0.1]), omega)
    assert not _is_stable(np.array([-1.0, 0.05]), omega)
    # within the margin (the truncation's noise on a neutral exponent) counts as stable
    assert _is_stable(np.array([-3.0, 0.5 * STABILITY_MARGIN * omega]), omega)
    assert not _is_stable(np.array([-3.0, 2 * STABILITY_MARGIN * omega]), omega)
