"""The linearised loop with a spring law other than the tanh (docs/model.md §3.1, §8).

The loop's stiffness is the law's tangent stiffness at the operating point plus ``Kp``: a
Duffing spring's ``k1 + 3 k3 u^2``, the oblique-spring mechanism's zero at its QZS centre, a
table sampled from the tanh the tanh's within the table's interpolation error.
"""
import numpy as np
import pytest

from qzs import IsolatorParameters, PIDamping, linearize
from qzs.model.springs import (ObliqueSpringQZS, PolynomialSpring, TabulatedSpring,
                               TanhSpring)

CONTROLLER = PIDamping()


@pytest.mark.parametrize("z0", [-0.06, -0.05, -0.075])
def test_a_duffing_spring_s_loop_stiffness_and_natural_frequency(z0):
    k1, k3 = 100.0, 5.0e4
    iso = IsolatorParameters(spring=PolynomialSpring(coefficients=(62.78, -k1, 0.0, -k3),
                                                     center=-0.06))
    model = linearize(iso, CONTROLLER, relative_position=z0)
    stiffness = k1 + 3 * k3 * (z0 + 0.06) ** 2 + CONTROLLER.pi_kp
    assert model.stiffness == pytest.approx(stiffness, rel=1e-12)
    assert model.undamped_natural_frequency == pytest.approx(
        np.sqrt(stiffness / iso.mass) / (2 * np.pi), rel=1e-12)
    # the loop's low-frequency transmissibility is 1 (the PI's integral), its corner the
    # natural frequency's order: the law moved the whole transfer, not a number beside it
    tanh = linearize(IsolatorParameters(), CONTROLLER, relative_position=z0)
    assert model.transmissibility(0.01) == pytest.approx(1.0, abs=1e-3)
    assert model.transmissibility(3.0) != pytest.approx(tanh.transmissibility(3.0), rel=1e-3)


def test_the_quasi_zero_mechanism_leaves_only_the_position_loop_s_stiffness():
    law = ObliqueSpringQZS.quasi_zero()
    iso = IsolatorParameters(spring=law)
    model = linearize(iso, CONTROLLER, relative_position=law.center)
    assert model.stiffness == pytest.approx(CONTROLLER.pi_kp, rel=1e-9)
    off = linearize(iso, CONTROLLER, relative_position=law.center + 0.02)
    assert off.stiffness > CONTROLLER.pi_kp + 1.0  # stiffer away from the centre


def test_a_table_of_the_tanh_linearises_as_the_tanh_within_its_interpolation_error():
    """The loop's stiffness anywhere in the stroke: its largest error falls with the table's
    spacing (PCHIP's slope error: between h and h^2 near the tanh's knee, where its
    shape-preserving slopes limit it)."""
    tanh = TanhSpring()
    z0 = np.linspace(-0.1, -0.02, 33)
    exact = np.array([linearize(IsolatorParameters(), CONTROLLER, relative_position=z).stiffness
                      for z in z0])
    errors = []
    for count in (41, 81, 161):
        table = TabulatedSpring.from_law(tanh, np.linspace(-0.12, 0.0, count))
        iso = IsolatorParameters(spring=table)
        errors.append(max(abs(linearize(iso, CONTROLLER, relative_position=z).stiffness - k)
                          for z, k in zip(z0, exact)))
    assert errors[-1] < 1e-3 * exact.max(), errors  # [N/m]
    # each halving of the spacing at least halves it, and two quarter it at least 8-fold
    assert errors[0] / errors[1] > 2 and errors[1] / errors[2] > 2, errors
    assert errors[0] / errors[2] > 8, errors


def test_a_negative_loop_stiffness_has_no_undamped_natural_frequency():
    """A law whose negative stiffness outweighs Kp (the oblique mechanism with a softer
    vertical spring: k_v + 2 k_o (1 - L0/d) = 120 - 200 = -80 N/m, with Kp = 50 N/m) has no
    undamped natural frequency: it is NaN, without a RuntimeWarning; the stiffness is the
    closed form's and the transfer is still the loop's (its unstable pole on the right)."""
    iso = IsolatorParameters(spring=ObliqueSpringQZS(vertical_stiffness=120.0))
    model = linearize(iso, CONTROLLER)  # the suite turns a RuntimeWarning into an error
    assert model.stiffness == pytest.approx(120.0 + 400.0 * (1 - 1.5) + CONTROLLER.pi_kp,
                                            rel=1e-12)
    assert np.isnan(model.undamped_natural_frequency)
    assert np.max(model.poles.real) > 0
