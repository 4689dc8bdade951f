"""The six-axis stability test (qzs.engine.hexapod.prepare): each leg's stiff modes on the
lightest mass the legs move, in closed form for the cubic configuration."""
import dataclasses

import numpy as np

from qzs import ControllerParameters, IsolatorParameters, largest_stable_step
from qzs.engine.hexapod.prepare import hexapod_stability_test
from qzs.model.hexapod import PlatformParameters, cubic_geometry


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
