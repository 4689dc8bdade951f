"""A six-leg platform's run streamed to NetCDF, chunk by chunk (``qzs hexapod simulate --out``).

The layout is :meth:`qzs.engine.hexapod.HexapodResult.to_xarray`'s (CF-1.10, dimensions
``time`` (unlimited), ``dof`` and ``leg``; :func:`qzs.engine.hexapod.hexapod_file_layout`),
written through :class:`~qzs.iotools.files.ResultWriter`'s machinery: a hidden temporary
file beside the target, disk space reserved before each chunk, renamed onto the target only
when the run has ended; on any error or interruption nothing is left behind. Flags are
stored as int8 (0/1) with ``flag_values`` and ``flag_meanings``.
"""
from pathlib import Path

import numpy as np

from qzs.engine.hexapod.layout import N_CHANNELS, N_FLAGS
from qzs.engine.hexapod.result import HEXAPOD_CHANNELS, HEXAPOD_FLAGS, hexapod_file_layout
from qzs.errors import ParameterError
from qzs.iotools.files import ResultWriter, _close

__all__ = ["HexapodWriter", "estimated_hexapod_size", "save_hexapod_result"]

_CHUNK_ROWS = 4096            # HDF5 chunk along time
_OVERHEAD = 256 << 10         # header, coordinates and attributes [bytes]
_CHUNK_INDEX = 128            # chunk index per chunk and variable [bytes]


def estimated_hexapod_size(n_samples):
    """Size of a hexapod result file of ``n_samples`` samples [bytes], an upper estimate.

    Parameters
    ----------
    n_samples : int
        Output samples [samples] (``duration * sample_rate + 1``).

    Returns
    -------
    int
        Estimated size [bytes]: 8 bytes per channel value, 1 per flag, in whole chunks of
        4096 samples, plus the chunk index and about 256 KiB of header.
    """
    chunks = -(-max(int(n_samples), 0) // _CHUNK_ROWS)
    names = len(HEXAPOD_CHANNELS) + len(HEXAPOD_FLAGS)
    return chunks * (_CHUNK_ROWS * (8 * N_CHANNELS + N_FLAGS) + _CHUNK_INDEX * names) + _OVERHEAD


class HexapodWriter(ResultWriter):
    """Stream a hexapod run (:func:`qzs.simulate_hexapod`'s ``sink``) to a NetCDF file.

    Parameters
    ----------
    path : str or Path
        Target file, ending in ``.nc``; its folder is created if missing.

    Raises
    ------
    ParameterError
        A suffix other than ``.nc``.
    WriteError
        The temporary file cannot be created (attributes ``path`` and ``reason``).

    Examples
    --------
    >>> with HexapodWriter("platform.nc") as writer:  # doctest: +SKIP
    ...     result = simulate_hexapod(geometry, platform, sink=writer.append)
    ...     writer.finish(result)
    """

    def __init__(self, path):
        self.path = Path(path)
        if self.path.suffix.lower() != ".nc":
            raise ParameterError(f"`path` of a hexapod run must end in .nc (NetCDF), got "
                                 f"{str(path)!r}.")
        self._suffix = ".nc"
        self._create()

    def _open(self):
        import h5netcdf
        import h5py

        self._file = h5netcdf.File(self._tmp, "w")
        self._file.dimensions = {"time": None, "dof": 6, "leg": 6}
        layout = hexapod_file_layout()
        self._variables = {}
        for name, (dims, values, attrs) in layout["coordinates"].items():
            if name == "time":
                variable = self._file.create_variable("time", dims, np.float64,
                                                      chunks=(_CHUNK_ROWS,))
                self._variables["time"] = variable
            elif isinstance(values[0], str):  # variable-length strings, as xarray writes them
                variable = self._file.create_variable(name, dims, dtype=h5py.string_dtype())
                variable[:] = np.array(values, dtype=object)
            else:
                variable = self._file.create_variable(name, dims, data=np.asarray(values))
            for key, value in attrs.items():
                variable.attrs[key] = value
        for name, (dims, attrs) in layout["variables"].items():
            dtype = np.int8 if name in HEXAPOD_FLAGS else np.float64
            chunks = (_CHUNK_ROWS,) if len(dims) == 1 else (_CHUNK_ROWS, 6)
            variable = self._file.create_variable(name, dims, dtype, chunks=chunks)
            for key, value in attrs.items():
                variable.attrs[key] = value
            self._variables[name] = variable

    def _check_block(self, data, flags):
        data, flags = np.asarray(data, dtype=float), np.asarray(flags)
        if data.ndim != 2 or data.shape[1] != N_CHANNELS or flags.shape != (data.shape[0],
                                                                            N_FLAGS):
            raise ParameterError(f"`data` must have shape (n, {N_CHANNELS}) and `flags` "
                                 f"(n, {N_FLAGS}), got {data.shape} and {flags.shape}.")
        return data, flags

    def _write(self, data, flags, start, stop):
        self._file.resize_dimension("time", stop)
        for name, (column, dim, _, _) in HEXAPOD_CHANNELS.items():
            self._variables[name][start:stop] = (data[:, column] if dim is None
                                                 else data[:, column:column + 6])
        for name, (column, _) in HEXAPOD_FLAGS.items():
            self._variables[name][start:stop] = flags[:, column:column + 6].astype(np.int8)
        self._file._h5file.flush()  # on disk, inside the space reserved for it

    def _size(self, rows):
        return estimated_hexapod_size(rows)

    def _close_file(self, result):
        for key, value in result.global_attributes().items():
            self._file.attrs[key] = value
        handle, self._file = self._file, None
        self._variables = {}
        _close(handle)

    def finish(self, result):
        """Write the run's settings and outcome, flush, and rename the file onto ``path``.

        Parameters
        ----------
        result : HexapodResult
            The run (its parameters and ``run`` dict become global attributes).

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
        return super().finish(result)


def save_hexapod_result(result, path):
    """Write a hexapod run held in memory to a NetCDF file, atomically.

    Parameters
    ----------
    result : HexapodResult
        A run holding every sample (not the preview of a run streamed to a file).
    path : str or Path
        Target ``.nc`` file; checked (folder, permissions, free space) before writing.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        ``result`` holds a preview only (``run["preview_every"]`` > 1).
    OutputPathError
        ``path`` cannot be written.
    """
    from qzs.iotools.paths import check_output_path

    every = result.run.get("preview_every", 1)
    if every > 1:
        raise ParameterError(
            f"this result holds every {every}th sample only (a preview of a run streamed to a "
            "file); the whole run is in the file it was streamed to.")
    check_output_path(path, argument="path", suffixes=(".nc",),
                      estimated_bytes=estimated_hexapod_size(len(result)))
    with HexapodWriter(path) as writer:
        for start in range(0, len(result), 100_000):
            writer.append(result._data[start:start + 100_000],
                          result._flags[start:start + 100_000])
        return writer.finish(result)
