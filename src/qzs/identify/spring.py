"""A spring law fitted to static force-displacement pairs (paper Section 2.1.2, docs/model.md §3).

:func:`fit_spring` fits the MagSpring's tanh (the paper's Fig. 5, as it always has), a
polynomial, the three-spring QZS mechanism or a smoothed table (how: :mod:`qzs.identify.
spring_laws`), or all four, choosing the one of least Bayesian information criterion

    ``BIC = n ln(RSS / n) + k ln n``

(Gaussian residuals of one variance; ``n`` pairs, ``RSS`` the residual sum of squares [N^2],
``k`` the parameters: 2 for the tanh, ``degree + 1`` for the polynomial, 5 for the mechanism,
the smoothing spline's effective degrees of freedom, the trace of its hat matrix, for the
table). Lower is better; a difference above 10 is strong evidence.
"""
import dataclasses
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from qzs._format import number
from qzs._validation import choice, integer, positive_real, real
from qzs.errors import DataError, FitError, ParameterError
from qzs._validation import deprecated_alias
from qzs.identify._protocol import FitProtocol
from qzs.identify._statistics import student_quantile
from qzs.identify.spring_laws import (CRITERION, LawFit, criterion_record, fit_oblique,
                                      fit_polynomial, fit_table, law_force, pairs_dataset,
                                      parameter_lines, record_head)
from qzs.model.springs import TABLE_MIN_POINTS, SpringLaw, TanhSpring

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["SpringFit", "fit_spring", "CONVENTIONS", "LAWS", "CRITERION"]

CONVENTIONS = ("model", "test_machine")
#: What ``fit_spring(law=...)`` fits: a law by its name, or ``"best"`` of them all.
LAWS = ("tanh", "polynomial", "oblique", "table", "best")
#: Files :meth:`SpringFit.save` writes.
SPRING_FIT_SUFFIXES = (*FitProtocol.save_suffixes, ".toml")
_NAN_PAIR = (math.nan, math.nan)


@dataclass(frozen=True, eq=False)
class SpringFit(FitProtocol):
    """Result of :func:`fit_spring`.

    Every number is in the model's convention and SI units; a number that does not apply is
    NaN, with the reason in ``undefined``.

    Attributes
    ----------
    spring_force, spring_shape : float
        ``a`` [N] and ``b`` [1/m] in the model's convention (docs/model.md §3: ``F = -a*tanh(b*z)``,
        z upward, a > 0 for a restoring spring). NaN when another law was fitted.
    confidence : float
        Confidence level of the intervals [-] (0.95).
    convention : str
        Displacement convention of the input data: ``"model"`` (z = x - y, the spring
        pushes up when compressed, as docs/model.md §1) or ``"test_machine"`` (displacement
        measured the other way round, as the paper's Fig. 5, where the fit reads a < 0).
    residual_rms : float
        RMS of the force residuals [N].
    outliers : tuple of int
        Indices of points whose residual exceeds 4 robust standard deviations.
    kind : str
        The law fitted: ``"tanh"``, ``"polynomial"``, ``"oblique"`` or ``"table"``.
    law : SpringLaw or None
        The fitted law, ready for ``IsolatorParameters(spring=law)``; None when the fitted
        numbers make no law (a tanh whose ``a < 0``, a mechanism of a negative stiffness),
        ``undefined["law"]`` saying why.
    parameters : Mapping[str, float]
        The fitted parameters by name (the tanh: ``plateau``, ``shape``; the polynomial:
        ``c0``, ``c1``, ... and ``center``; the mechanism: ``center``, ``preload``,
        ``far_stiffness`` = k_v + 2 k_o, ``oblique_force`` = 2 k_o L0,
        ``horizontal_distance``, and with ``free_length`` given ``vertical_stiffness``,
        ``oblique_stiffness``, ``free_length``; the table: ``smoothing`` and
        ``effective_parameters``).
    intervals : Mapping[str, tuple of float]
        Parameter name -> (low, high) confidence interval at ``confidence``, in its unit
        (Student t on the linearised covariance; infinite where the data do not determine
        it). A parameter without one is named in ``undefined``. (``spring_force_interval``
        and ``spring_shape_interval``, deprecated, are ``intervals["plateau"]`` and
        ``intervals["shape"]`` of the tanh.)
    units : Mapping[str, str]
        Parameter name -> unit.
    undefined : Mapping[str, str]
        What is undefined (NaN or left out) and why.
    criterion : float
        The fit's BIC (:data:`CRITERION`) [-].
    n_points : int
        Force-displacement pairs fitted.
    n_parameters : float
        ``k`` of the criterion: the parameters (a table's effective degrees of freedom).
    candidates : Mapping[str, SpringFit]
        With ``law="best"``: every law that made a law, by name, the chosen one among them;
        empty otherwise.
    rejected : Mapping[str, str]
        With ``law="best"``: the laws that made none, and why.
    displacement, force : ndarray
        The pairs fitted, ``displacement`` [m] in the model's convention, ``force`` [N].
    residual : ndarray
        Measured minus fitted force [N].
    """

    spring_force: float
    spring_shape: float
    confidence: float
    convention: str
    residual_rms: float
    outliers: tuple
    kind: str
    law: SpringLaw | None
    parameters: Mapping[str, float]
    intervals: Mapping[str, tuple]
    units: Mapping[str, str]
    undefined: Mapping[str, str]
    criterion: float
    n_points: int
    n_parameters: float
    candidates: Mapping[str, "SpringFit"]
    rejected: Mapping[str, str]
    displacement: np.ndarray = dataclasses.field(repr=False)
    force: np.ndarray = dataclasses.field(repr=False)
    residual: np.ndarray = dataclasses.field(repr=False)

    _figure = "plot_spring_law_fit"
    save_suffixes = SPRING_FIT_SUFFIXES
    spring_force_interval = deprecated_alias(
        "spring_force_interval", "intervals['plateau']",
        lambda fit: fit.intervals.get("plateau", _NAN_PAIR) if fit.kind == "tanh" else _NAN_PAIR)
    spring_shape_interval = deprecated_alias(
        "spring_shape_interval", "intervals['shape']",
        lambda fit: fit.intervals.get("shape", _NAN_PAIR) if fit.kind == "tanh" else _NAN_PAIR)

    def as_paper_reports(self) -> tuple[float, float]:
        """``(a, b)`` as the test machine's convention would print them (paper Fig. 5)."""
        return -self.spring_force, self.spring_shape

    def predict(self, displacement: ArrayLike) -> NDArray[np.float64]:
        """The fitted force at ``displacement`` [N], even when ``law`` is None.

        Parameters
        ----------
        displacement : float or array_like
            Relative position [m], in the model's convention.

        Returns
        -------
        ndarray
            Force on the payload [N].
        """
        return law_force(self.kind, self.law, self.parameters, displacement)

    def summary(self) -> str:
        """The fit as text: law, parameters with intervals, residual, criterion, candidates."""
        lines = [f"spring fit: {self.kind} law, {self.n_points} points ({self.convention} "
                 f"convention, reported in the model's)", *parameter_lines(self)]
        lines.append(f"  residual rms {number(self.residual_rms, 4, 'N')}; BIC "
                     f"{number(self.criterion, 6)} (k = {self.n_parameters:.4g})")
        lines.append("  outliers (|residual| > 4 robust sd): "
                     + (", ".join(map(str, self.outliers)) or "none"))
        lines.append("  law: " + (self.law.describe() if self.law is not None else "none"))
        for name, why in self.undefined.items():
            lines.append(f"  {name} undefined: {why}")
        if self.candidates:
            lines.append(f"  candidates by {CRITERION} (lowest chosen):")
            for kind, fit in sorted(self.candidates.items(), key=lambda c: c[1].criterion):
                mark = "  <- chosen" if kind == self.kind else ""
                lines.append(f"    {kind:<10} BIC {number(fit.criterion, 6):>10}, k = "
                             f"{fit.n_parameters:.4g}, residual rms "
                             f"{number(fit.residual_rms, 4, 'N')}{mark}")
        for kind, why in self.rejected.items():
            lines.append(f"    {kind:<10} not a candidate: {why}")
        return "\n".join(lines)

    def to_record(self) -> dict[str, Any]:
        """The fit as plain data (what :meth:`save` writes as JSON; NaN as None).

        Returns
        -------
        dict
        """
        return {**record_head(self), "convention": self.convention,
                "residual_rms": self.residual_rms, "outliers": list(self.outliers),
                "criterion": criterion_record(self),
                "candidates": {k: {"criterion": f.criterion, "n_parameters": f.n_parameters,
                                   "residual_rms": f.residual_rms}
                               for k, f in self.candidates.items()},
                "rejected": dict(self.rejected)}

    def to_xarray(self) -> "xr.Dataset":
        """The pairs fitted as an ``xarray.Dataset`` on ``point`` (CF-1.10, units on each).

        ``displacement`` [m] (model convention), ``force`` and ``residual`` [N]; the law, its
        parameters, their intervals (``<name>_lower``, ``<name>_upper``) and units, and
        ``confidence_level`` as global attributes.

        Returns
        -------
        xarray.Dataset
        """
        return pairs_dataset(self, f"spring fit (qzs.fit_spring): {self.kind} law",
                             convention=self.convention)

    def _writers(self) -> dict[str, Any]:
        """``.toml``: the law as a ``[spring]`` table, what ``qzs simulate --spring`` reads."""
        return {".toml": self._write_toml}

    def _write_toml(self, path: Path) -> Path:
        from qzs.iotools.config import spring_text
        from qzs.iotools.files import write_text

        if self.law is None:
            raise ParameterError(f"`path` {str(path)!r}: this {self.kind} fit made no law "
                                 f"({self.undefined.get('law', '')}), so there is no "
                                 "[spring] table to write; save it as .json.", ("path",))
        text = spring_text(self.law, note=f"fitted by qzs.fit_spring to {self.n_points} "
                           f"points, residual rms {self.residual_rms:.4g} N")
        return write_text(path, text)


def _tanh(z, f, confidence):
    """The MagSpring's tanh: ``(a, b, a_interval, b_interval, LawFit)``."""
    def model(zz, a, b):
        return -a * np.tanh(b * zz)

    span = max(np.ptp(z), 1e-12)
    guess = (max(np.max(np.abs(f)), 1e-9) * np.sign(np.mean(-f * z)) or 1.0, 4.0 / span)
    try:
        params, covariance = optimize.curve_fit(model, z, f, p0=guess, maxfev=20000)
    except RuntimeError as error:
        raise FitError(f"the tanh fit did not converge ({error}); check the data's "
                       "sign convention and that it spans the transition region.") from None
    errors = np.sqrt(np.clip(np.diag(covariance), 0, np.inf)) * student_quantile(confidence,
                                                                         max(z.size - 2, 1))
    a, b = params
    if b < 0:  # tanh is odd: (a, b) and (-a, -b) are the same law
        a, b = -a, -b
    a_interval = (float(a - errors[0]), float(a + errors[0]))
    b_interval = (float(b - errors[1]), float(b + errors[1]))
    law, undefined = None, {}
    if a >= 0.0 and b > 0.0:
        law = TanhSpring(plateau=float(a), shape=float(b))
    else:
        undefined["law"] = (f"the fitted a = {a:.6g} N is negative: in the model's convention "
                            "(docs/model.md §1) these data push away from z = 0; if the "
                            "displacement was measured the other way round, pass "
                            "convention='test_machine'")
    fitted = LawFit(law, {"plateau": float(a), "shape": float(b)},
                    {"plateau": a_interval, "shape": b_interval},
                    {"plateau": "N", "shape": "1/m"}, undefined, model(z, *params), 2.0,
                    kind="tanh", displacement=z, force=f, confidence=confidence)
    return float(a), float(b), a_interval, b_interval, fitted


def _minimum_points(kind, degree):
    """The least pairs a law takes, and why: one more than its parameters."""
    return {"tanh": (4, "two parameters and the residual's spread"),
            "polynomial": (degree + 2, f"{degree + 1} coefficients and the residual's spread"),
            "oblique": (6, "five parameters and the residual's spread"),
            "table": (6, "the smoothing spline's five and the residual's spread")}[kind]


def _check_points(kinds, n, degree):
    """A DataError unless ``n`` pairs are enough for one of ``kinds``."""
    least, why = min(_minimum_points(kind, degree) for kind in kinds)
    if n < least:
        law = f"the {kinds[0]} law" if len(kinds) == 1 else "any law"
        raise DataError(f"a spring fit needs at least {least} points for {law} ({why}), got "
                        f"{n} in `displacement` and `force`; measure more points.")


def _fit_one(kind, z, f, convention, confidence, degree, center, smoothing, free_length,
             table_points):
    """One law fitted: a :class:`SpringFit` with its criterion."""
    _check_points((kind,), z.size, degree)
    old = {}
    if kind == "tanh":
        a, b, _, _, fitted = _tanh(z, f, confidence)
    else:
        a = b = math.nan
        old = {name: f"the fitted law is {kind!r}, not the tanh: see `law` and `parameters`"
               for name in ("spring_force", "spring_shape")}
        if kind == "polynomial":
            fitted = fit_polynomial(z, f, degree, center, confidence)
        elif kind == "oblique":
            fitted = fit_oblique(z, f, free_length, confidence)
        else:
            fitted = fit_table(z, f, smoothing, table_points, confidence)
    residual = fitted.residual
    n = z.size
    undefined = {**old, **fitted.undefined}
    criterion, why = fitted.bic()
    if why is not None:
        undefined["criterion"] = why
    scale = 1.4826 * np.median(np.abs(residual - np.median(residual)))
    outliers = tuple(int(i) for i in np.flatnonzero(np.abs(residual) > 4 * max(scale, 1e-300)))
    return SpringFit(a, b, confidence, convention, fitted.residual_rms, outliers, kind, fitted.law,
                     dict(fitted.parameters), dict(fitted.intervals), dict(fitted.units),
                     undefined, criterion, n, fitted.n_parameters, {}, {}, z, f, residual)


def _fit_best(z, f, *options):
    """Every law fitted; the one of least criterion among those that make a law."""
    candidates, rejected, caught = {}, {}, {}
    for kind in LAWS[:-1]:
        with warnings.catch_warnings(record=True) as heard:
            warnings.simplefilter("always")
            try:
                fit = _fit_one(kind, z, f, *options)
            except (DataError, FitError) as error:
                rejected[kind] = str(error)
                continue
        if fit.law is None or math.isnan(fit.criterion):
            rejected[kind] = fit.undefined["law" if fit.law is None else "criterion"]
        else:
            candidates[kind], caught[kind] = fit, heard
    if not candidates:
        raise FitError("no spring law fits these data: " + "; ".join(
            f"{kind}: {why}" for kind, why in rejected.items()))
    chosen = min(candidates.values(), key=lambda fit: fit.criterion)
    for heard in caught[chosen.kind]:  # the chosen fit's warnings, not the others'
        warnings.warn_explicit(heard.message, heard.category, heard.filename, heard.lineno)
    return dataclasses.replace(chosen, candidates=candidates, rejected=rejected)


def _smoothing(value):
    if isinstance(value, str):
        return choice("smoothing", value, ("aicc",),
                      fix="or give a number >= 0, the spline's penalty weight")
    return real("smoothing", value, minimum=0.0,
                fix="the spline's penalty weight (positions scaled to [0, 1]), or 'aicc'")


def fit_spring(displacement: ArrayLike, force: ArrayLike, *, law: str = "tanh",
               convention: str = "model", confidence: float = 0.95, degree: int = 3,
               center: float | None = None, smoothing: float | str = "aicc",
               free_length: float | None = None, table_points: int = 101) -> SpringFit:
    """Fit a spring law to static force-displacement pairs.

    ``law="tanh"`` (the default) fits the MagSpring's ``F = -a tanh(b z)`` (paper Fig. 5);
    ``"polynomial"``, ``"oblique"`` and ``"table"`` fit those laws (:mod:`qzs.identify.
    spring_laws` says how); ``"best"`` fits all four and returns the one of least
    :data:`CRITERION` among those that make a law (``candidates`` holds them all).

    Parameters
    ----------
    displacement : array_like
        Spring displacement [m].
    force : array_like
        Measured spring force [N].
    law : {"tanh", "polynomial", "oblique", "table", "best"}
        The law to fit.
    convention : {"model", "test_machine"}
        Sign convention of ``displacement`` (see :class:`SpringFit`). The result
        is always reported in the model's convention.
    confidence : float
        Level of the confidence intervals (Student t on the Jacobian covariance).
    degree : int
        The polynomial's degree, >= 1.
    center : float, optional
        Position the polynomial's powers are taken about [m]; default the middle of the
        data's range.
    smoothing : float or "aicc"
        The table's smoothing spline's penalty weight ``lam`` >= 0 (positions scaled to
        [0, 1], so ``lam`` is dimensionless; 0 interpolates the mean forces), or ``"aicc"``:
        the ``lam`` of least corrected Akaike criterion (:mod:`qzs.identify.spring_laws`).
    free_length : float, optional
        The mechanism's oblique springs' free length L0 [m], known from its build: with it
        the fit determines ``vertical_stiffness`` and ``oblique_stiffness`` too (a force curve
        alone determines only k_v + 2 k_o and 2 k_o L0).
    table_points : int
        Positions of the table, evenly spaced over the data's range, >= 3.

    Returns
    -------
    SpringFit

    Raises
    ------
    ParameterError
        An unknown ``law`` or ``convention``, a bad ``confidence``, ``degree``, ``center``,
        ``smoothing``, ``free_length`` or ``table_points``.
    DataError
        Mismatched lengths, non-finite samples, fewer points (or distinct positions) than
        the law needs.
    FitError
        The least-squares fit did not converge (with ``"best"``: no law fitted).
    """
    law = choice("law", law, LAWS, fix="'best' fits them all and chooses by BIC")
    if convention not in CONVENTIONS:
        raise ParameterError(f"`convention` must be one of {CONVENTIONS}, got {convention!r}.")
    student_quantile(confidence, 1)  # validates `confidence` before the work
    degree = integer("degree", degree, 1, fix="e.g. 3 for a cubic (Duffing) spring")
    if center is not None:
        center = real("center", center, fix="a position [m], or None for the data's middle")
    smoothing = _smoothing(smoothing)
    if free_length is not None:
        free_length = positive_real("free_length", free_length,
                                    fix="the oblique springs' free length [m], or None")
    table_points = integer("table_points", table_points, TABLE_MIN_POINTS,
                           fix="e.g. 101 positions over the data's range")
    z = np.asarray(displacement, dtype=float).ravel()
    f = np.asarray(force, dtype=float).ravel()
    if z.shape != f.shape:
        raise DataError(f"`displacement` and `force` must have the same length, got "
                        f"{z.size} and {f.size}.")
    bad = np.count_nonzero(~np.isfinite(z) | ~np.isfinite(f))
    if bad:
        raise DataError(f"{bad} force-displacement pairs are not finite (NaN or inf); "
                        "remove them first.")
    if convention == "test_machine":
        z = -z
    options = (convention, confidence, degree, center, smoothing, free_length, table_points)
    if law == "best":
        _check_points(LAWS[:-1], z.size, degree)
        return _fit_best(z, f, *options)
    return _fit_one(law, z, f, *options)
