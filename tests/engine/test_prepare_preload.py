"""The bumpless start with everything the motor's command holds (docs/model.md §5, §5.1).

The static load is worked out with the base at rest; the PI's integral (without one, a linear
controller's integrator) nets every other term of the command as it stands at the run's own
t = 0: the proportional and damping terms, the blocks' outputs with the linear controller's
states at t = 0 and a sampled block's first output. The motor therefore starts at the static
load, ``m*g - a*tanh(-b*z0)``, whatever those terms put out there. Each case below started
the motor elsewhere before the rule was kept everywhere (issue 40): a lag's output from its
states, a sampled feedthrough, the damping of a payload slipping at t = 0, the damping on a
moving base when a linear controller's integrator carries the load, a feedthrough on the
base's acceleration. The cases from a slip at t = 0 after them each hold a term a planted bug
dropped unseen (the mutation round of issue 40): the damping without the amplifier's
high-pass (settled, it reads 0 at t = 0), the compensation along the slip, a block on the
slip velocity.
"""
import numpy as np
import pytest

from qzs import (FrictionCompensation, IsolatorParameters, LinearController, PIDamping, Sine,
                 simulate)
from qzs.model.isolator import InitialState

ISOLATOR = IsolatorParameters()
Z_REF = PIDamping().position_setpoint
#: y' = 2 pi f A = 0.19 m/s at t = 0, y'' = 0.
MOVING = Sine(amplitude=0.01, frequency=3.0, fade_in=0.0)
#: y'' = -(2 pi f)^2 A = -3.55 m/s^2 at t = 0, y' = 0.
ACCELERATING = Sine(amplitude=0.01, frequency=3.0, phase=np.pi / 2, fade_in=0.0)
OFF_SETPOINT = InitialState(relative_position=Z_REF + 1e-3)
#: Slipping upwards at t = 0, 1 cm/s.
SLIPPING = InitialState(relative_velocity=0.01)
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
    # the charge amplifier's high-pass off: the damping reads the payload's velocity itself,
    # not 0 as with a settled high-pass
    "damping without the high-pass, slipping at t = 0": (
        MOVING, PIDamping(damping_gain=100.0, velocity_highpass=0.0), SLIPPING),
    "no PI integral, linear PI and damping without the high-pass, slipping at t = 0": (
        MOVING, PIDamping(pi_ki=0.0, damping_gain=100.0, velocity_highpass=0.0,
                          linear=LINEAR_PI), SLIPPING),
    # the compensation pushes along the slip (its direction) from t = 0 on
    "compensation, slipping at t = 0": (
        MOVING, PIDamping(compensation=FrictionCompensation()), SLIPPING),
    "sampled compensation, slipping at t = 0": (
        MOVING, PIDamping(controller_rate=1000.0, compensation=FrictionCompensation()),
        SLIPPING),
    "feedthrough on the slip velocity, slipping at t = 0": (
        MOVING, PIDamping(linear=LinearController.from_transfer_function(
            [300.0], [1.0], "relative_velocity")), SLIPPING),
    "sampled feedthrough on the slip velocity, slipping at t = 0": (
        MOVING, PIDamping(linear=LinearController(
            a=[[0.5]], b=[[1.0]], c=[1.0], d=[300.0], inputs=("relative_velocity",),
            sample_time=1e-3)), SLIPPING),
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



def test_a_sampled_compensation_holds_its_law_at_the_initial_state_from_t_0():
    """Sampled, the compensation at t = 0 is its law at the initial slip, not 0.

    With ``fraction = 1`` and the plant's own friction levels (its viscous part not
    compensated, the default) it cancels the friction but the viscous ``-c_v v``:
    ``F_comp = -(F_friction + c_v v0)``; the continuous compensation's value at t = 0.
    """
    controller = PIDamping(controller_rate=1000.0, compensation=FrictionCompensation())
    run = simulate(MOVING, ISOLATOR, controller, duration=0.01, initial_state=SLIPPING)
    v0 = SLIPPING.relative_velocity
    expected = -(run["friction_force"][0] + ISOLATOR.viscous_damping * v0)
    assert expected > 1.0  # along the slip: the friction's Coulomb level, some newtons
    assert run["compensation_force"][0] == pytest.approx(expected, rel=1e-12)


def test_a_lag_on_the_slip_velocity_starts_at_its_equilibrium():
    """A first-order lag ``k w / (s + w)`` on the slip velocity starts in equilibrium with
    the initial slip: its output at t = 0 is its DC gain times ``v0``, ``k v0``, and its
    state does not move at first (A x0 + B u0 = 0)."""
    gain, corner = 200.0, 50.0
    lag = LinearController.from_transfer_function([gain * corner], [1.0, corner],
                                                  "relative_velocity")
    run = simulate(MOVING, ISOLATOR, PIDamping(linear=lag), duration=0.01,
                   initial_state=SLIPPING)
    assert run["linear_force"][0] == pytest.approx(gain * SLIPPING.relative_velocity,
                                                   rel=1e-9)


def test_with_a_pi_integral_the_pi_carries_the_load_not_the_linear_integrator():
    """Both the PI and a linear controller have an integrator: the PI's carries the static
    load (docs/model.md §5.1), the linear one starts empty. At the setpoint with the base at
    rest, its output ``C x0 + D u0`` is then 0, the motor's whole static load the PI's."""
    run = simulate(Sine(amplitude=0.01, frequency=3.0), ISOLATOR, PIDamping(linear=LINEAR_PI),
                   duration=0.01)
    assert run["linear_force"][0] == pytest.approx(0.0, abs=1e-9)
    assert run["pi_force"][0] == pytest.approx(static_load(Z_REF), rel=1e-12)
