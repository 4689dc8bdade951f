"""The spring laws other than the tanh fitted to force-displacement pairs (docs/model.md §3.1).

:func:`qzs.identify.fit_spring` validates the data and calls one of these; each returns a
:class:`LawFit` (the law, its parameters and intervals, its prediction at the data and the
number of parameters the selection criterion counts). The data are in the model's convention
(``z`` the relative position [m], ``F`` the force on the payload [N], upward positive).

=============  ===========================================================================
law            how it is fitted
=============  ===========================================================================
polynomial     ``F = sum_k c_k (z - center)^k``, linear least squares (columns scaled to
               ``|u| <= 1``); Student-t intervals on ``s^2 (X^T X)^-1``, exact for
               Gaussian noise; ``degree + 1`` parameters
oblique        ``F = P - K u + A u / sqrt(u^2 + d^2)``, ``u = z - center``: the only
               combinations a force curve determines are ``K = k_v + 2 k_o`` and
               ``A = 2 k_o L0`` (``k_o`` and ``L0`` enter as their product), so 5
               parameters (center, P, K, A, d) are fitted: a grid over (center, d) with
               (P, K, A) by linear least squares, then Levenberg-Marquardt on all five;
               linearised Student-t intervals. ``k_v``, ``k_o`` and ``L0`` follow when
               ``free_length`` is given; otherwise the law is the mechanism with ``k_v = 0``
               (every split gives the same force) and those three are undefined
table          a cubic smoothing spline (``scipy.interpolate.make_smoothing_spline``) through
               the mean force at each distinct position (weighted by its count), positions
               scaled to [0, 1]; ``lam`` (or given) minimises the corrected Akaike
               criterion of a linear smoother (Hurvich, Simonoff & Tsai, J. R. Stat. Soc. B
               60 (1998) 271-293) ``ln(RSS/n) + 1 + 2 (tr H + 1) / (n - tr H - 2)`` over
               ``log10 lam`` in [-12, 3], ``tr H`` the trace of the spline's hat matrix;
               the spline is sampled at ``table_points`` evenly spaced positions over the
               data's range as a :class:`TabulatedSpring` (PCHIP, ``outside="refuse"``);
               its parameters are the spline's effective degrees of freedom, ``tr H``.
               (Not scipy's default, generalised cross-validation: where the points barely
               resolve the curve, as 41 points over the MagSpring's stroke, its minimum is
               at ``lam -> 0``, interpolating the noise.)
=============  ===========================================================================
"""
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize
from scipy.interpolate import make_smoothing_spline

from qzs._format import number
from qzs.errors import DataError, FitError
from qzs.identify._protocol import FitProtocol, interval_attributes
from qzs.identify._statistics import fit_covariance, student_quantile
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, SpringLaw, TabulatedSpring

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["LawFit", "fit_polynomial", "fit_oblique", "fit_table", "oblique_force",
           "law_force", "parameter_lines", "pairs_dataset", "record_head", "criterion_record",
           "CRITERION", "OBLIQUE_FITTED",
           "TABLE_LAMBDA_RANGE"]

#: The criterion a fit is compared by (:meth:`LawFit.bic`; ``fit_spring(law="best")``).
CRITERION = "BIC = n ln(RSS/n) + k ln n"

#: The oblique law's fitted parameters, their units, and what each is.
OBLIQUE_FITTED = {"center": ("m", "position where the oblique springs are horizontal"),
                  "preload": ("N", "force at the centre, P"),
                  "far_stiffness": ("N/m", "k_v + 2 k_o, the stiffness far from the centre"),
                  "oblique_force": ("N", "2 k_o L0, the oblique springs' force scale"),
                  "horizontal_distance": ("m", "distance to the hinges, d")}
#: The range of ``log10 lam`` the table's smoothing searches for the least AICc.
TABLE_LAMBDA_RANGE = (-12.0, 3.0)
#: Columns of the identity solved at once for the trace of the smoothing spline's hat matrix.
_TRACE_BLOCK = 256
#: Why a mechanism's springs are not determined by its force curve.
_SPLIT = ("a force curve determines only k_v + 2 k_o and 2 k_o L0 (k_o and L0 enter as their "
          "product): the law is the mechanism with vertical_stiffness = 0, one of the many with "
          "the same force at every z; give free_length = L0 [m] to determine the three")


@dataclass(frozen=True, eq=False)
class LawFit(FitProtocol):
    """One law fitted to force-displacement pairs (what :func:`qzs.identify.fit_spring` makes
    its :class:`~qzs.identify.SpringFit` of).

    Attributes
    ----------
    law : SpringLaw or None
        The law; None when the fitted numbers make no law (``undefined["law"]`` says why).
    parameters : dict of str to float
        Fitted (or derived) parameters.
    intervals : dict of str to tuple of float
        Their confidence intervals at ``confidence``: name -> ``(low, high)``.
    units : dict of str to str
        Their units.
    undefined : dict of str to str
        What is undefined and why.
    predicted : ndarray
        The fitted force at the data [N].
    n_parameters : float
        Parameters the criterion counts (a table's effective degrees of freedom).
    kind : str
        The law fitted: ``"tanh"``, ``"polynomial"``, ``"oblique"`` or ``"table"``.
    displacement, force : ndarray
        The pairs fitted: relative position [m] (model convention), force on the payload [N].
    confidence : float
        Level of the intervals [-].
    """

    law: SpringLaw | None
    parameters: dict
    intervals: dict
    units: dict
    undefined: dict
    predicted: np.ndarray = field(repr=False)
    n_parameters: float
    kind: str = field(kw_only=True)
    displacement: np.ndarray = field(kw_only=True, repr=False)
    force: np.ndarray = field(kw_only=True, repr=False)
    confidence: float = field(kw_only=True)

    _figure = "plot_spring_law_fit"

    @property
    def n_points(self) -> int:
        """Pairs fitted."""
        return int(self.displacement.size)

    @property
    def residual(self) -> np.ndarray:
        """Measured minus fitted force at the data [N]."""
        return self.force - self.predicted

    @property
    def residual_rms(self) -> float:
        """RMS of :attr:`residual` [N]."""
        return float(np.sqrt(np.mean(self.residual ** 2)))

    def bic(self) -> tuple[float, str | None]:
        """The fit's :data:`CRITERION` [-], NaN with the reason where it is undefined.

        Returns
        -------
        value : float
        reason : str or None
            Why ``value`` is NaN; None when it is defined.
        """
        residual = self.residual
        rss = float(residual @ residual)
        n = self.displacement.size
        if n - self.n_parameters < 1.0:
            return math.nan, (f"the law has {self.n_parameters:.4g} parameters for {n} "
                              "points: it follows the noise, and RSS/n no longer "
                              "estimates its variance (smooth the table more)")
        if rss <= 0.0:
            return math.nan, ("the residuals are all zero (the data lie exactly on the "
                              "law): n ln(RSS/n) is -inf")
        return n * math.log(rss / n) + self.n_parameters * math.log(n), None

    @property
    def criterion(self) -> float:
        """:meth:`bic`'s value [-] (NaN where undefined)."""
        return self.bic()[0]

    def predict(self, displacement: ArrayLike) -> NDArray[np.float64]:
        """The fitted force at ``displacement`` [N], even when ``law`` is None
        (:func:`law_force`).

        Parameters
        ----------
        displacement : float or array_like
            Relative position [m], model convention.

        Returns
        -------
        ndarray
        """
        return law_force(self.kind, self.law, self.parameters, displacement)

    def summary(self) -> str:
        """The fit as text: its law, parameters with intervals, residual and criterion.

        Returns
        -------
        str
        """
        lines = [f"{self.kind} law fitted to {self.n_points} points (model convention)",
                 *parameter_lines(self),
                 f"  residual rms {number(self.residual_rms, 4, 'N')}; BIC "
                 f"{number(self.criterion, 6)} (k = {self.n_parameters:.4g})",
                 "  law: " + (self.law.describe() if self.law is not None else "none")]
        lines += [f"  {name} undefined: {why}" for name, why in self.undefined.items()]
        return "\n".join(lines)

    def to_record(self) -> dict[str, Any]:
        """The fit as plain data (what :meth:`save` writes as JSON; NaN as None).

        Returns
        -------
        dict
        """
        return {**record_head(self), "residual_rms": self.residual_rms,
                "criterion": criterion_record(self)}

    def to_xarray(self) -> "xr.Dataset":
        """The pairs fitted on ``point`` (:func:`pairs_dataset`, CF-1.10, units on each).

        Returns
        -------
        xarray.Dataset
        """
        return pairs_dataset(self, f"{self.kind} law fitted (qzs.identify.spring_laws)")


def record_head(fit: Any) -> dict[str, Any]:
    """The head of a spring fit's record: kind, law, parameters, intervals, units, what is
    undefined, the confidence level.

    Parameters
    ----------
    fit : LawFit or SpringFit
        The fit.

    Returns
    -------
    dict
    """
    return {"kind": fit.kind, "law": None if fit.law is None else fit.law.to_dict(),
            "parameters": dict(fit.parameters),
            "intervals": {k: list(v) for k, v in fit.intervals.items()},
            "units": dict(fit.units), "undefined": dict(fit.undefined),
            "confidence": fit.confidence}


def criterion_record(fit: Any) -> dict[str, Any]:
    """A spring fit's criterion as plain data: name, value [-], points and parameters.

    Parameters
    ----------
    fit : LawFit or SpringFit
        The fit.

    Returns
    -------
    dict
    """
    return {"name": CRITERION, "value": fit.criterion, "n_points": fit.n_points,
            "n_parameters": fit.n_parameters}


def law_force(kind: str, law: SpringLaw | None, parameters: Mapping[str, float],
              displacement: ArrayLike) -> NDArray[np.float64]:
    """A fitted law's force at ``displacement`` [N]: the law's, or, where the fitted numbers
    made none, the tanh's or the mechanism's formula of its parameters.

    Parameters
    ----------
    kind : str
        The law fitted.
    law : SpringLaw or None
        The law made of the fit.
    parameters : dict
        The fitted parameters (the tanh's ``plateau``, ``shape``; the mechanism's).
    displacement : float or array_like
        Relative position [m], model convention.

    Returns
    -------
    ndarray
        Force on the payload [N].
    """
    z = np.asarray(displacement, dtype=float)
    if law is not None:
        return law.force(z)
    if kind == "tanh":
        return -parameters["plateau"] * np.tanh(parameters["shape"] * z)
    p = parameters
    return oblique_force(z - p["center"], p["preload"], p["far_stiffness"],
                         p["oblique_force"], p["horizontal_distance"])


def parameter_lines(fit: Any) -> list[str]:
    """A fit's parameters as text lines, each with its unit and interval.

    Parameters
    ----------
    fit : LawFit or SpringFit
        The fit (``parameters``, ``units``, ``intervals``, ``confidence``).

    Returns
    -------
    list of str
    """
    percent = f"{100 * fit.confidence:g} %"
    lines = []
    for name, value in fit.parameters.items():
        unit = fit.units.get(name, "")
        low, high = fit.intervals.get(name, (None, None))
        where = (f"  [{number(low, 4)}, {number(high, 4)}] {unit} ({percent})"
                 if name in fit.intervals else "")
        lines.append(f"  {name} = {number(value, 6, unit)}{where}")
    return lines


def pairs_dataset(fit: Any, title: str, **attrs: Any) -> "xr.Dataset":
    """A spring fit's pairs as an ``xarray.Dataset`` on ``point`` (CF-1.10, units on each).

    ``displacement`` [m] (model convention), ``force`` and ``residual`` [N]; the law,
    ``attrs``, the residual's RMS, the parameters, their intervals (``<name>_lower``,
    ``<name>_upper``) and units, and ``confidence_level`` as global attributes.

    Parameters
    ----------
    fit : LawFit or SpringFit
        The fit.
    title : str
        The dataset's title.
    **attrs
        Further global attributes, after the law's.

    Returns
    -------
    xarray.Dataset
    """
    from qzs.iotools.schema import Schema, Variable, to_dataset

    schema = Schema(kind="a spring fit", dimensions={"point": None}, variables=(
        Variable(name="displacement", dims=("point",), units="m",
                 long_name="relative position z (model convention)"),
        Variable(name="force", dims=("point",), units="N",
                 long_name="measured spring force on the payload"),
        Variable(name="residual", dims=("point",), units="N",
                 long_name="measured minus fitted force")))
    head = {"title": title, "law": fit.kind, **attrs,
            "residual_rms": fit.residual_rms, "residual_rms_units": "N",
            **interval_attributes(fit, lambda name: fit.units.get(name, ""))}
    return to_dataset(schema, {"displacement": fit.displacement, "force": fit.force,
                               "residual": fit.residual}, head)


def _intervals(names, values, covariance, confidence, dof):
    """Student-t intervals ``value -+ t * sqrt(var)``; infinite where the data do not determine."""
    half = np.sqrt(np.clip(np.diag(covariance), 0.0, np.inf)) * student_quantile(confidence, dof)
    return {n: (float(v - h), float(v + h)) for n, v, h in zip(names, values, half)}


def _distinct(z, needed, law, why):
    count = np.unique(z).size
    if count < needed:
        raise DataError(f"a {law} spring fit needs at least {needed} distinct positions in "
                        f"`displacement` ({why}), got {count}; measure more positions.")


def fit_polynomial(z, f, degree, center, confidence):
    """The polynomial of ``degree`` about ``center`` by linear least squares (module docstring).

    Parameters
    ----------
    z : ndarray
        Relative positions [m], model convention, finite.
    f : ndarray
        Forces on the payload [N], finite, as many.
    degree : int
        Degree, >= 1.
    center : float or None
        Position the powers are taken about [m]; None: the middle of the data's range.
    confidence : float
        Level of the intervals.

    Returns
    -------
    LawFit
    """
    k = degree + 1
    _distinct(z, k, "polynomial", f"one per coefficient of degree {degree}")
    center = 0.5 * (float(z.min()) + float(z.max())) if center is None else center
    u = z - center
    scale = float(np.max(np.abs(u))) or 1.0
    design = np.vander(u / scale, k, increasing=True)
    scaled, *_ = np.linalg.lstsq(design, f, rcond=None)
    predicted = design @ scaled
    covariance, dof = fit_covariance(design, f - predicted, k)
    powers = scale ** np.arange(k)
    coefficients = scaled / powers
    covariance = covariance / np.outer(powers, powers)
    names = [f"c{i}" for i in range(k)]
    units = {n: "N" if i == 0 else "N/m" if i == 1 else f"N/m^{i}" for i, n in enumerate(names)}
    parameters = {n: float(c) for n, c in zip(names, coefficients)}
    parameters["center"] = float(center)
    units["center"] = "m"
    return LawFit(PolynomialSpring(coefficients=coefficients, center=center), parameters,
                  _intervals(names, coefficients, covariance, confidence, dof), units,
                  {"center": "chosen, not fitted: the position the powers are taken about"},
                  predicted, float(k), kind="polynomial", displacement=z, force=f,
                  confidence=confidence)


def oblique_force(u, preload, far, amplitude, distance):
    """The mechanism's force from its determined parameters: ``P - K u + A u / sqrt(u^2 + d^2)``.

    Parameters
    ----------
    u : ndarray
        Position from the centre, ``z - center`` [m].
    preload : float
        P [N].
    far : float
        K = k_v + 2 k_o [N/m].
    amplitude : float
        A = 2 k_o L0 [N].
    distance : float
        d [m].

    Returns
    -------
    ndarray
        Force on the payload [N].
    """
    return preload - far * u + amplitude * u / np.hypot(u, distance)


def fit_oblique(z, f, free_length, confidence):
    """The three-spring mechanism's five determined parameters, and its law (module docstring).

    Parameters
    ----------
    z : ndarray
        Relative positions [m], model convention, finite.
    f : ndarray
        Forces on the payload [N], finite, as many.
    free_length : float or None
        The oblique springs' free length L0 [m] if known: then k_v and k_o are determined.
    confidence : float
        Level of the intervals.

    Returns
    -------
    LawFit
    """
    _distinct(z, 5, "oblique", "five parameters: centre, preload, k_v + 2 k_o, 2 k_o L0, d")
    low, high = float(z.min()), float(z.max())
    span = high - low
    best = (np.inf, None)
    # a mechanism of springs: k_v + 2 k_o >= 0 and 2 k_o L0 >= 0 (a curve fitted better by a
    # negative spring is no mechanism; the search keeps to the springs that exist)
    floor = (-np.inf, 0.0, 0.0)
    for center in np.linspace(low, high, 41):  # (P, K, A) are linear once (center, d) are set
        u = z - center
        for distance in np.geomspace(span / 100.0, span * 10.0, 31):
            design = np.column_stack([np.ones_like(u), -u, u / np.hypot(u, distance)])
            linear = optimize.lsq_linear(design, f, bounds=(floor, np.inf)).x
            cost = float(np.sum((design @ linear - f) ** 2))
            if cost < best[0]:
                best = (cost, (center, *linear, distance))

    def residual(x):
        return oblique_force(z - x[0], *x[1:]) - f

    def jacobian(x):
        center, _, far, amplitude, distance = x
        u = z - center
        length = np.hypot(u, distance)
        cube = length ** 3
        return np.column_stack([far - amplitude * distance ** 2 / cube, np.ones_like(u), -u,
                                u / length, -amplitude * u * distance / cube])

    start = np.clip(best[1], (-np.inf, -np.inf, 0.0, 0.0, 1e-12), np.inf)
    solution = optimize.least_squares(residual, start, jac=jacobian, method="trf",
                                      bounds=((-np.inf, -np.inf, 0.0, 0.0, 1e-12), np.inf),
                                      x_scale="jac", max_nfev=20000)
    if not solution.success:
        raise FitError(f"the oblique-spring fit did not converge ({solution.message}); check "
                       "that the data span the mechanism's centre.")
    values = solution.x.copy()
    values[4] = abs(values[4])  # d enters squared
    names = list(OBLIQUE_FITTED)
    covariance, dof = fit_covariance(jacobian(values), solution.fun, 5)
    parameters = dict(zip(names, map(float, values)))
    intervals = _intervals(names, values, covariance, confidence, dof)
    units = {n: unit for n, (unit, _) in OBLIQUE_FITTED.items()}
    center, preload, far, amplitude, distance = values
    predicted = oblique_force(z - center, preload, far, amplitude, distance)
    undefined = {}
    if free_length is None:
        law = None
        if far > 0.0 and amplitude > 0.0:
            law = ObliqueSpringQZS(vertical_stiffness=0.0, oblique_stiffness=far / 2.0,
                                   free_length=amplitude / far, horizontal_distance=distance,
                                   center=center, preload=preload)
        for name in ("vertical_stiffness", "oblique_stiffness", "free_length"):
            undefined[name] = _SPLIT
    else:
        oblique, vertical = amplitude / (2.0 * free_length), far - amplitude / free_length
        parameters.update(vertical_stiffness=float(vertical), oblique_stiffness=float(oblique),
                          free_length=float(free_length))
        units.update(vertical_stiffness="N/m", oblique_stiffness="N/m", free_length="m")
        undefined["free_length"] = "given, not fitted"
        # k_v = K - A / L0 and k_o = A / (2 L0) are linear in (K, A): their covariance
        block = covariance[2:4, 2:4]
        derived = np.array([[1.0, -1.0 / free_length], [0.0, 0.5 / free_length]])
        spread = (derived @ block @ derived.T if np.all(np.isfinite(block))
                  else np.diag([np.inf, np.inf]))  # (K, A) not determined by the data
        intervals.update(_intervals(["vertical_stiffness", "oblique_stiffness"],
                                    [vertical, oblique], spread, confidence, dof))
        law = None
        if vertical >= 0.0 and oblique >= 0.0:
            law = ObliqueSpringQZS(vertical_stiffness=vertical, oblique_stiffness=oblique,
                                   free_length=free_length, horizontal_distance=distance,
                                   center=center, preload=preload)
    if law is None:
        undefined["law"] = _oblique_refusal(far, amplitude, free_length)
    return LawFit(law, parameters, intervals, units, undefined, predicted, 5.0, kind="oblique",
                  displacement=z, force=f, confidence=confidence)


def _oblique_refusal(far, amplitude, free_length):
    """Why the fitted numbers make no mechanism of springs of non-negative stiffness."""
    if amplitude <= 0.0:
        return (f"the fit's 2 k_o L0 = {amplitude:.4g} N is not positive: no oblique springs "
                "of positive stiffness and length give this curve (its slope near the centre "
                "falls, where compressed oblique springs make it rise); fit another law")
    if far <= 0.0:
        return (f"the fit's k_v + 2 k_o = {far:.4g} N/m is not positive: no springs of "
                "non-negative stiffness give it; fit another law")
    return (f"with free_length = {free_length:g} m the vertical spring's stiffness would be "
            f"{far - amplitude / free_length:.4g} N/m < 0; the data need free_length >= "
            f"{amplitude / far:.4g} m (2 k_o L0 / (k_v + 2 k_o)), or leave it out")


def _hat_trace(s, weights, lam):
    """Trace of the smoothing spline's hat matrix at ``lam``: its effective parameters."""
    m = s.size
    total = 0.0
    for start in range(0, m, _TRACE_BLOCK):
        columns = np.arange(start, min(start + _TRACE_BLOCK, m))
        unit = np.zeros((m, columns.size))
        unit[columns, np.arange(columns.size)] = 1.0
        spline = make_smoothing_spline(s, unit, w=weights, lam=lam)
        total += float(np.trace(spline(s[columns])))
    return total


def fit_table(z, f, smoothing, points, confidence=0.95):
    """A smoothing spline's forces at ``points`` positions: a :class:`TabulatedSpring`.

    Parameters
    ----------
    z : ndarray
        Relative positions [m], model convention, finite.
    f : ndarray
        Forces on the payload [N], finite, as many.
    smoothing : float or "aicc"
        The spline's penalty weight (positions scaled to [0, 1]), or ``"aicc"`` to choose it
        (module docstring).
    points : int
        Positions of the table, evenly spaced over the data's range.
    confidence : float
        The level a fit states [-] (a table has no parameter intervals).

    Returns
    -------
    LawFit
    """
    _distinct(z, 5, "table", "the smoothing spline's least")
    positions, inverse, counts = np.unique(z, return_inverse=True, return_counts=True)
    means = np.bincount(inverse, weights=f) / counts
    within = float(np.sum((f - means[inverse]) ** 2))  # what no curve through z can remove
    origin, span = float(positions[0]), float(positions[-1] - positions[0])
    scaled = (positions - origin) / span
    weights = counts.astype(float)

    def smooth(log_lam):
        spline = make_smoothing_spline(scaled, means, w=weights, lam=10.0 ** log_lam)
        rss = within + float(weights @ (means - spline(scaled)) ** 2)
        return spline, rss, _hat_trace(scaled, weights, 10.0 ** log_lam)

    def criterion(log_lam):  # Hurvich, Simonoff & Tsai's AICc of a linear smoother
        _, rss, trace = smooth(log_lam)
        if trace >= f.size - 2.0 or rss <= 0.0:
            return np.inf
        return math.log(rss / f.size) + 1.0 + 2.0 * (trace + 1.0) / (f.size - trace - 2.0)

    if smoothing == "aicc":
        grid = np.linspace(*TABLE_LAMBDA_RANGE, 16)
        scores = [criterion(x) for x in grid]
        i = int(np.argmin(scores))
        bracket = (grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)])
        found = optimize.minimize_scalar(criterion, bounds=bracket, method="bounded",
                                         options={"xatol": 0.01})
        log_lam = float(found.x) if found.fun <= scores[i] else float(grid[i])
    else:
        log_lam = float(np.log10(smoothing)) if smoothing > 0.0 else -np.inf
    spline, _, trace = smooth(log_lam)
    table = np.linspace(positions[0], positions[-1], points)
    law = TabulatedSpring(positions=table, forces=spline((table - origin) / span))
    parameters = {"smoothing": float(10.0 ** log_lam), "effective_parameters": trace}
    units = {"smoothing": "-", "effective_parameters": "-"}
    undefined = {"intervals": "a smoothed table has no parameter intervals: its forces are a "
                              "smoother's output, biased by the smoothing"}
    return LawFit(law, parameters, {}, units, undefined, law.force(z), trace, kind="table",
                  displacement=z, force=f, confidence=confidence)
