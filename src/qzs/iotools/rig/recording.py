"""Readers for test-rig logs: CSV, dSPACE ControlDesk MAT (v5/v7 and v7.3), MF4, NetCDF.

Every reader returns one :class:`Recording`: a uniform time base [s] and the channels
named by their *role* (``base_velocity``, ``force``, ...) in SI units. A **channel map**
(TOML) says which signal of the file plays which role::

    [channels.base_velocity]       # a role from ROLES
    source = "Y[3]/shaker_vel"     # a signal name, or (MAT) Y(3) checked to be named so
    unit = "mm/s"                  # the unit after `scale`; converted to SI (UNITS)
    scale = 1.0                    # SI value = raw * scale * unit factor (default 1)

    [time]                         # optional
    source = "time"                # CSV column / NetCDF variable (default "time"), MAT: a
                                   # Y signal (default X(1).Data); MF4: each channel's own
    unit = "s"                     # "s" or "ms"

    [options]                      # optional
    resample = false               # put a non-uniform time base on a uniform grid
    tolerance = 1e-3               # allowed relative jitter of the sample interval
    nan = "raise"                  # or "interpolate": fill NaN samples, with a warning

    [experiment]                   # optional, read by ``qzs experiment`` (qzs.experiment)
    highpass_corner = 1.0          # [Hz]; amplitude [m], f0, f1 [Hz]: the chirp, if known

Signal names match exactly, else by their last ``/`` component (dSPACE names carry a
model path); outside MAT files an indexed source ``"Y[3]/name"`` means just ``name``.
Supported file layouts:

- **CSV**: one header line of column names, then numbers; ``#`` lines are comments.
- **dSPACE ControlDesk MAT export**: one top-level struct variable (the map's
  ``[options] variable`` names it if the file holds several) with fields ``X``, a
  struct array whose ``X(1).Data`` is the time vector, and ``Y``, a struct array of
  signals with ``Name`` (char) and ``Data`` (vector on the ``X(1)`` raster). MAT v5/v7
  are read by ``scipy.io.loadmat``; v7.3 (HDF5) by h5py, in MATLAB's own layout: a
  struct is a group with a ``MATLAB_class`` attribute; a scalar struct's fields are
  its members; a struct array's fields are datasets of object references (into
  ``#refs#``), one per element; char arrays are uint16 datasets; numeric vectors are
  datasets of either orientation. Cell arrays, multi-row chars and signals on other
  rasters (``X(2)``...) are not supported.
- **MF4** (ASAM MDF 4, via asammdf): channels by name, each with its own time stamps.
- **NetCDF** (xarray, h5netcdf engine): variables on one time dimension.
"""
from __future__ import annotations

import io
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from qzs._validation import known_keys, read_toml, strictly_increasing
from qzs._optional import require
from qzs.errors import DataError, DataWarning, ParameterError
from qzs.iotools.files import is_units_row

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["Recording", "ChannelMap", "ChannelSpec", "ROLES", "UNITS",
           "load_channel_map", "read_recording", "write_dspace_mat"]

#: Channel roles and the SI unit(s) each must have.
ROLES = {"base_velocity": ("m/s",), "base_acceleration": ("m/s^2",),
         "payload_velocity": ("m/s",), "payload_acceleration": ("m/s^2",),
         "relative_position": ("m",), "displacement": ("m",), "force": ("N",),
         "motor_command": ("V", "N")}
#: Accepted units: name -> (SI unit, factor to SI).
UNITS = {"m": ("m", 1.0), "mm": ("m", 1e-3), "um": ("m", 1e-6), "µm": ("m", 1e-6),
         "m/s": ("m/s", 1.0), "mm/s": ("m/s", 1e-3), "um/s": ("m/s", 1e-6),
         "m/s^2": ("m/s^2", 1.0), "m/s2": ("m/s^2", 1.0), "mm/s^2": ("m/s^2", 1e-3),
         "mm/s2": ("m/s^2", 1e-3), "g": ("m/s^2", 9.80665),
         "N": ("N", 1.0), "kN": ("N", 1e3), "V": ("V", 1.0)}
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
FORMATS = {".csv": "csv", ".txt": "csv", ".mat": "mat", ".mf4": "mf4", ".mdf": "mf4",
           ".nc": "netcdf", ".nc4": "netcdf", ".netcdf": "netcdf"}
NAN_POLICIES = ("raise", "interpolate")
EXPERIMENT_KEYS = ("highpass_corner", "amplitude", "f0", "f1", "method", "fft_length",
                   "n_averages")
#: How to put a log on a uniform time base, in every interface that reads logs.
_RESAMPLE_FIX = ("resample it onto a uniform grid: set resample = true in the channel map's "
                 "[options], or pass --resample to `qzs experiment` (resample=True to "
                 "read_recording)")
_INDEXED = re.compile(r"^\s*([XY])\[(\d+)\]\s*(?:/(.*))?$")


# ---------------------------------------------------------------- the common object
@dataclass(frozen=True, eq=False)
class Recording:
    """A test-rig log on a uniform time base, channels by role in SI units.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Sample times [s], strictly increasing and uniformly spaced.
    channels : Mapping[str, ndarray]
        Role (see :data:`ROLES`) -> samples, shape (n,), in SI units.
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


# ---------------------------------------------------------------- the channel map
@dataclass(frozen=True)
class ChannelSpec:
    """One role of a channel map: which signal, its unit, its scale (see module doc).

    Attributes
    ----------
    role : str
        The channel's role, a key of :data:`ROLES`.
    source : str
        The signal's name in the file (or, in a MAT file, ``Y(k)`` or ``Y[k]/name``).
    unit : str
        The unit of ``raw * scale``, a key of :data:`UNITS`; converted to SI on reading.
    scale : float
        Factor applied to the raw samples before the unit conversion (a sensitivity).
    """

    role: str
    source: str
    unit: str
    scale: float = 1.0


@dataclass(frozen=True)
class ChannelMap:
    """A parsed channel map (see the module doc for the TOML layout).

    Attributes
    ----------
    channels : Mapping[str, ChannelSpec]
        Role -> its channel.
    time_source : str or None
        Signal holding the time base; None for the format's default (CSV column
        ``time``, NetCDF the signal's dimension, MAT ``X(1).Data``).
    time_unit : {"s", "ms"}
        Unit of the time base.
    resample : bool
        Put a non-uniform time base on a uniform grid.
    tolerance : float
        Allowed relative jitter of the sample interval [-], in (0, 1).
    nan : {"raise", "interpolate"}
        What NaN samples do: raise :class:`DataError`, or get filled with a warning.
    variable : str or None
        MAT files: the top-level struct to read; None if the file holds one.
    experiment : Mapping[str, object]
        The ``[experiment]`` table, read by ``qzs experiment`` (chirp and analysis).
    """

    channels: Mapping[str, ChannelSpec]
    time_source: str | None = None
    time_unit: str = "s"
    resample: bool = False
    tolerance: float = 1e-3
    nan: str = "raise"
    variable: str | None = None
    experiment: Mapping[str, object] = field(default_factory=dict)


def _check_keys(table, allowed, where):
    known_keys(table, allowed, where, "channel map: ")


def load_channel_map(source: str | Path | Mapping[str, Any] | ChannelMap) -> ChannelMap:
    """Parse a channel map from a TOML file, a TOML-like ``dict``, or pass a ChannelMap.

    Parameters
    ----------
    source : str, Path, dict or ChannelMap
        A TOML file, its content as a dict, or a ChannelMap (returned as is).

    Returns
    -------
    ChannelMap

    Raises
    ------
    ParameterError
        Unknown role, unit, table or key; no channels; a unit that does not fit the role.
    """
    if isinstance(source, ChannelMap):
        return source
    if isinstance(source, (str, Path)):
        document = read_toml(source, "channel map")
    elif isinstance(source, Mapping):
        document = dict(source)
    else:
        raise ParameterError(f"`channel_map` must be a TOML path, a dict or a ChannelMap, "
                             f"got {type(source).__name__}.")
    _check_keys(document, ("channels", "time", "options", "experiment"), "the top level")
    tables = document.get("channels") or {}
    if not tables:
        raise ParameterError("channel map: no [channels.<role>] table; name at least one "
                             f"role of {list(ROLES)}.")
    specs = {role: _channel_spec(role, table) for role, table in tables.items()}
    time, options = document.get("time", {}), document.get("options", {})
    experiment = document.get("experiment", {})
    _check_keys(time, ("source", "unit"), "[time]")
    _check_keys(options, ("resample", "tolerance", "nan", "variable"), "[options]")
    _check_keys(experiment, EXPERIMENT_KEYS, "[experiment]")
    time_unit = time.get("unit", "s")
    if time_unit not in TIME_UNITS:
        raise ParameterError(f"channel map: [time] unit must be one of {list(TIME_UNITS)}, "
                             f"got {time_unit!r}.")
    nan = options.get("nan", "raise")
    if nan not in NAN_POLICIES:
        raise ParameterError(f"channel map: [options] nan must be one of {NAN_POLICIES}, "
                             f"got {nan!r}.")
    tolerance = options.get("tolerance", 1e-3)
    if not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
        raise ParameterError(f"channel map: [options] tolerance must be in (0, 1), "
                             f"got {tolerance!r}.")
    if not isinstance(options.get("resample", False), bool):
        raise ParameterError(f"channel map: [options] resample must be true or false, "
                             f"got {options['resample']!r}.")
    return ChannelMap(MappingProxyType(specs), time.get("source"), time_unit,
                      options.get("resample", False), float(tolerance), nan,
                      options.get("variable"), MappingProxyType(dict(experiment)))


def _channel_spec(role, table):
    if role not in ROLES:
        raise ParameterError(f"channel map: unknown role {role!r}; roles are {list(ROLES)}.")
    if isinstance(table, str):
        raise ParameterError(f"channel map: [channels.{role}] needs a unit: write "
                             f'[channels.{role}] source = "{table}" unit = "..." .')
    _check_keys(table, ("source", "unit", "scale"), f"[channels.{role}]")
    for key in ("source", "unit"):
        if not isinstance(table.get(key), str) or not table[key].strip():
            raise ParameterError(f"channel map: [channels.{role}] needs `{key}` (a string), "
                                 f"got {table.get(key)!r}.")
    unit = table["unit"].strip()
    if unit not in UNITS:
        raise ParameterError(f"channel map: [channels.{role}] unit {unit!r} is not supported; "
                             f"use one of {list(UNITS)} (and `scale` for a sensitivity).")
    if UNITS[unit][0] not in ROLES[role]:
        raise ParameterError(f"channel map: [channels.{role}] unit {unit!r} is not a unit of "
                             f"{' or '.join(ROLES[role])}.")
    scale = table.get("scale", 1.0)
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not np.isfinite(scale) \
            or scale == 0:
        raise ParameterError(f"channel map: [channels.{role}] scale must be a finite non-zero "
                             f"number, got {scale!r}.")
    return ChannelSpec(role, table["source"].strip(), unit, float(scale))


# ---------------------------------------------------------------- reading
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
    readers = {"csv": _read_csv, "mat": _read_mat, "mf4": _read_mf4, "netcdf": _read_netcdf}
    signals = readers[format](path, spec)
    resample = spec.resample if resample is None else bool(resample)
    return _assemble(signals, spec, resample, f"{path} ({format})")


def _name_part(source):
    match = _INDEXED.match(source)
    if match is None:
        return source
    if match.group(3) is None:
        raise DataError(f"source {source!r} indexes a MAT struct array, which this format "
                        "does not have; give the signal's name instead.")
    return match.group(3).strip()


def _short(name):
    return str(name).replace('"', "").rstrip("/").split("/")[-1].strip()


def _find(source, names, path):
    """Index of the signal called ``source`` in ``names`` (exact, else by last component)."""
    names = [str(n) for n in names]
    if source in names:
        return names.index(source)
    hits = [i for i, n in enumerate(names) if _short(n) == _short(source)]
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise DataError(f"{str(path)!r}: signal name {source!r} is ambiguous, it matches "
                        f"{[names[i] for i in hits]}; give the full name.")
    raise DataError(f"{str(path)!r} has no signal {source!r}; signals found: {names}.")


def _read_csv(path, spec):
    import pandas as pd

    try:
        table = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise DataError(f"{str(path)!r} is not a readable CSV file with a header: "
                        f"{error}") from None
    names = [str(c).strip() for c in table.columns]
    if len(table) and is_units_row([str(v) for v in table.iloc[0] if not pd.isna(v)]):
        table = table.iloc[1:]  # a units row under the names (a CSV file qzs wrote)
    columns = {}
    for key, source in [("time", spec.time_source or "time"),
                        *((r, _name_part(s.source)) for r, s in spec.channels.items())]:
        values = pd.to_numeric(table.iloc[:, _find(source, names, path)], errors="coerce")
        columns[key] = values.to_numpy(dtype=float)
    time = columns.pop("time")
    return {role: (time, values) for role, values in columns.items()}


def _read_netcdf(path, spec):
    import xarray as xr

    try:
        dataset = xr.load_dataset(path, engine="h5netcdf")
    except (OSError, ValueError) as error:
        raise DataError(f"{str(path)!r} is not a readable NetCDF file: {error}") from None
    names = [str(n) for n in (*dataset.data_vars, *dataset.coords)]
    signals = {}
    for role, channel in spec.channels.items():
        variable = dataset[names[_find(_name_part(channel.source), names, path)]]
        if variable.ndim != 1:
            raise DataError(f"{str(path)!r}: variable {variable.name!r} has dimensions "
                            f"{variable.dims}; a signal must be 1-D in time.")
        time_name = spec.time_source or variable.dims[0]
        if time_name not in dataset.variables:
            raise DataError(f"{str(path)!r} has no time variable {time_name!r}; variables "
                            f"found: {names}.")
        time = dataset[time_name]
        if np.issubdtype(time.dtype, np.datetime64) or np.issubdtype(time.dtype, np.timedelta64):
            time = (time - time[0]) / np.timedelta64(1, "s")
        signals[role] = (time.to_numpy().astype(float), variable.to_numpy().astype(float))
    return signals


def _read_mf4(path, spec):
    MDF = require("asammdf", "reading MF4 logs").MDF

    try:
        mdf = MDF(path)
    except Exception as error:  # asammdf raises its own and built-in errors alike
        raise DataError(f"{str(path)!r} is not a readable MDF file: {error}") from None
    with mdf:
        names = sorted(n for n in mdf.channels_db if not n.startswith("$") and n != "time")
        signals = {}
        for role, channel in spec.channels.items():
            name = names[_find(_name_part(channel.source), names, path)]
            if len(mdf.channels_db[name]) > 1:
                raise DataError(f"{str(path)!r}: channel {name!r} is in several groups "
                                f"{list(mdf.channels_db[name])}; rename or export one.")
            signal = mdf.get(name)
            signals[role] = (np.asarray(signal.timestamps, float),
                             np.asarray(signal.samples, float))
    return signals


# ---------------------------------------------------------------- MAT files
def _read_mat(path, spec):
    import h5py

    variables = _load_mat73(path) if h5py.is_hdf5(path) else _load_mat5(path)
    structs = {k: v for k, v in variables.items() if isinstance(v, dict) and "X" in v and "Y" in v}
    if spec.variable is not None:
        if spec.variable not in structs:
            raise DataError(f"{str(path)!r} has no dSPACE struct {spec.variable!r}; structs with "
                            f"X and Y found: {sorted(structs)}.")
        record = structs[spec.variable]
    elif len(structs) == 1:
        record = next(iter(structs.values()))
    else:
        raise DataError(f"{str(path)!r} must hold one struct with fields X and Y (dSPACE "
                        f"export), found {sorted(structs) or 'none'} among variables "
                        f"{sorted(variables)}; name one in [options] variable.")
    xs, ys = _elements(record["X"]), _elements(record["Y"])
    if not xs or "Data" not in xs[0]:
        raise DataError(f"{str(path)!r}: X(1).Data (the time vector) is missing.")
    time = _vector(xs[0]["Data"], "X(1).Data", path)
    names = [str(y.get("Name", "")) for y in ys]
    if spec.time_source is not None:
        time = _vector(ys[_find(spec.time_source, names, path)]["Data"], spec.time_source, path)
    signals = {}
    for role, channel in spec.channels.items():
        match = _INDEXED.match(channel.source)
        if match and match.group(1) == "Y":
            k = int(match.group(2))
            if not 1 <= k <= len(ys):
                raise DataError(f"{str(path)!r}: {channel.source!r} is out of range, Y has "
                                f"{len(ys)} elements; signals found: {names}.")
            if match.group(3) and _short(names[k - 1]) != _short(match.group(3)):
                raise DataError(f"{str(path)!r}: Y({k}) is named {names[k - 1]!r}, not "
                                f"{match.group(3)!r}; signals found: {names}.")
            index = k - 1
        elif match:
            raise DataError(f"{str(path)!r}: {channel.source!r}: only Y(k) hold signals.")
        else:
            index = _find(channel.source, names, path)
        values = _vector(ys[index].get("Data"), f"Y({index + 1}).Data", path)
        if values.size != time.size:
            raise DataError(f"{str(path)!r}: Y({index + 1}) ({names[index]!r}) has {values.size} "
                            f"samples but X(1) has {time.size}; only signals on the X(1) "
                            "raster are supported.")
        signals[role] = (time, values)
    return signals


def _elements(value):
    """A MAT struct array as a list of dicts (a scalar struct is a list of one)."""
    if isinstance(value, dict):
        return [value]
    return [v for v in np.ravel(np.asarray(value, dtype=object)) if isinstance(v, dict)]


def _vector(value, what, path):
    array = np.asarray(value if value is not None else [], dtype=float)
    if array.ndim > 1 and sum(d > 1 for d in array.shape) > 1:
        raise DataError(f"{str(path)!r}: {what} has shape {array.shape}; expected a vector.")
    return array.ravel()


def _load_mat5(path):
    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

    try:
        return loadmat(path, simplify_cells=True)
    except (MatReadError, ValueError, TypeError, OSError, EOFError, NotImplementedError,
            UnicodeDecodeError) as error:
        raise DataError(f"{str(path)!r} is not a readable MAT file ({error}); export it "
                        "again from ControlDesk as MAT (v5, v7 or v7.3).") from None


def _load_mat73(path):
    import h5py

    try:
        with h5py.File(path, "r") as handle:
            return {name: _h5_value(handle, handle[name]) for name in handle
                    if not name.startswith("#")}
    except (OSError, KeyError, ValueError, TypeError) as error:  # h5py's errors are these
        raise DataError(f"{str(path)!r} is not a readable MAT file (v7.3, HDF5: {error}); "
                        "export it again from ControlDesk.") from None


def _h5_class(obj):
    value = obj.attrs.get("MATLAB_class", b"")
    return value.decode() if isinstance(value, bytes) else str(value)


def _h5_value(handle, obj):
    """A MATLAB v7.3 object as Python: struct -> dict or list of dicts, char -> str."""
    import h5py

    if isinstance(obj, h5py.Group):
        fields = {name: obj[name] for name in obj}
        arrays = {n: d for n, d in fields.items()
                  if isinstance(d, h5py.Dataset) and d.dtype == h5py.ref_dtype
                  and _h5_class(d) != "cell"}
        if not arrays:  # scalar struct: fields are members
            return {n: _h5_value(handle, d) for n, d in fields.items()}
        count = max(d.size for d in arrays.values())  # struct array: one reference per element
        refs = {n: d[()].ravel(order="F") for n, d in arrays.items()}
        return [{n: _h5_value(handle, handle[r[k]]) for n, r in refs.items() if k < r.size}
                for k in range(count)]
    if obj.attrs.get("MATLAB_empty", 0):
        return "" if _h5_class(obj) == "char" else np.array([])
    data = obj[()]
    if _h5_class(obj) == "char":
        return "".join(map(chr, np.ravel(data, order="F")))
    if obj.dtype == h5py.ref_dtype:
        return [_h5_value(handle, handle[r]) for r in data.ravel(order="F")]
    return np.asarray(data)


def write_dspace_mat(path, time, signals, *, version="5", variable="qzs_log", units=None):
    """Write a dSPACE ControlDesk-style MAT file (for tests and examples).

    Parameters
    ----------
    path : str or Path
        The file to write.
    time : array_like, shape (n,)
        Time vector [s], stored as ``X(1).Data``.
    signals : dict
        Signal name -> samples, shape (n,), stored as ``Y(k).Name``/``Y(k).Data`` in order;
        float32 samples are stored as MATLAB ``single`` (as dSPACE often does).
    version : {"5", "7.3"}
        MAT v5 (scipy.io.savemat, compressed) or v7.3 (HDF5 in MATLAB's layout).
    variable : str
        Name of the top-level struct.
    units : dict, optional
        Signal name -> unit text, stored as ``Y(k).Unit``.
    """
    units = units or {}
    time = np.asarray(time, dtype=float)
    xs = [{"Name": "Time", "Unit": "s", "Data": time}]
    ys = [{"Name": name, "Unit": units.get(name, ""), "Data": _real(v)}
          for name, v in signals.items()]
    if version == "5":
        from scipy.io import savemat

        def array(items):
            out = np.zeros((1, len(items)), dtype=[(k, "O") for k in items[0]])
            for i, item in enumerate(items):
                for k, v in item.items():
                    out[0, i][k] = v[None, :] if isinstance(v, np.ndarray) else v
            return out

        record = np.zeros((1, 1), dtype=[("X", "O"), ("Y", "O"), ("Description", "O")])
        record[0, 0]["X"], record[0, 0]["Y"] = array(xs), array(ys)
        record[0, 0]["Description"] = "written by qzs.readers.write_dspace_mat"
        buffer = io.BytesIO()
        savemat(buffer, {variable: record}, do_compression=True)
        data = bytearray(buffer.getvalue())  # a fixed header text: no date, same bytes each run
        data[:116] = b"MATLAB 5.0 MAT-file, written by qzs.readers.write_dspace_mat".ljust(116)
        Path(path).write_bytes(bytes(data))
    elif version == "7.3":
        _write_mat73(path, variable, xs, ys)
    else:
        raise ParameterError(f"`version` must be '5' or '7.3', got {version!r}.")
    return Path(path)


def _real(values):
    array = np.asarray(values)
    return array if array.dtype == np.float32 else array.astype(float)


def _write_mat73(path, variable, xs, ys):
    import h5py

    def put(group, name, value):
        if isinstance(value, str):
            data = np.array([[ord(c)] for c in value] or [[0]], dtype=np.uint16)
            dataset = group.create_dataset(name, data=data)
            dataset.attrs["MATLAB_class"] = np.bytes_("char")
            dataset.attrs["MATLAB_int_decode"] = np.int32(2)
            if not value:
                dataset.attrs["MATLAB_empty"] = np.uint8(1)
        else:  # a 1xn row vector is stored (n, 1): HDF5 reverses MATLAB's dimensions
            dataset = group.create_dataset(name, data=value[:, None])
            matlab = "single" if value.dtype == np.float32 else "double"
            dataset.attrs["MATLAB_class"] = np.bytes_(matlab)
        return dataset

    def struct_array(parent, name, items):
        group = parent.create_group(name)
        group.attrs["MATLAB_class"] = np.bytes_("struct")
        fields = np.empty(len(items[0]), dtype=h5py.vlen_dtype(np.dtype("S1")))
        fields[:] = [np.array(list(key), dtype="S1") for key in items[0]]
        group.attrs["MATLAB_fields"] = fields
        if len(items) == 1:  # a 1x1 struct keeps its fields as members
            for key, value in items[0].items():
                put(group, key, value)
            return
        for key in items[0]:
            refs = []
            for item in items:
                target = put(handle["#refs#"], f"{name}_{key}_{len(handle['#refs#'])}", item[key])
                refs.append(target.ref)
            group.create_dataset(key, data=np.array(refs, dtype=h5py.ref_dtype)[:, None])

    with h5py.File(path, "w", userblock_size=512) as handle:
        handle.create_group("#refs#")
        top = handle.create_group(variable)
        top.attrs["MATLAB_class"] = np.bytes_("struct")
        struct_array(top, "X", xs)
        struct_array(top, "Y", ys)
        put(top, "Description", "written by qzs.readers.write_dspace_mat")
    header = b"MATLAB 7.3 MAT-file, Platform: qzs, Created by: qzs.readers HDF5 schema 1.00 ."
    with open(path, "r+b") as raw:
        raw.write(header.ljust(116) + b"\x00" * 8 + b"\x00\x02IM")
    return Path(path)


# ---------------------------------------------------------------- checks, units
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
