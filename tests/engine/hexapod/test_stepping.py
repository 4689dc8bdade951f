"""The six-axis stepping (qzs.engine.hexapod.stepping): each solver converges at its order, the
legs' stick-slip transitions located inside the steps included (diffrax-style: the error
against a fine reference falls by 2**order when the step halves)."""
import numpy as np
import pytest

from qzs import ControllerParameters, Sine
from qzs.engine.hexapod import simulate_hexapod
from qzs.model.hexapod import PlatformParameters, cubic_geometry

ORDERS = {"euler": 1, "ode3": 3, "rk4": 4}


@pytest.fixture(scope="module")
def run():
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0)   # Table 1 legs, friction on
    excitation = {"z": Sine(amplitude=0.005, frequency=3.0, fade_in=0.0)}

    def simulate(dt, solver):
        return simulate_hexapod(geometry, platform, None, controller, excitation=excitation,
                                duration=1.0, dt=dt, sample_rate=100.0, solver=solver)

    return simulate


@pytest.mark.parametrize("solver", list(ORDERS))
def test_each_solver_converges_at_its_order_through_stick_slip(run, solver):
    reference = run(1.25e-5, "rk4")
    assert reference.run["events"] > 5 and reference["locked"].any()
    errors = [np.abs(run(dt, solver)["platform_pose"] - reference["platform_pose"]).max()
              for dt in (1e-3, 5e-4, 2.5e-4)]
    slopes = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(slopes - ORDERS[solver]) < 0.3), (errors, slopes)
