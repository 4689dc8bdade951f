"""Spring laws as values: the MagSpring's tanh, the three-spring QZS, a polynomial, a table.

Each law (docs/model.md §3 and §3.1) is a frozen keyword-only dataclass with its force on the
payload ``force(z)`` [N] (upward positive, ``z`` the relative position [m]), its tangent
stiffness ``stiffness(z) = -dF/dz`` [N/m] (positive: restoring) and its stored energy
``energy(z)`` [J] with ``F = -dE/dz``, each vectorised over arrays.

A law also packs into one flat float64 array (:meth:`SpringLaw.pack`), which a kernel
evaluates without knowing the class (:func:`evaluate_packed` is the plain-Python reference a
kernel mirrors). Element 0 is the law's code; the rest, by code:

=====  =============  ==========================================================================
code   law            layout after the code
=====  =============  ==========================================================================
0      tanh           ``plateau a [N], shape b [1/m]``
1      oblique        ``k_v [N/m], k_o [N/m], L0 [m], d [m], center [m], preload [N]``
2      polynomial     ``center [m], n, c_0 .. c_(n-1)`` (ascending powers, [N/m^k])
3      table          ``outside (0 refuse, 1 extend), n, F_n [N], F'_n [N/m]`` (force and slope
                      at the last breakpoint), then the n breakpoints x_i [m], then the n - 1
                      pieces' ``c0 [N], c1 [N/m], c2 [N/m^2], c3 [N/m^3]`` in ascending powers
                      of ``t = z - x_i``, then the n energies E_i [J] at the breakpoints
=====  =============  ==========================================================================

Offsets are the ``TABLE_*`` constants below. A table is evaluated by a binary search for the
piece and Horner's rule: force ``c0 + t(c1 + t(c2 + t c3))``, energy
``E_i - t(c0 + t(c1/2 + t(c2/3 + t c3/4)))``, both exact for the piece.
"""
import dataclasses
import math
import os
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs._validation import (choice, known_keys, non_negative_real, parameter, positive_real,
                             real, validate_fields)
from qzs.errors import ParameterError
from qzs.model.spring_table import hermite_pieces, pchip_slopes, piece_energies, read_force_curve

__all__ = ["SpringLaw", "TanhSpring", "ObliqueSpringQZS", "PolynomialSpring", "TabulatedSpring",
           "SPRING_LAWS", "OUTSIDE_RULES", "check_equilibrium", "evaluate_packed"]

#: What a table does outside its positions: refuse (an error; a kernel's status) or extend
#: (continue linearly with the end slope).
OUTSIDE_RULES = ("refuse", "extend")
#: Codes of the laws in :meth:`SpringLaw.pack`.
TANH, OBLIQUE, POLYNOMIAL, TABLE = 0, 1, 2, 3
#: Offsets in a packed table: the outside rule, the breakpoint count, the force and slope at
#: the last breakpoint, the first breakpoint (then the pieces and the energies follow).
TABLE_OUTSIDE, TABLE_COUNT, TABLE_END_FORCE, TABLE_END_SLOPE, TABLE_POSITIONS = 1, 2, 3, 4, 5
#: The least number of points of a table: PCHIP's end slopes take three.
TABLE_MIN_POINTS = 3
#: :func:`evaluate_packed` status: evaluated; outside a refusing table (results NaN).
STATUS_OK, STATUS_OUTSIDE = 0, 1
#: Samples of the stroke :func:`check_equilibrium` searches (besides a table's breakpoints).
EQUILIBRIUM_SAMPLES = 4097


def _positions(z):
    return np.asarray(z, dtype=float)


@dataclass(frozen=True, kw_only=True, eq=False)
class SpringLaw:
    """A spring law: force, stiffness and stored energy at a relative position.

    The base of :class:`TanhSpring`, :class:`ObliqueSpringQZS`, :class:`PolynomialSpring` and
    :class:`TabulatedSpring`; analysis code uses only what is defined here. Two laws are
    equal when they are of the same class and pack to the same numbers.
    """

    kind: ClassVar[str] = ""
    code: ClassVar[int] = -1

    def force(self, z: ArrayLike) -> NDArray[np.float64]:
        """Spring force on the payload [N], upward positive.

        Parameters
        ----------
        z : float or array_like
            Relative position [m].

        Returns
        -------
        ndarray
            Force [N], the shape of ``z``.
        """
        return self._force(_positions(z))

    def stiffness(self, z: ArrayLike) -> NDArray[np.float64]:
        """Tangent stiffness ``-dF/dz`` [N/m]; positive is restoring.

        Parameters
        ----------
        z : float or array_like
            Relative position [m].

        Returns
        -------
        ndarray
            Stiffness [N/m], the shape of ``z``.
        """
        return self._stiffness(_positions(z))

    def energy(self, z: ArrayLike) -> NDArray[np.float64]:
        """Stored energy [J], ``F = -dE/dz``, zero at the law's stated reference position.

        Parameters
        ----------
        z : float or array_like
            Relative position [m].

        Returns
        -------
        ndarray
            Energy [J], the shape of ``z``.
        """
        return self._energy(_positions(z))

    def describe(self) -> str:
        """One line: the law and its parameters with units."""
        return self._describe()

    def pack(self) -> NDArray[np.float64]:
        """The law as one float64 array: its code, then its numbers (module docstring)."""
        return self._pack()

    @property
    def domain(self) -> tuple[float, float]:
        """Positions [m] where the law is defined: (-inf, inf) but for a refusing table."""
        return (-math.inf, math.inf)

    def to_dict(self) -> dict[str, Any]:
        """The law as plain data: ``{"law": kind, field: value, ...}`` (arrays as lists)."""
        data = {"law": self.kind}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            data[f.name] = value.tolist() if isinstance(value, np.ndarray) else value
        return data

    def parameters(self) -> dict[str, tuple[Any, str]]:
        """The law with its units, as a run's records write it: ``{name: (value, unit)}``.

        ``law`` (its kind, unit ``-``) first, then each field; arrays as lists of floats.

        Returns
        -------
        dict of str to (object, str)
        """
        meta: dict[str, tuple[Any, str]] = {"law": (self.kind, "-")}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                value = [float(x) for x in value]
            meta[f.name] = (value, f.metadata.get("unit", ""))
        return meta

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "SpringLaw":
        """A law from :meth:`to_dict`'s data; on the base class the ``law`` key picks the class.

        Parameters
        ----------
        data : dict
            ``{"law": kind, field: value, ...}``; unknown keys are refused.

        Returns
        -------
        SpringLaw
        """
        if not isinstance(data, dict):
            raise ParameterError(f"`data` must be a dict of a spring law's fields, got "
                                 f"{data!r}.", ("data",))
        fields = dict(data)
        kind = fields.pop("law", cls.kind or None)
        if cls is SpringLaw:
            kind = choice("law", kind, tuple(SPRING_LAWS))
            target = SPRING_LAWS[kind]
        else:
            choice("law", kind, (cls.kind,), fix=f"use SpringLaw.from_dict for a {kind!r} law")
            target = cls
        known_keys(fields, ["law", *(f.name for f in dataclasses.fields(target))],
                   f"a {target.kind!r} spring law", options=("data",))
        return target(**fields)

    def _force(self, z):
        raise NotImplementedError

    _stiffness = _energy = _force

    def _describe(self):
        raise NotImplementedError

    _pack = _describe

    def __eq__(self, other):
        return type(other) is type(self) and np.array_equal(self.pack(), other.pack())

    def __hash__(self):
        return hash((type(self).__name__, self.pack().tobytes()))


@dataclass(frozen=True, kw_only=True, eq=False)
class TanhSpring(SpringLaw):
    """The MagSpring: ``F = -a tanh(b z)`` (paper eq. 2, docs/model.md §3).

    Energy ``(a/b) ln cosh(b z)``, zero at ``z = 0``; stiffness ``a b / cosh^2(b z)``. The
    same arithmetic as :func:`qzs.model.isolator.spring_force` and its siblings, bit for bit.

    Parameters
    ----------
    plateau : float
        The constant force a [N] the spring tends to when compressed (``spring_force``).
    shape : float
        The transition coefficient b [1/m] (``spring_shape``).
    """

    kind: ClassVar[str] = "tanh"
    code: ClassVar[int] = TANH
    plateau: float = parameter(60.84, "N", "MagSpring force amplitude a")
    shape: float = parameter(78.10, "1/m", "MagSpring shape coefficient b")

    def __post_init__(self):
        validate_fields(self, {"plateau": non_negative_real, "shape": positive_real})

    def _force(self, z):
        return -self.plateau * np.tanh(self.shape * z)

    def _stiffness(self, z):
        return self.plateau * self.shape / np.cosh(self.shape * z) ** 2

    def _energy(self, z):
        u = np.abs(self.shape * z)
        return self.plateau / self.shape * (u + np.log1p(np.exp(-2 * u)) - np.log(2))

    def _describe(self):
        return (f"tanh spring (MagSpring): F = -{self.plateau:g} N * tanh({self.shape:g} 1/m * z), "
                f"stiffness {self.plateau * self.shape:.4g} N/m at z = 0 m")

    def _pack(self):
        return np.array([TANH, self.plateau, self.shape])


@dataclass(frozen=True, kw_only=True, eq=False)
class ObliqueSpringQZS(SpringLaw):
    """The three-spring QZS mechanism (Carrella, Brennan & Waters, J. Sound Vib. 301 (2007)).

    A vertical spring (stiffness ``k_v``) and two oblique springs (stiffness ``k_o``, free
    length ``L0``) hinged at the horizontal distance ``d`` either side, horizontal at
    ``z = center``. With ``u = z - center`` and ``L = sqrt(u^2 + d^2)`` (docs/model.md §3.1):

    * force ``F = P - k_v u - 2 k_o (1 - L0/L) u`` [N], ``P`` the vertical spring's preload;
    * stiffness ``k_v + 2 k_o (1 - L0 d^2 / L^3)`` [N/m], ``k_v + 2 k_o (1 - L0/d)`` at u = 0;
    * energy ``-P u + (k_v/2 + k_o) u^2 - 2 k_o L0 (L - d)`` [J], zero at ``z = center``.

    Quasi-zero stiffness at the centre needs ``L0 > d`` and ``k_v = 2 k_o (L0/d - 1)``
    (:meth:`quasi_zero` chooses it). The defaults meet it exactly (``L0/d = 1.5``, so
    ``k_v = k_o``): the oblique springs are 62.5 mm compressed at the centre, the centre is
    the paper's operating point -0.060 m, the preload carries the payload's 62.78 N there
    (6.4 kg at 9.81 m/s^2), and over the stroke +-0.080 m the stiffness stays >= 0 (every
    position has a stable equilibrium for some weight) and rises to 241 N/m at the ends
    (0.98 Hz with 6.4 kg), the force staying within 62.78 +- 7.6 N.

    Parameters
    ----------
    vertical_stiffness : float
        Stiffness of the vertical spring, k_v [N/m], >= 0.
    oblique_stiffness : float
        Stiffness of each oblique spring, k_o [N/m], >= 0.
    free_length : float
        Free length of each oblique spring, L0 [m], > 0.
    horizontal_distance : float
        Horizontal distance from the payload's axis to each oblique spring's hinge, d [m], > 0
        (the oblique springs' length when horizontal).
    center : float
        Relative position where the oblique springs are horizontal [m].
    preload : float
        Force of the vertical spring at ``z = center`` [N] (upward positive).
    """

    kind: ClassVar[str] = "oblique"
    code: ClassVar[int] = OBLIQUE
    vertical_stiffness: float = parameter(200.0, "N/m", "vertical spring stiffness k_v")
    oblique_stiffness: float = parameter(200.0, "N/m", "oblique spring stiffness k_o")
    free_length: float = parameter(0.1875, "m", "oblique springs' free length L0")
    horizontal_distance: float = parameter(0.125, "m", "horizontal distance to the hinges d")
    center: float = parameter(-0.060, "m", "position where the oblique springs are horizontal")
    preload: float = parameter(62.78, "N", "vertical spring's force at the centre")

    def __post_init__(self):
        validate_fields(self, {
            "vertical_stiffness": non_negative_real, "oblique_stiffness": non_negative_real,
            "free_length": positive_real, "horizontal_distance": positive_real,
            "center": real, "preload": real})

    @classmethod
    def quasi_zero(cls, **geometry: float) -> "ObliqueSpringQZS":
        """The mechanism with ``k_v = 2 k_o (L0/d - 1)``: zero stiffness at ``z = center``.

        Parameters
        ----------
        **geometry : float
            Any field but ``vertical_stiffness`` (the others default as the class's).

        Returns
        -------
        ObliqueSpringQZS

        Raises
        ------
        ParameterError
            ``vertical_stiffness`` given, or ``free_length <= horizontal_distance``: the
            oblique springs are then not compressed at the centre and only stiffen it.
        """
        if "vertical_stiffness" in geometry:
            raise ParameterError("`vertical_stiffness` is what quasi_zero chooses; leave it out, "
                                 "or build ObliqueSpringQZS(...) with it directly.",
                                 ("vertical_stiffness",))
        law = cls(vertical_stiffness=0.0, **geometry)
        length, distance = law.free_length, law.horizontal_distance
        if length <= distance:
            raise ParameterError(
                f"`free_length` ({length!r} m) must exceed `horizontal_distance` ({distance!r} m) "
                "for a quasi-zero stiffness: only oblique springs compressed at the centre have "
                "the negative stiffness that cancels the vertical spring's, and with "
                "free_length <= horizontal_distance no vertical stiffness >= 0 gives zero; "
                f"lengthen the oblique springs (e.g. free_length = {1.5 * distance:g} m) or "
                "bring the hinges closer.", ("free_length", "horizontal_distance"))
        return dataclasses.replace(
            law, vertical_stiffness=2.0 * law.oblique_stiffness * (length / distance - 1.0))

    def _force(self, z):
        u = z - self.center
        length = np.hypot(u, self.horizontal_distance)
        return (self.preload - self.vertical_stiffness * u
                - 2.0 * self.oblique_stiffness * (1.0 - self.free_length / length) * u)

    def _stiffness(self, z):
        u = z - self.center
        d = self.horizontal_distance
        length = np.hypot(u, d)
        return (self.vertical_stiffness
                + 2.0 * self.oblique_stiffness * (1.0 - self.free_length * d * d / length ** 3))

    def _energy(self, z):
        u = z - self.center
        d = self.horizontal_distance
        # L - d = u^2 / (L + d): no cancellation near the centre.
        spread = 2.0 * self.free_length / (np.hypot(u, d) + d)
        return u * (-self.preload
                    + u * (0.5 * self.vertical_stiffness + self.oblique_stiffness * (1.0 - spread)))

    def _describe(self):
        center = float(self.stiffness(self.center))
        return (f"oblique-spring QZS: k_v = {self.vertical_stiffness:g} N/m, k_o = "
                f"{self.oblique_stiffness:g} N/m, L0 = {self.free_length:g} m, d = "
                f"{self.horizontal_distance:g} m, horizontal at z = {self.center:g} m with "
                f"preload {self.preload:g} N; stiffness there {center:.4g} N/m")

    def _pack(self):
        return np.array([OBLIQUE, self.vertical_stiffness, self.oblique_stiffness,
                         self.free_length, self.horizontal_distance, self.center, self.preload])


def _float_series(name, values, fix):
    """``values`` as a read-only 1-D float array of finite numbers, or a ParameterError."""
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be a sequence of numbers, got {values!r}; {fix}.",
                             (name,)) from None
    if array.ndim != 1:
        raise ParameterError(f"`{name}` must be a 1-D sequence of numbers, got shape "
                             f"{array.shape}; {fix}.", (name,))
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise ParameterError(f"`{name}` must be finite, but {bad.size} of its {array.size} "
                             f"values are NaN or inf (the first at index {bad[0]}: "
                             f"{array[bad[0]]!r}); {fix}.", (name,))
    array.setflags(write=False)
    return array


@dataclass(frozen=True, kw_only=True, eq=False)
class PolynomialSpring(SpringLaw):
    """A polynomial force law ``F = sum_k c_k (z - center)^k`` (docs/model.md §3.1).

    Stiffness ``-sum_k k c_k u^(k-1)``, energy ``-sum_k c_k u^(k+1)/(k+1)``, zero at
    ``z = center`` (``u = z - center``). A Duffing spring carrying ``P`` is
    ``coefficients=(P, -k1, 0, -k3)``: linear stiffness ``k1``, cubic ``k3``; a quadratic
    characteristic has ``c_2 != 0``.

    Parameters
    ----------
    coefficients : array_like
        ``c_0 [N], c_1 [N/m], c_2 [N/m^2], ...``: ascending powers, at least one.
    center : float
        Position the powers are taken about [m]; default 0.
    """

    kind: ClassVar[str] = "polynomial"
    code: ClassVar[int] = POLYNOMIAL
    coefficients: np.ndarray = parameter(unit="N/m^k", doc="coefficients, ascending powers")
    center: float = parameter(0.0, "m", "position the powers are taken about")

    def __post_init__(self):
        coefficients = _float_series("coefficients", self.coefficients,
                                     "give c_0 [N], c_1 [N/m], ... as numbers")
        if coefficients.size == 0:
            raise ParameterError("`coefficients` must hold at least one number (c_0 [N]), got "
                                 "none; e.g. (62.78, -100.0, 0.0, -5e4) for a Duffing spring.",
                                 ("coefficients",))
        object.__setattr__(self, "coefficients", coefficients)
        validate_fields(self, {"center": real})

    def _force(self, z):
        u = z - self.center
        total = np.zeros_like(u)
        for c in self.coefficients[::-1]:
            total = total * u + c
        return total

    def _stiffness(self, z):
        u = z - self.center
        total = np.zeros_like(u)
        for k in range(self.coefficients.size - 1, 0, -1):
            total = total * u + k * self.coefficients[k]
        return -total

    def _energy(self, z):
        u = z - self.center
        total = np.zeros_like(u)
        for k in range(self.coefficients.size - 1, -1, -1):
            total = total * u + self.coefficients[k] / (k + 1)
        return -total * u

    def _describe(self):
        terms = ", ".join(f"c{k} = {c:g} N" + (f"/m^{k}" if k > 1 else "/m" if k else "")
                          for k, c in enumerate(self.coefficients))
        return f"polynomial spring about z = {self.center:g} m: {terms}"

    def _pack(self):
        return np.concatenate([[POLYNOMIAL, self.center, self.coefficients.size],
                               self.coefficients])


@dataclass(frozen=True, kw_only=True, eq=False)
class TabulatedSpring(SpringLaw):
    """A measured force curve, interpolated by PCHIP (docs/model.md §3.1).

    The shape-preserving C1 piecewise cubic of Fritsch & Carlson with Fritsch & Butland's
    slopes (``scipy.interpolate.PchipInterpolator``'s algorithm): monotone where the data is,
    no overshoot. Energy is each piece's exact integral, zero at ``positions[0]``. Outside
    the table: ``"refuse"`` raises (a kernel stops with a status), ``"extend"`` continues
    linearly with the end slope (C1 at the ends).

    Parameters
    ----------
    positions : array_like
        Relative positions [m], strictly increasing, at least 3, finite.
    forces : array_like
        Force on the payload at each position [N], upward positive, finite.
    outside : {"refuse", "extend"}
        What the law does outside ``[positions[0], positions[-1]]``.
    """

    kind: ClassVar[str] = "table"
    code: ClassVar[int] = TABLE
    positions: np.ndarray = parameter(unit="m", doc="relative positions of the table")
    forces: np.ndarray = parameter(unit="N", doc="forces at the positions")
    outside: str = parameter("refuse", "-", "outside the table: refuse or extend")

    def __post_init__(self):
        x = _float_series("positions", self.positions, "remove or re-measure those points")
        y = _float_series("forces", self.forces, "remove or re-measure those points")
        if x.size != y.size:
            raise ParameterError(f"`positions` and `forces` must have the same length, got "
                                 f"{x.size} and {y.size}; give one force per position.",
                                 ("positions", "forces"))
        if x.size < TABLE_MIN_POINTS:
            raise ParameterError(
                f"`positions` must hold at least {TABLE_MIN_POINTS} points for the PCHIP "
                f"interpolant (its end slopes take three), got {x.size}; measure more points, "
                "or use PolynomialSpring for a straight line.", ("positions",))
        step = np.diff(x)
        if np.any(step <= 0.0):
            i = int(np.argmax(step <= 0.0))
            what = "repeated" if step[i] == 0.0 else "decreasing"
            fix = ("reverse the table (it decreases throughout: a test machine's sign?)"
                   if np.all(step < 0.0) else
                   "sort the table by position and average the forces of repeated positions")
            raise ParameterError(
                f"`positions` must be strictly increasing, but it is {what} at index {i + 1} "
                f"({float(x[i + 1])!r} m after {float(x[i])!r} m; {int(np.count_nonzero(step <= 0.0))} such "
                f"steps); {fix}.", ("positions",))
        object.__setattr__(self, "positions", x)
        object.__setattr__(self, "forces", y)
        validate_fields(self, {"outside": lambda n, v: choice(n, v, OUTSIDE_RULES)})
        slopes = pchip_slopes(x, y)
        pieces = hermite_pieces(x, y, slopes)
        energies = piece_energies(x, pieces)
        packed = np.concatenate([[TABLE, OUTSIDE_RULES.index(self.outside), x.size, y[-1],
                                  slopes[-1]], x, pieces.ravel(), energies])
        packed.setflags(write=False)
        object.__setattr__(self, "_packed", packed)

    @classmethod
    def from_law(cls, law: SpringLaw, positions: ArrayLike,
                 outside: str = "refuse") -> "TabulatedSpring":
        """The table of another law's forces at ``positions``.

        Parameters
        ----------
        law : SpringLaw
            The law sampled.
        positions : array_like
            Relative positions [m], strictly increasing, at least 3.
        outside : {"refuse", "extend"}
            As the class's.

        Returns
        -------
        TabulatedSpring
        """
        if not isinstance(law, SpringLaw):
            raise ParameterError(f"`law` must be a spring law (TanhSpring, ...), got {law!r}.",
                                 ("law",))
        x = _float_series("positions", positions, "remove those points")
        return cls(positions=x, forces=law.force(x), outside=outside)

    @classmethod
    def read_csv(cls, path: "str | os.PathLike[str]", *, position_unit: str | None = None,
                 force_unit: str | None = None,
                 outside: str = "refuse", position_column: str = "position",
                 force_column: str = "force") -> "TabulatedSpring":
        """A measured force curve from a CSV file with a header (see ``read_force_curve``).

        Parameters
        ----------
        path : str or Path
            The CSV file: a header line (a column's unit may follow its name in brackets,
            ``position [mm]``), then rows of numbers.
        position_unit : {"m", "mm"} or None
            Unit of the positions; None: the header's. Both given, they must agree.
        force_unit : {"N", "kN"} or None
            Unit of the forces, as ``position_unit``.
        outside : {"refuse", "extend"}
            As the class's.
        position_column, force_column : str
            Names of the two columns.

        Returns
        -------
        TabulatedSpring
        """
        positions, forces = read_force_curve(
            path, position_unit=position_unit, force_unit=force_unit,
            position_column=position_column, force_column=force_column)
        return cls(positions=positions, forces=forces, outside=outside)

    @property
    def domain(self) -> tuple[float, float]:
        """Positions [m] where the law is defined: the table's, or all if it extends."""
        if self.outside == "extend":
            return (-math.inf, math.inf)
        return (float(self.positions[0]), float(self.positions[-1]))

    def _evaluate(self, z):
        """(t, piece index, below, above) of each position, refusing outside if asked."""
        x = self.positions
        below, above = z < x[0], z > x[-1]
        if self.outside == "refuse" and (np.any(below) or np.any(above)):
            far = float(z[below | above].ravel()[0])
            raise ParameterError(
                f"`z` = {far!r} m is outside the table [{float(x[0])!r}, {float(x[-1])!r}] m of a "
                "TabulatedSpring with outside='refuse'; measure the curve over the whole "
                "stroke, or build it with outside='extend' (linear beyond the ends).", ("z",))
        i = np.clip(np.searchsorted(x, z, side="right") - 1, 0, x.size - 2)
        return z - x[i], i, below, above

    def _pieces(self):
        n = self.positions.size
        start = TABLE_POSITIONS + n
        return self._packed[start:start + 4 * (n - 1)].reshape(n - 1, 4), \
            self._packed[start + 4 * (n - 1):]

    def _force(self, z):
        t, i, below, above = self._evaluate(z)
        pieces, _ = self._pieces()
        c0, c1, c2, c3 = np.moveaxis(pieces[i], -1, 0)
        inside = c0 + t * (c1 + t * (c2 + t * c3))
        low = pieces[0, 0] + (z - self.positions[0]) * pieces[0, 1]
        high = (self._packed[TABLE_END_FORCE]
                + (z - self.positions[-1]) * self._packed[TABLE_END_SLOPE])
        return np.where(below, low, np.where(above, high, inside))

    def _stiffness(self, z):
        t, i, below, above = self._evaluate(z)
        pieces, _ = self._pieces()
        _, c1, c2, c3 = np.moveaxis(pieces[i], -1, 0)
        inside = -(c1 + t * (2.0 * c2 + t * (3.0 * c3)))
        return np.where(below, -pieces[0, 1],
                        np.where(above, -self._packed[TABLE_END_SLOPE], inside))

    def _energy(self, z):
        t, i, below, above = self._evaluate(z)
        pieces, energies = self._pieces()
        c0, c1, c2, c3 = np.moveaxis(pieces[i], -1, 0)
        inside = energies[i] - t * (c0 + t * (c1 / 2.0 + t * (c2 / 3.0 + t * (c3 / 4.0))))
        u_low = z - self.positions[0]
        u_high = z - self.positions[-1]
        low = energies[0] - u_low * (pieces[0, 0] + u_low * (pieces[0, 1] / 2.0))
        high = energies[-1] - u_high * (self._packed[TABLE_END_FORCE]
                                        + u_high * (self._packed[TABLE_END_SLOPE] / 2.0))
        return np.where(below, low, np.where(above, high, inside))

    def _describe(self):
        x, y = self.positions, self.forces
        return (f"tabulated spring: {x.size} points over [{x[0]:g}, {x[-1]:g}] m, forces "
                f"{y.min():.4g} to {y.max():.4g} N, PCHIP, outside: {self.outside}")

    def _pack(self):
        return self._packed.copy()


#: The laws by the name :meth:`SpringLaw.to_dict` writes (``"law"``).
SPRING_LAWS = {cls.kind: cls for cls in (TanhSpring, ObliqueSpringQZS, PolynomialSpring,
                                         TabulatedSpring)}


def evaluate_packed(packed: NDArray[np.float64], z: float) -> tuple[float, float, float, int]:
    """Force, stiffness and energy of a packed law at one position: what a kernel computes.

    Plain Python, scalar, no allocation: the reference a numba or C kernel mirrors (a
    binary search and Horner's rule for a table).

    Parameters
    ----------
    packed : ndarray
        :meth:`SpringLaw.pack`'s array.
    z : float
        Relative position [m].

    Returns
    -------
    force : float
        [N].
    stiffness : float
        [N/m].
    energy : float
        [J].
    status : int
        :data:`STATUS_OK`, or :data:`STATUS_OUTSIDE` (and NaN values) outside a refusing table.
    """
    code = int(packed[0])
    if code == TANH:
        a, b = packed[1], packed[2]
        u = abs(b * z)
        return (-a * math.tanh(b * z), a * b / math.cosh(b * z) ** 2,
                a / b * (u + math.log1p(math.exp(-2.0 * u)) - math.log(2.0)), STATUS_OK)
    if code == OBLIQUE:
        kv, ko, free, d, center, preload = packed[1:7]
        u = z - center
        length = math.hypot(u, d)
        return (preload - kv * u - 2.0 * ko * (1.0 - free / length) * u,
                kv + 2.0 * ko * (1.0 - free * d * d / length ** 3),
                u * (-preload + u * (0.5 * kv + ko * (1.0 - 2.0 * free / (length + d)))),
                STATUS_OK)
    if code == POLYNOMIAL:
        u, n = z - packed[1], int(packed[2])
        force = slope = work = 0.0
        for k in range(n - 1, -1, -1):
            c = packed[3 + k]
            force = force * u + c
            work = work * u + c / (k + 1)
            if k > 0:
                slope = slope * u + k * c
        return force, -slope, -work * u, STATUS_OK
    return _evaluate_packed_table(packed, z)


def _evaluate_packed_table(packed, z):
    """:func:`evaluate_packed` for a table: binary search, then Horner."""
    n = int(packed[TABLE_COUNT])
    x0, xn = packed[TABLE_POSITIONS], packed[TABLE_POSITIONS + n - 1]
    pieces = TABLE_POSITIONS + n
    energies = pieces + 4 * (n - 1)
    if z < x0 or z > xn:
        if packed[TABLE_OUTSIDE] == 0.0:
            return math.nan, math.nan, math.nan, STATUS_OUTSIDE
        if z < x0:
            t, force, slope, energy = z - x0, packed[pieces], packed[pieces + 1], packed[energies]
        else:
            t, force, slope = z - xn, packed[TABLE_END_FORCE], packed[TABLE_END_SLOPE]
            energy = packed[energies + n - 1]
        return (force + t * slope, -slope, energy - t * (force + t * (slope / 2.0)), STATUS_OK)
    low, high = 0, n - 1
    while high - low > 1:
        middle = (low + high) // 2
        if z >= packed[TABLE_POSITIONS + middle]:
            low = middle
        else:
            high = middle
    t = z - packed[TABLE_POSITIONS + low]
    c0, c1, c2, c3 = packed[pieces + 4 * low:pieces + 4 * low + 4]
    return (c0 + t * (c1 + t * (c2 + t * c3)), -(c1 + t * (2.0 * c2 + t * (3.0 * c3))),
            packed[energies + low] - t * (c0 + t * (c1 / 2.0 + t * (c2 / 3.0 + t * (c3 / 4.0)))),
            STATUS_OK)


def check_equilibrium(law: SpringLaw, weight: float, stroke: tuple[float, float], *,
                      hold: float = 0.0) -> float:
    """The stable equilibrium inside the stroke nearest its middle, or a ParameterError.

    A stable equilibrium is a position where the net force ``F(z) + hold - weight`` falls
    through zero as ``z`` rises (a positive stiffness there, or a quasi-zero one whose
    force still falls through it). The stroke is searched at
    :data:`EQUILIBRIUM_SAMPLES` positions (and a table's breakpoints), each crossing refined
    by Brent's method (docs/model.md §3.1).

    Parameters
    ----------
    law : SpringLaw
        The spring.
    weight : float
        The payload's weight m g [N], >= 0.
    stroke : tuple of float
        The lowest and highest relative position [m] the payload may reach.
    hold : float
        A constant upward force the motor adds [N] (e.g. a PI integral's); default 0: the
        spring alone.

    Returns
    -------
    float
        The equilibrium position [m].

    Raises
    ------
    ParameterError
        No stable equilibrium in the stroke (the message gives the force range over the
        stroke and the fix), or bad arguments.
    """
    from scipy.optimize import brentq

    if not isinstance(law, SpringLaw):
        raise ParameterError(f"`law` must be a spring law (TanhSpring, ...), got {law!r}.",
                             ("law",))
    weight = non_negative_real("weight", weight, fix="the payload's mass times g [N]")
    hold = real("hold", hold, fix="a force [N], 0 for the spring alone")
    try:
        low, high = (real("stroke", v) for v in stroke)
    except (TypeError, ValueError):
        raise ParameterError(f"`stroke` must be two positions (low, high) [m], got {stroke!r}; "
                             "e.g. (-0.14, 0.02).", ("stroke",)) from None
    if not low < high:
        raise ParameterError(f"`stroke` must be (low, high) with low < high [m], got "
                             f"{stroke!r}; e.g. (-0.14, 0.02).", ("stroke",))
    first, last = law.domain
    if low < first or high > last:
        raise ParameterError(
            f"`stroke` ({low!r}, {high!r}) m reaches beyond the table [{first!r}, {last!r}] m "
            "of a TabulatedSpring with outside='refuse'; measure the curve over the whole "
            "stroke, or build the law with outside='extend'.", ("stroke",))
    z = np.linspace(low, high, EQUILIBRIUM_SAMPLES)
    if isinstance(law, TabulatedSpring):
        z = np.union1d(z, law.positions[(law.positions > low) & (law.positions < high)])
    load = weight - hold
    net = law.force(z) - load
    sign = np.sign(net)
    found = [brentq(lambda p: float(law.force(p)) - load, z[i], z[i + 1], xtol=1e-15)
             for i in np.flatnonzero((sign[:-1] > 0) & (sign[1:] < 0))]
    for i in np.flatnonzero(sign == 0.0):  # a sample exactly at an equilibrium
        if (i == 0 or sign[i - 1] > 0) and (i == z.size - 1 or sign[i + 1] < 0):
            found.append(float(z[i]))
    if found:
        middle = 0.5 * (low + high)
        return float(min(found, key=lambda p: abs(p - middle)))
    forces = net + load
    least, most = float(forces.min()), float(forces.max())
    if load > most:
        fix = (f"its force over the stroke is at most {most:.6g} N, {load - most:.4g} N short "
               f"of the load: raise the law's force by at least that, or let the motor hold "
               f"the difference (`hold` >= {weight - most:.4g} N)")
    elif load < least:
        fix = (f"its force over the stroke is at least {least:.6g} N, {least - load:.4g} N more "
               f"than the load (it pushes the payload to the upper stop): lower the law's "
               f"force by at least that, or let the motor pull (`hold` <= {weight - least:.4g} N)")
    else:
        where = z[np.argmin(np.abs(net))]
        fix = (f"its force equals the load only where it rises with z (negative stiffness, "
               f"near z = {where:.4g} m): no position is stable; stiffen the law there (an "
               "ObliqueSpringQZS's vertical_stiffness at least its quasi_zero value)")
    raise ParameterError(
        f"`law` ({law.describe()}) has no stable equilibrium inside `stroke` "
        f"[{low:g}, {high:g}] m for `weight` {weight:g} N minus `hold` {hold:g} N; {fix}.",
        ("law", "weight", "hold", "stroke"))
