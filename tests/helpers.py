"""Named parameter sets and small helpers shared by the simulator tests."""
import numpy as np

from qzs import Chirp, ControllerParameters, IsolatorParameters

#: MagSpring shape [1/m] small enough that ``-a*tanh(b*z)`` is linear to ~1e-10 over the
#: strokes used in the linear tests: the stiffness is then ``a*b`` about z = 0.
LINEAR_SHAPE = 1e-3

#: The default chirp shortened to 20 s: 10 mm, 0 -> 20 Hz, breaks stiction near 2 Hz.
SHORT_CHIRP = Chirp(duration=20.0)
PASSIVE = ControllerParameters(pi_kp=0.0, pi_ki=0.0)


def linear_isolator(stiffness=100.0, damping=100.0, mass=6.4, **overrides):
    """A frictionless, weightless isolator with a linear spring and no reachable stop.

    The stops are centred on z = 0 and 1 km away, the motor never saturates.
    """
    settings = dict(mass=mass, gravity=0.0, stiction_force=0.0, coulomb_force=0.0,
                    spring_shape=LINEAR_SHAPE, spring_force=stiffness / LINEAR_SHAPE,
                    viscous_damping=damping, stop_center=0.0, stroke_half=1e3,
                    motor_force_max=1e9)
    settings.update(overrides)
    return IsolatorParameters(**settings)


def linear_controller(**overrides):
    """PI (+ damping) loop about the setpoint z = 0, continuous, high-pass off."""
    settings = dict(position_setpoint=0.0, pi_kp=0.0, pi_ki=0.0, damping_gain=0.0,
                    velocity_highpass=0.0, controller_rate=0.0)
    settings.update(overrides)
    return ControllerParameters(**settings)


def stick_rises(locked):
    """Number of slip -> locked transitions in a boolean series."""
    return int(np.count_nonzero(np.diff(locked.astype(np.int8)) == 1))
