"""Result files (NetCDF, CSV) and the atomic writer every file of qzs goes through.

Every writer is atomic: it writes a temporary file beside the target and
renames it into place, so an interrupted write never leaves a half-written file.
"""
import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np

from qzs.engine.results import CHANNELS, FLAGS
from qzs.errors import DataError, ParameterError
from qzs.model.excitation import read_displacement_csv
from qzs.model.registry import parse_value

__all__ = ["atomic_path", "save_result", "read_result", "read_displacement_csv"]


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


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def save_result(result, path):
    """Write a :class:`~qzs.engine.results.SimulationResult` to NetCDF (``.nc``) or CSV (``.csv``).

    Both carry every parameter, the excitation, the run settings and the qzs
    version as metadata (NetCDF global attributes; CSV ``# key = value`` header
    lines).

    Parameters
    ----------
    result : SimulationResult
        The run.
    path : str or Path
        Target file, ending in ``.nc`` or ``.csv``.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        Any other suffix.
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
    """Read a saved result (``.nc`` or ``.csv``) back as an ``xarray.Dataset``.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`save_result` (any suffix other than ``.nc`` is read as CSV).

    Returns
    -------
    xarray.Dataset
        The channels on coordinate ``time`` [s], units and metadata in attributes.

    Raises
    ------
    DataError
        Missing file, or a CSV without a header line or with mismatched columns.
    """
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
                attrs[key] = parse_value(value)
        else:
            raise DataError(f"{str(path)!r} has no column header line.")
        data = np.loadtxt(handle, delimiter=",", ndmin=2)
    if data.shape[1] != len(names):
        raise DataError(f"{str(path)!r}: {len(names)} column names but {data.shape[1]} columns.")
    variables = {n: ("time", data[:, i], {"units": units[i]} if units else {})
                 for i, n in enumerate(names) if n != "time"}
    return xr.Dataset(variables, coords={"time": data[:, names.index("time")]}, attrs=attrs)
