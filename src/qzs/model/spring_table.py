"""A measured force curve as data: PCHIP pieces, their exact integrals, and the CSV reader.

The arithmetic behind :class:`qzs.model.springs.TabulatedSpring` (docs/model.md §3.1), written
in plain numpy so that a kernel (numba, C) can mirror it line by line:

* :func:`pchip_slopes`: the slopes at the breakpoints of the shape-preserving piecewise cubic
  Hermite interpolant (Fritsch & Butland's weighted harmonic mean, one-sided three-point ends),
  the algorithm of ``scipy.interpolate.PchipInterpolator``;
* :func:`hermite_pieces`: each piece's cubic in ascending powers of ``t = z - x_i``;
* :func:`piece_energies`: the stored energy at each breakpoint, ``E = -integral of F``, exact
  for the cubic pieces;
* :func:`read_force_curve`: positions and forces from a CSV file with a header, in SI units.
"""
import re

import numpy as np

from qzs._validation import choice, read_csv_table
from qzs.errors import DataError, ParameterError

__all__ = ["POSITION_UNITS", "FORCE_UNITS", "pchip_slopes", "hermite_pieces", "piece_energies",
           "read_force_curve"]

#: Position units a force curve may be written in: name -> metres per unit.
POSITION_UNITS = {"m": 1.0, "mm": 1e-3}
#: Force units a force curve may be written in: name -> newtons per unit.
FORCE_UNITS = {"N": 1.0, "kN": 1e3}
#: A CSV column header ``name`` or ``name [unit]``.
_HEADER = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*(?:\[\s*(?P<unit>[^\[\]]*?)\s*\])?\s*$")


def pchip_slopes(positions, forces):
    """Slopes [N/m] at the breakpoints of the PCHIP interpolant of ``forces`` over ``positions``.

    Interior slopes are the weighted harmonic mean of the neighbouring secants (Fritsch &
    Butland), 0 where the secants differ in sign or one is 0 (a local extremum stays one);
    the end slopes are the one-sided three-point estimate, set to 0 if its sign differs from
    the end secant's and limited to three times that secant where the secants change sign.
    The same algorithm as ``scipy.interpolate.PchipInterpolator``.

    Parameters
    ----------
    positions : ndarray
        Breakpoints [m], strictly increasing, at least 3.
    forces : ndarray
        Forces [N] at them.

    Returns
    -------
    ndarray
        Slopes dF/dz [N/m] at the breakpoints.
    """
    h = np.diff(positions)
    secant = np.diff(forces) / h
    slopes = np.zeros_like(positions)
    left, right = secant[:-1], secant[1:]
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    flat = (np.sign(left) != np.sign(right)) | (left == 0.0) | (right == 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = (w1 + w2) / (w1 / left + w2 / right)
    slopes[1:-1] = np.where(flat, 0.0, harmonic)
    slopes[0] = _end_slope(h[0], h[1], secant[0], secant[1])
    slopes[-1] = _end_slope(h[-1], h[-2], secant[-1], secant[-2])
    return slopes


def _end_slope(h0, h1, m0, m1):
    """One-sided three-point slope at an end, made shape-preserving (as scipy's PCHIP)."""
    slope = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(slope) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(slope) > 3.0 * abs(m0):
        return 3.0 * m0
    return slope


def hermite_pieces(positions, forces, slopes):
    """Coefficients of the cubic Hermite pieces, ascending powers of ``t = z - x_i``.

    Parameters
    ----------
    positions : ndarray
        Breakpoints x_i [m], strictly increasing.
    forces : ndarray
        Forces [N] at them.
    slopes : ndarray
        Slopes dF/dz [N/m] at them.

    Returns
    -------
    ndarray
        Shape (n - 1, 4): row i holds ``c0 [N], c1 [N/m], c2 [N/m^2], c3 [N/m^3]`` with
        ``F(z) = c0 + c1*t + c2*t^2 + c3*t^3`` on ``x_i <= z <= x_(i+1)``.
    """
    h = np.diff(positions)
    secant = np.diff(forces) / h
    excess = (slopes[:-1] + slopes[1:] - 2.0 * secant) / h
    return np.column_stack([forces[:-1], slopes[:-1],
                            (secant - slopes[:-1]) / h - excess, excess / h])


def piece_energies(positions, pieces):
    """Stored energy [J] at each breakpoint, 0 at the first: ``E_(i+1) = E_i - integral of F``.

    Each piece's integral is exact for its cubic:
    ``h*(c0 + h*(c1/2 + h*(c2/3 + h*c3/4)))`` with ``h = x_(i+1) - x_i``.

    Parameters
    ----------
    positions : ndarray
        Breakpoints [m].
    pieces : ndarray
        Shape (n - 1, 4), from :func:`hermite_pieces`.

    Returns
    -------
    ndarray
        Energies [J] at the n breakpoints.
    """
    h = np.diff(positions)
    c0, c1, c2, c3 = pieces.T
    work = h * (c0 + h * (c1 / 2.0 + h * (c2 / 3.0 + h * (c3 / 4.0))))
    return np.concatenate([[0.0], -np.cumsum(work)])


def _column(names, wanted, unit, units, unit_name, path):
    """Index and SI scale of the column ``wanted`` (header ``wanted`` or ``wanted [unit]``)."""
    headers = [_HEADER.match(name) for name in names]
    found = [i for i, m in enumerate(headers) if m and m.group("name") == wanted]
    if not found:
        raise DataError(f"{str(path)!r} has no column {wanted!r} (a header {wanted!r} or "
                        f"'{wanted} [unit]'); columns found: {names}.")
    written = headers[found[0]].group("unit")
    if written is not None and written not in units:
        listed = ", ".join(repr(u) for u in units)
        raise DataError(f"the header of column {wanted!r} in {str(path)!r} says [{written}]; "
                        f"write it as one of {listed} (e.g. '{wanted} [{next(iter(units))}]').")
    if unit is None:
        if written is None:
            raise ParameterError(
                f"`{unit_name}` is not given and the header of column {wanted!r} in "
                f"{str(path)!r} names no unit; pass `{unit_name}` (one of {tuple(units)}) or "
                f"write the header as '{wanted} [{next(iter(units))}]'.", (unit_name,))
        unit = written
    choice(unit_name, unit, tuple(units))
    if written is not None and written != unit:
        raise ParameterError(
            f"`{unit_name}` is {unit!r} but the header of column {wanted!r} in {str(path)!r} "
            f"says [{written}]: mismatched units; pass `{unit_name}={written!r}` or correct the "
            "header.", (unit_name,))
    return found[0], units[unit]


def read_force_curve(path, *, position_unit=None, force_unit=None, position_column="position",
                     force_column="force"):
    """Positions [m] and forces [N] of a measured force curve in a CSV file with a header.

    Parameters
    ----------
    path : str or Path
        The CSV file: a header line, then rows of numbers; blank lines and lines starting
        with ``#`` are skipped. A column's header may carry its unit in brackets,
        ``position [mm]``, ``force [N]``.
    position_unit : {"m", "mm"} or None
        Unit of the position column; None (default): the header's. Given and written in
        the header, the two must agree.
    force_unit : {"N", "kN"} or None
        Unit of the force column, as ``position_unit``.
    position_column, force_column : str
        Names of the two columns (without the unit).

    Returns
    -------
    positions, forces : ndarray
        In [m] and [N], in the file's order.

    Raises
    ------
    DataError
        A missing, unreadable or malformed file, a missing column, non-finite samples.
    ParameterError
        A unit that is not one of the allowed ones, not given anywhere, or given differently
        in the argument and the header.
    """
    names, data = read_csv_table(
        path, "force curve",
        f"a header with {position_column!r} and {force_column!r}, then rows of numbers")
    i, to_metres = _column(names, position_column, position_unit, POSITION_UNITS,
                           "position_unit", path)
    j, to_newtons = _column(names, force_column, force_unit, FORCE_UNITS, "force_unit", path)
    positions, forces = data[:, i] * to_metres, data[:, j] * to_newtons
    bad = int(np.count_nonzero(~np.isfinite(positions)) + np.count_nonzero(~np.isfinite(forces)))
    if bad:
        raise DataError(f"{str(path)!r}: {bad} non-finite samples (NaN or inf) in "
                        f"{position_column!r}/{force_column!r}; clean the curve first.")
    return positions, forces
