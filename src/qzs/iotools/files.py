"""Result files (NetCDF, CSV) and the atomic writer every file of qzs goes through.

Every writer is atomic: it writes a temporary file beside the target and
renames it into place, so an interrupted write never leaves a half-written file.
A run's result goes through :class:`ResultWriter`, which streams it in chunks:
memory grows with the chunk, not with the run. Failures while writing (a full
disk, no permission) raise :class:`~qzs.errors.WriteError` (a DataError) with attributes
``path`` and ``reason`` and leave neither the target nor a temporary file behind.
"""
import contextlib
import ctypes
import errno
import functools
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from qzs.engine import kernels as K
from qzs.engine.results import (CHANNELS, FLAGS, NONE_VALUE, file_attributes,
                                variable_attributes)
from qzs.errors import DataError, ParameterError, WriteError
from qzs.model.excitation import read_displacement_csv
from qzs.model.registry import parse_value

__all__ = ["atomic_path", "save_result", "read_result", "read_displacement_csv", "ResultWriter",
           "estimated_size", "RESULT_SUFFIXES"]

#: File formats of a run's result: suffix -> name.
RESULT_SUFFIXES = {".nc": "NetCDF", ".csv": "CSV"}
_NAMES = [*CHANNELS, *FLAGS]
_CSV_FORMAT = "%.10g"
_CHUNK_ROWS = 4096             # HDF5 chunk along time: 32 KiB per float variable
_FREE_MARGIN = 1 << 20         # bytes kept free beyond an estimate or a chunk
_CSV_BYTES_PER_VALUE = 17      # "-1.234567891e-05," at the %.10g format
_NC_OVERHEAD = 128 << 10       # header and attributes [bytes]
_NC_CHUNK_INDEX = 128          # chunk index per chunk (B-tree) [bytes]
_CSV_OVERHEAD = 8 << 10        # header and trailer lines [bytes]


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
    return _data_error(path, reason, f"cannot write {str(path)!r} ({action}): {reason}; "
                                     "nothing was written.")


def _data_error(path, reason, message):
    return WriteError(path, reason, message)


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


def _suffix(path):
    suffix = Path(path).suffix.lower()
    if suffix not in RESULT_SUFFIXES:
        raise ParameterError(f"`path` must end in .nc or .csv, got {str(path)!r}.")
    return suffix


def estimated_size(n_samples, suffix):
    """Size of a result file of ``n_samples`` samples [bytes], an upper estimate.

    NetCDF: 8 bytes per channel value and 1 per flag, in whole chunks of 4096
    samples, plus about 128 KiB of header and the chunk index; CSV: about 17 bytes
    per value (the ``%.10g`` format and a comma) plus the header lines.

    Parameters
    ----------
    n_samples : int
        Output samples of the run [samples] (``duration * sample_rate + 1``).
    suffix : {".nc", ".csv"}
        The file format (a path's suffix; a path is accepted too).

    Returns
    -------
    int
        Estimated size [bytes].
    """
    suffix = _suffix(f"x{suffix}" if str(suffix).startswith(".") else suffix)
    n = max(int(n_samples), 0)
    if suffix == ".nc":
        chunks = -(-n // _CHUNK_ROWS)
        return (chunks * (_CHUNK_ROWS * (8 * len(CHANNELS) + len(FLAGS))
                          + _NC_CHUNK_INDEX * len(_NAMES)) + _NC_OVERHEAD)
    return n * _CSV_BYTES_PER_VALUE * len(_NAMES) + _CSV_OVERHEAD


class ResultWriter:
    """Stream a run's result to NetCDF (``.nc``) or CSV (``.csv``), chunk by chunk.

    Memory grows with the chunk appended, not with the run. The file is written
    to a hidden temporary file beside ``path`` and renamed onto ``path`` by
    :meth:`finish`; :meth:`abort` (also called on any exception, ``KeyboardInterrupt``
    included, when used as a context manager) removes it. NetCDF files follow
    CF-1.10 (docs/model.md §7): ``time`` is an unlimited dimension, the flags are
    int8 with ``flag_values``/``flag_meanings``, the parameters global attributes
    with their units. CSV files have the parameters as ``# key = value [unit]``
    header lines, the rows, and the run's outcome as trailing ``# run.key = value``
    lines (known only at the end). :func:`save_result` writes through this class.

    Parameters
    ----------
    path : str or Path
        Target file, ending in ``.nc`` or ``.csv``; its folder is created if missing.
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        Controller parameters of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.

    Raises
    ------
    ParameterError
        A suffix other than ``.nc`` or ``.csv``.
    WriteError
        The temporary file cannot be created (attributes ``path`` and ``reason``).

    Examples
    --------
    >>> with ResultWriter("run.nc", isolator=iso, controller=ctrl,
    ...                   excitation=ex) as writer:  # doctest: +SKIP
    ...     for data, flags in chunks:
    ...         writer.append(data, flags)
    ...     writer.finish(run)
    """

    def __init__(self, path, *, isolator, controller, excitation):
        self.path = Path(path)
        self._suffix = _suffix(self.path)
        self._isolator, self._controller, self._excitation = isolator, controller, excitation
        self._head, _ = file_attributes(isolator, controller, excitation, None)
        self._create()

    def _create(self):
        """The hidden temporary file beside ``path``, its space reserved, opened (``_open``)."""
        self._rows = 0
        self._file = None
        self._tmp = None
        self._fd = None  # kept open to reserve disk space ahead of the library's writes
        self._variables = {}
        self._finished = False
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".part",
                                             dir=self.path.parent)
            self._tmp = Path(tmp)
            _reserve_space(self._fd, _NC_OVERHEAD + _FREE_MARGIN, self.path.parent)
            self._open()
        except (OSError, RuntimeError) as error:
            self.abort()
            raise _write_error(self.path, error, "creating the file") from None
        except BaseException:
            self.abort()
            raise

    @property
    def rows(self):
        """Samples written so far [samples]."""
        return self._rows

    # -- hooks of the format (a subclass writes another layout through them) ------------
    def _open(self):
        if self._suffix == ".nc":
            self._open_netcdf()
        else:
            self._open_csv()

    def _check_block(self, data, flags):
        """``data, flags`` as arrays of the right shapes, or ParameterError."""
        data, flags = np.asarray(data, dtype=float), np.asarray(flags)
        if data.ndim != 2 or data.shape[1] != K.N_CHANNELS or flags.shape != (data.shape[0], 2):
            raise ParameterError(f"`data` must have shape (n, {K.N_CHANNELS}) and `flags` "
                                 f"(n, 2), got {data.shape} and {flags.shape}.")
        return data, flags

    def _write(self, data, flags, start, stop):
        if self._suffix == ".nc":
            self._append_netcdf(data, flags, start, stop)
        else:
            self._append_csv(data, flags, start, stop)

    def _size(self, rows):
        """The file's estimated size with ``rows`` samples [bytes]."""
        return estimated_size(rows, self._suffix)

    def _close_file(self, run):
        _, tail = file_attributes(self._isolator, self._controller, self._excitation, run)
        if self._suffix == ".nc":
            self._finish_netcdf(tail)
        else:
            self._finish_csv(tail)

    # -- NetCDF -------------------------------------------------------------------------
    def _open_netcdf(self):
        import h5netcdf

        self._file = h5netcdf.File(self._tmp, "w")
        self._file.dimensions["time"] = None
        attributes = variable_attributes()
        self._variables = {}
        for name in _NAMES:
            dtype = np.int8 if name in FLAGS else np.float64
            variable = self._file.create_variable(name, ("time",), dtype,
                                                  chunks=(_CHUNK_ROWS,))
            for key, value in attributes[name].items():
                variable.attrs[key] = value
            self._variables[name] = variable

    def _append_netcdf(self, data, flags, start, stop):
        self._file.resize_dimension("time", stop)
        for name, (col, _, _) in CHANNELS.items():
            self._variables[name][start:stop] = data[:, col]
        for name, (col, _) in FLAGS.items():
            self._variables[name][start:stop] = flags[:, col].astype(np.int8)
        self._file._h5file.flush()  # on disk, inside the space reserved for it

    def _finish_netcdf(self, tail):
        for key, value in {**self._head, **tail}.items():
            self._file.attrs[key] = value
        handle, self._file = self._file, None
        self._variables = {}
        _close(handle)

    # -- CSV ----------------------------------------------------------------------------
    def _open_csv(self):
        self._file = open(self._tmp, "w", encoding="utf-8", newline="\n")
        for line in _header_lines(self._head):
            self._file.write(f"# {line}\n")
        self._file.write(",".join(_NAMES) + "\n")

    def _append_csv(self, data, flags, start, stop):
        columns = np.empty((stop - start, len(_NAMES)))
        for i, (name, (col, _, _)) in enumerate(CHANNELS.items()):
            columns[:, i] = data[:, col]
        for i, (col, _) in enumerate(FLAGS.values(), start=len(CHANNELS)):
            columns[:, i] = flags[:, col]
        np.savetxt(self._file, columns, delimiter=",", fmt=_CSV_FORMAT)

    def _finish_csv(self, tail):
        for line in _header_lines(tail):
            self._file.write(f"# {line}\n")
        self._file.flush()
        os.fsync(self._file.fileno())
        handle, self._file = self._file, None
        _close(handle)

    # -- public -------------------------------------------------------------------------
    def _check_open(self, action):
        if self._finished or self._tmp is None:
            raise ParameterError(f"cannot {action}: the ResultWriter of {str(self.path)!r} is "
                                 "already finished or aborted.")

    def append(self, data, flags):
        """Append samples to the file.

        Parameters
        ----------
        data : ndarray, shape (n, N_CHANNELS)
            Output samples, one column per kernel channel (the columns of
            :data:`qzs.engine.results.CHANNELS`), in their units.
        flags : ndarray of bool, shape (n, 2)
            The flags of :data:`qzs.engine.results.FLAGS`.

        Raises
        ------
        ParameterError
            Wrong shapes, or the writer is finished.
        WriteError
            Writing failed (disk full, permissions): the temporary file is removed
            (attributes ``path`` and ``reason``).
        """
        self._check_open("append")
        data, flags = self._check_block(data, flags)
        n = data.shape[0]
        if n == 0:
            return
        start, stop = self._rows, self._rows + n
        try:
            self._check_space(n)
            self._write(data, flags, start, stop)
        except (OSError, RuntimeError) as error:  # h5py reports some write failures so
            self.abort()
            raise _write_error(self.path, error) from None
        except BaseException:
            self.abort()
            raise
        self._rows = stop

    def _check_space(self, n):
        """Reserve the disk space of a chunk before the library writes it.

        The HDF5 library does not survive a full disk (a write that fails with ENOSPC
        can end in a segmentation fault when the file is closed), so the space is
        reserved first (``fallocate`` beyond the end of the file, Linux), or, where
        that is not possible, the free space is checked: a full disk then raises
        ``OSError(ENOSPC)`` here, before anything is written.
        """
        grows = self._size(self._rows + n) - self._size(self._rows)
        _reserve_space(self._fd, grows + _FREE_MARGIN, self.path.parent)

    def finish(self, run):
        """Write the run's settings and outcome, flush, and rename the file onto ``path``.

        Parameters
        ----------
        run : dict
            The run's settings and outcome (:attr:`qzs.engine.results.SimulationResult.run`),
            written as ``run.<key>`` attributes with their units.

        Returns
        -------
        Path
            The path written.

        Raises
        ------
        WriteError
            Writing failed: the temporary file is removed (attributes ``path`` and
            ``reason``).
        """
        self._check_open("finish")
        try:
            self._close_file(run)
            _release_reserve(self._fd)
            os.close(self._fd)
            self._fd = None
            os.chmod(self._tmp, 0o666 & ~_umask())  # mkstemp makes 0600
            os.replace(self._tmp, self.path)
        except (OSError, RuntimeError) as error:
            self.abort()
            raise _write_error(self.path, error, "finishing the file") from None
        except BaseException:
            self.abort()
            raise
        self._tmp = None
        self._finished = True
        return self.path

    def abort(self):
        """Close and remove the temporary file; ``path`` is left untouched. Idempotent."""
        handle, self._file = self._file, None
        self._variables = {}
        if handle is not None:
            with contextlib.suppress(Exception):
                _close(handle)
        fd, self._fd = self._fd, None
        if fd is not None:
            with contextlib.suppress(OSError):
                os.close(fd)
        tmp, self._tmp = self._tmp, None
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is not None or not self._finished:
            self.abort()
        return False

    def __del__(self):  # a writer dropped unfinished leaves no temporary file
        try:
            self.abort()
        except Exception:  # noqa: BLE001 - at interpreter exit anything may be gone
            pass

    def __repr__(self):
        state = "finished" if self._finished else ("aborted" if self._tmp is None else "open")
        return f"<{type(self).__name__} {str(self.path)!r}, {self._rows} rows, {state}>"


@functools.lru_cache(maxsize=1)
def _fallocate():
    """libc's ``fallocate`` (Linux), or None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        function = ctypes.CDLL(None, use_errno=True).fallocate64
    except (OSError, AttributeError):  # pragma: no cover - other libcs
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64]
    function.restype = ctypes.c_int
    return function


_FALLOC_FL_KEEP_SIZE = 1


def _reserve_space(fd, length, folder):
    """Reserve ``length`` bytes of disk beyond the end of the file ``fd`` [bytes].

    ``fallocate(FALLOC_FL_KEEP_SIZE)``: the blocks are allocated, the file's size is
    unchanged, so later writes there cannot fail for lack of space. Where the system
    or file system cannot, the free space is compared with ``length`` instead.

    Raises
    ------
    OSError
        ``ENOSPC`` if the disk has not ``length`` bytes free.
    """
    function = _fallocate()
    if function is not None:
        end = os.fstat(fd).st_size
        if function(fd, _FALLOC_FL_KEEP_SIZE, end, int(length)) == 0:
            return
        code = ctypes.get_errno()
        if code not in (errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
            raise OSError(code, os.strerror(code))
    if shutil.disk_usage(folder).free < length:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def _release_reserve(fd):
    """Give back the blocks reserved beyond the end of the file (shrinking frees them)."""
    size = os.fstat(fd).st_size
    os.ftruncate(fd, size + 1)
    os.ftruncate(fd, size)


def _close(handle):
    """Close a file; after a failure make sure the HDF5 library never touches it again.

    h5netcdf's ``close`` flushes attributes and then closes the HDF5 file; when that
    fails (a full disk), a second attempt, e.g. from its ``__del__``, crashes the
    interpreter (segmentation fault). So on failure the h5netcdf object is marked
    closed and only the underlying h5py file is closed (which releases the file
    descriptor), and the error is raised again.
    """
    try:
        handle.close()
    except BaseException:
        if hasattr(handle, "_closed"):  # an h5netcdf.File
            h5file = getattr(handle, "_File__h5file", None)
            handle._closed = True
            handle._File__h5file = None
            if h5file is not None:
                with contextlib.suppress(Exception):
                    h5file.close()
        raise


def _header_lines(attrs):
    """``key = value [unit]`` lines of a CSV header or trailer; ``<key>_units`` folded in."""
    lines = []
    for key, value in attrs.items():
        if key.endswith("_units") and key[:-len("_units")] in attrs:
            continue
        unit = attrs.get(f"{key}_units")
        text = _format(value)
        lines.append(f"{key} = {text} [{unit}]" if unit else f"{key} = {text}")
    return lines


def _format(value):
    if isinstance(value, np.ndarray):
        return " ".join(_format(v) for v in value.tolist())
    if isinstance(value, float):
        return repr(value)
    return str(value).replace("\n", " ")


def save_result(result, path):
    """Write a :class:`~qzs.engine.results.SimulationResult` to NetCDF (``.nc``) or CSV (``.csv``).

    Both carry every parameter with its unit, the excitation, the run settings and
    the qzs version as metadata (NetCDF: CF-1.10 global attributes; CSV:
    ``# key = value [unit]`` lines), see docs/model.md §7. Written through
    :class:`ResultWriter` in chunks, atomically.

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
        Any other suffix, or a preview of a streamed run (``run["preview_every"] > 1``).
    WriteError
        Writing failed (disk full, permissions; attributes ``path`` and ``reason``);
        nothing is left behind.
    """
    every = result.run.get("preview_every", 1)
    if every != 1:
        raise ParameterError(f"this result keeps only every {every}th sample of a run streamed "
                             "to a file (a preview); its full samples are in that file.")
    data, flags = result._data, result._flags
    with ResultWriter(path, isolator=result.isolator, controller=result.controller,
                      excitation=result.excitation) as writer:
        step = 1 << 17
        for start in range(0, max(len(result), 1), step):
            writer.append(data[start:start + step], flags[start:start + step])
        return writer.finish(result.run)


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


def read_result(path):
    """Read a saved result (``.nc`` or ``.csv``) back as an ``xarray.Dataset``.

    The flags come back boolean and ``None`` parameters as ``None``, so that a
    NetCDF file reads back as the run's :meth:`~qzs.engine.results.SimulationResult.to_xarray`
    (a CSV one too, to its 10 significant digits).

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
        Missing or unreadable file, or a CSV without a header line or with mismatched
        columns.
    """
    import xarray as xr

    path = Path(path)
    if not path.exists():
        raise DataError(f"no such file: {str(path)!r}.")
    if path.suffix.lower() == ".nc":
        try:
            dataset = xr.load_dataset(path, engine="h5netcdf")
        except (OSError, ValueError) as error:
            raise DataError(f"{str(path)!r} is not a readable NetCDF file: {error}") from None
        for name in FLAGS:
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
            for line in handle:
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
            else:
                raise DataError(f"{str(path)!r} has no column header line.")
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
    known = variable_attributes()
    variables = {}
    for i, name in enumerate(names):
        if name == "time":
            continue
        values = data[:, i].astype(bool) if name in FLAGS else data[:, i]
        variable_attrs = dict(known.get(name, {}))
        if units:
            variable_attrs["units"] = units[i]
        variables[name] = ("time", values, variable_attrs)
    time = data[:, names.index("time")] if "time" in names else np.arange(data.shape[0])
    _restore_none(attrs)
    return xr.Dataset(variables, coords={"time": ("time", time, dict(known["time"]))},
                      attrs=attrs)
