"""The six-axis drivers (qzs.engine.hexapod.simulate): the output rate decimates the run, it
does not change it; every sample of a streamed run reaches the sink in time order."""
import numpy as np
import pytest

from qzs import ControllerParameters, Sine
from qzs.engine.hexapod import simulate_hexapod
from qzs.model.hexapod import PlatformParameters, cubic_geometry

STABLE = ControllerParameters(pi_kp=2000.0, pi_ki=800.0)


@pytest.fixture(scope="module")
def setup():
    return (cubic_geometry(cube_edge=0.3, cube_center_height=0.3),
            PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5])))


def test_a_lower_output_rate_keeps_every_kth_sample_bit_for_bit(setup):
    geometry, platform = setup
    options = dict(controller=STABLE, excitation={"z": Sine(amplitude=0.005, frequency=3.0),
                                                  "rx": Sine(amplitude=0.01, frequency=2.0)},
                   duration=0.3, dt=1e-4)
    every_step = simulate_hexapod(geometry, platform, **options, sample_rate=1e4)
    decimated = simulate_hexapod(geometry, platform, **options, sample_rate=500.0)
    assert len(every_step) == 3001 and len(decimated) == 151
    for name in ("time", "platform_pose", "relative_position", "motor_force", "base_work"):
        np.testing.assert_array_equal(decimated[name], every_step[name][::20], err_msg=name)
    np.testing.assert_array_equal(decimated["locked"], every_step["locked"][::20])

    blocks = []
    streamed = simulate_hexapod(geometry, platform, **options, sample_rate=500.0,
                                sink=lambda data, flags: blocks.append(data.copy()))
    rows = np.concatenate(blocks)
    np.testing.assert_array_equal(rows[:, 0], decimated["time"])
    assert streamed.statistics == decimated.statistics
