"""Test-rig logs read into one :class:`Recording`, whatever the format.

Every reader returns one :class:`Recording`: a uniform time base [s] and the channels
named by their *role* (``base_velocity``, ``force``, ...) in SI units; a **channel map**
(:mod:`qzs.iotools.rig.channel_map`) says which signal of the file plays which role.
:func:`read_recording` chooses the format's reader by the file's suffix, then checks the
time bases and samples, resamples on request and converts to SI. Supported formats, one
module each: CSV (:mod:`~qzs.iotools.rig.csv`), dSPACE ControlDesk MAT v5/v7/v7.3
(:mod:`~qzs.iotools.rig.dspace`), MF4 (:mod:`~qzs.iotools.rig.mf4`), NetCDF
(:mod:`~qzs.iotools.rig.netcdf`).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from qzs._validation import strictly_increasing
from qzs.errors import DataError, DataWarning, ParameterError
from qzs.iotools.rig.channel_map import TIME_UNITS, UNITS, ChannelMap, load_channel_map
from qzs.iotools.rig.csv import read_csv
from qzs.iotools.rig.dspace import read_dspace_mat
from qzs.iotools.rig.mf4 import read_mf4
from qzs.iotools.rig.netcdf import read_netcdf

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["Recording", "FORMATS", "READERS", "read_recording"]

FORMATS = {".csv": "csv", ".txt": "csv", ".mat": "mat", ".mf4": "mf4", ".mdf": "mf4",
           ".nc": "netcdf", ".nc4": "netcdf", ".netcdf": "netcdf"}
#: The reader of each format: (path, channel map) -> role -> (time, raw samples).
READERS = {"csv": read_csv, "mat": read_dspace_mat, "mf4": read_mf4, "netcdf": read_netcdf}
#: How to put a log on a uniform time base, in every interface that reads logs.
_RESAMPLE_FIX = ("resample it onto a uniform grid: set resample = true in the channel map's "
                 "[options], or pass --resample to `qzs experiment` (resample=True to "
                 "read_recording)")


@dataclass(frozen=True, eq=False)
class Recording:
    """A test-rig log on a uniform time base, channels by role in SI units.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s], strictly increasing and uniformly spaced.
    channels : Mapping[str, ndarray]
        Role (see :data:`~qzs.iotools.rig.channel_map.ROLES`) -> samples, shape (n,), in SI units.
    units : Mapping[str, str]
        Role -> SI unit of its samples.
    sample_rate : float
        Sample rate [Hz].
    source : str
        Where the data came from (file path and format).
    """

    time: np.ndarray
    channels: Mapping[str, np.ndarray]
    units: Mapping[str, str]
    sample_rate: float
    source: str

    def __post_init__(self):
        time = np.array(self.time, dtype=float)
        if time.ndim != 1 or time.size < 2:
            raise DataError(f"`time` must be 1-D with at least 2 samples, got shape {time.shape}.")
        channels = {}
        for name, values in self.channels.items():
            array = np.array(values, dtype=float)
            if array.shape != time.shape:
                raise DataError(f"channel {name!r} has shape {array.shape}, `time` has "
                                f"{time.shape}; every channel needs one sample per time.")
            array.setflags(write=False)
            channels[name] = array
        if set(self.units) != set(channels):
            raise DataError(f"`units` must name exactly the channels {sorted(channels)}, "
                            f"got {sorted(self.units)}.")
        time.setflags(write=False)
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "channels", MappingProxyType(channels))
        object.__setattr__(self, "units", MappingProxyType(dict(self.units)))
        object.__setattr__(self, "sample_rate", float(self.sample_rate))

    def __getitem__(self, role: str) -> np.ndarray:
        try:
            return self.channels[role]
        except KeyError:
            raise KeyError(f"no channel {role!r}; the recording has "
                           f"{sorted(self.channels)}.") from None

    @property
    def duration(self) -> float:
        """Time span of the recording [s]."""
        return float(self.time[-1] - self.time[0])

    def to_xarray(self) -> xr.Dataset:
        """Repackage as an ``xarray.Dataset`` on coordinate ``time`` [s], units in attrs."""
        import xarray as xr

        return xr.Dataset({name: ("time", values, {"units": self.units[name]})
                           for name, values in self.channels.items()},
                          coords={"time": ("time", self.time, {"units": "s"})},
                          attrs={"sample_rate": self.sample_rate, "source": self.source})

    def __repr__(self):
        return (f"<Recording {self.time.size} samples at {self.sample_rate:g} Hz, "
                f"{self.duration:g} s, channels {list(self.channels)} from {self.source}>")


def read_recording(path: str | Path, channel_map: str | Path | Mapping[str, Any] | ChannelMap, *,
                   resample: bool | None = None, format: str | None = None) -> Recording:
    """Read a test-rig log into a :class:`Recording`.

    Parameters
    ----------
    path : str or Path
        The log file (.csv, .mat, .mf4/.mdf, .nc).
    channel_map : str, Path, dict or ChannelMap
        Which signal is which role (see the module doc).
    resample : bool, optional
        Linearly interpolate onto a uniform grid at the median sample interval if the
        time base is not uniform; default the map's ``[options] resample``.
    format : {"csv", "mat", "mf4", "netcdf"}, optional
        Default from the file's suffix.

    Returns
    -------
    Recording

    Raises
    ------
    DataError
        Missing file or channel (the message lists the signals found), non-increasing or
        duplicated time, a non-uniform time base without ``resample``, NaN samples
        (unless the map's ``nan = "interpolate"``), mismatched lengths.
    """
    path = Path(path)
    spec = load_channel_map(channel_map)
    if not path.exists():
        raise DataError(f"log file not found: {str(path)!r}.")
    if path.is_dir():
        raise DataError(f"log file {str(path)!r} is a folder; pass the log file.")
    if path.stat().st_size == 0:
        raise DataError(f"log file {str(path)!r} is empty (0 bytes); the export or copy "
                        "did not finish: export the log again.")
    if format is None:
        format = FORMATS.get(path.suffix.lower())
        if format is None:
            raise ParameterError(f"cannot tell the format of {str(path)!r} from its suffix; "
                                 f"use one of {sorted(FORMATS)} or pass `format`.")
    elif format not in set(FORMATS.values()):
        raise ParameterError(f"`format` must be one of {sorted(set(FORMATS.values()))}, "
                             f"got {format!r}.")
    signals = READERS[format](path, spec)
    resample = spec.resample if resample is None else bool(resample)
    return _assemble(signals, spec, resample, f"{path} ({format})")


def _assemble(signals, spec, resample, source):
    """Check time bases and samples, resample on request, convert to SI."""
    factor = TIME_UNITS[spec.time_unit]
    checked = {}
    for role, (time, values) in signals.items():
        time = np.asarray(time, float) * factor
        values = np.asarray(values, float)
        if time.size != values.size:
            raise DataError(f"{source}: {role} has {values.size} samples but its time has "
                            f"{time.size}.")
        if time.size < 2:
            raise DataError(f"{source}: {role} has {time.size} sample(s); need a time series.")
        _check_time(time, role, source)
        checked[role] = (time, _fill_nan(values, role, spec.nan, source))
    times = [t for t, _ in checked.values()]
    shared = all(t.size == times[0].size and np.array_equal(t, times[0]) for t in times)
    if not shared and not resample:
        sizes = {role: t.size for role, (t, _) in checked.items()}
        raise DataError(f"{source}: the channels have different time bases ({sizes} samples); "
                        f"{_RESAMPLE_FIX}.")
    time = times[0]
    steps = np.diff(time)
    step = float(np.median(steps))
    jitter = float(np.max(np.abs(steps - step)) / step)
    if shared and jitter <= spec.tolerance:
        rate = (time.size - 1) / (time[-1] - time[0])
        values = {role: v for role, (_, v) in checked.items()}
    elif not resample:
        raise DataError(f"{source}: the time base is not uniform: sample intervals range from "
                        f"{steps.min():.6g} to {steps.max():.6g} s (relative jitter {jitter:.3g} > "
                        f"tolerance {spec.tolerance:g}); {_RESAMPLE_FIX}, or raise the map's "
                        "[options] tolerance.")
    else:  # linear interpolation onto the finest median interval over the common span
        step = min(float(np.median(np.diff(t))) for t in times)
        start, end = max(t[0] for t in times), min(t[-1] for t in times)
        if end <= start:
            raise DataError(f"{source}: the channels' time spans do not overlap.")
        time = start + step * np.arange(int(np.floor((end - start) / step + 1e-9)) + 1)
        rate = 1.0 / step
        values = {role: np.interp(time, t, v) for role, (t, v) in checked.items()}
    channels, units = {}, {}
    for role, raw in values.items():
        channel = spec.channels[role]
        si_unit, unit_factor = UNITS[channel.unit]
        channels[role] = raw * (channel.scale * unit_factor)
        units[role] = si_unit
    return Recording(time=time, channels=channels, units=units, sample_rate=rate, source=source)


def _check_time(time, role, source):
    bad = np.count_nonzero(~np.isfinite(time))
    if bad:
        raise DataError(f"{source}: the time of {role} has {bad} non-finite values; "
                        "a time base cannot be repaired, fix the log.")
    strictly_increasing("time", time, DataError, "sort the log and drop duplicates first",
                        where=f"{source}: ")


def _fill_nan(values, role, policy, source):
    bad = ~np.isfinite(values)
    count = int(np.count_nonzero(bad))
    if not count:
        return values
    if policy == "raise" or count > values.size - 2:
        raise DataError(f"{source}: channel {role} has {count} non-finite (NaN or inf) samples "
                        f"of {values.size}; clean the log, or set nan = \"interpolate\" in the "
                        "map's [options] to fill them linearly.")
    warnings.warn(f"{source}: channel {role}: {count} non-finite samples of {values.size} "
                  "filled by linear interpolation.", DataWarning, stacklevel=4)
    index = np.arange(values.size)
    filled = values.copy()
    filled[bad] = np.interp(index[bad], index[~bad], values[~bad])
    return filled
