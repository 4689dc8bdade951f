"""The friction law's describing function against Coulomb's closed form ``4 Fc/(pi A)``."""
import numpy as np
import pytest

from qzs import IsolatorParameters, ParameterError
from qzs.analysis import control_design as cd


def test_coulomb_describing_function_against_python_controls_numerical_one(validation):
    force = 2.0
    isolator = IsolatorParameters(stiction_force=force, coulomb_force=force)
    amplitude = np.array([1e-3, 1e-2, 0.3])
    numeric = cd.friction_describing_function(isolator, amplitude, points=20000)
    np.testing.assert_allclose(numeric.real, cd.coulomb_describing_function(force, amplitude),
                               rtol=1e-6)
    validation("Describing function of Coulomb friction", "4 Fc / (pi A) against python-control's "
               "numerical first harmonic", np.abs(
                   numeric.real / cd.coulomb_describing_function(force, amplitude) - 1).max(),
               1e-6)
    assert np.all(np.abs(numeric.imag) < 1e-3 * numeric.real)


def test_the_friction_nonlinearity_is_the_odd_steady_friction_law():
    law = cd.FrictionNonlinearity(10.0, 1.0, 100.0)
    assert law(0.0) == 0.0
    assert law(1e-3) == pytest.approx(1.0 + 9.0 * np.exp(-0.1), rel=1e-15)
    assert law(-1e-3) == -law(1e-3)
    assert law(10.0) == pytest.approx(1.0, rel=1e-12)  # the Stribeck term has died out


def test_the_amplitude_is_required():
    with pytest.raises(ParameterError, match="`amplitude`"):
        cd.friction_describing_function()
