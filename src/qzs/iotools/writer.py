"""One streaming, atomic CF writer: a result's file written chunk by chunk from its schema.

:class:`StreamWriter` writes the layout of a :class:`~qzs.iotools.schema.Schema` to NetCDF
(``.nc``, CF-1.10, the unlimited dimension growing with each appended block), to MATLAB
(``.mat``, :mod:`qzs.iotools.matfile`: MAT 7.3 grown chunk by chunk, MAT 5 at the end if
it fits) or, for a schema whose streamed variables are all one-dimensional, to CSV
(``.csv``). Which column of an
appended block goes to which variable is the caller's mapping; the single run's
:class:`~qzs.engine.result_file.ResultWriter` and the six-axis run's
:class:`~qzs.engine.hexapod.result.HexapodWriter` are two such configurations.

:func:`write_dataset` writes a whole dataset of a schema (NetCDF, or CSV in long format) and
:func:`write_table` rows of a table (CSV), both with the units row of :data:`CSV_LAYOUT`.

The file is written to a hidden temporary file beside the target (``.<name>.*.part``) and
renamed onto the target by :meth:`StreamWriter.finish`; the disk space of each chunk is
reserved before it is written. :meth:`StreamWriter.abort` removes the temporary file; so
does any exception (``KeyboardInterrupt`` and :class:`~qzs.errors.Terminated` included)
while appending or finishing, or when the writer is used as a context manager. Failures
while writing (a full disk, no permission) raise :class:`~qzs.errors.WriteError` with
attributes ``path`` and ``reason`` and leave neither the target nor a temporary file behind.
"""
import contextlib
import csv
import errno
import functools
import io
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from qzs.errors import ParameterError
from qzs.iotools.files import RESULT_SUFFIXES, _umask, _write_error, atomic_path, write_text
from qzs.iotools.matfile import MatStream
from qzs.iotools.cf_layout import (container_attributes, container_long_name, file_schema,
                                   to_file_layout)
from qzs.iotools.schema import CONVENTIONS

__all__ = ["StreamWriter", "estimated_file_size", "write_dataset", "write_netcdf", "write_table",
           "CSV_LAYOUT"]

#: How the CSV files of qzs lay out their table (docs/model.md §7): ``#`` comment lines
#: (``key = value [unit]``), the last of which says on which lines the table starts; a row
#: of column names; a row of their units (CF ``units``; empty for a text column); the data;
#: trailing ``#`` lines. Read with pandas ``read_csv(path, comment="#", header=[0, 1])``
#: (columns ``(name, unit)``), numpy ``loadtxt(path, delimiter=",", skiprows=N + 1)`` (N:
#: the names' line, given in the layout line) or MATLAB ``readtable`` with
#: ``VariableNamesLine`` N and ``VariableUnitsLine`` N + 1.
CSV_LAYOUT = "column names on line {names}, units on line {units}, data from line {data}"

_CSV_FORMAT = "%.10g"
_FREE_MARGIN = 1 << 20         # bytes kept free beyond an estimate or a chunk
_CSV_BYTES_PER_VALUE = 17      # "-1.234567891e-05," at the %.10g format
_NC_CHUNK_INDEX = 128          # chunk index per chunk and variable (B-tree) [bytes]
_CSV_OVERHEAD = 8 << 10        # header and trailer lines [bytes]


def _suffix(path, suffixes=tuple(RESULT_SUFFIXES), kind=None):
    suffix = Path(path).suffix.lower()
    if suffix not in suffixes:
        of = f" of {kind}" if kind else ""
        shown = " or ".join([", ".join(suffixes[:-1]), suffixes[-1]] if len(suffixes) > 2
                            else suffixes)
        raise ParameterError(f"`path`{of} must end in {shown}, got {str(path)!r}.")
    return suffix


def _row_bytes(schema, variable):
    """Bytes one sample of a streamed variable takes in a NetCDF file [bytes]."""
    width = int(np.prod([schema.dimensions[d] for d in variable.dims[1:]], dtype=np.int64))
    return width * np.dtype(variable.cast([]).dtype).itemsize


def estimated_file_size(schema, n_samples, suffix):
    """Size of a file of ``n_samples`` samples of ``schema`` [bytes], an upper estimate.

    NetCDF: each streamed variable's bytes per sample (8 per float value, 1 per flag) in
    whole chunks of ``schema.chunk_rows`` samples, plus the chunk index and
    ``schema.header_bytes``; CSV: about 17 bytes per value (the ``%.10g`` format and a
    comma) plus the header lines; MATLAB: twice the NetCDF estimate (a ``.mat`` file is
    streamed as MAT 7.3 and, if it fits, copied to MAT 5 at the end: both are on disk then).

    Parameters
    ----------
    schema : Schema
        What the file holds.
    n_samples : int
        Samples along the unlimited dimension [samples].
    suffix : {".nc", ".csv", ".mat"}
        The file format (a path's suffix; a path is accepted too).

    Returns
    -------
    int
        Estimated size [bytes].
    """
    suffix = _suffix(f"x{suffix}" if str(suffix).startswith(".") else suffix)
    n = max(int(n_samples), 0)
    streamed = schema.streamed()
    if suffix == ".mat":  # streamed as MAT 7.3, then copied to MAT 5: both on disk at once
        return 2 * estimated_file_size(schema, n, ".nc")
    if suffix == ".nc":
        chunks = -(-n // schema.chunk_rows)
        row = sum(_row_bytes(schema, v) for v in streamed)
        return (chunks * (schema.chunk_rows * row + _NC_CHUNK_INDEX * len(streamed))
                + schema.header_bytes)
    return n * _CSV_BYTES_PER_VALUE * len(streamed) + _CSV_OVERHEAD


class StreamWriter:
    """Stream a result to NetCDF (``.nc``), MATLAB (``.mat``) or CSV (``.csv``), atomically.

    Memory grows with the block appended, not with the result. NetCDF files follow the
    schema (CF-1.10): the unlimited dimension grows with each block, streamed variables
    are chunked by ``schema.chunk_rows`` samples (and the whole of their other
    dimensions), flags are int8 with ``flag_values``/``flag_meanings``, variables not
    along the unlimited dimension are written from ``values`` when the file is created,
    and the global attributes (``Conventions``, ``attributes``, then those given to
    :meth:`finish`) at the end. CSV files (a schema whose streamed variables are all
    one-dimensional) have the ``attributes`` as ``# key = value [unit]`` header lines, then
    the table of :data:`CSV_LAYOUT` (a row of column names, a row of their units, the data),
    one column per streamed variable at the ``%.10g`` format, and the attributes given to
    :meth:`finish` as trailing ``# key = value`` lines (known only at the end). MATLAB files
    hold the same variables, names and attributes in the layout of :mod:`qzs.iotools.matfile`;
    they are grown as MAT 7.3 (resizable HDF5 datasets, memory bounded by the block) and,
    when every variable fits MAT 5 (2 GiB), copied to MAT 5 by :meth:`finish`, one variable
    in memory at a time.

    Parameters
    ----------
    path : str or Path
        Target file; its folder is created if missing.
    schema : Schema
        What the file holds; one dimension of unlimited length (size None).
    blocks : mapping of str to int
        The arrays :meth:`append` takes, in order, by name, with their number of columns
        (``{"data": 24, "flags": 2}``).
    columns : mapping of str to (str, int or slice)
        Each streamed variable -> (block name, column or slice of columns): where its
        values are in an appended block.
    values : mapping of str to array_like, optional
        The values of the variables not along the unlimited dimension (coordinate labels).
    attributes : mapping, optional
        Global attributes known before the result (head lines of a CSV file), after
        ``Conventions`` (CF-1.10).
    suffixes : tuple of str
        The formats allowed, by suffix (``.nc``, ``.mat``, and ``.csv`` for a
        one-dimensional schema).

    Raises
    ------
    ParameterError
        A suffix not in ``suffixes``, a CSV file of a schema with variables of more than
        one dimension, or ``columns``/``values`` that do not name the schema's variables.
    WriteError
        The temporary file cannot be created (attributes ``path`` and ``reason``).

    Examples
    --------
    >>> with StreamWriter("run.nc", schema, blocks={"data": 3},
    ...                   columns={"time": ("data", 0), "x": ("data", 1),
    ...                            "v": ("data", 2)}) as writer:  # doctest: +SKIP
    ...     for block in blocks:
    ...         writer.append(block)
    ...     writer.finish({"history": "..."})
    """

    def __init__(self, path, schema, *, blocks, columns, values=None, attributes=None,
                 suffixes=(".nc",)):
        self.path = Path(path)
        self.schema = schema
        self._suffix = _suffix(self.path, tuple(suffixes), schema.kind)
        if schema.unlimited is None:
            raise ParameterError(f"{schema.kind} has no dimension of unlimited length (size "
                                 "None) to stream along.")
        self._blocks = dict(blocks)
        self._streamed = schema.streamed()
        streamed = {v.name for v in self._streamed}
        self._columns = [(v, list(self._blocks).index(columns[v.name][0]),
                          columns[v.name][1]) for v in self._streamed
                         if v.name in columns and columns[v.name][0] in self._blocks]
        fixed = [v.name for v in schema if v.name not in streamed]
        values = dict(values or {})
        wrong = ([n for n in columns if n not in streamed]
                 + [n for n in values if n not in fixed])
        missing = ([v.name for v in self._streamed if v.name not in columns]
                   + [n for n in fixed if n not in values])
        if wrong or missing or len(self._columns) != len(self._streamed):
            raise ParameterError(f"`columns` of {schema.kind} must place each streamed "
                                 f"variable {[v.name for v in self._streamed]} in a block of "
                                 f"{list(self._blocks)} and `values` give {fixed}; missing "
                                 f"{missing}, unknown {wrong}.")
        if self._suffix == ".csv" and (fixed or any(len(v.dims) > 1 for v in self._streamed)):
            raise ParameterError(f"{schema.kind} has variables of more than one dimension: "
                                 "write it as NetCDF (.nc), not CSV.")
        self._values = values
        self._layout = schema
        if self._suffix == ".nc":  # CF's own means for what it has no home for (decision 34)
            self._layout, columns, self._values = file_schema(schema, columns, values)
            self._columns = [(v, list(self._blocks).index(columns[v.name][0]),
                              columns[v.name][1]) for v in self._layout.streamed()]
        self._head = {"Conventions": CONVENTIONS, **(attributes or {})}
        self._create()

    def _create(self):
        """The hidden temporary file beside ``path``, its space reserved, opened (``_open``)."""
        self._rows = 0
        self._file = None
        self._tmp = None
        self._fd = None  # kept open to reserve disk space ahead of the library's writes
        self._variables = {}
        self._finished = False
        with self._aborting("creating the file"):
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".part",
                                             dir=self.path.parent)
            self._tmp = Path(tmp)
            _reserve_space(self._fd, self.schema.header_bytes + _FREE_MARGIN, self.path.parent)
            if self._suffix == ".nc":
                self._open_netcdf()
            elif self._suffix == ".mat":
                self._file = MatStream(self._tmp, self.schema, self._values)
            else:
                self._open_csv()

    @contextlib.contextmanager
    def _aborting(self, action):
        """Abort (remove the temporary file) on any exception; an ``OSError`` (or the HDF5
        library's ``RuntimeError``) becomes a :class:`WriteError` saying what failed."""
        try:
            yield
        except (OSError, RuntimeError) as error:  # h5py reports some write failures so
            self.abort()
            raise _write_error(self.path, error, action) from None
        except BaseException:
            self.abort()
            raise

    @property
    def rows(self):
        """Samples written so far [samples]."""
        return self._rows

    def _size(self, rows):
        """The file's estimated size with ``rows`` samples [bytes]."""
        return estimated_file_size(self.schema, rows, self._suffix)

    # -- NetCDF -------------------------------------------------------------------------
    def _open_netcdf(self):
        import h5netcdf
        import h5py

        schema = self._layout
        # HDF5 1.10's file format: an unlimited dimension's chunks indexed by an extensible
        # array, whose memory stays flat; the 1.8 format's B-tree kept 16 MB more at 2e7
        # samples than at 2e6 (netCDF-C 4.7+, netCDF4-python, h5py, MATLAB R2021b+ read it)
        self._file = h5netcdf.File(self._tmp, "w", libver=("v110", "latest"))
        self._file.dimensions = dict(schema.dimensions)
        self._variables = {}
        for variable in schema:
            if variable.dims[:1] == (schema.unlimited,):
                chunks = (schema.chunk_rows, *(schema.dimensions[d] for d in variable.dims[1:]))
                created = self._file.create_variable(variable.name, variable.dims,
                                                     variable.cast([]).dtype, chunks=chunks)
                self._variables[variable.name] = created
            elif variable.dtype == "str" and variable.dims == (variable.name,):
                # CF: no 1-D string variable named as its dimension; characters, as xarray
                # writes them (``_Encoding`` makes xarray read strings back)
                labels = np.char.encode(variable.cast(self._values[variable.name]), "utf-8")
                width = max(1, max((len(label) for label in labels), default=1))
                self._file.dimensions[f"{variable.name}_strlen"] = width
                created = self._file.create_variable(
                    variable.name, (variable.name, f"{variable.name}_strlen"), dtype="S1",
                    data=labels.astype(f"S{width}")[:, None].view("S1"))
                created.attrs["_Encoding"] = "utf-8"
            elif variable.dtype == "str":  # variable-length strings, as xarray writes them
                created = self._file.create_variable(variable.name, variable.dims,
                                                     dtype=h5py.string_dtype())
                created[:] = np.array(variable.cast(self._values[variable.name]), dtype=object)
            else:
                created = self._file.create_variable(
                    variable.name, variable.dims, data=variable.cast(self._values[variable.name]))
            for key, value in variable.attrs().items():
                created.attrs[key] = value

    def _append_netcdf(self, blocks, start, stop):
        self._file.resize_dimension(self._layout.unlimited, stop)
        # through the HDF5 datasets themselves, one handle each per append (a handle kept
        # open holds its chunks: 210 MB more at 2e6 samples): h5netcdf's item assignment
        # checks the data type, opening the dataset again, on every call (a quarter of the
        # writing's time at one sample per step)
        datasets = self._file._h5file
        for variable, block, column in self._columns:
            values = blocks[block][:, column]
            if isinstance(column, (int, np.integer)):  # one column at a time: a transposed
                values = np.ascontiguousarray(values)  # copy of the block (13 MB) costs the
            datasets[variable.name][start:stop] = variable.cast(values)  # peak, not speed
        datasets.flush()  # on disk, inside the space reserved for it

    def _finish_netcdf(self, tail):
        plain, containers = container_attributes({**self._head, **tail})
        for key, value in plain.items():
            self._file.attrs[key] = value
        for section, attrs in containers.items():  # CF names have no dots (decision 34)
            container = self._file.create_variable(section, (), data=np.int8(0))
            container.attrs["long_name"] = container_long_name(section)
            for key, value in attrs.items():
                container.attrs[key] = value
        handle, self._file = self._file, None
        self._variables = {}
        _close(handle)

    # -- MATLAB -------------------------------------------------------------------------
    def _append_mat(self, blocks, start, stop):
        for variable, block, column in self._columns:
            self._file.append(variable.name, blocks[block][:, column], start, stop)
        self._file.flush()

    # -- CSV ----------------------------------------------------------------------------
    def _open_csv(self):
        self._file = open(self._tmp, "w", encoding="utf-8", newline="\n")
        self._file.write(_csv_head(self._head, [v.name for v in self._streamed],
                                   [v.units or "" for v in self._streamed]))

    def _append_csv(self, blocks, start, stop):
        columns = np.empty((stop - start, len(self._columns)))
        for i, (_, block, column) in enumerate(self._columns):
            columns[:, i] = blocks[block][:, column]
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
            raise ParameterError(f"cannot {action}: the {type(self).__name__} of "
                                 f"{str(self.path)!r} is already finished or aborted.")

    def _check_blocks(self, blocks):
        """The appended blocks as 2-D arrays of one length and their widths, or ParameterError."""
        arrays = [np.asarray(b) for b in blocks]
        n = arrays[0].shape[0] if arrays and arrays[0].ndim == 2 else None
        if (len(arrays) != len(self._blocks) or n is None
                or any(a.shape != (n, width) for a, width in zip(arrays, self._blocks.values()))):
            wanted = " and ".join(f"`{name}` (n, {width})" for name, width in self._blocks.items())
            got = " and ".join(str(a.shape) for a in arrays)
            raise ParameterError(f"the blocks must have shape {wanted}, got {got or 'none'}.")
        return arrays

    def append(self, *blocks):
        """Append samples: one array per block, rows along the unlimited dimension.

        Parameters
        ----------
        *blocks : ndarray, shape (n, width)
            The blocks named by ``blocks`` at creation (e.g. ``data, flags``), with the same
            number of rows ``n``.

        Raises
        ------
        ParameterError
            Wrong number of blocks or shapes, or the writer is finished.
        WriteError
            Writing failed (disk full, permissions): the temporary file is removed
            (attributes ``path`` and ``reason``).
        """
        self._check_open("append")
        blocks = self._check_blocks(blocks)
        n = blocks[0].shape[0]
        if n == 0:
            return
        start, stop = self._rows, self._rows + n
        with self._aborting("writing"):
            self._check_space(n)
            if self._suffix == ".nc":
                self._append_netcdf(blocks, start, stop)
            elif self._suffix == ".mat":
                self._append_mat(blocks, start, stop)
            else:
                self._append_csv(blocks, start, stop)
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

    def finish(self, attributes=None):
        """Write the global attributes known at the end, flush, and rename onto ``path``.

        Parameters
        ----------
        attributes : mapping, optional
            Global attributes known only at the end (the run's outcome, ``history``):
            NetCDF writes them after those given at creation, CSV as trailing lines.

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
        tail = dict(attributes or {})
        with self._aborting("finishing the file"):
            if self._suffix == ".nc":
                self._finish_netcdf(tail)
            elif self._suffix == ".mat":
                _release_reserve(self._fd)  # the space of the MAT 5 copy, if it is one
                self._file.finish({**self._head, **tail})
                self._file = None
            else:
                self._finish_csv(tail)
            _release_reserve(self._fd)
            os.close(self._fd)
            self._fd = None
            os.chmod(self._tmp, 0o666 & ~_umask())  # mkstemp makes 0600
            os.replace(self._tmp, self.path)
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
    import ctypes

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
        import ctypes

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


def _csv_head(attrs, names, units):
    """The head of a CSV table: ``#`` attribute lines, the layout line, names, units."""
    lines = [f"# {line}" for line in _header_lines(attrs)]
    n = len(lines) + 2  # the names' line number, counting from 1, after the layout line
    lines.append("# " + CSV_LAYOUT.format(names=n, units=n + 1, data=n + 2))
    rows = io.StringIO()
    writer = csv.writer(rows, lineterminator="\n")
    writer.writerow(names)
    writer.writerow(units)
    return "\n".join(lines) + "\n" + rows.getvalue()


def write_dataset(dataset, path):
    """Write a dataset built from a schema (``to_dataset``) to NetCDF, CSV or MATLAB, atomically.

    ``.nc``: the dataset as it is (CF-1.10, h5netcdf). ``.csv``: one row per point of its
    dimensions (long format: a curve of each case one row per frequency), the
    coordinates first, then the data variables, laid out as :data:`CSV_LAYOUT` says (a
    row of names, a row of units from the variables' ``units``), the global attributes as
    ``# key = value [unit]`` header lines, numbers at the ``%.10g`` format, flags 0/1.
    ``.mat``: the NetCDF's variables under the same names, units and attributes in
    structs (:func:`qzs.iotools.matfile.write_mat`).

    Parameters
    ----------
    dataset : xarray.Dataset
        The data, with CF attributes (:func:`qzs.iotools.schema.to_dataset`).
    path : str or Path
        Target file, ``.nc``, ``.csv`` or ``.mat``; its folder is created if missing.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ParameterError
        Another suffix.
    WriteError
        Writing failed (disk full, permissions); nothing is left behind.
    """
    path = Path(path)
    suffix = _suffix(path, (".nc", ".csv", ".mat"), "a dataset")
    if suffix == ".mat":
        from qzs.iotools.matfile import write_mat

        return write_mat(dataset, path)
    try:
        with atomic_path(path) as tmp:
            if suffix == ".nc":
                write_netcdf(dataset, tmp)
            else:
                tmp.write_text(_table_text(dataset), encoding="utf-8")
    except OSError as error:
        raise _write_error(path, error) from None
    return path


def write_netcdf(dataset, path):
    """Write a dataset to NetCDF (h5netcdf) in qzs's file layout, CF-1.10 (not atomic).

    :func:`qzs.iotools.cf_layout.to_file_layout`: dotted global attributes in container
    variables, no ``_FillValue`` on coordinates;
    :func:`qzs.iotools.files.read_result` reads it back as ``dataset``. Callers write to a
    temporary path (:func:`qzs.iotools.files.atomic_path`).

    Parameters
    ----------
    dataset : xarray.Dataset
        The data, with CF attributes (:func:`qzs.iotools.schema.to_dataset`).
    path : str or Path
        The file to write.

    Returns
    -------
    Path
        ``path``.
    """
    layout, encoding = to_file_layout(dataset)
    layout.to_netcdf(path, engine="h5netcdf", encoding=encoding)
    return Path(path)


def write_table(rows, path, *, units, attrs=None):
    """Write rows of a table (dicts) as CSV with a units row (:data:`CSV_LAYOUT`), atomically.

    The columns are every key, in the order met; a key a row lacks, ``None`` and a float
    that is NaN or +-inf are empty cells.

    Parameters
    ----------
    rows : sequence of dict
        Column name -> value.
    path : str or Path
        Target ``.csv`` file; its folder is created if missing.
    units : callable
        Column name -> its unit (``""`` for a text column).
    attrs : mapping, optional
        Global attributes, as ``# key = value [unit]`` head lines.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ParameterError
        A suffix other than ``.csv``.
    WriteError
        Writing failed (disk full, permissions); nothing is left behind.
    """
    path = Path(path)
    _suffix(path, (".csv",), "a table")
    columns = list(dict.fromkeys(key for row in rows for key in row))
    body = io.StringIO()
    writer = csv.writer(body, lineterminator="\n")
    for row in rows:
        writer.writerow(["" if row.get(key) is None else _cell(row[key], repr)
                         for key in columns])
    text = _csv_head(attrs or {}, columns, [units(key) or "" for key in columns])
    return write_text(path, text + body.getvalue())


def _table_text(dataset):
    """A dataset as a long CSV table (:func:`write_dataset`)."""
    dims = list(dataset.dims)
    indexed = [d for d in dims if d in dataset.coords]  # a dimension without labels: no column
    extra = [name for name in dataset.coords if name not in dims]
    names = [*indexed, *extra, *dataset.data_vars]
    shape = tuple(dataset.sizes[d] for d in dims)
    columns = []
    for name in names:
        variable = dataset[name]
        values = variable.transpose(*[d for d in dims if d in variable.dims]).values
        values = np.broadcast_to(
            values.reshape([dataset.sizes[d] if d in variable.dims else 1 for d in dims]),
            shape).ravel()
        columns.append(values)
    units = [str(dataset[name].attrs.get("units", "")) for name in names]
    rows = io.StringIO()
    writer = csv.writer(rows, lineterminator="\n")
    for row in zip(*columns):
        writer.writerow([_cell(value) for value in row])
    return _csv_head(dataset.attrs, names, units) + rows.getvalue()


def _cell(value, number=lambda value: _CSV_FORMAT % value):
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return "" if not np.isfinite(value) else number(float(value))
    return str(value)


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
