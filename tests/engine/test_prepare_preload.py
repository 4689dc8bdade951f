"""The bumpless start with everything the motor's command holds (docs/model.md §5, §5.1).

The static load is worked out with the base at rest; the PI's integral (without one, a linear
controller's integrator) nets every other term of the command as it stands at the run's own
t = 0: the proportional and damping terms, the blocks' outputs with the linear controller's
states at t = 0 and a sampled block's first output. The motor therefore starts at the static
load, ``m*g - a*tanh(-b*z0)``, whatever those terms put out there. Each case below started
the motor elsewhere before the rule was kept everywhere (issue 40): a lag's output from its
states, a sampled feedthrough, the damping of a payload slipping at t = 0, the damping on a
moving base when a linear controller's integrator carries the load, a feedthrough on the
base's acceleration.
"""
import numpy as np
import pytest

from qzs import IsolatorParameters, LinearController, PIDamping, Sine, simulate
from qzs.model.isolator import InitialState

ISOLATOR = IsolatorParameters()
Z_REF = PIDamping().position_setpoint
#: y' = 2 pi f A = 0.19 m/s at t = 0, y'' = 0.
MOVING = Sine(amplitude=0.01, frequency=3.0, fade_in=0.0)
#: y'' = -(2 pi f)^2 A = -3.55 m/s^2 at t = 0, y' = 0.
ACCELERATING = Sine(amplitude=0.01, frequency=3.0, phase=np.pi / 2, fade_in=0.0)
OFF_SETPOINT = InitialState(relative_position=Z_REF + 1e-3)
#: A first-order lag on the position error, 200 N/m at DC: started 1 mm off the setpoint its
#: states hold -0.2 N.
LAG = LinearController.from_transfer_function([200.0 * 50.0], [1.0, 50.0], "position_error")
#: A PI on the position error, written as a linear controller (its integrator carries the load).
LINEAR_PI = LinearController.from_transfer_function([30.0, 3000.0], [1.0, 0.0],
                                                    "position_error")
DISCRETE = LinearController(a=[[0.5]], b=[[1.0]], c=[1.0], d=[300.0],
                            inputs=("position_error",), sample_time=1e-3)

CASES = {
    "lag on the error, off the setpoint": (MOVING, PIDamping(linear=LAG), OFF_SETPOINT),
    "sampled PI, discrete feedthrough, off the setpoint": (
        MOVING, PIDamping(controller_rate=1000.0, linear=DISCRETE), OFF_SETPOINT),
    "damping, slipping at t = 0": (MOVING, PIDamping(damping_gain=100.0),
                                   InitialState(relative_velocity=0.01)),
    "no PI integral, linear PI and damping": (
        MOVING, PIDamping(pi_ki=0.0, damping_gain=100.0, linear=LINEAR_PI), InitialState()),
    "feedthrough on the base's acceleration": (
        ACCELERATING, PIDamping(linear=LinearController.from_transfer_function(
            [-2.0], [1.0], "base_acceleration")), InitialState()),
}


def static_load(z0, isolator=ISOLATOR):
    """The load the spring does not carry at ``z0`` [N] (the stops far away)."""
    return isolator.mass * isolator.gravity - isolator.spring_force * np.tanh(
        -isolator.spring_shape * z0)


@pytest.mark.parametrize("name", list(CASES))
def test_the_motor_starts_at_the_static_load_whatever_the_rest_of_the_command(name):
    """The motor force recorded at t = 0 is the static load at the initial position."""
    excitation, controller, start = CASES[name]
    run = simulate(excitation, ISOLATOR, controller, duration=0.01, initial_state=start)
    z0 = Z_REF if start.relative_position is None else start.relative_position
    assert run["motor_force"][0] == pytest.approx(static_load(z0), rel=1e-12, abs=1e-12)

