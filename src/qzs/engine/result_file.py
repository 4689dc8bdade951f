"""A run's result file: the streaming writer, whole-result save and read, size estimates.

:class:`ResultWriter`, a configuration of :class:`qzs.iotools.writer.StreamWriter` with
:func:`~qzs.engine.channels.simulation_schema`, streams a run to NetCDF, CSV or MATLAB
(docs/model.md §7); :func:`save_result` writes a whole :class:`~qzs.engine.result.SimulationResult`
through it, :func:`read_result` reads a file back as an ``xarray.Dataset``, and
:func:`estimated_size` bounds a file's size before the run.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from qzs.engine.channels import FLAGS, channel_count, run_channels, simulation_schema
from qzs.engine.metadata import controller_from_attributes, file_attributes
from qzs.errors import DataError, ParameterError
from qzs.iotools import files
from qzs.iotools.paths import check_output_path
from qzs.iotools.writer import StreamWriter, estimated_file_size

if TYPE_CHECKING:
    import xarray as xr

    from qzs.model.controller import ControllerParameters

__all__ = ["RESULT_SUFFIXES", "ResultWriter", "estimated_size", "save_result", "read_result",
           "read_controller"]

#: File formats of a run's result: suffix -> name.
RESULT_SUFFIXES = files.RESULT_SUFFIXES


def _columns(controller):
    """Where a run's output rows go in its file: variable -> (block, column) of
    ``(data, flags)``."""
    return {**{name: ("data", column) for name, (column, _, _)
               in run_channels(controller).items()},
            **{name: ("flags", column) for name, (column, _) in FLAGS.items()}}


class ResultWriter(StreamWriter):
    """Stream a run's result to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

    :class:`~qzs.iotools.writer.StreamWriter` configured with :func:`simulation_schema`:
    memory grows with the chunk appended, not with the run; the file is written to a
    hidden temporary file beside ``path`` and renamed onto ``path`` by :meth:`finish`;
    :meth:`abort` (also called on any exception, ``KeyboardInterrupt`` included, when
    used as a context manager) removes it. NetCDF files follow CF-1.10 (docs/model.md §7):
    ``time`` is an unlimited dimension, the flags are int8 with
    ``flag_values``/``flag_meanings``, the parameters attributes of container variables
    with their units (decision 34; :func:`read_result` gives them back as ``isolator.mass``).
    CSV files have the parameters as ``# key = value [unit]`` header lines, the rows, and
    the run's outcome as trailing ``# run.key = value`` lines (known only at the end).
    MATLAB files (:mod:`qzs.iotools.matfile`) hold the same variables, with the units and
    parameters in structs.
    :func:`save_result` writes through this class; so does :func:`qzs.simulate`'s
    ``sink`` when a run is streamed to a file. :meth:`append` takes ``data, flags``: output
    rows of shape (n, N_CHANNELS), one column per channel of :data:`CHANNELS`, and the flags
    of :data:`FLAGS`, shape (n, 2).

    Parameters
    ----------
    path : str or Path
        Target file, ending in ``.nc``, ``.csv`` or ``.mat``; its folder is created if
        missing.
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        Controller parameters of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.

    Raises
    ------
    ParameterError
        A suffix other than ``.nc``, ``.csv`` or ``.mat``.
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
        self._parameters = (isolator, controller, excitation)
        head, _ = file_attributes(isolator, controller, excitation, None)
        super().__init__(path, simulation_schema(controller),
                         blocks={"data": channel_count(controller), "flags": 2},
                         columns=_columns(controller), attributes=head, suffixes=tuple(RESULT_SUFFIXES))

    def finish(self, run):
        """Write the run's settings and outcome, flush, and rename the file onto ``path``.

        Parameters
        ----------
        run : dict
            :attr:`SimulationResult.run` (its entries become ``run.*`` global attributes,
            with the ``history`` line).

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
        _, tail = file_attributes(*self._parameters, run)
        return super().finish(tail)


def estimated_size(n_samples, suffix):
    """Size of a run's result file of ``n_samples`` samples [bytes], an upper estimate.

    NetCDF: 8 bytes per channel value and 1 per flag, in whole chunks of 4096
    samples, plus about 128 KiB of header and the chunk index; CSV: about 17 bytes
    per value (the ``%.10g`` format and a comma) plus the header lines
    (:func:`qzs.iotools.writer.estimated_file_size` of :func:`simulation_schema`).

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
    return estimated_file_size(simulation_schema(), n_samples, suffix)


def save_result(result, path):
    """Write a :class:`SimulationResult` to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

    Each carries every parameter with its unit, the excitation, the run settings and
    the qzs version as metadata (NetCDF: CF-1.10 global attributes; CSV:
    ``# key = value [unit]`` lines; MATLAB: structs, :mod:`qzs.iotools.matfile`), see
    docs/model.md §7. Written through :class:`ResultWriter` in chunks, atomically.

    Parameters
    ----------
    result : SimulationResult
        The run.
    path : str or Path
        Target file, ending in ``.nc``, ``.csv`` or ``.mat``.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        Any other suffix (an :class:`~qzs.errors.OutputPathError` naming ``path``, its
        extension and the accepted ones, before anything is written), or a preview of a
        streamed run (``run["preview_every"] > 1``).
    WriteError
        Writing failed (disk full, permissions; attributes ``path`` and ``reason``);
        nothing is left behind.
    """
    check_output_path(path, argument="path", suffixes=tuple(RESULT_SUFFIXES))
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


def read_result(path: str | Path) -> xr.Dataset:
    """Read a saved run (``.nc`` or ``.csv``) back as an ``xarray.Dataset``.

    The flags come back boolean and ``None`` parameters as ``None``, so that a
    NetCDF file reads back as the run's :meth:`SimulationResult.to_xarray` (a CSV one
    too, to its 10 significant digits): :func:`qzs.iotools.files.read_result` with
    :func:`simulation_schema`.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`save_result` or :class:`ResultWriter` (any suffix other
        than ``.nc`` is read as CSV).

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
    return files.read_result(path, simulation_schema(every_block=True))


def read_controller(source: str | Path | xr.Dataset) -> ControllerParameters:
    """The controller of a saved run, its blocks included (a linear controller's matrices,
    sensors and timing): equal to the run's ``result.controller``.

    Parameters
    ----------
    source : str, Path or xarray.Dataset
        A run's file (``.nc``, ``.csv``: :func:`read_result`; ``.mat``: its ``parameters``
        struct, MAT 5), or the dataset :func:`read_result` gave.

    Returns
    -------
    ControllerParameters

    Raises
    ------
    DataError
        A missing or unreadable file, a MAT 7.3 file (read its ``parameters`` with h5py),
        or attributes that make no controller.
    """
    if not isinstance(source, (str, Path)):
        return controller_from_attributes(source.attrs)
    path = Path(source)
    if path.suffix.lower() != ".mat":
        return controller_from_attributes(read_result(path).attrs)
    import scipy.io

    if not path.exists():
        raise DataError(f"no such file: {str(path)!r}.")
    try:
        mat = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False,
                               variable_names=["parameters"])
    except NotImplementedError:
        raise DataError(f"{str(path)!r} is a MAT 7.3 (HDF5) file: read its `parameters` "
                        "with h5py, or save the run as MAT 5 or NetCDF.") from None
    except (OSError, ValueError) as error:
        raise DataError(f"{str(path)!r} is not a readable MATLAB file: {error}") from None
    if "parameters" not in mat:
        raise DataError(f"{str(path)!r} has no `parameters` struct: not a run's file of qzs.")
    return controller_from_attributes(_flat(mat["parameters"], ""))


def _flat(struct, prefix):
    """A MATLAB struct (``scipy.io.loadmat``'s) as dotted names; ``[]`` (None) as None."""
    import numpy as np

    flat = {}
    for name in struct._fieldnames:
        value = getattr(struct, name)
        if hasattr(value, "_fieldnames"):
            flat.update(_flat(value, f"{prefix}{name}."))
        else:
            flat[f"{prefix}{name}"] = (None if isinstance(value, np.ndarray) and value.size == 0
                                       else value)
    return flat
