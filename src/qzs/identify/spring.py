"""The MagSpring's tanh law fitted to static force-displacement pairs (paper Section 2.1.2)."""
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize

from qzs.errors import DataError, ParameterError
from qzs.identify._statistics import student_quantile

__all__ = ["SpringFit", "fit_spring", "CONVENTIONS"]

CONVENTIONS = ("model", "test_machine")


@dataclass(frozen=True)
class SpringFit:
    """Result of :func:`fit_spring`.

    Attributes
    ----------
    spring_force, spring_shape : float
        ``a`` [N] and ``b`` [1/m] in the model's convention (docs/model.md §3: ``F = -a*tanh(b*z)``,
        z upward, a > 0 for a restoring spring).
    spring_force_interval, spring_shape_interval : tuple of float
        Confidence intervals at ``confidence``.
    confidence : float
        Confidence level of the intervals.
    convention : str
        Displacement convention of the input data: ``"model"`` (z = x - y, the spring
        pushes up when compressed, as docs/model.md §1) or ``"test_machine"`` (displacement
        measured the other way round, as the paper's Fig. 5, where the fit reads a < 0).
    residual_rms : float
        RMS of the force residuals [N].
    outliers : tuple of int
        Indices of points whose residual exceeds 4 robust standard deviations.
    """

    spring_force: float
    spring_shape: float
    spring_force_interval: tuple
    spring_shape_interval: tuple
    confidence: float
    convention: str
    residual_rms: float
    outliers: tuple

    def as_paper_reports(self) -> tuple[float, float]:
        """``(a, b)`` as the test machine's convention would print them (paper Fig. 5)."""
        return -self.spring_force, self.spring_shape


def fit_spring(displacement: ArrayLike, force: ArrayLike, *, convention: str = "model",
               confidence: float = 0.95) -> SpringFit:
    """Fit the MagSpring's tanh law to static force-displacement pairs.

    Parameters
    ----------
    displacement : array_like
        Spring displacement [m].
    force : array_like
        Measured spring force [N].
    convention : {"model", "test_machine"}
        Sign convention of ``displacement`` (see :class:`SpringFit`). The result
        is always reported in the model's convention.
    confidence : float
        Level of the confidence intervals (Student t on the Jacobian covariance).

    Returns
    -------
    SpringFit

    Raises
    ------
    DataError
        Mismatched lengths, non-finite samples, fewer than 4 points.
    RuntimeError
        The least-squares fit did not converge.
    """
    if convention not in CONVENTIONS:
        raise ParameterError(f"`convention` must be one of {CONVENTIONS}, got {convention!r}.")
    student_quantile(confidence, 1)  # validates `confidence` before the work
    z = np.asarray(displacement, dtype=float).ravel()
    f = np.asarray(force, dtype=float).ravel()
    if z.shape != f.shape:
        raise DataError(f"`displacement` and `force` must have the same length, got "
                        f"{z.size} and {f.size}.")
    bad = np.count_nonzero(~np.isfinite(z) | ~np.isfinite(f))
    if bad:
        raise DataError(f"{bad} force-displacement pairs are not finite (NaN or inf); "
                        "remove them first.")
    if z.size < 4:
        raise DataError(f"a spring fit needs at least 4 points, got {z.size}.")
    if convention == "test_machine":
        z = -z

    def model(zz, a, b):
        return -a * np.tanh(b * zz)

    span = max(np.ptp(z), 1e-12)
    guess = (max(np.max(np.abs(f)), 1e-9) * np.sign(np.mean(-f * z)) or 1.0, 4.0 / span)
    try:
        params, covariance = optimize.curve_fit(model, z, f, p0=guess, maxfev=20000)
    except RuntimeError as error:
        raise RuntimeError(f"the tanh fit did not converge ({error}); check the data's "
                           "sign convention and that it spans the transition region.") from None
    residual = f - model(z, *params)
    errors = np.sqrt(np.clip(np.diag(covariance), 0, np.inf)) * student_quantile(confidence,
                                                                         max(z.size - 2, 1))
    scale = 1.4826 * np.median(np.abs(residual - np.median(residual)))
    outliers = tuple(int(i) for i in np.flatnonzero(np.abs(residual) > 4 * max(scale, 1e-300)))
    a, b = params
    if b < 0:  # tanh is odd: (a, b) and (-a, -b) are the same law
        a, b = -a, -b
    return SpringFit(float(a), float(b), (float(a - errors[0]), float(a + errors[0])),
                     (float(b - errors[1]), float(b + errors[1])), confidence, convention,
                     float(np.sqrt(np.mean(residual ** 2))), outliers)
