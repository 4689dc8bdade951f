"""Small argument checks shared by the parameter classes and public functions.

Messages follow scipy's style: name the argument, the value received and the fix.
"""
import dataclasses
import math
import numbers
import os
from pathlib import Path

import numpy as np

from qzs.errors import ParameterError


def as_float(name, value, error=ParameterError):
    """Return ``value`` as a finite float or raise ``error`` naming ``name``."""
    if isinstance(value, (bool, np.bool_)):
        raise error(f"`{name}` must be a number, got the boolean {value!r}.")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise error(f"`{name}` must be a number, got {value!r}.") from None
    if not math.isfinite(number):
        raise error(f"`{name}` must be finite, got {number!r}.")
    return number


def integer(name, value, minimum, error=ParameterError):
    """Return ``value`` as an int that must be an integer (not a bool) >= ``minimum``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) \
            or value < minimum:
        raise error(f"`{name}` must be an integer >= {minimum}, got {value!r}.")
    return int(value)


def worker_count(workers, limit=None, error=ParameterError):
    """The workers (threads or processes) to use: ``workers``, an integer >= 1 (not a bool),
    or the machine's core count if it is None; at most ``limit`` (>= 1) if given."""
    if workers is not None and (isinstance(workers, (bool, np.bool_))
                                or not isinstance(workers, (int, np.integer)) or workers < 1):
        raise error(f"`workers` must be a positive integer, got {workers!r}.")
    count = int(workers) if workers is not None else (os.cpu_count() or 1)
    return count if limit is None else max(1, min(count, limit))


def _real(value):
    """``value`` as a float if it is a real number (not a bool), else None."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return None
    return float(value)


def real(name, value, *, minimum=None, strict=False, fix="", error=ParameterError):
    """Return ``value`` as a float: a real number (not a bool), finite, at least ``minimum``.

    A number that is not one says ``"`name` must be a number, got 'x'."``; NaN, inf or a
    value below ``minimum`` (or equal to it if ``strict``) says
    ``"`name` must be a finite number >= 0, got -1.0."`` (no bound without ``minimum``).
    ``fix`` ends either message (e.g. ``"; e.g. 0.5"``).
    """
    number = _real(value)
    if number is None:
        raise error(f"`{name}` must be a number, got {value!r}{fix}.")
    if not math.isfinite(number) or (minimum is not None and (
            number < minimum or (strict and number == minimum))):
        bound = "" if minimum is None else (f" > {minimum:g}" if strict else f" >= {minimum:g}")
        raise error(f"`{name}` must be a finite number{bound}, got {number!r}{fix}.")
    return number


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
        raise error(f"`{name}` must be two numbers (low, high) in {unit}, got {value!r}; "
                    f"e.g. {example}.") from None
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise error(f"`{name}` must satisfy {minimum:g} <= low <= high (finite, in {unit}), "
                    f"got {value!r}; e.g. {example}.")
    return (low, high)


def finite_real(name, value, *, positive=False, error=ParameterError):
    """Return ``value`` as a float: a real number (not a bool), finite, and > 0 if ``positive``.

    Says ``"`name` must be a finite number, got 'x'."`` or, for a finite number that
    is not positive, ``"`name` must be positive, got 0."`` (the value as given).
    """
    number = _real(value)
    if number is None or not math.isfinite(number):
        raise error(f"`{name}` must be a finite number, got {value!r}.")
    if positive and number <= 0.0:
        raise error(f"`{name}` must be positive, got {value!r}.")
    return number


def positive_real(name, value, error=ParameterError):
    """Return ``value`` as a float: a real number (not a bool), finite and > 0.

    Every refusal says ``"`name` must be a positive finite number, got 0."`` (the value
    as given).
    """
    number = _real(value)
    if number is None or not math.isfinite(number) or number <= 0.0:
        raise error(f"`{name}` must be a positive finite number, got {value!r}.")
    return number


def positive(name, value, error=ParameterError):
    """Return ``value`` as a float that must be finite and > 0."""
    number = as_float(name, value, error)
    if number <= 0.0:
        raise error(f"`{name}` must be positive, got {number!r}.")
    return number


def non_negative(name, value, error=ParameterError):
    """Return ``value`` as a float that must be finite and >= 0."""
    number = as_float(name, value, error)
    if number < 0.0:
        raise error(f"`{name}` must be non-negative, got {number!r}.")
    return number


def choice(name, value, options, error=ParameterError):
    """Return ``value`` if it is one of ``options``."""
    if value not in options:
        listed = ", ".join(repr(o) for o in options)
        raise error(f"`{name}` must be one of {listed}; got {value!r}.")
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


def read_toml(path, what, error=ParameterError):
    """Parse a TOML file, or raise ``error`` saying which file (``what``) is missing or bad.

    A missing file, a folder, a file that is not UTF-8 text (a binary file given by
    mistake) and invalid TOML each get a message naming the file and the fix.
    """
    import tomllib

    path = Path(path)
    try:
        with open(path, "rb") as handle:
            return tomllib.load(handle)
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


def known_keys(table, allowed, where, prefix=""):
    """Return ``table`` if it is a dict whose keys are all in ``allowed``, else raise.

    ``where`` names the table in the message (e.g. ``[analysis]``); ``prefix`` the file.
    """
    if not isinstance(table, dict):
        raise ParameterError(f"{prefix}{where} must be a table, got {table!r}.")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise ParameterError(f"{prefix}unknown key(s) {unknown} in {where}; allowed are "
                             f"{sorted(allowed)}.")
    return table
