"""The result of a run (qzs.engine.result.SimulationResult): every channel an attribute and an
item, kinematics consistent with the excitation, the run's metadata, ``to_xarray`` with units."""
import numpy as np
import pytest
from helpers import SHORT_CHIRP

import qzs
from qzs import simulate
from qzs.engine.channels import CHANNELS, FLAGS


@pytest.fixture(scope="module")
def short_run():
    return simulate(SHORT_CHIRP, duration=3.0, dt=1e-4, sample_rate=500.0)


def test_every_channel_is_an_attribute_and_an_item(short_run):
    r = short_run
    assert len(r) == 3.0 * 500 + 1
    for name in [*CHANNELS, *FLAGS]:
        values = getattr(r, name)
        assert values.shape == (len(r),)
        np.testing.assert_array_equal(values, r[name])
        assert values.dtype == (bool if name in FLAGS else float)
    np.testing.assert_allclose(r.time, np.arange(len(r)) / 500.0, rtol=0, atol=1e-12)
    with pytest.raises(KeyError, match="no channel 'acceleration'; channels are time, base_displacement"):
        r["acceleration"]
    with pytest.raises(AttributeError):
        r.acceleration


def test_kinematic_channels_are_consistent(short_run):
    r = short_run
    np.testing.assert_allclose(r.payload_displacement, r.base_displacement + r.relative_position, rtol=0,
                               atol=1e-16)
    np.testing.assert_allclose(r.payload_velocity, r.base_velocity + r.relative_velocity, rtol=0, atol=1e-16)
    y, yd, ydd = qzs.engine.base_motion_series(SHORT_CHIRP, r.time)
    np.testing.assert_allclose(r.base_displacement, y, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.base_acceleration, ydd, rtol=0, atol=1e-12)


def test_run_metadata(short_run):
    run = short_run.run
    assert run["solver"] == "ode3" and run["dt"] == 1e-4 and run["sample_rate"] == 500.0
    assert run["steps"] == 30000 and run["completed"] is True and short_run.completed
    assert run["stop_low"] == pytest.approx(-0.14) and run["stop_high"] == pytest.approx(0.02)
    assert short_run.steps_per_second > 0
    assert "1501 samples" in repr(short_run) and "ode3" in repr(short_run)


def test_to_xarray_carries_units_and_metadata(short_run):
    dataset = short_run.to_xarray()
    assert set(dataset.data_vars) == (set(CHANNELS) - {"time"}) | set(FLAGS)
    for name, (_, unit, doc) in CHANNELS.items():
        assert dataset[name].attrs["units"] == unit
        if name != "time":
            np.testing.assert_array_equal(dataset[name].values, short_run[name])
            assert dataset[name].attrs["long_name"] == doc
    assert dataset["locked"].dtype == bool
    attrs = dataset.attrs
    assert attrs["qzs_version"] == qzs.__version__
    assert attrs["isolator.mass"] == 6.4 and attrs["controller.pi_kp"] == 50.0
    assert attrs["excitation"] == "Chirp" and attrs["excitation.duration"] == 20.0
    assert attrs["run.solver"] == "ode3" and attrs["run.completed"] == 1
    for value in attrs.values():  # netCDF-storable: no None, no bool
        assert isinstance(value, (str, int, float)) and not isinstance(value, bool)
