"""Small argument checks shared by the parameter classes and public functions.

Messages follow scipy's style: name the argument, the value received and the fix.
"""
import dataclasses
import math
import numbers
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from qzs.errors import ParameterError


@dataclasses.dataclass(frozen=True, kw_only=True)
class Structured:
    """An ``error`` for the checks below, for an exception that carries the argument's name,
    its value and the reason as attributes rather than one message.

    ``Structured(build=build)`` makes the checks call ``build(name, value, reason)`` (the
    reason is the requirement and the fix: ``"must be positive; e.g. 0.5"``); e.g.
    ``Structured(build=functools.partial(ProblemError, "variables.mass"))`` in a problem file.
    """

    build: object


def refusal(error, name, value, requirement, fix=""):
    """The exception saying that ``name`` (given ``value``) ``requirement``, then ``fix``.

    Parameters
    ----------
    error : type or Structured
        An exception class, called with the whole message ``"`name` must be positive, got
        0.0; fix."``, or a :class:`Structured` builder, called with (name, value, reason).
    name : str
        The argument, option or key.
    value : object
        The value received, shown with ``repr``.
    requirement : str
        What it must be (``"must be positive"``).
    fix : str
        What to do (``"e.g. 1e-3 [s]"``); '' for nothing.

    Returns
    -------
    Exception
        To be raised by the caller.
    """
    if isinstance(error, Structured):
        return error.build(name, value, requirement + (f"; {fix}" if fix else ""))
    shown = f"the boolean {value!r}" if isinstance(value, (bool, np.bool_)) else repr(value)
    message = f"`{name}` {requirement}, got {shown}" + (f"; {fix}" if fix else "") + "."
    if isinstance(error, type) and issubclass(error, ParameterError) \
            and error.__init__ is ParameterError.__init__:
        return error(message, (name,))  # the argument it names, for a caller's spelling
    return error(message)


def _real(value):
    """``value`` as a float if it is a real number (not a bool; a 0-d numeric array counts),
    else None. Text is not a number: callers that read text parse it first."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return None
    return float(value)


def _bounds(minimum, maximum, strict):
    """The requirement a bounded number states: "must be positive", "must be >= 1", ..."""
    if maximum is None:
        if minimum is None:
            return "must be finite"
        if minimum == 0.0:
            return "must be positive" if strict else "must be non-negative"
        return f"must be {'>' if strict else '>='} {minimum:g}"
    low = "-inf" if minimum is None else f"{minimum:g}"
    opening, closing = ("(" if strict or minimum is None else "["), (")" if strict else "]")
    return f"must lie in {opening}{low}, {maximum:g}{closing}"


def real(name, value, error=ParameterError, *, minimum=None, maximum=None, strict=False,
         fix=""):
    """Return ``value`` as a float: a real number (not a bool, not text), finite, within
    ``minimum`` and ``maximum`` (excluded if ``strict``).

    The one check of a real number; :func:`positive_real` and :func:`non_negative_real` are it
    with their bound. Messages (value shown as a float once it is a number):
    ``"`x` must be a number, got 'a'"``, ``"`x` must be finite, got nan"``,
    ``"`x` must be positive, got 0.0"``, ``"`x` must be non-negative, got -1.0"``,
    ``"`x` must be >= 1, got 0.5"``, ``"`x` must lie in [0, 1], got 2.0"``, then
    ``"; fix."``.

    Parameters
    ----------
    name : str
        The argument, option or key, as the user wrote it.
    value : object
        The value received.
    error : type or Structured
        What to raise (:func:`refusal`).
    minimum, maximum : float, optional
        The bounds (None: none).
    strict : bool
        Exclude the bounds themselves.
    fix : str
        What to do, ending the message ('' for nothing).

    Returns
    -------
    float
    """
    number = _real(value)
    if number is None:
        raise refusal(error, name, value, "must be a number", fix)
    if not math.isfinite(number):
        raise refusal(error, name, number, "must be finite", fix)
    if ((minimum is not None and (number < minimum or (strict and number == minimum)))
            or (maximum is not None and (number > maximum or (strict and number == maximum)))):
        raise refusal(error, name, number, _bounds(minimum, maximum, strict), fix)
    return number


def positive_real(name, value, error=ParameterError, *, fix=""):
    """Return ``value`` as a finite float > 0 (:func:`real` with ``minimum=0, strict``)."""
    return real(name, value, minimum=0.0, strict=True, fix=fix, error=error)


def non_negative_real(name, value, error=ParameterError, *, fix=""):
    """Return ``value`` as a finite float >= 0 (:func:`real` with ``minimum=0``)."""
    return real(name, value, minimum=0.0, fix=fix, error=error)


def integer(name, value, minimum, error=ParameterError, *, maximum=None, fix=""):
    """Return ``value`` as an int: an integer (not a bool, not a float, not text) with
    ``minimum <= value <= maximum``; else ``"`x` must be an integer >= 1, got 0.5"``."""
    whole = (isinstance(value, (int, np.integer))
             and not isinstance(value, (bool, np.bool_)))
    if not whole or value < minimum or (maximum is not None and value > maximum):
        bound = (f"in [{minimum}, {maximum}]" if maximum is not None else f">= {minimum}")
        raise refusal(error, name, value, f"must be an integer {bound}", fix)
    return int(value)


#: The largest seed: numpy's generators take any integer >= 0, but the files qzs writes keep
#: a seed as a 64-bit integer attribute.
MAX_SEED = 2 ** 63 - 1


def seed(name, value, error=ParameterError):
    """Return ``value`` as the seed of a random generator: an integer in [0, 2**63 - 1].

    The one check of a seed (a random excitation's, a sweep's, a design search's and its
    draws'): numpy's generators refuse a negative one, and the files qzs writes keep it as
    a 64-bit integer. ``"`seed` must be an integer in [0, 9223372036854775807], got -3;
    e.g. 1 (any whole number >= 0 gives its own repeatable draws)."``

    Parameters
    ----------
    name : str
        The argument, option or key, as the user wrote it.
    value : object
        The value received.
    error : type or Structured
        What to raise (:func:`refusal`).

    Returns
    -------
    int
    """
    return integer(name, value, 0, error, maximum=MAX_SEED,
                   fix="e.g. 1 (any whole number >= 0 gives its own repeatable draws)")


def worker_count(workers, limit=None, error=ParameterError):
    """The workers (threads or processes) to use: ``workers``, an integer >= 1 (not a bool),
    or the machine's core count if it is None; at most ``limit`` (>= 1) if given."""
    count = (os.cpu_count() or 1) if workers is None else integer("workers", workers, 1, error)
    return count if limit is None else max(1, min(count, limit))


def interval(name, value, unit, *, minimum=0.0, example=None, error=ParameterError):
    """Return ``value``, two numbers ``(low, high)``, as floats with ``minimum <= low <= high``.

    ``unit`` names their unit in the messages, ``example`` (default ``"(1, 2) unit"``, or
    ``minimum`` for 1 when it is larger) the fix they end with: ``"`band` must satisfy
    0 <= low <= high (finite, in Hz), got (5, 1); e.g. (1, 20)."``.
    """
    if example is None:
        example = f"({max(minimum, 1.0):g}, 2) {unit}"
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise refusal(error, name, value, f"must be two numbers (low, high) in {unit}",
                      f"e.g. {example}") from None
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise refusal(error, name, value, f"must satisfy {minimum:g} <= low <= high (finite, "
                                          f"in {unit})", f"e.g. {example}")
    return (low, high)


def choice(name, value, options, error=ParameterError, *, fix=""):
    """Return ``value`` if it is one of ``options``; else ``"`x` must be one of 'a', 'b',
    got 'c'"``."""
    if value not in options:
        listed = ", ".join(repr(o) for o in options)
        raise refusal(error, name, value, f"must be one of {listed}", fix)
    return value


def validate_fields(instance, rules):
    """Validate and normalise the fields of a frozen dataclass in ``__post_init__``.

    Parameters
    ----------
    instance : dataclass instance
        The frozen instance being initialised.
    rules : dict
        Field name -> checker ``f(name, value) -> value``. A value of ``None`` is
        passed through untouched when the checker is wrapped with :func:`optional`.
    """
    for name, rule in rules.items():
        object.__setattr__(instance, name, rule(name, getattr(instance, name)))


def optional(rule):
    """Wrap a checker so that ``None`` passes through unchanged."""

    def check(name, value):
        return None if value is None else rule(name, value)

    return check


def parameter(default=dataclasses.MISSING, unit="", doc=""):
    """A dataclass field with its default (none: required), its unit and a one-line description.

    The unit and description are what the parameter registry
    (:mod:`qzs.model.registry`) reports for the field.
    """
    return dataclasses.field(default=default, metadata={"unit": unit, "doc": doc})


def finite_series(name, values, error, fix="interpolate or trim them first"):
    """``values`` as a 1-D float array with no NaN or inf, or ``error`` naming the count."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise error(f"`{name}` must be a 1-D series, got shape {array.shape}.")
    bad = int(np.count_nonzero(~np.isfinite(array)))
    if bad:
        raise error(f"`{name}` has {bad} non-finite (NaN or inf) samples out of {array.size}; "
                    f"{fix}.")
    return array


def finite_rows(name, values, error, fix="interpolate or trim them first"):
    """``values`` as a 2-D float array (one series per row) with no NaN or inf, or ``error``
    naming the rows that hold any."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 2:
        raise error(f"`{name}` must be a 2-D array, one series per row, got shape "
                    f"{array.shape}.")
    bad = np.flatnonzero(~np.isfinite(array).all(axis=1))
    if bad.size:
        raise error(f"`{name}` has non-finite (NaN or inf) samples in {bad.size} of "
                    f"{array.shape[0]} rows ({bad[:10].tolist()}"
                    f"{', ...' if bad.size > 10 else ''}); {fix}.")
    return array


def read_csv_table(path, what, expected, error=None):
    """Read a CSV file of a header line and rows of numbers: its column names and its data.

    Blank lines and lines starting with ``#`` are skipped. A missing file, a folder, a file
    that is not UTF-8 text (a binary file given by mistake), an empty file, a non-numeric
    value and a row of the wrong length each get a message naming the file (``what``, e.g.
    "displacement record") and the fix; ``expected`` says what the file should hold (e.g.
    "a header with 'time' and 'displacement', then rows of numbers").

    Parameters
    ----------
    path : str or Path
        The CSV file.
    what : str
        What the file is, for the messages.
    expected : str
        What it should hold, for the messages.
    error : type, optional
        The exception to raise; default :class:`qzs.errors.DataError`.

    Returns
    -------
    names : list of str
        The header's column names, stripped.
    data : ndarray
        The rows, shape (rows, columns), at least one row; not checked for NaN or inf.
    """
    from qzs.errors import DataError

    error = DataError if error is None else error
    path = Path(path)
    if not path.exists():
        raise error(f"{what} not found: {str(path)!r}.")
    if path.is_dir():
        raise error(f"{what} {str(path)!r} is a folder; pass the CSV file ({expected}).")
    try:
        with open(path, encoding="utf-8") as handle:
            lines = [line for line in handle if line.strip() and not line.startswith("#")]
    except UnicodeDecodeError as err:
        raise error(
            f"{what} {str(path)!r} is not UTF-8 text (byte "
            f"{err.object[err.start]:#04x} at position {err.start}), so it is not a CSV "
            "file; was a binary file (a log, a figure, a result) given by mistake? Pass the CSV "
            f"file ({expected}).") from None
    if not lines:
        raise error(f"{str(path)!r} is empty.")
    names = [n.strip() for n in lines[0].split(",")]
    try:
        data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]], ndmin=2)
    except ValueError as err:
        raise error(f"{str(path)!r}: non-numeric value ({err}).") from None
    if data.shape[0] == 0 or data.shape[1] != len(names):
        raise error(f"{str(path)!r}: expected rows of {len(names)} numbers, got shape "
                    f"{data.shape}.")
    return names, data


def read_toml(path, what, error=ParameterError, empty="write its tables into it"):
    """Parse a TOML file, or raise ``error`` saying which file (``what``) is missing or bad.

    A missing file, a folder, a file that is not UTF-8 text (a binary file given by
    mistake), invalid TOML and a file that sets nothing (empty, blank or only comments:
    what a failed ``qzs params --toml > FILE.toml`` left) each get a message naming the
    file and the fix; ``empty`` is the fix of the last.
    """
    import tomllib

    path = Path(path)
    try:
        with open(path, "rb") as handle:
            document = tomllib.load(handle)
        if not document:
            raise error(f"{what} {str(path)!r} is empty (no table or key, only blanks or "
                        f"comments): it sets nothing; {empty}.")
        return document
    except FileNotFoundError:
        raise error(f"{what} not found: {str(path)!r}.") from None
    except IsADirectoryError:
        raise error(f"{what} {str(path)!r} is a folder; pass the TOML file.") from None
    except UnicodeDecodeError as err:
        raise error(
            f"{what} {str(path)!r} is not UTF-8 text (byte {err.object[err.start]:#04x} at "
            f"position {err.start}), so it is not a TOML file; was a binary file (a log, a "
            "figure, a result) given by mistake? Pass the TOML file.") from None
    except tomllib.TOMLDecodeError as err:
        raise error(f"{what} {str(path)!r} is not valid TOML: {err}.") from None


def strictly_increasing(name, time, error, fix="sort it and drop duplicates first", where=""):
    """Raise ``error`` if ``time`` is not strictly increasing (says where, how, how often).

    ``where`` prefixes the message (e.g. the file the time base came from).
    """
    steps = np.diff(time)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        what = "duplicated" if steps[i] == 0 else "decreasing"
        raise error(f"{where}`{name}` must be strictly increasing, but it is {what} at sample {i + 1} "
                    f"(t = {float(time[i + 1])!r} s after t = {float(time[i])!r} s; "
                    f"{int(np.count_nonzero(steps <= 0))} such steps); {fix}.")


def known_keys(table, allowed, where, prefix="", options=(), *, required=(), noun="key",
               fix="", error=ParameterError):
    """Return ``table`` if it is a dict whose keys are all in ``allowed`` and that has every
    ``required`` key, else raise: the one check of a table's (a dict's) keys.

    Its messages, one format: ``"{prefix}unknown key(s) ['x'] in {where}; allowed are
    ['a', 'b']."``, ``"{prefix}missing key(s) ['a'] in {where}; required are ['a'], allowed
    are ['a', 'b']."`` and ``"{prefix}{where} must be a table, got 3."``, each ended by
    ``"; {fix}"`` when ``fix`` is given.

    Parameters
    ----------
    table : object
        The table (a dict) read.
    allowed : iterable of str
        Its keys that may be given (the ``required`` ones need not be repeated).
    where : str
        The table or argument, as the user wrote it (``[analysis]``, ```settings```).
    prefix : str
        Put before the message (the file: ``"'run.toml': "``).
    options : tuple of str
        The arguments the error is about (:attr:`ParameterError.options`).
    required : sequence of str
        Keys that must be given.
    noun : str
        What a key is (``"key"``, ``"table"``, ``"axis"``, ``"option"``), in the message.
    fix : str
        What to do, ending the message ('' for nothing).
    error : type or Structured
        What to raise: an exception class called with the message (and ``options`` for a
        :class:`ParameterError`), or a :class:`Structured` builder called with the first
        wrong key, its value and the message without ``prefix`` (the reason).

    Returns
    -------
    dict
        ``table``.
    """
    if not isinstance(table, dict):
        raise _table_refusal(error, prefix, options, "", table,
                             f"{where} must be a table, got {table!r}", fix)
    allowed = sorted({*allowed, *required}, key=str)
    missing = [key for key in required if key not in table]
    unknown = sorted(set(table) - set(allowed), key=str)
    if unknown:
        reason = f"unknown {noun}(s) {unknown} in {where}; allowed are {allowed}"
    elif missing:
        reason = (f"missing {noun}(s) {missing} in {where}; required are {list(required)}, "
                  f"allowed are {allowed}")
    else:
        return table
    key = (unknown or missing)[0]
    raise _table_refusal(error, prefix, options, key, table.get(key), reason, fix)


def _table_refusal(error, prefix, options, key, value, reason, fix):
    """:func:`known_keys`'s exception: ``reason`` (and ``fix``) about ``key``."""
    reason += f"; {fix}" if fix else ""
    if isinstance(error, Structured):
        return error.build(key, value, reason)
    if isinstance(error, type) and issubclass(error, ParameterError) \
            and error.__init__ is ParameterError.__init__:
        return error(f"{prefix}{reason}.", options)
    return error(f"{prefix}{reason}.")


def renamed_keyword(new, value, old, old_value, *, stacklevel=3):
    """A keyword's value under its new name, its old name kept one release with a warning.

    Parameters
    ----------
    new : str
        The keyword's name now (``"tolerance"``).
    value : object
        Its value (None: not given).
    old : str
        The deprecated name (``"tolerance_db"``).
    old_value : object
        The value given under the old name (None: not given).
    stacklevel : int
        Where the warning points (3: the caller of the function that calls this).

    Returns
    -------
    object
        ``value``, else ``old_value``.

    Raises
    ------
    ParameterError
        Both names given.

    Warns
    -----
    DeprecationWarning
        The old name given: it says the new one.
    """
    if old_value is None:
        return value
    import warnings

    if value is not None:
        raise ParameterError(f"give `{new}` only, got both `{new}` ({value!r}) and its "
                             f"deprecated name `{old}` ({old_value!r}); drop `{old}`.", (new, old))
    warnings.warn(f"`{old}` is deprecated and will be removed in the next release; use "
                  f"`{new}` (the same value and unit).", DeprecationWarning, stacklevel=stacklevel)
    return old_value


def deprecated_alias(old: str, new: str, value: Callable[[Any], Any]) -> property:
    """A property ``old`` that warns (DeprecationWarning naming ``new``) and returns ``value``:
    an attribute's old spelling kept one release (:func:`renamed_keyword` for a keyword).

    Parameters
    ----------
    old : str
        The deprecated attribute's name.
    new : str
        What to use instead, as the warning shows it (``"intervals['plateau']"``).
    value : callable
        The object -> the value (the same numbers as ``new``).

    Returns
    -------
    property
    """
    def get(self: Any) -> Any:
        import warnings

        warnings.warn(f"`{type(self).__name__}.{old}` is deprecated and will be removed in "
                      f"the next release; use `{new}`.", DeprecationWarning, stacklevel=2)
        return value(self)

    return property(get, doc=f"Deprecated (one release): use ``{new}``.")
