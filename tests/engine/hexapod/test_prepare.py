"""The six-axis stability test (qzs.engine.hexapod.prepare): each leg's stiff modes on the
lightest mass the legs move, in closed form for the cubic configuration; and each leg's
bumpless start with its blocks (docs/model.md §5.1)."""
import dataclasses

import numpy as np
from helpers import vertical_legs

from qzs import (ControllerParameters, IsolatorParameters, LinearController, PIDamping, Sine,
                 largest_stable_step)
from qzs.engine.hexapod import simulate_hexapod
from qzs.engine.hexapod.prepare import hexapod_stability_test
from qzs.model.hexapod import PlatformParameters, cubic_geometry

#: The base accelerating at t = 0 (y'' = -(2 pi 3)^2 0.01 = -3.55 m/s^2, y' = 0).
ACCELERATING = Sine(amplitude=0.01, frequency=3.0, phase=np.pi / 2, fade_in=0.0)


def test_the_cubic_legs_move_half_the_platforms_mass():
    """The cube's six legs run along three orthogonal axes, two per axis: with rotations
    negligible (a huge inertia), G M^-1 G^T = U U^T / m, whose largest eigenvalue is that of
    U^T U / m = 2 I / m. The lightest mass a leg moves is m / 2, so the largest stable step
    is the single axis's with the mass m / 2."""
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.0, inertia=np.diag([1e6, 1e6, 1e6]))
    # the stiffest mode: the stop's, undamped, sqrt(k/m) (ode3 and rk4 hold part of the
    # imaginary axis: their limit grows with the mass)
    isolator = IsolatorParameters(stop_stiffness=1e7, stop_damping=0.0)
    controller = ControllerParameters(velocity_highpass=0.0, damping_gain=0.0)
    for solver in ("ode3", "rk4"):
        limit = largest_stable_step(dataclasses.replace(isolator, mass=11.0), controller, solver)
        whole = largest_stable_step(dataclasses.replace(isolator, mass=22.0), controller, solver)
        assert limit < 0.9 * whole               # the mass matters
        stable = hexapod_stability_test(geometry, platform, isolator, controller, solver)
        assert stable(0.999 * limit) and not stable(1.001 * limit)


def test_each_leg_nets_its_own_base_accelerometer_at_t_0():
    """On the cube a base accelerating along x and z at t = 0 reads differently along each
    leg. A feedthrough on the base's acceleration puts out ``-2 y''_i`` on leg ``i``, which
    that leg's PI preload nets: each motor starts where it starts without the block, at its
    leg's static load (the blocks move no motor at t = 0)."""
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    feedthrough = LinearController.from_transfer_function([-2.0], [1.0], "base_acceleration")
    options = dict(excitation={"x": ACCELERATING, "z": Sine(amplitude=0.004, frequency=5.0,
                                                             phase=np.pi / 2, fade_in=0.0)},
                   duration=0.01, sample_rate=10000.0)
    plain = simulate_hexapod(geometry, platform, controller=PIDamping(), **options)
    fed = simulate_hexapod(geometry, platform, controller=PIDamping() + feedthrough, **options)
    linear = fed["linear_force"][0]
    assert np.ptp(linear) > 1.0  # N: the legs read different accelerations
    np.testing.assert_allclose(fed["motor_force"][0], plain["motor_force"][0], rtol=0,
                               atol=1e-9)


def test_with_a_pi_integral_each_legs_pi_carries_the_load_not_its_linear_integrator():
    """Both the PI and a linear controller have an integrator: on each leg the PI's carries
    the static load (docs/model.md §5.1), the linear one starts empty (0 output at home with
    the base at rest), as on the single axis."""
    isolator = IsolatorParameters()
    linear_pi = LinearController.from_transfer_function([30.0, 3000.0], [1.0, 0.0],
                                                        "position_error")
    platform = PlatformParameters(mass=6 * isolator.mass, inertia=np.diag([1.0, 1.0, 1.5]))
    result = simulate_hexapod(vertical_legs(), platform, isolator, PIDamping() + linear_pi,
                              excitation={"z": Sine(amplitude=0.01, frequency=3.0)},
                              duration=0.01)
    static = isolator.mass * isolator.gravity - isolator.spring_force * np.tanh(
        -isolator.spring_shape * PIDamping().position_setpoint)
    np.testing.assert_allclose(result["linear_force"][0], 0.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(result["pi_force"][0], static, rtol=1e-9)
