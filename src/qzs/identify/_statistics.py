"""Confidence intervals of least-squares fits: covariance of the Jacobian, Student-t quantile.

All intervals are Student-t intervals on the covariance ``s^2 (J^T J)^-1`` of the
least-squares Jacobian ``J`` at the optimum (``s^2`` the residual variance): they assume
independent residuals of equal variance, and are local (linearised) intervals.
"""
import warnings

import numpy as np
from scipy import stats

from qzs._validation import finite_series
from qzs.errors import DataError, FitWarning, ParameterError


def fit_covariance(jacobian, residual, n_parameters):
    """``s^2 (J^T J)^-1`` and degrees of freedom; warns if J is (nearly) rank-deficient.

    A parameter with a component along a direction the data do not determine gets an
    infinite variance.
    """
    dof = residual.size - n_parameters
    variance = float(residual @ residual) / dof
    _, singular, vt = np.linalg.svd(jacobian, full_matrices=False)
    determined = singular > 1e-9 * singular[0]
    covariance = (vt[determined].T / singular[determined] ** 2) @ vt[determined] * variance
    if not determined.all():
        warnings.warn("the fit's Jacobian is (nearly) singular: some parameters are not "
                      "determined by these data, their intervals are unbounded.",
                      FitWarning, stacklevel=3)
        undetermined = np.any(np.abs(vt[~determined]) > 1e-6, axis=0)
        covariance[undetermined, undetermined] = np.inf
    return covariance, dof


def student_quantile(confidence, dof):
    """Two-sided Student-t quantile: ``t.ppf((1 + confidence) / 2, dof)``.

    The half-width of a ``confidence`` interval is this times the standard error
    (1.96 for 95 % and many degrees of freedom, not the one-sided 1.645).
    """
    if not 0 < confidence < 1:
        raise ParameterError(f"`confidence` must be in (0, 1), got {confidence!r}.")
    return float(stats.t.ppf(0.5 + confidence / 2, dof))


def profile_threshold(confidence, dof):
    """Rise of the residual sum of squares, in units of the residual variance, that bounds
    a profile-likelihood interval of one parameter: ``F(1, dof)`` quantile, ``t^2``."""
    return student_quantile(confidence, dof) ** 2


def finite_samples(name, values):
    return finite_series(name, values, DataError,
                         "clean or interpolate them first (qzs.iotools.rig can, nan = 'interpolate')")
