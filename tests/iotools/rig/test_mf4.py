"""MF4 rig logs (qzs.iotools.rig.mf4): channels by name; different rates need resampling."""
import numpy as np
import pytest
from helpers import (LOG_BASE as BASE, LOG_MAP as MAP, LOG_PAYLOAD as PAYLOAD, LOG_RATE as RATE,
                     LOG_TIME as TIME, check_log_recording as check)

from qzs.errors import DataError
from qzs.iotools.rig import read_recording


def test_mf4(tmp_path):
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    mdf.append([Signal(BASE, TIME, name="shaker_vel", unit="mm/s"),
                Signal(PAYLOAD, TIME, name="payload_vel", unit="mm/s")])
    mdf.save(tmp_path / "log.mf4", overwrite=True)
    check(read_recording(tmp_path / "log.mf4", MAP))


def test_mf4_different_rates_need_resampling(tmp_path):
    from asammdf import MDF, Signal

    slow = TIME[::2]
    mdf = MDF(version="4.10")
    mdf.append([Signal(BASE, TIME, name="shaker_vel")])
    mdf.append([Signal(PAYLOAD[::2], slow, name="payload_vel")])
    mdf.save(tmp_path / "log.mf4", overwrite=True)
    with pytest.raises(DataError, match="different time bases.*resample"):
        read_recording(tmp_path / "log.mf4", MAP)
    recording = read_recording(tmp_path / "log.mf4", MAP, resample=True)
    assert recording.sample_rate == pytest.approx(RATE)
    np.testing.assert_allclose(recording["base_velocity"], BASE[:-1] * 1e-3, atol=1e-12)
