"""The isolator's controller: PI position loop plus active damping (paper Fig. 6).

The control laws::

    e       = z_ref - z
    F_pi    = Kp*e + Ki*integral(e)            (anti-windup: the integral is frozen
                                                while the motor saturates and e pushes
                                                further into saturation)
    F_d     = -Kd * v_payload_measured         (accelerometer integrated by the charge
                                                amplifier, with its first-order high-pass)
    F_motor = clip(F_pi + F_d, -F_max, F_max)

Continuous, or sampled at ``controller_rate`` with zero-order hold (dSPACE DS1104).
"""
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from qzs._validation import non_negative_real, parameter, real, validate_fields
from qzs.model.isolator import IsolatorParameters, spring_stiffness

__all__ = ["ControllerParameters", "closed_loop_natural_frequency"]


@dataclass(frozen=True, kw_only=True)
class ControllerParameters:
    """Gains and settings of the PI position loop and the active damping loop.

    Parameters
    ----------
    position_setpoint : float
        Encoder position setpoint z_ref [m]; default -0.060 m, the middle of the
        MagSpring's constant-force region (docs/model.md §1, operating point).
    pi_kp : float
        Proportional gain Kp [N/m]; Kp = 50 N/m moves the resonance to about 0.45 Hz.
    pi_ki : float
        Integral gain Ki [N/(m*s)].
    damping_gain : float
        Active damping gain Kd [N*s/m] on the measured payload velocity.
    velocity_highpass : float
        Corner of the charge amplifier's first-order high-pass on the payload
        velocity [Hz]; 0 switches it off.
    controller_rate : float
        Sampling rate of a discrete controller with zero-order hold [Hz];
        0 (default) runs the controller in continuous time.
    """

    position_setpoint: float = parameter(-0.060, "m", "encoder position setpoint z_ref")
    pi_kp: float = parameter(50.0, "N/m", "PI proportional gain Kp")
    pi_ki: float = parameter(20.0, "N/(m*s)", "PI integral gain Ki")
    damping_gain: float = parameter(0.0, "N*s/m", "active damping gain Kd")
    velocity_highpass: float = parameter(1.0, "Hz", "charge-amplifier high-pass corner (0 = off)")
    controller_rate: float = parameter(0.0, "Hz", "controller sampling rate (0 = continuous)")

    def __post_init__(self):
        validate_fields(self, {
            "position_setpoint": real,
            "pi_kp": non_negative_real,
            "pi_ki": non_negative_real,
            "damping_gain": non_negative_real,
            "velocity_highpass": non_negative_real,
            "controller_rate": non_negative_real,
        })

    def to_dict(self) -> dict[str, Any]:
        """Return the parameters as a plain ``dict``."""
        return asdict(self)


def closed_loop_natural_frequency(isolator: IsolatorParameters | None = None,
                                  controller: "ControllerParameters | None" = None,
                                  relative_position: float | None = None) -> float:
    """Undamped natural frequency [Hz] of the payload with the PI loop closed.

    ``sqrt((k_spring(z) + Kp)/m) / (2*pi)`` with ``k_spring`` the MagSpring's
    tangent stiffness at ``relative_position`` (default: the setpoint). The
    integral and damping terms shift it only slightly; the full linearised
    model is :func:`qzs.analysis.linear.linearize`.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Controller parameters; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default ``controller.position_setpoint``.

    Returns
    -------
    float
        Natural frequency [Hz].
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    z = controller.position_setpoint if relative_position is None else relative_position
    stiffness = float(spring_stiffness(z, isolator)) + controller.pi_kp
    return float(np.sqrt(stiffness / isolator.mass) / (2 * np.pi))
