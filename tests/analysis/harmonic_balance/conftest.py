"""Shared by the tests of qzs.analysis.harmonic_balance: models with closed forms, the
softening curve, and the smooth model integrated in time with its variational equations."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qzs
from qzs import ControllerParameters, IsolatorParameters
from qzs.analysis.harmonic_balance import (SmoothModel, frequency_response_curve,
                                           periodic_response, smooth_right_hand_side)

#: The MagSpring about z = 0, frictionless and lightly damped, no controller, no gravity:
#: a softening oscillator of 4.34 Hz whose resonance leans left and folds.
SOFTENING = dict(isolator=IsolatorParameters(stiction_force=0.0, coulomb_force=0.0,
                                             viscous_damping=3.0, gravity=0.0),
                 controller=ControllerParameters(pi_kp=0.0, pi_ki=0.0, position_setpoint=0.0))
SOFTENING_AMPLITUDE = 0.5e-3
#: Harmonics that resolve the softening orbits to 1e-9 m (10 leave 3e-6 m at the peak).
SOFTENING_HARMONICS = 20


def _linear_model(*, stiffness=400.0, viscous_damping=15.0, pi_kp=50.0, pi_ki=20.0,
                 damping_gain=30.0, velocity_highpass=1.0, amplitude=1e-3):
    """A smooth model that is linear: a MagSpring so wide (b = 1e-5 1/m) that ``a tanh(b z)``
    is ``a b z`` to 1e-12 over the 16 cm the weight sags it by, no dry friction."""
    shape = 1e-5
    return SmoothModel(mass=6.4, gravity=9.81, spring_force=stiffness / shape,
                       spring_shape=shape, stiction_force=0.0, coulomb_force=0.0,
                       stribeck_decay=100.0, viscous_damping=viscous_damping,
                       position_setpoint=-0.002, pi_kp=pi_kp, pi_ki=pi_ki,
                       damping_gain=damping_gain, velocity_highpass=velocity_highpass,
                       friction_velocity=1e-3, amplitude=amplitude)


def _linear_transmissibility(frequency, model):
    """Payload over base displacement of the linear model, complex [-]: from
    ``m s^2 X + Kd HP(s) s X + (c s + k + Kp + Ki/s)(X - Y) = 0``, ``HP(s) = s/(s + w_hp)``."""
    s = 2j * np.pi * np.asarray(frequency, dtype=float)
    k = model.spring_force * model.spring_shape
    highpass = s / (s + model.highpass_omega) if model.velocity_highpass > 0 else 1.0
    relative = model.viscous_damping * s + k + model.pi_kp + model.pi_ki / s
    return relative / (model.mass * s * s + model.damping_gain * highpass * s + relative)


@pytest.fixture
def linear_model():
    """The factory of linear smooth models (see :func:`_linear_model`)."""
    return _linear_model


@pytest.fixture
def linear_transmissibility():
    """The closed form ``(frequency, model) -> X/Y`` of a linear model (complex)."""
    return _linear_transmissibility


@pytest.fixture
def softening():
    """The softening case: ``parameters`` (isolator and controller), ``amplitude`` [m] and
    ``harmonics``."""
    return dict(parameters=SOFTENING, amplitude=SOFTENING_AMPLITUDE,
                harmonics=SOFTENING_HARMONICS)


@pytest.fixture(scope="session")
def softening_curve():
    model = SmoothModel.from_parameters(**SOFTENING, amplitude=SOFTENING_AMPLITUDE)
    return frequency_response_curve(model, (3.0, 4.6), harmonics=SOFTENING_HARMONICS)


def _variational(frequency, model):
    """The smooth ODE with its variational equations, the Jacobian by central differences."""
    def rhs(t, y):
        x, phi = y[:4], y[4:].reshape(4, 4)
        jac = np.empty((4, 4))
        for j in range(4):
            step = np.zeros(4)
            step[j] = 1e-7 * max(1.0, abs(x[j]))
            jac[:, j] = (smooth_right_hand_side(t, x + step, frequency, model)
                         - smooth_right_hand_side(t, x - step, frequency, model)) / (2 * step[j])
        return np.concatenate([smooth_right_hand_side(t, x, frequency, model),
                               (jac @ phi).ravel()])
    return rhs


def _monodromy(solution):
    """``(start, end, Phi)``: the state at phase 0, after one period of the smooth ODE, and
    the monodromy matrix (scipy DOP853, tight tolerances)."""
    period = 1.0 / solution.frequency
    start = solution.state_at_start()
    sol = solve_ivp(_variational(solution.frequency, solution.model), (0, period),
                    np.concatenate([start, np.eye(4).ravel()]), method="DOP853", rtol=1e-11,
                    atol=1e-13)
    return start, sol.y[:4, -1], sol.y[4:, -1].reshape(4, 4)


@pytest.fixture
def monodromy():
    """The function ``solution -> (start, end, Phi)`` (see :func:`_monodromy`)."""
    return _monodromy


@pytest.fixture(scope="session")
def linear_curve():
    """The frequency-response curve of the default linear model, 0.3-8 Hz, 3 harmonics."""
    return frequency_response_curve(_linear_model(), (0.3, 8.0), harmonics=3)


@pytest.fixture(scope="session")
def frictionless_small_motion():
    """``(solutions, linear)``: the default plant without dry friction, with active damping,
    at 0.1 mm (the MagSpring's tangent stiffness, steep on its plateau, stays put), solved
    at 0.2, 1, 3 and 10 Hz with 5 harmonics, and its linearised closed loop
    (python-control)."""
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    controller = ControllerParameters(damping_gain=30.0)
    model = SmoothModel.from_parameters(isolator, controller, amplitude=1e-4)
    solutions = {frequency: periodic_response(frequency, model, harmonics=5)
                 for frequency in (0.2, 1.0, 3.0, 10.0)}
    return solutions, qzs.linearize(isolator, controller)
