"""The NetCDF file layout: a result's dataset as CF-1.10 reads it, and back.

What qzs keeps in memory does not always have a CF spelling; a NetCDF file holds the same
content in CF's own means (docs/model.md, decision 34), as the IOOS compliance checker
(``compliance-checker --test=cf:1.10``) reads it:

- **Parameters**: dotted global attributes (``isolator.mass``) become the attributes of a
  *container variable* (``isolator``, a scalar int8), since CF attribute names have no dots;
  a dotted variable name (a batch's coordinate ``compensation.fraction``) is written with
  ``__`` for each dot (``compensation__fraction``).
- **Elapsed time**: a dimension named ``time`` is, to CF, a calendar time (units
  ``"<unit> since <date>"``); a run's time has no date, so the file names it
  ``elapsed_time`` (plain seconds, no ``standard_name``).
- **Mixed units**: a variable over a six-axis dimension (``dof``, ``output_dof``,
  ``input_dof``: x, y, z [m] then rx, ry, rz [rad]) whose unit differs between translations
  and rotations is stored as one variable per unit: ``<name>_translation`` and
  ``<name>_rotation`` on the dimensions ``translation`` and ``rotation`` (``output_...``,
  ``input_...`` for a matrix, four blocks), each with its one unit.
- **Units UDUNITS cannot spell**: ``dB/decade`` is written ``0.05`` (a value in dB per
  decade is twenty times the dimensionless log-log slope ``d ln T / d ln f``), the
  in-memory unit kept in ``units_as_shown``.
- **Labels**: a string coordinate named as its dimension is a character array on
  ``<name>_strlen``; coordinates carry no ``_FillValue``.

:func:`to_file_layout` makes a dataset's file form, :func:`file_schema` a streamed
schema's, and :func:`from_file_layout` reads either back to what ``to_xarray()`` gives.
"""
from dataclasses import replace

import numpy as np

__all__ = ["CONTAINERS", "FILE_DIMENSIONS", "FILE_UNITS", "container_attributes", "file_name",
           "to_file_layout", "from_file_layout", "file_schema", "split_parts"]

#: The global attribute of a file that lists its container variables (docs/model.md,
#: decision 34): scalar variables whose attributes hold a group of parameters
#: (``isolator``: ``mass``, ``mass_units``, ...), since CF attribute names have no dots.
CONTAINERS = "parameter_containers"
#: Dimensions renamed in a file: memory name -> file name.
FILE_DIMENSIONS = {"time": "elapsed_time"}
#: Units UDUNITS cannot parse, as written in a file: memory unit -> (file unit, why).
FILE_UNITS = {"dB/decade": ("0.05", "dB per decade of frequency, 20 log10 of the ratio per "
                                    "log10 of the frequency: 20 times the dimensionless "
                                    "log-log slope d ln T / d ln f, hence the unit 0.05")}
#: The six-axis dimensions and the two halves each is split into where units differ.
_DOF_DIMENSIONS = ("dof", "output_dof", "input_dof")
_HALVES = (("translation", slice(0, 3)), ("rotation", slice(3, 6)))
#: The attributes that tie a part of a split variable to its whole.
_PART_OF, _WHOLE_UNITS, _WHOLE_DIMS, _SHOWN = ("part_of", "units_of_whole", "dims_of_whole",
                                               "units_as_shown")


def _half_dimension(dim, half):
    """The file dimension of one half of a six-axis dimension (``dof`` -> ``rotation``)."""
    return half if dim == "dof" else dim.replace("dof", half)


def _half_coordinates(dim, labels, present):
    """The label coordinates of ``dim``'s halves that are dimensions of the file (``present``):
    ``(name, labels, long_name)`` each, the one description of both file paths."""
    for half, where in _HALVES:
        name = _half_dimension(dim, half)
        if name in present:
            part = [str(label) for label in list(labels)[where]]
            yield name, part, f"{half} part of {dim}: {', '.join(part)}"


def _units_by_dof(attrs):
    """The six per-axis units of a variable's ``units_by_dof`` ("x: m; ...") or None."""
    text = attrs.get("units_by_dof")
    if not isinstance(text, str):
        return None
    units = [item.partition(":")[2].strip() for item in text.split(";")]
    return units if len(units) == 6 else None


def split_parts(name, dims, attrs, entry_units=None):
    """How a variable of mixed units is stored: one part per unit, or None if it has one.

    Parameters
    ----------
    name : str
        The variable.
    dims : tuple of str
        Its dimensions.
    attrs : mapping
        Its attributes: ``units_by_dof`` gives a one-axis variable's six units;
        ``units_by_entry`` names the variable that gives a matrix's 36 (``entry_units``).
    entry_units : callable, optional
        Name -> the 6x6 unit of each entry of a matrix over ``(output_dof, input_dof)``
        (the dataset's variable ``attrs["units_by_entry"]``).

    Returns
    -------
    list of (str, tuple, tuple, str) or None
        Per part: its name, its dimensions, the index of its block in the whole (a tuple
        of slices, one per dimension) and its unit; None for a variable of one unit.
    """
    six = [d for d in dims if d in _DOF_DIMENSIONS]
    if not six:
        return None
    if len(six) == 1:
        units = _units_by_dof(attrs)
        if units is None or len(set(units)) == 1:
            return None
        block_units = {(half,): units[where.start] for half, where in _HALVES}
    elif len(six) == 2 and entry_units is not None and "units_by_entry" in attrs:
        table = np.asarray(entry_units(attrs["units_by_entry"]), dtype=str)
        if len(set(table.ravel())) == 1:
            return None
        block_units = {(a, b): str(table[wa.start, wb.start])
                       for a, wa in _HALVES for b, wb in _HALVES}
    else:
        return None
    halves = dict(_HALVES)
    parts = []
    for key, unit in block_units.items():
        by_dim = dict(zip(six, key))
        part_dims = tuple(_half_dimension(d, by_dim[d]) if d in by_dim else d for d in dims)
        index = tuple(halves[by_dim[d]] if d in by_dim else slice(None) for d in dims)
        parts.append((f"{name}_{'_per_'.join(key)}", part_dims, index, unit))
    return parts


def container_attributes(attrs):
    """Split global attributes into CF-legal ones and container variables' attributes.

    A key ``section.name`` (``isolator.mass``, ``run.dt_units``) becomes the attribute
    ``name`` of the container ``section`` (further dots become ``__``); the other keys stay
    global. CF attribute names are letters, digits and underscores (CF §2.3).

    Parameters
    ----------
    attrs : mapping of str to object
        Global attributes as qzs keeps them in memory (dotted keys).

    Returns
    -------
    (dict, dict of str to dict)
        The global attributes without dotted keys (with :data:`CONTAINERS` listing the
        containers, if any), and container name -> its attributes.
    """
    plain, containers = {}, {}
    for key, value in attrs.items():
        section, dot, name = str(key).partition(".")
        if dot and section and name:
            containers.setdefault(section, {})[file_name(name)] = value
        else:
            plain[key] = value
    if containers:
        plain[CONTAINERS] = " ".join(containers)
    return plain, containers


def file_name(name):
    """A variable's name in a file: each dot as ``__`` (``compensation.fraction`` ->
    ``compensation__fraction``), since CF names are letters, digits and underscores (§2.3);
    :func:`from_file_layout` gives the dots back.

    Parameters
    ----------
    name : str
        The name in memory.

    Returns
    -------
    str
    """
    return str(name).replace(".", "__")


def container_long_name(section):
    """The ``long_name`` of the container variable of ``section``'s parameters."""
    return (f"container of the {section} parameters: each attribute is one, with its unit "
            "in <name>_units")


def _history_line():
    """A CF ``history`` line for a file whose dataset has none: when and by which qzs."""
    import datetime

    from qzs._version import __version__

    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    return f"{now} qzs {__version__}: written"


def _file_units(attrs):
    """``attrs`` with a unit UDUNITS cannot parse replaced by its file spelling."""
    unit = attrs.get("units")
    if isinstance(unit, str) and unit in FILE_UNITS:
        spelled, why = FILE_UNITS[unit]
        return {**attrs, "units": spelled, _SHOWN: unit, "units_meaning": why}
    return dict(attrs)


def _part_attributes(attrs, dims, unit):
    """A part's attributes, in its whole's order: its own unit, then what ties it to its
    whole (``part_of`` is filled in by the caller)."""
    part = {key: (unit if key == "units" else value) for key, value in attrs.items()}
    part.setdefault("units", unit)
    return {**part, _PART_OF: None, _WHOLE_UNITS: attrs.get("units", ""),
            _WHOLE_DIMS: " ".join(dims)}


def to_file_layout(dataset):
    """A dataset as qzs writes it to NetCDF: CF-1.10 as the compliance checker reads it.

    Dotted global attributes go to container variables (:func:`container_attributes`);
    a dotted variable name gets ``__`` for its dots (:func:`file_name`);
    ``time`` becomes ``elapsed_time``; a variable of mixed units becomes one variable per
    unit (:func:`split_parts`); a unit UDUNITS cannot parse gets its file spelling
    (:data:`FILE_UNITS`); coordinates get no ``_FillValue`` and a string coordinate named
    as its dimension is stored as a character array (the encoding returned); a dataset
    without ``Conventions`` or ``history`` gets them (a sweep's ``title`` from its
    ``sweep_title``). :func:`from_file_layout` undoes all of it.

    Parameters
    ----------
    dataset : xarray.Dataset
        A result's dataset (:func:`qzs.iotools.schema.to_dataset`).

    Returns
    -------
    (xarray.Dataset, dict)
        The dataset to write and its ``encoding`` for ``to_netcdf``.
    """
    import xarray as xr

    from qzs.iotools.schema import CONVENTIONS

    plain, containers = container_attributes(dataset.attrs)
    out = dataset.copy()
    out.attrs = {"Conventions": CONVENTIONS, **plain}
    if "title" not in out.attrs and "sweep_title" in out.attrs:  # as export_sweep titles it
        out.attrs["title"] = (f"qzs sweep {out.attrs.get('sweep_name', '')}: "
                              f"{out.attrs['sweep_title']}")
    out.attrs.setdefault("history", _history_line())
    for name in out.variables:  # CF: flag_values of the flag's own type
        if "flag_values" in out[name].attrs and out[name].dtype.kind in "iu":
            out[name].attrs["flag_values"] = np.asarray(out[name].attrs["flag_values"],
                                                        dtype=out[name].dtype)
        out[name].attrs = _file_units(out[name].attrs)
    entry_units = lambda name: out[name].values  # noqa: E731
    data = {}  # the parts of a variable of mixed units in its place
    for name in list(out.data_vars):
        variable = out[name]
        parts = split_parts(name, variable.dims, variable.attrs, entry_units)
        if parts is None:
            data[name] = variable.variable
            continue
        for part, dims, index, unit in parts:
            attrs = _part_attributes(variable.attrs, variable.dims, unit)
            attrs[_PART_OF] = name
            data[part] = xr.Variable(dims, variable.values[index], attrs)
    out = xr.Dataset(data, coords=out.coords, attrs=out.attrs)
    for dim in _DOF_DIMENSIONS:  # the halves' labels
        if dim in out.coords:
            for name, labels, long_name in _half_coordinates(dim, out[dim].values, out.dims):
                out = out.assign_coords({name: (name, np.array(labels, dtype=object), {
                    "long_name": long_name, "units": "1"})})
    for section, attrs in containers.items():
        out[section] = xr.DataArray(np.int8(0), attrs={
            "long_name": container_long_name(section), **attrs})
    out = out.rename({k: v for k, v in FILE_DIMENSIONS.items() if k in out.variables})
    out = out.rename({name: file_name(name) for name in out.variables if "." in name})
    encoding = {name: {"_FillValue": None} for name in out.coords
                if out[name].dtype.kind in "fc"}
    for name in out.coords:  # CF allows no 1-D string variable named as its dimension
        if name in out.dims and out[name].dtype.kind in "OUS":
            encoding[name] = {"dtype": "S1", "char_dim_name": f"{name}_strlen"}
    return out, encoding


def file_schema(schema, columns, values):
    """A streamed schema's file form: :func:`to_file_layout`'s layout, chunk by chunk.

    Parameters
    ----------
    schema : Schema
        What the stream holds in memory.
    columns : mapping of str to (str, int or slice)
        Where each streamed variable's values are: block name and column(s).
    values : mapping of str to array_like
        The values of the schema's fixed variables (coordinates such as ``dof``).

    Returns
    -------
    (Schema, dict, dict)
        The file's schema (dimensions renamed, variables of mixed units split, the halves'
        label coordinates added), and its ``columns`` and ``values``.
    """
    from qzs.iotools.schema import Variable

    rename = lambda dim: FILE_DIMENSIONS.get(dim, dim)  # noqa: E731
    dimensions = {rename(d): n for d, n in schema.dimensions.items()}
    file_columns, file_values, variables = {}, {}, []
    for variable in schema.variables:
        attrs = variable.attrs()
        parts = split_parts(variable.name, variable.dims, attrs)
        if parts is None:
            variables.append(replace(variable, dims=tuple(map(rename, variable.dims))))
            if variable.name in columns:
                file_columns[variable.name] = columns[variable.name]
            continue
        block, column = columns[variable.name]
        for part, dims, index, unit in parts:
            dimensions.update({d: 3 for d in dims if d not in dimensions})
            part_attrs = _part_attributes(attrs, variable.dims, unit)
            part_attrs[_PART_OF] = variable.name
            reserved = ("units", "long_name", "flag_values", "flag_meanings")
            variables.append(Variable(
                name=part, dims=tuple(map(rename, dims)), units=unit,
                long_name=variable.long_name, dtype=variable.dtype,
                flag_meanings=variable.flag_meanings,
                attributes={k: v for k, v in part_attrs.items() if k not in reserved},
                order=tuple(part_attrs)))
            last = index[-1]
            file_columns[part] = (block, slice(column.start + last.start,
                                               column.start + last.stop))
    coordinates = []
    for coordinate in schema.coordinates:
        name = rename(coordinate.name)
        coordinates.append(replace(coordinate, name=name, dims=tuple(map(rename,
                                                                         coordinate.dims))))
        if coordinate.name in values:
            file_values[name] = values[coordinate.name]
        if coordinate.name in columns:
            file_columns[name] = columns[coordinate.name]
        if coordinate.name in _DOF_DIMENSIONS and coordinate.name in values:
            for half_dim, labels, long_name in _half_coordinates(
                    coordinate.name, values[coordinate.name], dimensions):
                coordinates.append(Variable(name=half_dim, dims=(half_dim,), units="1",
                                            dtype=coordinate.dtype, long_name=long_name,
                                            order=("long_name", "units")))
                file_values[half_dim] = labels
    for variable in schema.variables:
        if variable.name in values:
            file_values[variable.name] = values[variable.name]
    return (replace(schema, dimensions=dimensions, coordinates=tuple(coordinates),
                    variables=tuple(variables)), file_columns, file_values)


def from_file_layout(dataset):
    """The inverse of :func:`to_file_layout`: the dataset ``to_xarray()`` gives.

    Containers back to dotted global attributes, ``__`` in a variable's name back to a
    dot, ``elapsed_time`` back to ``time``, the
    parts of a variable of mixed units joined, units back to their in-memory spelling.

    Parameters
    ----------
    dataset : xarray.Dataset
        A NetCDF file of qzs as xarray reads it.

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    sections = str(dataset.attrs.get(CONTAINERS, "")).split()
    attrs = {k: v for k, v in dataset.attrs.items() if k != CONTAINERS}
    for section in sections:
        if section in dataset.variables:
            for name, value in dataset[section].attrs.items():
                if name != "long_name":
                    attrs[f"{section}.{name.replace('__', '.')}"] = value
    dataset = dataset.drop_vars([s for s in sections if s in dataset.variables])
    dataset.attrs = attrs
    dataset = dataset.rename({v: k for k, v in FILE_DIMENSIONS.items()
                              if v in dataset.variables or v in dataset.dims})
    dataset = dataset.rename({name: str(name).replace("__", ".") for name in dataset.variables
                              if "__" in str(name)})
    wholes, names = {}, list(dataset.data_vars)
    for name in names:
        whole = dataset[name].attrs.get(_PART_OF)
        if whole is not None:
            wholes.setdefault(str(whole), []).append(name)
    for whole, parts in wholes.items():
        first = dataset[parts[0]]
        dims = tuple(str(first.attrs[_WHOLE_DIMS]).split())
        shape = tuple(dataset.sizes[d] for d in dims)
        values = np.empty(shape, dtype=first.dtype)
        halves = dict(_HALVES)
        for part in parts:
            variable = dataset[part]
            index = []
            for dim, part_dim in zip(dims, variable.dims):
                half = next((h for h in halves if part_dim == _half_dimension(dim, h)
                             and dim in _DOF_DIMENSIONS), None)
                index.append(halves[half] if half is not None and part_dim != dim
                             else slice(None))
            values[tuple(index)] = variable.values
        whole_attrs = {k: (first.attrs[_WHOLE_UNITS] if k == "units" else v)
                       for k, v in first.attrs.items()
                       if k not in (_PART_OF, _WHOLE_UNITS, _WHOLE_DIMS)}
        dataset = dataset.drop_vars(parts)
        dataset[whole] = xr.Variable(dims, values, whole_attrs)
    if wholes:  # each whole where its first part was
        first_part = {parts[0]: whole for whole, parts in wholes.items()}
        every_part = {part for parts in wholes.values() for part in parts}
        order = [first_part.get(name, name) for name in names if name not in every_part
                 or name in first_part]
        dataset = dataset[order + [n for n in dataset.data_vars if n not in order]]
    halves = [_half_dimension(d, h) for d in _DOF_DIMENSIONS for h, _ in _HALVES]
    dataset = dataset.drop_vars([h for h in halves if h in dataset.variables])
    for name in dataset.variables:
        shown = dataset[name].attrs.get(_SHOWN)
        if shown is not None:
            dataset[name].attrs = {k: (shown if k == "units" else v)
                                   for k, v in dataset[name].attrs.items()
                                   if k not in (_SHOWN, "units_meaning")}
    return dataset
