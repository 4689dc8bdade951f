"""What a linear controller reads (qzs.model.sensors): each sensor named in SENSORS is, in a
run, the physical quantity its description says, in the kernels' order."""
import numpy as np
import pytest

from qzs import LinearController, PIDamping, Sine, simulate
from qzs.model.sensors import MAX_STATES, SENSORS

#: A static gain this small leaves the run as it is (its force is ~1e-9 N) [N per unit].
GAIN = 1e-9


def _quantity(result, sensor):
    """The quantity ``sensor`` names, from the run's own channels."""
    if sensor == "position_error":
        return result.controller.position_setpoint - result.relative_position
    return result[sensor]


@pytest.mark.parametrize("sensor", list(SENSORS))
def test_each_sensor_is_the_quantity_it_names(sensor):
    # a discrete controller may feed the payload acceleration through (it reads it with the
    # force held); a continuous one reads it through its states only
    sample_time = 1e-3 if sensor == "payload_acceleration" else 0.0
    linear = LinearController(d=[[GAIN]], inputs=(sensor,), sample_time=sample_time)
    result = simulate(Sine(amplitude=0.004, frequency=3.0), controller=PIDamping() + linear,
                      duration=0.5, dt=1e-4, sample_rate=1000.0)
    force = result["linear_force"] / GAIN
    quantity = _quantity(result, sensor)
    if sample_time:  # each row is a sample instant, recorded before that sample (the value
        # held until then, as the sampled PI's): the output read at the row before
        np.testing.assert_allclose(force[1:], quantity[:-1], rtol=1e-6,
                                   atol=1e-6 * np.ptp(quantity))
    else:
        np.testing.assert_allclose(force, quantity, rtol=1e-9, atol=1e-9 * np.ptp(quantity))


def test_the_sensors_have_units_and_a_controller_its_state_bound():
    assert all(unit in ("m", "m/s", "m/s^2") for unit, _ in SENSORS.values())
    # each its quantity's unit: a position error in m, a velocity in m/s, an acceleration in m/s^2
    quantity = {"error": "m", "velocity": "m/s", "acceleration": "m/s^2"}
    assert {name: unit for name, (unit, _) in SENSORS.items()} == \
        {name: quantity[name.rsplit("_", 1)[1]] for name in SENSORS}
    with pytest.raises(ValueError, match="states"):
        LinearController(a=np.eye(MAX_STATES + 1), b=np.ones((MAX_STATES + 1, 1)),
                         c=np.ones((1, MAX_STATES + 1)), d=[[0.0]])
