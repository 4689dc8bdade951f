"""MATLAB files of a result: MAT 5 through ``scipy.io``, MAT 7.3 (HDF5) for large variables.

A ``.mat`` file holds what the result's NetCDF file holds, in the form MATLAB's ``load``
expects; it is built from the same dataset (``to_xarray()``, or the
:class:`~qzs.iotools.schema.Schema` a :class:`~qzs.iotools.writer.StreamWriter` streams),
never from a second description of the variables:

==========================  =============================================================
every coordinate, variable  a MATLAB variable of the same name, same values and shape
                            (a 1-D array is a column, ``n x 1``; an ``(n, m)`` array is
                            ``n x m``); float64 ``double``, counts ``int64``, flags (0/1)
                            ``logical``, strings a cell array of char
``units``                   struct: variable -> its unit (``''`` where it has none)
``variable_attributes``     struct: variable -> struct of its other CF attributes
                            (``long_name``, ``flag_meanings``, ``comment``, ...)
``parameters``              struct of the run's parameters, nested by section with the
                            registry's names (``parameters.isolator.mass``); a parameter
                            that is ``None`` is ``[]``
``parameter_units``         struct of the same shape: each parameter's unit (``''``: none)
``attributes``              struct: the other global attributes (``title``, ``history``,
                            ``Conventions``, ``qzs_version``, ...)
``description``             char: what the file holds and where its units are
``netcdf_names``            struct: MATLAB name -> NetCDF name, only if a name was changed
==========================  =============================================================

A global attribute is a parameter when its name has a section (``isolator.mass``,
``run.steps``, ``settings.f0``) or a unit beside it (``amplitude`` with
``amplitude_units``); its unit is that ``<name>_units`` attribute. A parameter whose name
also heads a section (a hexapod run's ``excitation.z``, the excitation's class, beside
``excitation.z.amplitude``) is that section's field ``value``.

Names: MATLAB's are identifiers of at most 63 characters (``namelengthmax``), a letter
first, then letters, digits and ``_``, no keyword. Every name of qzs is one already; any
other is changed as MATLAB's ``matlab.lang.makeValidName`` does (other characters become
``_``, an ``x`` in front of a name that does not start with a letter, ``xFor`` for the
keyword ``for``), cut to 63 characters, and listed in ``netcdf_names``. Two names that
become one are an error.

Versions: MAT 5 (``scipy.io.savemat``, uncompressed, ``oned_as='column'``) is read by
every MATLAB, Octave and ``scipy.io.loadmat``, but holds at most 2 GiB per variable
(:data:`MAT5_LIMIT`). A file with a larger variable is MAT 7.3: HDF5 behind MATLAB's
512-byte header, which MATLAB R2006b and later load, and ``h5py`` reads (the arrays
transposed: HDF5 stores row-major what MATLAB reads column-major). ``version`` forces one.

Streaming (:class:`MatStream`, what :class:`~qzs.iotools.writer.StreamWriter` writes a
``.mat`` run through): the samples are appended chunk by chunk to a MAT 7.3 file
(resizable HDF5 datasets), so memory stays bounded by the chunk. At the end, a run whose
variables all fit MAT 5 is converted to MAT 5, one variable in memory at a time (the
disk holds both files for that moment); a larger run stays MAT 7.3. Either way the file
appears, complete, under its name only at the end: nothing is left on an error.
"""
import contextlib
import os
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from qzs.errors import ParameterError
from qzs.iotools.files import _write_error, atomic_path

__all__ = ["MAT5_LIMIT", "MAT_VERSIONS", "RESERVED_NAMES", "matlab_name", "mat_layout",
           "is_flag", "write_mat", "MatStream"]

#: The largest variable a MAT 5 file holds [bytes] (MATLAB: 2 GiB per variable in MAT 5
#: and 7 files); a file with a larger one is written as MAT 7.3.
MAT5_LIMIT = 2 ** 31
#: The versions :func:`write_mat` writes.
MAT_VERSIONS = ("5", "7.3")
#: The names of the structs and text beside the variables (a variable may not have one).
RESERVED_NAMES = ("units", "variable_attributes", "parameters", "parameter_units",
                  "attributes", "description", "netcdf_names")
#: MATLAB's ``namelengthmax`` [characters].
NAME_LENGTH = 63
#: MATLAB's keywords (``iskeyword``): not names of variables or fields.
MATLAB_KEYWORDS = frozenset((
    "break", "case", "catch", "classdef", "continue", "else", "elseif", "end", "for",
    "function", "global", "if", "otherwise", "parfor", "persistent", "return", "spmd",
    "switch", "try", "while"))
_USERBLOCK = 512              # bytes before the HDF5 superblock of a MAT 7.3 file
_HEADER_TEXT = 116            # bytes of the header's text (then 8 subsystem, 2 version, 2 'IM')
_ELEMENT_OVERHEAD = 1 << 10   # a MAT 5 element's tags, dimensions and name [bytes]
_SLAB = 1 << 24               # bytes copied at once when a large variable is written
_CLASSES = {"f8": "double", "f4": "single", "i1": "int8", "u1": "uint8", "i2": "int16",
            "u2": "uint16", "i4": "int32", "u4": "uint32", "i8": "int64", "u8": "uint64"}


def matlab_name(name):
    """``name`` as a MATLAB identifier, changed as ``matlab.lang.makeValidName`` does.

    Parameters
    ----------
    name : str
        A NetCDF name (of a variable, attribute or parameter section).

    Returns
    -------
    str
        ``name`` itself if valid; else with other characters as ``_``, an ``x`` in front
        of a name not starting with a letter, ``xFor`` for the keyword ``for``; at most
        63 characters.

    Examples
    --------
    >>> matlab_name("relative_position"), matlab_name("2nd harmonic"), matlab_name("end")
    ('relative_position', 'x2nd_harmonic', 'xEnd')
    """
    text = str(name)
    if text in MATLAB_KEYWORDS:
        return "x" + text.capitalize()
    text = re.sub(r"[^A-Za-z0-9_]", "_", text) or "x"
    if not text[0].isalpha() or not text[0].isascii():
        text = "x" + text
    return text[:NAME_LENGTH]


def _names(originals, where):
    """MATLAB names of ``originals``; a ParameterError if two become one."""
    names = {}
    for original in originals:
        name = matlab_name(original)
        if name in names.values():
            first = next(k for k, v in names.items() if v == name)
            raise ParameterError(f"{where} {first!r} and {original!r} both become the MATLAB "
                                 f"name {name!r}; rename one of them.")
        names[original] = name
    return names


def _value(value):
    """An attribute's value for MATLAB: None stays None (``[]``), lists become arrays."""
    if value is None or isinstance(value, (str, bool, int, float)):
        return value
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    array = np.asarray(value)
    if array.dtype.kind in "UOS":
        return np.array([str(v) for v in array.ravel()], dtype=object).reshape(array.shape)
    return array


def _struct(items, where):
    """A flat ``{name: value}`` as a struct (dict) with MATLAB field names."""
    names = _names(list(items), where)
    return {names[key]: _value(value) for key, value in items.items()}


def _nested(items, where):
    """``{"isolator.mass": v}`` -> ``{"isolator": {"mass": v}}``, MATLAB names throughout.

    A value whose name also heads a section (a hexapod's ``excitation.z``, the class of
    the excitation, beside ``excitation.z.amplitude``) is that section's field ``value``.
    """
    paths = {key: tuple(matlab_name(p) for p in str(key).split(".")) for key in items}
    sections = {path[:i] for path in paths.values() for i in range(1, len(path))}
    tree = {}
    for key, value in items.items():
        path = paths[key] + (("value",) if paths[key] in sections else ())
        node = tree
        for part in path[:-1]:
            node = node.setdefault(part, {})
        if path[-1] in node:
            raise ParameterError(f"{where} {key!r} becomes the MATLAB field "
                                 f"{'.'.join(path)!r}, which is taken; rename it.")
        node[path[-1]] = value
    return tree


def mat_layout(variables, attributes):
    """The names and the structs of a MAT file of these variables and global attributes.

    Parameters
    ----------
    variables : mapping of str to mapping
        Every coordinate and variable, in order (coordinates first): name -> its CF
        attributes.
    attributes : mapping of str to object
        The global attributes (parameters with ``<name>_units``, ``none_parameters``, ...).

    Returns
    -------
    names : dict of str to str
        NetCDF name -> MATLAB name of every variable.
    structs : dict of str to object
        ``units``, ``variable_attributes``, ``parameters``, ``parameter_units``,
        ``attributes``, ``description`` and, if a name changed, ``netcdf_names``:
        dicts (structs), strings, numbers and arrays, ``None`` for ``[]``.

    Raises
    ------
    ParameterError
        Two names that become one MATLAB name, a variable named as one of
        :data:`RESERVED_NAMES`, or parameters whose sections collide.
    """
    names = _names(list(variables), "variables")
    taken = sorted(set(names.values()) & set(RESERVED_NAMES))
    if taken:
        raise ParameterError(f"variables {taken} have the names of the MAT file's structs "
                             f"{list(RESERVED_NAMES)}; rename them.")
    attributes = dict(attributes)
    none = set(str(attributes.get("none_parameters", "")).split())
    units = {k[:-len("_units")] for k in attributes
             if k.endswith("_units") and k[:-len("_units")] in attributes}
    companions = {f"{u}_units" for u in units}
    parameters = [k for k in attributes if k not in companions and ("." in k or k in units)]
    others = {k: v for k, v in attributes.items() if k not in companions and k not in parameters}
    values = {k: None if k in none else attributes[k] for k in parameters}
    structs = {
        "units": {names[n]: str(a.get("units", "")) for n, a in variables.items()},
        "variable_attributes": {names[n]: _struct({k: v for k, v in a.items() if k != "units"},
                                                  f"attributes of {n!r}")
                                for n, a in variables.items()},
        "parameters": _nested({k: _value(v) for k, v in values.items()}, "parameter"),
        "parameter_units": _nested({k: str(attributes.get(f"{k}_units", ""))
                                    for k in parameters}, "parameter"),
        "attributes": _struct(others, "global attributes"),
        "description": _description(attributes),
    }
    changed = {m: n for n, m in names.items() if m != n}
    if changed:
        structs["netcdf_names"] = changed
    return names, structs


def _description(attributes):
    title = str(attributes.get("title", "a result of qzs")).strip()
    return (f"{title}. Each variable is named as in the NetCDF file of qzs (1-D arrays are "
            "columns); its unit is units.<name>, its other attributes "
            "variable_attributes.<name>; the parameters are in parameters.<section>.<name> "
            "with their units in parameter_units.<section>.<name>; the other attributes "
            "(history, version, ...) in attributes.")


# -- MAT 5 -------------------------------------------------------------------------------
def _mat5(value):
    """A value as ``scipy.io.savemat`` writes it as MATLAB expects: None -> ``[]``,
    strings arrays -> cell arrays, structs recursively."""
    if value is None:
        return np.zeros((0, 0))
    if isinstance(value, dict):
        return {k: _mat5(v) for k, v in value.items()}
    if isinstance(value, np.ndarray) and value.dtype.kind in "UOS":
        cells = np.empty(value.shape, dtype=object)
        for index, text in np.ndenumerate(value):
            cells[index] = str(text)
        return cells
    return value


def _savemat(handle, name, value):
    """Append one variable to an open MAT 5 file (the header is written with the first)."""
    from scipy.io import savemat

    savemat(handle, {name: _mat5(value)}, long_field_names=True, do_compression=False,
            oned_as="column")


# -- MAT 7.3 -----------------------------------------------------------------------------
def _header73():
    """The 128 bytes MATLAB writes at the start of a MAT 7.3 file's 512-byte userblock."""
    from qzs._version import __version__

    text = (f"MATLAB 7.3 MAT-file, Platform: qzs {__version__} {sys.platform}, Created on: "
            f"{time.asctime()} HDF5 schema 1.00 .")
    return (text.encode("ascii", "replace")[:_HEADER_TEXT].ljust(_HEADER_TEXT, b" ")
            + b"\0" * 8 + b"\x00\x02" + b"IM")


def _string_attribute(target, name, text):
    """A scalar fixed-length ASCII string attribute (NULLTERM), as MATLAB writes ``MATLAB_class``.

    Written in the file's own type, so that HDF5 converts nothing (a conversion from
    numpy's null-padded strings would cut the last character to make room for a null).
    """
    import h5py

    kind = h5py.h5t.C_S1.copy()
    kind.set_size(len(text))
    attribute = h5py.h5a.create(target.id, name.encode("ascii"), kind,
                                h5py.h5s.create(h5py.h5s.SCALAR))
    attribute.write(np.array(text.encode("ascii"), dtype=f"S{len(text)}"), mtype=kind)


def _matlab_class(dtype):
    if dtype.kind == "b":
        return "logical"
    cls = _CLASSES.get(dtype.str[1:])
    if cls is None:
        raise ParameterError(f"values of type {dtype} cannot be written to a MAT file; "
                             f"the types are {sorted(_CLASSES.values())}, bool and strings.")
    return cls


def _h5_empty(parent, name, cls, shape=(0, 0)):
    """An empty MATLAB array: its dimensions as data, ``MATLAB_empty`` 1."""
    dataset = parent.create_dataset(name, data=np.array(shape, dtype=np.uint64))
    _string_attribute(dataset, "MATLAB_class", cls)
    dataset.attrs.create("MATLAB_empty", np.uint32(1))
    return dataset


def _h5_char(parent, name, text):
    """A MATLAB char row: uint16 codes, shape (length, 1) in HDF5 (1 x length in MATLAB)."""
    if not text:
        return _h5_empty(parent, name, "char")
    codes = np.frombuffer(text.encode("utf-16-le"), dtype="<u2")
    dataset = parent.create_dataset(name, data=codes.reshape(-1, 1))
    _string_attribute(dataset, "MATLAB_class", "char")
    dataset.attrs.create("MATLAB_int_decode", np.int32(2))
    return dataset


def _h5_cell(parent, name, strings):
    """A cell array of char: a dataset of references to chars in ``/#refs#``, transposed."""
    import h5py

    refs = parent.file.require_group("#refs#")
    shape = _matlab_shape(strings.shape)
    cells = strings.reshape(shape)
    table = np.empty(shape[::-1], dtype=h5py.ref_dtype)
    for index in np.ndindex(*shape):
        table[index[::-1]] = _h5_char(refs, f"c{len(refs)}", str(cells[index])).ref
    dataset = parent.create_dataset(name, data=table, dtype=h5py.ref_dtype)
    _string_attribute(dataset, "MATLAB_class", "cell")
    return dataset


def _h5_numeric_attributes(dataset, dtype):
    _string_attribute(dataset, "MATLAB_class", _matlab_class(dtype))
    if dtype.kind == "b":
        dataset.attrs.create("MATLAB_int_decode", np.int32(1))


def _matlab_shape(shape):
    """The shape MATLAB gives an array of numpy shape ``shape`` (1-D: a column)."""
    shape = tuple(int(n) for n in shape)
    return (1, 1) if not shape else (shape[0], 1) if len(shape) == 1 else shape


def _h5_array(parent, name, array):
    """A numeric or logical array, transposed (HDF5 row-major, MATLAB column-major)."""
    array = np.asarray(array)
    if array.size == 0:
        return _h5_empty(parent, name, _matlab_class(array.dtype), _matlab_shape(array.shape))
    data = array.reshape(_matlab_shape(array.shape)).T
    stored = data.astype(np.uint8) if array.dtype.kind == "b" else data
    dataset = parent.create_dataset(name, data=np.ascontiguousarray(stored))
    _h5_numeric_attributes(dataset, array.dtype)
    return dataset


def _h5_write(parent, name, value):
    """Write ``value`` (struct, text, strings, number, array, None) as MATLAB reads it."""
    if isinstance(value, dict):
        group = parent.create_group(name)
        _string_attribute(group, "MATLAB_class", "struct")
        if value:
            import h5py

            kind = h5py.vlen_dtype(np.dtype("S1"))
            fields = np.empty(len(value), dtype=kind)
            for i, field in enumerate(value):
                fields[i] = np.frombuffer(field.encode("ascii"), dtype="S1")
            group.attrs.create("MATLAB_fields", fields, dtype=kind)
        for field, item in value.items():
            _h5_write(group, field, item)
        return group
    if value is None:
        return _h5_empty(parent, name, "double")
    if isinstance(value, str):
        return _h5_char(parent, name, value)
    array = np.asarray(value)
    if array.dtype.kind in "UOS":
        return _h5_cell(parent, name, array)
    return _h5_array(parent, name, array)


def _write_header(path):
    with open(path, "r+b") as handle:
        handle.write(_header73())


def _open73(path):
    import h5py

    return h5py.File(path, "w", userblock_size=_USERBLOCK, libver="earliest")


# -- a dataset ---------------------------------------------------------------------------
def _variable_bytes(variable):
    return int(variable.size) * (variable.dtype.itemsize if variable.dtype.kind not in "UOS"
                                 else 8)


def write_mat(dataset, path, *, version=None, limit=None):
    """Write a result's dataset to a MATLAB file, atomically (layout: this module).

    Each variable is read from ``dataset`` on its own (a lazily opened store, such as a
    sweep's Zarr, is never loaded whole; a MAT 7.3 variable is copied in slabs).

    Parameters
    ----------
    dataset : xarray.Dataset
        The result (``to_xarray()``, a file read back, a sweep store opened lazily).
    path : str or Path
        The ``.mat`` file; its folder is created if missing.
    version : {None, "5", "7.3"}
        None: MAT 5 unless a variable holds more than ``limit`` bytes, then MAT 7.3.
    limit : int, optional
        The largest variable of a MAT 5 file [bytes]; default :data:`MAT5_LIMIT` (2 GiB).

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        An unknown ``version``, MAT 5 asked for a variable above ``limit`` (the message
        says how to split it), names that collide in MATLAB, or values of a type MATLAB
        files do not hold.
    OutputPathError
        ``path`` does not end in ``.mat`` or cannot be written.
    WriteError
        Writing failed (disk full, permissions; attributes ``path`` and ``reason``);
        nothing is left behind.
    """
    from qzs.iotools.paths import check_output_path

    if version is not None and str(version) not in MAT_VERSIONS:
        raise ParameterError(f"`version` must be one of {list(MAT_VERSIONS)} or None "
                             f"(chosen by size), got {version!r}.")
    limit = MAT5_LIMIT if limit is None else int(limit)
    path = check_output_path(path, argument="path", suffixes=(".mat",))
    order = [*dataset.coords, *dataset.data_vars]
    names, structs = mat_layout({n: dict(dataset[n].attrs) for n in order}, dataset.attrs)
    large = [n for n in order if _variable_bytes(dataset.variables[n]) + _ELEMENT_OVERHEAD > limit]
    if version is None:
        version = "7.3" if large else "5"
    if str(version) == "5" and large:
        name = large[0]
        dims = dataset.variables[name].dims
        raise ParameterError(
            f"variable {name!r} holds {_variable_bytes(dataset.variables[name])} bytes, more "
            f"than MAT 5's {limit} per variable; write MAT 7.3 (`version` None or '7.3'), or "
            f"split the dataset along {dims[0]!r} (e.g. dataset.isel({dims[0]}=slice(0, n)))"
            " into files that fit.")
    try:
        with atomic_path(path) as tmp:
            if str(version) == "5":
                with open(tmp, "wb") as handle:
                    for name in order:
                        _savemat(handle, names[name], _values_of(dataset.variables[name]))
                    for name, value in structs.items():
                        _savemat(handle, name, value)
            else:
                with _open73(tmp) as handle:
                    for name in order:
                        _h5_variable(handle, names[name], dataset.variables[name])
                    for name, value in structs.items():
                        _h5_write(handle, name, value)
                _write_header(tmp)
    except (OSError, RuntimeError) as error:
        raise _write_error(path, error) from None
    return path


def _h5_variable(handle, name, variable):
    """A variable of a dataset into a MAT 7.3 file; a large numeric one in slabs."""
    if variable.dtype.kind in "OSU" or variable.ndim == 0 or variable.size == 0 or \
            _variable_bytes(variable) <= _SLAB:
        return _h5_write(handle, name, _values_of(variable))
    shape = _matlab_shape(variable.shape)
    stored = np.uint8 if variable.dtype.kind == "b" else variable.dtype
    dataset = handle.create_dataset(name, shape=shape[::-1], dtype=stored)
    _h5_numeric_attributes(dataset, variable.dtype)
    rows = max(1, _SLAB // max(1, _variable_bytes(variable) // shape[0]))
    for start in range(0, shape[0], rows):
        block = np.asarray(variable[start:start + rows].values)
        dataset[..., start:start + block.shape[0]] = block.reshape(
            (block.shape[0], *shape[1:])).T.astype(stored)
    return dataset


def _values_of(variable):
    """A dataset variable's values as MATLAB gets them: flags bool, strings objects."""
    values = np.asarray(variable.values)
    if values.dtype.kind in "OSU":
        return values.astype(object)
    return values != 0 if is_flag(variable.attrs) and values.dtype.kind != "b" else values


def is_flag(attributes):
    """True for a 0/1 flag (CF ``flag_values`` 0 and 1): MATLAB ``logical``.

    Parameters
    ----------
    attributes : mapping
        A variable's CF attributes.

    Returns
    -------
    bool
    """
    values = attributes.get("flag_values")
    return values is not None and sorted(np.ravel(values).tolist()) == [0, 1]


# -- a streamed run ----------------------------------------------------------------------
class MatStream:
    """A MATLAB file grown chunk by chunk: MAT 7.3 while streaming, MAT 5 at the end if it fits.

    What :class:`~qzs.iotools.writer.StreamWriter` writes a ``.mat`` file through. The
    variables along the schema's unlimited dimension are resizable HDF5 datasets (chunks
    of ``schema.chunk_rows`` samples), appended to in MATLAB's orientation; the others
    (labels) are kept and written at the end. Memory grows with the appended block.

    Parameters
    ----------
    path : str or Path
        The file to grow (a temporary file; the caller renames it).
    schema : Schema
        What the file holds (one dimension of unlimited length).
    values : mapping of str to array_like
        The values of the variables not along the unlimited dimension.

    Raises
    ------
    ParameterError
        Names that collide in MATLAB, or strings along the unlimited dimension.
    """

    def __init__(self, path, schema, values):
        self.path = Path(path)
        self.schema = schema
        self._names, _ = self.layout({})  # names checked before anything is written
        self._values = {v.name: _flag(v, v.cast(values[v.name])) for v in schema
                        if v.name in values}
        self._rows = 0
        self._dtypes = {}
        for variable in schema.streamed():
            if variable.dtype == "str":
                raise ParameterError(f"variable {variable.name!r} of {schema.kind} is strings "
                                     "along the streamed dimension; a .mat file streams "
                                     "numbers only.")
            self._dtypes[variable.name] = np.dtype(bool if is_flag(variable.attrs())
                                                   else variable.cast([]).dtype)
        self._file = _open73(self.path)
        self._datasets = {}
        for variable in schema.streamed():
            width = tuple(schema.dimensions[d] for d in variable.dims[1:])[::-1] or (1,)
            dtype = self._dtypes[variable.name]
            self._datasets[variable.name] = self._file.create_dataset(
                self._names[variable.name], shape=(*width, 0), maxshape=(*width, None),
                chunks=(*width, schema.chunk_rows),
                dtype=np.uint8 if dtype.kind == "b" else dtype)

    def append(self, name, values, start, stop):
        """Write the samples ``start:stop`` of variable ``name``.

        Parameters
        ----------
        name : str
            A streamed variable of the schema.
        values : ndarray, shape (stop - start, ...)
            Its samples, in the variable's own units.
        start : int
            Where they start along the unlimited dimension [samples].
        stop : int
            Where they end (exclusive) [samples].
        """
        dataset, dtype = self._datasets[name], self._dtypes[name]
        if dataset.shape[-1] < stop:
            dataset.resize(stop, axis=dataset.ndim - 1)
        block = np.asarray(values)
        block = (block != 0) if dtype.kind == "b" else block.astype(dtype, copy=False)
        dataset[..., start:stop] = block.T
        self._rows = max(self._rows, stop)

    def flush(self):
        """Flush the HDF5 file's buffers to disk."""
        self._file.flush()

    def layout(self, attributes):
        """:func:`mat_layout` of this file with these global attributes.

        Parameters
        ----------
        attributes : mapping
            The global attributes.

        Returns
        -------
        (dict, dict)
        """
        return mat_layout({v.name: v.attrs() for v in self.schema}, attributes)

    def largest_variable(self):
        """The bytes of the largest variable written so far [bytes]."""
        sizes = [self._rows * int(np.prod(self._datasets[n].shape[:-1])) * d.itemsize
                 for n, d in self._dtypes.items()]
        sizes += [v.size * (8 if v.dtype.kind in "OUS" else v.itemsize)
                  for v in map(np.asarray, self._values.values())]
        return max(sizes, default=0)

    def finish(self, attributes, *, version=None, limit=None):
        """Close the file as MAT 7.3, or convert it to MAT 5 (same path) if it fits.

        Parameters
        ----------
        attributes : mapping
            The global attributes (parameters, history, ...).
        version : {None, "5", "7.3"}
            None: MAT 5 unless a variable holds more than ``limit`` bytes.
        limit : int, optional
            The largest variable of a MAT 5 file [bytes]; default :data:`MAT5_LIMIT`.

        Returns
        -------
        str
            The version written, ``"5"`` or ``"7.3"``.
        """
        limit = MAT5_LIMIT if limit is None else int(limit)
        names, structs = self.layout(attributes)
        if version is None:
            version = "7.3" if self.largest_variable() + _ELEMENT_OVERHEAD > limit else "5"
        if str(version) == "5":
            self.close()
            self._convert(names, structs)
            return "5"
        handle = self._file
        for name, dtype in self._dtypes.items():
            if self._rows == 0:  # MATLAB's empty arrays hold their dimensions instead
                del handle[names[name]]
                _h5_empty(handle, names[name], _matlab_class(dtype), (0, 1))
            else:
                _h5_numeric_attributes(self._datasets[name], dtype)
        for name, value in self._values.items():
            _h5_write(handle, names[name], value)
        for name, value in structs.items():
            _h5_write(handle, name, value)
        self.close()
        _write_header(self.path)
        return "7.3"

    def _convert(self, names, structs):
        """Rewrite the streamed MAT 7.3 file as MAT 5, one variable in memory at a time."""
        import h5py

        fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".mat5",
                                   dir=self.path.parent)
        try:
            with os.fdopen(fd, "wb") as out, h5py.File(self.path, "r") as spool:
                for variable in self.schema:
                    if variable.name in self._values:
                        value = self._values[variable.name]
                    else:
                        value = spool[names[variable.name]][()].T
                        if self._dtypes[variable.name].kind == "b":
                            value = value.astype(bool)
                        if len(variable.dims) == 1:
                            value = value[:, 0]
                    _savemat(out, names[variable.name], value)
                for name, value in structs.items():
                    _savemat(out, name, value)
                out.flush()
                os.fsync(out.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise

    def close(self):
        """Close the HDF5 file (idempotent); the caller removes or renames it."""
        handle, self._file = self._file, None
        self._datasets = {}
        if handle is not None:
            handle.close()


def _flag(variable, values):
    """A flag's values as bool (MATLAB ``logical``); others unchanged."""
    return np.asarray(values) != 0 if is_flag(variable.attrs()) else values
