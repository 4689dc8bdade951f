"""Linear analysis at the operating point (python-control).

Linearising eq. (1) about the setpoint while the payload slips, with the
Coulomb and Stribeck terms left out (they have no linear part at v = 0) and the
motor unsaturated, gives the closed loop

    m*s^2*X = -(k + c*s)*Z - (Kp + Ki/s)*Z - Kd*HP(s)*s*X,      Z = X - Y,

with ``k`` the MagSpring's tangent stiffness at the setpoint, ``c`` the viscous
friction, ``HP(s) = s/(s + w_hp)`` the charge amplifier's high-pass. Hence the
absolute transmissibility

    T(s) = X/Y = (c*s + k + Kp + Ki/s) / (m*s^2 + c*s + k + Kp + Ki/s + Kd*s*HP(s)).

This is the frictionless-guide limit the nonlinear simulator must reproduce
(tests), and the overlay shown with nonlinear transmissibility curves.
"""
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, spring_stiffness

if TYPE_CHECKING:
    import control

__all__ = ["LinearModel", "linearize", "linear_transmissibility", "loop_constants"]


@dataclass(frozen=True)
class LinearModel:
    """Linearised closed loop at the operating point.

    Attributes
    ----------
    transfer_function : control.TransferFunction
        Base displacement -> payload displacement, ``X/Y`` (dimensionless).
    state_space : control.StateSpace
        The same, as a state-space model (input y, output x).
    stiffness : float
        Total stiffness at the setpoint, spring + Kp [N/m].
    undamped_natural_frequency : float
        ``sqrt(stiffness/m)/(2*pi)`` [Hz]: about 0.08 Hz passive, 0.45 Hz with Kp = 50 N/m.
    natural_frequency : float
        Natural frequency of the dominant (least-damped oscillatory) pole pair [Hz].
    damping_ratio : float
        Its damping ratio [-].
    poles : ndarray
        Closed-loop poles [rad/s].
    """

    transfer_function: "control.TransferFunction"
    state_space: "control.StateSpace"
    stiffness: float
    undamped_natural_frequency: float
    natural_frequency: float
    damping_ratio: float
    poles: np.ndarray

    def transmissibility(self, frequency: ArrayLike) -> float | NDArray[np.float64]:
        """``|X/Y|`` at ``frequency`` [Hz] (amplitude ratio).

        Parameters
        ----------
        frequency : float or array_like
            Frequency [Hz].

        Returns
        -------
        float or ndarray
            Amplitude ratio ``|X/Y|`` [-], of the shape of ``frequency``.
        """
        response = self.transfer_function(2j * np.pi * np.asarray(frequency, dtype=float))
        return np.abs(response)


def loop_constants(isolator, controller, relative_position=None):
    """The linear closed loop's constants at an operating point, the one place they are read.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    relative_position : float, optional
        Operating point z [m]; default the position setpoint.

    Returns
    -------
    tuple of float
        ``(m, c, k, Kp, Ki, Kd, w_hp)``: mass [kg], viscous damping [N*s/m], MagSpring
        tangent stiffness at the operating point [N/m], PI gains [N/m, N/(m*s)], damping
        gain [N*s/m] and the high-pass corner [rad/s] (0: none).
    """
    z0 = controller.position_setpoint if relative_position is None else relative_position
    return (isolator.mass, isolator.viscous_damping, float(spring_stiffness(z0, isolator)),
            controller.pi_kp, controller.pi_ki, controller.damping_gain,
            2 * np.pi * controller.velocity_highpass)


def linearize(isolator: IsolatorParameters | None = None,
              controller: ControllerParameters | None = None,
              relative_position: float | None = None) -> LinearModel:
    """Linearise the closed-loop isolator at its operating point.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the position setpoint.

    Returns
    -------
    LinearModel
    """
    import control

    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    m, c, k, kp, ki, kd, w_hp = loop_constants(isolator, controller, relative_position)
    s = control.tf("s")
    highpass = s / (s + w_hp) if w_hp > 0 else 1
    coupling = c * s + k + kp + (ki / s if ki > 0 else 0)
    transfer = control.minreal(coupling / (m * s ** 2 + coupling + kd * s * highpass),
                               verbose=False)
    state_space = control.ss(transfer)
    poles = np.asarray(transfer.poles())
    oscillatory = poles[np.abs(poles.imag) > 1e-9]
    dominant = oscillatory if oscillatory.size else poles
    dominant = dominant[np.argmin(np.abs(dominant))] if dominant.size else 0j
    wn = abs(dominant)
    zeta = -dominant.real / wn if wn > 0 else 1.0
    undamped = np.sqrt((k + kp) / m) / (2 * np.pi)
    return LinearModel(transfer, state_space, k + kp, float(undamped), wn / (2 * np.pi),
                       float(zeta), poles)


def linear_transmissibility(frequency, isolator=None, controller=None):
    """Closed-form ``|X/Y|`` [-] of the linearised isolator at ``frequency`` [Hz].

    Parameters
    ----------
    frequency : float or array_like
        Frequency [Hz].
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.

    Returns
    -------
    float or ndarray
        Amplitude ratio ``|X/Y|`` [-] at the setpoint (see :func:`linearize`).
    """
    return linearize(isolator, controller).transmissibility(frequency)
