"""Files: parameter TOML, simulation results (NetCDF, CSV), displacement records.

Every writer is atomic: it writes a temporary file beside the target and
renames it into place, so an interrupted write never leaves a half-written file.
"""
import contextlib
import dataclasses
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from qzs._validation import known_keys, read_toml
from qzs.control import ControllerParameters
from qzs.errors import DataError, ParameterError
from qzs.model import IsolatorParameters

__all__ = [
    "atomic_path",
    "save_result",
    "read_result",
    "load_config",
    "save_config",
    "update_parameters",
    "parameter_table",
    "read_displacement_csv",
]

_SECTIONS = {"isolator": IsolatorParameters, "controller": ControllerParameters}
#: Keys allowed in the ``[excitation]`` and ``[simulation]`` tables of a config file.
EXCITATION_KEYS = ("kind", "amplitude", "f0", "f1", "frequency", "phase", "duration",
                   "method", "seed", "record")
SIMULATION_KEYS = ("dt", "sample_rate", "solver", "duration")


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    On any error the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def save_result(result, path):
    """Write a :class:`~qzs.results.SimulationResult` to NetCDF (``.nc``) or CSV (``.csv``).

    Both carry every parameter, the excitation, the run settings and the qzs
    version as metadata (NetCDF global attributes; CSV ``# key = value`` header
    lines). Returns the path written.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".nc", ".csv"):
        raise ParameterError(f"`path` must end in .nc or .csv, got {str(path)!r}.")
    if suffix == ".nc":
        dataset = result.to_xarray()
        for name in dataset.data_vars:  # NetCDF has no bool type
            if dataset[name].dtype == bool:
                dataset[name] = dataset[name].astype("i1")
        with atomic_path(path) as tmp:
            dataset.to_netcdf(tmp, engine="h5netcdf")
        return path
    from qzs.results import CHANNELS, FLAGS

    names = [*CHANNELS, *FLAGS]
    columns = np.column_stack([np.asarray(result[n], dtype=float) for n in names])
    units = [CHANNELS[n][1] if n in CHANNELS else "1" for n in names]
    header = [f"{key} = {value}" for key, value in result.metadata().items()]
    header.append("units: " + ",".join(units))
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as handle:
        for line in header:
            handle.write(f"# {line}\n")
        handle.write(",".join(names) + "\n")
        np.savetxt(handle, columns, delimiter=",", fmt="%.10g")
    return path


def read_result(path):
    """Read a saved result (``.nc`` or ``.csv``) back as an ``xarray.Dataset``."""
    import xarray as xr

    path = Path(path)
    if not path.exists():
        raise DataError(f"no such file: {str(path)!r}.")
    if path.suffix.lower() == ".nc":
        return xr.load_dataset(path, engine="h5netcdf")
    attrs, units = {}, []
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            if not line.startswith("#"):
                names = line.strip().split(",")
                break
            text = line[1:].strip()
            if text.startswith("units: "):
                units = text[len("units: "):].split(",")
            elif " = " in text:
                key, value = text.split(" = ", 1)
                attrs[key] = _parse_value(value)
        else:
            raise DataError(f"{str(path)!r} has no column header line.")
        data = np.loadtxt(handle, delimiter=",", ndmin=2)
    if data.shape[1] != len(names):
        raise DataError(f"{str(path)!r}: {len(names)} column names but {data.shape[1]} columns.")
    variables = {n: ("time", data[:, i], {"units": units[i]} if units else {})
                 for i, n in enumerate(names) if n != "time"}
    return xr.Dataset(variables, coords={"time": data[:, names.index("time")]}, attrs=attrs)


def _parse_value(text):
    """Parse a ``--set`` or header value: number, none, true/false, else the string."""
    lowered = text.strip().lower()
    if lowered in ("none", "null"):
        return None
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        number = float(text)
    except ValueError:
        return text.strip()
    return int(number) if number.is_integer() and "." not in text and "e" not in lowered else number


def update_parameters(isolator, controller, settings):
    """Return ``(isolator, controller)`` with the named parameters replaced.

    Parameters
    ----------
    isolator : IsolatorParameters
    controller : ControllerParameters
    settings : dict
        MODEL.md names (``mass``, ``pi_kp``, ...) to values; string values are
        parsed as numbers (``none`` for an optional value).

    Raises
    ------
    ParameterError
        For an unknown name (the message lists the valid ones) or an invalid value.
    """
    changes = {"isolator": {}, "controller": {}}
    for name, value in settings.items():
        if isinstance(value, str):
            value = _parse_value(value)
        for section, cls in _SECTIONS.items():
            if name in {f.name for f in dataclasses.fields(cls)}:
                changes[section][name] = value
                break
        else:
            valid = ", ".join(sorted(n for cls in _SECTIONS.values()
                                     for n in (f.name for f in dataclasses.fields(cls))))
            raise ParameterError(f"unknown parameter {name!r}; valid names are: {valid}.")
    return (dataclasses.replace(isolator, **changes["isolator"]),
            dataclasses.replace(controller, **changes["controller"]))


def load_config(path):
    """Read a TOML run configuration.

    Tables ``[isolator]`` and ``[controller]`` take MODEL.md parameter names;
    ``[excitation]`` (``kind`` = chirp, sine, random or file, and its options)
    and ``[simulation]`` (``dt``, ``sample_rate``, ``solver``, ``duration``) are
    optional. Unknown tables or keys are errors.

    Returns
    -------
    dict
        ``isolator`` and ``controller`` (parameter objects), ``excitation`` and
        ``simulation`` (plain dicts).
    """
    path = Path(path)
    document = read_toml(path, "config file")
    allowed = {"isolator", "controller", "excitation", "simulation"}
    unknown = set(document) - allowed
    if unknown:
        raise ParameterError(f"{str(path)!r}: unknown table(s) {sorted(unknown)}; "
                             f"allowed are {sorted(allowed)}.")
    settings = {**document.get("isolator", {}), **document.get("controller", {})}
    for section in ("isolator", "controller"):
        other = "controller" if section == "isolator" else "isolator"
        misplaced = set(document.get(section, {})) & {
            f.name for f in dataclasses.fields(_SECTIONS[other])}
        if misplaced:
            raise ParameterError(f"{str(path)!r}: {sorted(misplaced)} belong in [{other}], "
                                 f"not [{section}].")
    isolator, controller = update_parameters(IsolatorParameters(), ControllerParameters(),
                                             settings)
    for section, keys in (("excitation", EXCITATION_KEYS), ("simulation", SIMULATION_KEYS)):
        known_keys(document.get(section, {}), keys, f"[{section}]", f"{str(path)!r}: ")
    return {"isolator": isolator, "controller": controller,
            "excitation": dict(document.get("excitation", {})),
            "simulation": dict(document.get("simulation", {}))}


def save_config(path, isolator=None, controller=None, excitation=None, simulation=None):
    """Write parameters (and optional excitation/simulation tables) as TOML, atomically."""
    import tomli_w

    document = {"isolator": (isolator or IsolatorParameters()).to_dict(),
                "controller": (controller or ControllerParameters()).to_dict()}
    if excitation:
        document["excitation"] = dict(excitation)
    if simulation:
        document["simulation"] = dict(simulation)
    text = "# qzs run configuration: units as in `qzs params` (SI).\n" + tomli_w.dumps(document)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


def parameter_table(isolator=None, controller=None):
    """Rows ``(section, name, value, unit, description)`` of every parameter."""
    rows = []
    for section, obj in (("isolator", isolator or IsolatorParameters()),
                         ("controller", controller or ControllerParameters())):
        for f in dataclasses.fields(obj):
            rows.append((section, f.name, getattr(obj, f.name), f.metadata.get("unit", ""),
                         f.metadata.get("doc", "")))
    return rows


def read_displacement_csv(path, time_column="time", displacement_column="displacement"):
    """Read ``time`` [s] and ``displacement`` [m] columns from a CSV file with a header.

    Raises
    ------
    DataError
        Missing file or columns (the message lists the columns found), non-numeric
        or non-finite samples.
    """
    path = Path(path)
    if not path.exists():
        raise DataError(f"displacement record not found: {str(path)!r}.")
    with open(path, encoding="utf-8") as handle:
        lines = [line for line in handle if line.strip() and not line.startswith("#")]
    if not lines:
        raise DataError(f"{str(path)!r} is empty.")
    names = [n.strip() for n in lines[0].split(",")]
    missing = [c for c in (time_column, displacement_column) if c not in names]
    if missing:
        raise DataError(f"{str(path)!r} has no column(s) {missing}; columns found: {names}.")
    try:
        data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]], ndmin=2)
    except ValueError as error:
        raise DataError(f"{str(path)!r}: non-numeric value ({error}).") from None
    if data.shape[0] == 0 or data.shape[1] != len(names):
        raise DataError(f"{str(path)!r}: expected rows of {len(names)} numbers, got shape "
                        f"{data.shape}.")
    time = data[:, names.index(time_column)]
    displacement = data[:, names.index(displacement_column)]
    bad = int(np.count_nonzero(~np.isfinite(time)) + np.count_nonzero(~np.isfinite(displacement)))
    if bad:
        raise DataError(f"{str(path)!r}: {bad} non-finite samples (NaN or inf) in "
                        f"{time_column!r}/{displacement_column!r}; clean the record first.")
    return time, displacement


def format_value(value):
    """Human-readable parameter value (``None`` shown as 'setpoint' where it means that)."""
    if value is None:
        return "none"
    if isinstance(value, float) and math.isfinite(value):
        return f"{value:g}"
    return str(value)
