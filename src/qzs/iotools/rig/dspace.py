"""dSPACE ControlDesk MAT exports (v5/v7 and v7.3): read, and write for tests and examples.

One top-level struct variable (the map's ``[options] variable`` names it if the file holds
several) with fields ``X``, a struct array whose ``X(1).Data`` is the time vector, and ``Y``,
a struct array of signals with ``Name`` (char) and ``Data`` (vector on the ``X(1)``
raster). MAT v5/v7 are read by ``scipy.io.loadmat``; v7.3 (HDF5) by h5py, in MATLAB's own
layout: a struct is a group with a ``MATLAB_class`` attribute; a scalar struct's fields are
its members; a struct array's fields are datasets of object references (into ``#refs#``),
one per element; char arrays are uint16 datasets; numeric vectors are datasets of either
orientation. Cell arrays, multi-row chars and signals on other rasters (``X(2)``...) are
not supported.
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from qzs.errors import DataError, ParameterError
from qzs.iotools.rig.channel_map import INDEXED, find_signal, short_name

__all__ = ["read_dspace_mat", "write_dspace_mat"]


def read_dspace_mat(path, channel_map):
    """A dSPACE MAT export's signals by role, on the ``X(1)`` raster.

    Parameters
    ----------
    path : Path
        The log file.
    channel_map : ChannelMap
        Which signal is which role (:mod:`qzs.iotools.rig.channel_map`).

    Returns
    -------
    dict of str to (ndarray, ndarray)
        Role -> (time in the map's time unit, raw samples), checked and converted to SI by
        :func:`qzs.iotools.rig.recording.read_recording`.

    Raises
    ------
    DataError
        An unreadable file, or a signal missing (the message lists those found).
    """
    import h5py

    variables = _load_mat73(path) if h5py.is_hdf5(path) else _load_mat5(path)
    structs = {k: v for k, v in variables.items() if isinstance(v, dict) and "X" in v and "Y" in v}
    if channel_map.variable is not None:
        if channel_map.variable not in structs:
            raise DataError(f"{str(path)!r} has no dSPACE struct {channel_map.variable!r}; "
                            f"structs with X and Y found: {sorted(structs)}.")
        record = structs[channel_map.variable]
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
    if channel_map.time_source is not None:
        index = find_signal(channel_map.time_source, names, path)
        time = _vector(ys[index]["Data"], channel_map.time_source, path)
    signals = {}
    for role, channel in channel_map.channels.items():
        match = INDEXED.match(channel.source)
        if match and match.group(1) == "Y":
            k = int(match.group(2))
            if not 1 <= k <= len(ys):
                raise DataError(f"{str(path)!r}: {channel.source!r} is out of range, Y has "
                                f"{len(ys)} elements; signals found: {names}.")
            if match.group(3) and short_name(names[k - 1]) != short_name(match.group(3)):
                raise DataError(f"{str(path)!r}: Y({k}) is named {names[k - 1]!r}, not "
                                f"{match.group(3)!r}; signals found: {names}.")
            index = k - 1
        elif match:
            raise DataError(f"{str(path)!r}: {channel.source!r}: only Y(k) hold signals.")
        else:
            index = find_signal(channel.source, names, path)
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
