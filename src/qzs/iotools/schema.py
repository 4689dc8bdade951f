"""The file schema: what a result's dataset and file hold, declared once.

A :class:`Schema` names a result's dimensions (the one sized ``None`` is the unlimited
dimension a run is streamed along), its coordinates and its data variables; a
:class:`Variable` gives one variable's dimensions, units, long name, stored type (float64,
an int8 flag, an int64 count or a string), flag meanings and further CF attributes.
:func:`to_dataset` builds a result's ``xarray.Dataset`` from its schema and its arrays, and
:class:`~qzs.iotools.writer.StreamWriter` writes the same layout to a file chunk by chunk,
so that ``to_xarray()`` and a streamed file cannot drift apart. Each result type declares
its schema next to its class (``simulation_schema()`` in :mod:`qzs.engine.channels`,
``hexapod_schema()``, ``batch_schema(...)``, ``response_schema(...)``, ...); this module
knows none of them.

>>> schema = Schema(kind="a toy run", dimensions={"time": None}, coordinates=(
...     time_coordinate(),), variables=(
...     Variable(name="x", dims=("time",), units="m", long_name="position"),
...     Variable(name="stuck", dims=("time",), units="1", long_name="held",
...              dtype="int8", flag_meanings="free stuck")))
>>> to_dataset(schema, {"time": [0.0, 0.1], "x": [1.0, 2.0], "stuck": [False, True]},
...            {"title": "toy"})["stuck"].dtype
dtype('int8')
"""
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Mapping

import numpy as np

from qzs.errors import ParameterError

__all__ = ["Variable", "Schema", "to_dataset", "time_coordinate", "CONVENTIONS", "DTYPES",
           "FLAG_VALUES", "NONE_VALUE"]

#: The metadata conventions of every dataset and file of qzs (docs/model.md §7).
CONVENTIONS = "CF-1.10"
#: How a parameter whose value is ``None`` is stored (NetCDF has no null); the keys stored
#: so are listed in the global attribute ``none_parameters``.
NONE_VALUE = "none"
#: The stored types a variable may have: name -> numpy type.
DTYPES = MappingProxyType({"float64": np.float64, "int8": np.int8, "int64": np.int64,
                           "str": np.str_})
#: The values of every flag (CF ``flag_values``): 0 and 1, int8.
FLAG_VALUES = (0, 1)
_RESERVED = ("units", "long_name", "flag_values", "flag_meanings")
@dataclass(frozen=True, kw_only=True)
class Variable:
    """One variable of a result: dimensions, units, description, stored type, flags.

    Parameters
    ----------
    name : str
        The variable's name in the dataset and the file.
    dims : tuple of str
        Its dimensions, names of the schema's ``dimensions``.
    units : str, optional
        CF ``units`` ("1" for a ratio, a count or a flag); None: no ``units`` attribute.
    long_name : str, optional
        CF ``long_name``; None: no ``long_name`` attribute.
    dtype : {"float64", "int8", "int64", "str"}
        The stored type: float64 values, an int8 flag (or a small integer), an int64
        count, or strings.
    flag_meanings : str, optional
        The words for the values 0 and 1 (CF ``flag_meanings``, e.g. ``"free stuck"``);
        makes the variable a flag (``dtype`` "int8", ``flag_values`` 0 and 1).
    attributes : mapping of str to object, optional
        Further CF attributes (``standard_name``, ``axis``, ``comment``, ...).
    order : tuple of str, optional
        The order the attributes are written in, when it is not the default (``units``,
        ``long_name``, the further ``attributes``, ``flag_values``, ``flag_meanings``);
        it names every attribute the variable has.

    Raises
    ------
    ParameterError
        An unknown ``dtype``, flag meanings on a variable that is not int8, an attribute
        given twice, or an ``order`` that does not name exactly the variable's attributes.
    """

    name: str
    dims: tuple
    units: str | None = None
    long_name: str | None = None
    dtype: str = "float64"
    flag_meanings: str | None = None
    attributes: Mapping = field(default_factory=dict)
    order: tuple = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ParameterError(f"`name` of a Variable must be a non-empty string, got "
                                 f"{self.name!r}.")
        dims = (self.dims,) if isinstance(self.dims, str) else tuple(self.dims)
        object.__setattr__(self, "dims", dims)
        if self.dtype not in DTYPES:
            raise ParameterError(f"`dtype` of variable {self.name!r} must be one of "
                                 f"{list(DTYPES)}, got {self.dtype!r}.")
        if self.flag_meanings is not None and self.dtype != "int8":
            raise ParameterError(f"variable {self.name!r} has flag meanings, so its `dtype` "
                                 f"must be 'int8', got {self.dtype!r}.")
        twice = sorted(set(self.attributes) & set(_RESERVED))
        if twice:
            raise ParameterError(f"`attributes` of variable {self.name!r} repeat {twice}; "
                                 "give them as the fields of that name.")
        object.__setattr__(self, "attributes", MappingProxyType(dict(self.attributes)))
        object.__setattr__(self, "order", tuple(self.order))
        if self.order and sorted(self.order) != sorted(self._attributes()):
            raise ParameterError(f"`order` of variable {self.name!r} must name each of its "
                                 f"attributes {sorted(self._attributes())} once, got "
                                 f"{list(self.order)}.")

    @property
    def is_flag(self):
        """True for a flag (int8 0/1 with ``flag_values`` and ``flag_meanings``)."""
        return self.flag_meanings is not None

    def _attributes(self):
        attrs = {}
        if self.units is not None:
            attrs["units"] = self.units
        if self.long_name is not None:
            attrs["long_name"] = self.long_name
        attrs.update(self.attributes)
        if self.is_flag:
            attrs["flag_values"] = np.array(FLAG_VALUES, dtype=np.int8)
            attrs["flag_meanings"] = self.flag_meanings
        return attrs

    def attrs(self):
        """The variable's CF attributes, in the order they are written.

        Returns
        -------
        dict of str to object
        """
        attrs = self._attributes()
        return {key: attrs[key] for key in self.order} if self.order else attrs

    def cast(self, values, *, boolean_flags=False):
        """``values`` as an array of the stored type (flags int8 0/1, counts int64).

        Parameters
        ----------
        values : array_like
            The variable's values.
        boolean_flags : bool
            Keep a flag boolean (a result's dataset in memory) instead of int8.

        Returns
        -------
        ndarray
        """
        if self.dtype == "str":
            return np.asarray(values, dtype=str)
        if boolean_flags and self.is_flag:
            return np.asarray(values, dtype=bool)
        values = np.asarray(values)
        dtype = DTYPES[self.dtype]
        return values if values.dtype == dtype else values.astype(dtype)


def time_coordinate(name="time"):
    """The ``time`` coordinate of a run: plain seconds since its start (docs/model.md §7).

    Elapsed time, not an instant: no ``standard_name = "time"`` and no ``axis = "T"``, which
    in CF mark a calendar time (``"<unit> since <date>"``); a NetCDF file names it
    ``elapsed_time`` (:mod:`qzs.iotools.cf_layout`, docs/model.md decision 34).

    Parameters
    ----------
    name : str
        Its name and dimension.

    Returns
    -------
    Variable
    """
    return Variable(name=name, dims=(name,), units="s", long_name="time since the start of the run",
                    attributes={"comment": "elapsed run time without a calendar date; a NetCDF "
                                           "file names it elapsed_time (docs/model.md, "
                                           "decision 34)"},
                    order=("units", "long_name", "comment"))


@dataclass(frozen=True, kw_only=True)
class Schema:
    """What a result's dataset and file hold: dimensions, coordinates, variables, in order.

    Parameters
    ----------
    kind : str
        What the file holds, for messages (``"a run"``, ``"a hexapod run"``).
    dimensions : mapping of str to int or None
        Every dimension with its size; None for one whose length is the data's (the
        unlimited dimension a run is streamed along; at most one).
    coordinates : tuple of Variable
        The coordinates, in order.
    variables : tuple of Variable
        The data variables, in order.
    chunk_rows : int
        Samples per HDF5 chunk along the unlimited dimension [samples] (a streamed file).
    header_bytes : int
        An upper estimate of a file's header, coordinates and attributes [bytes].

    Raises
    ------
    ParameterError
        A name given twice, a variable on an undeclared dimension, or more than one
        dimension of unlimited length.
    """

    kind: str
    dimensions: Mapping
    coordinates: tuple = ()
    variables: tuple = ()
    chunk_rows: int = 4096
    header_bytes: int = 128 << 10

    def __post_init__(self):
        object.__setattr__(self, "dimensions", MappingProxyType(dict(self.dimensions)))
        object.__setattr__(self, "coordinates", tuple(self.coordinates))
        object.__setattr__(self, "variables", tuple(self.variables))
        names = [v.name for v in self]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ParameterError(f"the schema of {self.kind} names {twice} more than once.")
        for variable in self:
            unknown = [d for d in variable.dims if d not in self.dimensions]
            if unknown:
                raise ParameterError(f"variable {variable.name!r} of {self.kind} is on "
                                     f"undeclared dimension(s) {unknown}; the dimensions are "
                                     f"{list(self.dimensions)}.")
        if sum(size is None for size in self.dimensions.values()) > 1:
            raise ParameterError(f"the schema of {self.kind} has more than one dimension of "
                                 f"unlimited length: {dict(self.dimensions)}.")

    def __iter__(self):
        return iter(self.coordinates + self.variables)

    def __getitem__(self, name):
        for variable in self:
            if variable.name == name:
                return variable
        raise KeyError(f"{self.kind} has no variable {name!r}; it has {self.names}.")

    def __contains__(self, name):
        return name in self.names

    @property
    def names(self):
        """Every variable's name, coordinates first, in order."""
        return [v.name for v in self]

    @property
    def unlimited(self):
        """The dimension of unlimited length (None-sized), or None."""
        return next((d for d, size in self.dimensions.items() if size is None), None)

    def streamed(self):
        """The variables along the unlimited dimension (first), in order: what a writer appends.

        Returns
        -------
        list of Variable
        """
        return [v for v in self if v.dims[:1] == (self.unlimited,)]

    def attributes(self):
        """Every variable's CF attributes by name (:meth:`Variable.attrs`).

        Returns
        -------
        dict of str to dict
        """
        return {variable.name: variable.attrs() for variable in self}

    def replace(self, **changes):
        """A copy with some fields changed (``dataclasses.replace``).

        Parameters
        ----------
        **changes
            Fields and their new values.

        Returns
        -------
        Schema
        """
        return replace(self, **changes)


def to_dataset(schema, values, attrs=None, *, boolean_flags=False):
    """A result's ``xarray.Dataset`` from its schema and its arrays, CF-1.10.

    Every variable gets the attributes its schema declares and its stored type (flags
    int8 with ``flag_values``/``flag_meanings``, counts int64); the global attributes are
    ``Conventions`` followed by ``attrs``.

    Parameters
    ----------
    schema : Schema
        What the dataset holds.
    values : mapping of str to array_like
        The values of every coordinate and variable of ``schema``, by name.
    attrs : mapping, optional
        Global attributes (title, provenance, parameters with their units, ...).
    boolean_flags : bool
        Keep flags boolean instead of int8 (a run's dataset in memory; its file stores
        them as int8).

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ParameterError
        A variable of ``schema`` without values, values for a name ``schema`` does not
        have, or values whose shape does not match a dimension's declared size.
    """
    import xarray as xr

    missing = [name for name in schema.names if name not in values]
    unknown = [name for name in values if name not in schema]
    if missing or unknown:
        raise ParameterError(f"the values of {schema.kind} must be those of its schema "
                             f"{schema.names}; missing {missing}, unknown {unknown}.")

    def entry(variable):
        array = variable.cast(values[variable.name], boolean_flags=boolean_flags)
        sizes = [schema.dimensions[d] for d in variable.dims]
        if array.ndim != len(sizes) or any(size is not None and size != n
                                           for size, n in zip(sizes, array.shape)):
            raise ParameterError(f"variable {variable.name!r} of {schema.kind} must have "
                                 f"dimensions {variable.dims} of sizes {sizes}, got shape "
                                 f"{array.shape}.")
        return variable.dims, array, variable.attrs()

    return xr.Dataset({v.name: entry(v) for v in schema.variables},
                      coords={c.name: entry(c) for c in schema.coordinates},
                      attrs={"Conventions": CONVENTIONS, **(attrs or {})})
