"""Atomic writes, and results read back from NetCDF or CSV.

Every file of qzs is written atomically: :func:`atomic_path` gives a temporary file beside
the target and renames it into place, so an interrupted write never leaves a half-written
file. A result streamed chunk by chunk goes through :class:`~qzs.iotools.writer.StreamWriter`;
:func:`read_result` reads such a file back as an ``xarray.Dataset``.
"""
import contextlib
import errno
import os
import tempfile
from pathlib import Path

import numpy as np

from qzs.errors import DataError, WriteError
from qzs.iotools.cf_layout import from_file_layout
from qzs.iotools.schema import NONE_VALUE
from qzs.model.excitation import read_displacement_csv
from qzs.model.registry import parse_value

__all__ = ["atomic_path", "write_text", "read_result", "read_displacement_csv", "RESULT_SUFFIXES",
           "is_units_row"]

#: File formats of a result streamed to a file: suffix -> name.
RESULT_SUFFIXES = {".nc": "NetCDF", ".csv": "CSV", ".mat": "MATLAB"}

@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    On any error the temporary file is removed and ``path`` is left untouched.

    Parameters
    ----------
    path : str or Path
        The file to write; its folder is created if missing.

    Yields
    ------
    Path
        The temporary file to write instead.
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


def write_text(path, text):
    """Write ``text`` (UTF-8) to ``path`` atomically (:func:`atomic_path`).

    Parameters
    ----------
    path : str or Path
        The file; its folder is created if missing.
    text : str
        Its whole content.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    WriteError
        Writing failed (disk full, permissions); nothing is left behind.
    """
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    except OSError as error:
        raise _write_error(path, error) from None
    return path


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _write_error(path, error, action="writing"):
    """A :class:`WriteError` for an ``OSError`` while writing ``path`` (``path``, ``reason``)."""
    code = getattr(error, "errno", None)
    if code is None:  # HDF5 wraps the system error in its message
        text = str(error)
        code = next((c for c in (errno.ENOSPC, errno.EDQUOT, errno.EACCES, errno.EROFS)
                     if os.strerror(c).lower() in text.lower()), None)
    reasons = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
               errno.EACCES: "permission denied", errno.EPERM: "permission denied",
               errno.EROFS: "the file system is read-only",
               errno.ENOENT: "the folder does not exist"}
    reason = reasons.get(code) or (getattr(error, "strerror", None) or str(error)).split("\n")[0]
    return WriteError(path, reason, f"cannot write {str(path)!r} ({action}): {reason}; "
                                    "nothing was written.")


def _restore_none(attrs):
    """Parameters stored as ``"none"`` (listed in ``none_parameters``) back to ``None``."""
    for key in str(attrs.get("none_parameters", "")).split():
        if attrs.get(key) == NONE_VALUE:
            attrs[key] = None
    return attrs


def _parse_line(text):
    """``key = value [unit]`` -> (key, value, unit or None)."""
    key, value = text.split(" = ", 1)
    unit = None
    if value.endswith("]") and " [" in value:
        value, unit = value[:-1].rsplit(" [", 1)
    return key, parse_value(value), unit


def is_units_row(cells):
    """Whether a CSV row after the column names is a row of units, not data: some cell is
    not a number (the layout of ``qzs.iotools.writer.CSV_LAYOUT``).

    Every table of qzs has a unit that is not a number (``s``, ``Hz``); a data row has
    only numbers (or empty cells, where NaN was written).

    Parameters
    ----------
    cells : sequence of str
        The row's cells.

    Returns
    -------
    bool
    """
    for cell in cells:
        cell = cell.strip()
        if not cell:
            continue
        try:
            float(cell)
        except ValueError:
            return True
    return False


def _trailer(path, size=1 << 16):
    """The ``key = value`` comment lines after the last row of a CSV result."""
    with open(path, "rb") as handle:
        handle.seek(0, os.SEEK_END)
        end = handle.tell()
        handle.seek(max(0, end - size))
        lines = handle.read().decode("utf-8", errors="replace").splitlines()
    trailer = []
    for line in reversed(lines[1:] if end > size else lines):
        if not line.startswith("#"):
            break
        trailer.append(line[1:].strip())
    return [text for text in reversed(trailer) if " = " in text]


def read_result(path, schema=None):
    """Read a result file (``.nc`` or ``.csv``) back as an ``xarray.Dataset``.

    The flags come back boolean and ``None`` parameters as ``None``, so that a NetCDF file
    of a run reads back as the run's ``to_xarray()`` (a CSV one too, to its 10 significant
    digits). A NetCDF file describes itself; a CSV file's columns get their attributes and
    types (which are flags) from ``schema``, and without one come back as plain float
    columns. :func:`qzs.read_result` reads a single run's file with its schema.

    Parameters
    ----------
    path : str or Path
        A file written by a :class:`~qzs.iotools.writer.StreamWriter` (any suffix other than
        ``.nc`` is read as CSV).
    schema : Schema, optional
        What the file holds (:func:`qzs.engine.channels.simulation_schema` for a run); the
        flags of a NetCDF file without one are its variables with ``flag_values``.

    Returns
    -------
    xarray.Dataset
        The columns on coordinate ``time`` [s], units and metadata in attributes.

    Raises
    ------
    DataError
        Missing or unreadable file, a MATLAB (``.mat``) file, or a CSV without a header
        line or with mismatched columns.
    """
    import xarray as xr

    path = Path(path)
    if not path.exists():
        raise DataError(f"no such file: {str(path)!r}.")
    if path.suffix.lower() == ".mat":
        raise DataError(f"{str(path)!r} is a MATLAB file: load it in MATLAB (load), or in "
                        "Python with scipy.io.loadmat (MAT 5) or h5py (MAT 7.3); qzs reads "
                        "results back from .nc or .csv files.")
    if path.suffix.lower() == ".nc":
        try:
            dataset = xr.load_dataset(path, engine="h5netcdf")
        except (OSError, ValueError) as error:
            raise DataError(f"{str(path)!r} is not a readable NetCDF file: {error}") from None
        dataset = from_file_layout(dataset)
        flags = ([v.name for v in schema if v.is_flag] if schema is not None
                 else [name for name in dataset.data_vars
                       if "flag_values" in dataset[name].attrs])
        for name in flags:
            if name in dataset and "flag_values" in dataset[name].attrs:
                dataset[name] = dataset[name].astype(bool)
        _restore_none(dataset.attrs)
        return dataset
    attrs, units = {}, []
    try:
        handle = open(path, encoding="utf-8")
    except OSError as error:
        raise DataError(f"cannot read {str(path)!r}: {error.strerror}.") from None
    with handle:
        try:
            while True:
                line = handle.readline()
                if not line:
                    raise DataError(f"{str(path)!r} has no column header line.")
                if not line.startswith("#"):
                    names = line.strip().split(",")
                    break
                text = line[1:].strip()
                if text.startswith("units: "):  # files of qzs before 0.3
                    units = text[len("units: "):].split(",")
                elif " = " in text:
                    key, value, unit = _parse_line(text)
                    attrs[key] = value
                    if unit is not None:
                        attrs[f"{key}_units"] = unit
            start = handle.tell()
            row = handle.readline().strip().split(",")
            if is_units_row(row):  # the units row (writer.CSV_LAYOUT); older files have none
                units = row
            else:
                handle.seek(start)
            data = np.loadtxt(handle, delimiter=",", ndmin=2, comments="#")
        except DataError:
            raise
        except UnicodeDecodeError:
            raise DataError(f"{str(path)!r} is not a text (CSV) file.") from None
        except ValueError as error:
            raise DataError(f"{str(path)!r}: unreadable rows ({error}).") from None
    for text in _trailer(path):  # the run's outcome follows the rows
        key, value, unit = _parse_line(text)
        attrs[key] = value
        if unit is not None:
            attrs[f"{key}_units"] = unit
    if data.size == 0:
        data = np.empty((0, len(names)))
    if data.shape[1] != len(names):
        raise DataError(f"{str(path)!r}: {len(names)} column names but {data.shape[1]} columns.")
    known = schema.attributes() if schema is not None else {}
    flags = {v.name for v in schema if v.is_flag} if schema is not None else set()
    variables = {}
    for i, name in enumerate(names):
        if name == "time":
            continue
        values = data[:, i].astype(bool) if name in flags else data[:, i]
        variable_attrs = dict(known.get(name, {}))
        if units:
            variable_attrs["units"] = units[i]
        variables[name] = ("time", values, variable_attrs)
    time = data[:, names.index("time")] if "time" in names else np.arange(data.shape[0])
    _restore_none(attrs)
    return xr.Dataset(variables, coords={"time": ("time", time, dict(known.get("time", {})))},
                      attrs=attrs)
