"""Channel maps: which signal of a test-rig log plays which role, in which unit.

A channel map (TOML)::

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
model path; :func:`find_signal`); outside MAT files an indexed source ``"Y[3]/name"`` means
just ``name`` (:func:`signal_name`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from qzs._validation import known_keys, read_toml
from qzs.errors import DataError, ParameterError

__all__ = ["ChannelMap", "ChannelSpec", "ROLES", "UNITS", "TIME_UNITS", "NAN_POLICIES",
           "EXPERIMENT_KEYS", "INDEXED", "load_channel_map", "signal_name", "short_name",
           "find_signal"]

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
NAN_POLICIES = ("raise", "interpolate")
EXPERIMENT_KEYS = ("highpass_corner", "amplitude", "f0", "f1", "method", "fft_length",
                   "n_averages")
#: An indexed MAT source: ``Y[3]`` or ``X[1]``, optionally ``/name``.
INDEXED = re.compile(r"^\s*([XY])\[(\d+)\]\s*(?:/(.*))?$")


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
        document = read_toml(source, "channel map", empty=(
            "write its [channels] into it (`qzs experiment --write-map FILE.toml` writes a "
            "template with every key)"))
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


def signal_name(source):
    """The signal name of a channel map's ``source`` outside MAT files.

    Parameters
    ----------
    source : str
        A signal name, or ``"Y[k]/name"`` (a MAT index with a name: the name is meant).

    Returns
    -------
    str

    Raises
    ------
    DataError
        An index with no name (``"Y[3]"``), which only a MAT file can resolve.
    """
    match = INDEXED.match(source)
    if match is None:
        return source
    if match.group(3) is None:
        raise DataError(f"source {source!r} indexes a MAT struct array, which this format "
                        "does not have; give the signal's name instead.")
    return match.group(3).strip()


def short_name(name):
    """The last ``/`` component of a signal name, quotes removed (dSPACE model paths).

    Parameters
    ----------
    name : str
        A signal name.

    Returns
    -------
    str
    """
    return str(name).replace('"', "").rstrip("/").split("/")[-1].strip()


def find_signal(source, names, path):
    """Index of the signal called ``source`` in ``names`` (exact, else by last component).

    Parameters
    ----------
    source : str
        The name asked for.
    names : sequence of str
        The signals of the file.
    path : str or Path
        The file, for the messages.

    Returns
    -------
    int

    Raises
    ------
    DataError
        No such signal (the message lists those found), or an ambiguous short name.
    """
    names = [str(n) for n in names]
    if source in names:
        return names.index(source)
    hits = [i for i, n in enumerate(names) if short_name(n) == short_name(source)]
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise DataError(f"{str(path)!r}: signal name {source!r} is ambiguous, it matches "
                        f"{[names[i] for i in hits]}; give the full name.")
    raise DataError(f"{str(path)!r} has no signal {source!r}; signals found: {names}.")
