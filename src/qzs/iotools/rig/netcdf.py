"""NetCDF logs (xarray, h5netcdf engine): variables on one time dimension.

The time is the map's ``[time] source`` or the signal's dimension; datetimes and
timedeltas are read as seconds from the first sample.
"""
from __future__ import annotations

import numpy as np

from qzs.errors import DataError
from qzs.iotools.rig.channel_map import find_signal, signal_name

__all__ = ["read_netcdf"]


def read_netcdf(path, channel_map):
    """A NetCDF log's signals by role.

    Parameters
    ----------
    path : Path
        The log file.
    channel_map : ChannelMap
        Which signal is which role (:mod:`qzs.iotools.rig.channel_map`).

    Returns
    -------
    dict of str to (ndarray, ndarray)
        Role -> (time in the map's time unit, raw samples), checked and converted to SI by
        :func:`qzs.iotools.rig.recording.read_recording`.

    Raises
    ------
    DataError
        An unreadable file, or a signal missing (the message lists those found).
    """
    import xarray as xr

    try:
        dataset = xr.load_dataset(path, engine="h5netcdf")
    except (OSError, ValueError) as error:
        raise DataError(f"{str(path)!r} is not a readable NetCDF file: {error}") from None
    names = [str(n) for n in (*dataset.data_vars, *dataset.coords)]
    signals = {}
    for role, channel in channel_map.channels.items():
        variable = dataset[names[find_signal(signal_name(channel.source), names, path)]]
        if variable.ndim != 1:
            raise DataError(f"{str(path)!r}: variable {variable.name!r} has dimensions "
                            f"{variable.dims}; a signal must be 1-D in time.")
        time_name = channel_map.time_source or variable.dims[0]
        if time_name not in dataset.variables:
            raise DataError(f"{str(path)!r} has no time variable {time_name!r}; variables "
                            f"found: {names}.")
        time = dataset[time_name]
        if np.issubdtype(time.dtype, np.datetime64) or np.issubdtype(time.dtype, np.timedelta64):
            time = (time - time[0]) / np.timedelta64(1, "s")
        signals[role] = (time.to_numpy().astype(float), variable.to_numpy().astype(float))
    return signals
