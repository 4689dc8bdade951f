"""NetCDF rig logs (qzs.iotools.rig.netcdf): variables on one time coordinate."""
import pytest
from helpers import (LOG_BASE as BASE, LOG_MAP as MAP, LOG_PAYLOAD as PAYLOAD, LOG_TIME as TIME,
                     check_log_recording as check)

from qzs.iotools.rig import read_recording


def test_netcdf(tmp_path):
    import xarray as xr

    xr.Dataset({"shaker_vel": ("time", BASE), "payload_vel": ("time", PAYLOAD)},
               coords={"time": TIME}).to_netcdf(tmp_path / "log.nc", engine="h5netcdf")
    check(read_recording(tmp_path / "log.nc", MAP))
