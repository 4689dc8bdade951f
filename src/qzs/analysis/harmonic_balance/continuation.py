"""Pseudo-arclength continuation of the periodic response in frequency, around folds.

References
----------
Keller, H. B. (1977). Numerical solution of bifurcation and nonlinear eigenvalue problems. In
*Applications of Bifurcation Theory*, Academic Press, 359-384 (pseudo-arclength continuation).
"""
import numpy as np

from qzs._validation import integer, positive_real
from qzs.analysis.harmonic_balance.blas import _single_threaded_blas
from qzs.analysis.harmonic_balance.curve import _curve
from qzs.analysis.harmonic_balance.fourier import (DEFAULT_HARMONICS, _basis,
                                                   _check_settings)
from qzs.analysis.harmonic_balance.residual import _force_scale, _residual, _scales
from qzs.analysis.harmonic_balance.smooth_model import SmoothModel
from qzs.analysis.harmonic_balance.solution import (NEWTON_TOLERANCE, _linear_guess, _newton,
                                                    _solution)
from qzs.errors import ParameterError

__all__ = ["frequency_response_curve"]

#: Frequencies (geometric, over the range) where Newton tries to start the continuation [-].
START_ATTEMPTS = 12
#: Fewest continuation steps over the frequency range (the largest frequency step) [-].
MAX_POINTS_PER_RANGE = 150
#: Successive tangents of the continuation must make an angle with at least this cosine [-].
MIN_TANGENT_COSINE = 0.95


def _tangent(d_q, d_omega, scale, omega_scale, previous):
    """Unit tangent of the solution curve in scaled unknowns, oriented like ``previous``."""
    jac = np.hstack([d_q * scale[None, :], (d_omega * omega_scale)[:, None]])
    bordered = np.vstack([jac, previous[None, :]])
    rhs = np.zeros(jac.shape[0] + 1)
    rhs[-1] = 1.0
    tangent = np.linalg.solve(bordered, rhs)
    tangent /= np.linalg.norm(tangent)
    if tangent @ previous < 0:
        tangent = -tangent
    return tangent


def _corrector(u_pred, tangent, model, basis, scale, omega_scale):
    """Newton on the balance plus the arclength condition ``tangent . (u - u_pred) = 0``."""
    u = u_pred.copy()
    force = None
    for iteration in range(1, 16):
        q, omega = u[:-1] * scale, u[-1] * omega_scale
        if omega <= 0:
            return u, False, iteration
        residual, d_q, d_omega = _residual(q, omega, model, basis)
        force = _force_scale(model, omega, 1e-12)
        jac = np.vstack([np.hstack([d_q * scale[None, :], (d_omega * omega_scale)[:, None]]),
                         tangent[None, :]])
        rhs = -np.append(residual, tangent @ (u - u_pred))
        try:
            step = np.linalg.solve(jac, rhs)
        except np.linalg.LinAlgError:
            return u, False, iteration
        u = u + step
        if not np.all(np.isfinite(u)):
            return u, False, iteration
        if np.max(np.abs(step)) < NEWTON_TOLERANCE:
            residual = _residual(u[:-1] * scale, u[-1] * omega_scale, model, basis, False)[0]
            return u, bool(np.max(np.abs(residual)) / force < 1e-8), iteration
    return u, False, 16


def frequency_response_curve(model, frequency_range, *, harmonics=DEFAULT_HARMONICS,
                             time_points=None, max_points=2000, step=None):
    """Follow the smooth model's periodic response over a frequency range.

    Newton at the lower end (or at the first of 12 frequencies over the range, geometric,
    where it converges; the curve is then followed down and up from there), then
    pseudo-arclength continuation (Keller 1977) in the scaled unknowns
    ``(coefficients/scale, omega/omega_top)``: a predictor along the tangent, a corrector
    orthogonal to it, the step grown after easy corrections and halved after hard ones.
    Folds are where the tangent's frequency component changes sign; each point's stability
    is decided by :func:`floquet_exponents`.

    Parameters
    ----------
    model : SmoothModel
        The smooth model.
    frequency_range : (float, float)
        Lowest and highest frequency [Hz].
    harmonics : int
        Harmonics of z kept [-].
    time_points : int, optional
        Phases per period of the AFT [-]; default a power of two of at least ``8*harmonics``.
    max_points : int
        Points at most [-].
    step : float, optional
        First arclength step in scaled units [-]; default 1/200 of the range. Steps
        change by at most 1/150 of the range in frequency and 18 degrees in direction.

    Returns
    -------
    FrequencyResponseCurve
    """
    if not isinstance(model, SmoothModel):
        raise ParameterError(f"`model` must be a SmoothModel, got {type(model).__name__}.")
    try:
        low, high = (float(f) for f in frequency_range)
    except (TypeError, ValueError):
        raise ParameterError(f"`frequency_range` must be two frequencies (low, high) in Hz, "
                             f"got {frequency_range!r}.") from None
    if not (np.isfinite(low) and np.isfinite(high) and 0 < low < high):
        raise ParameterError(f"`frequency_range` must satisfy 0 < low < high (finite, Hz), got "
                             f"{frequency_range!r}.")
    harmonics, time_points = _check_settings(harmonics, time_points)
    max_points = integer("max_points", max_points, 2)
    with _single_threaded_blas():
        return _continue(model, low, high, harmonics, time_points, max_points, step)


def _continue(model, low, high, harmonics, time_points, max_points, step):
    """The body of :func:`frequency_response_curve` (arguments checked)."""
    basis = _basis(harmonics, time_points)
    omega_scale = 2 * np.pi * high
    scale = _scales(model, 2 * np.pi * high, basis.size)
    span = 1.0 - low / high
    ds = span / 200 if step is None else positive_real("step", step)
    ds_min = span * 1e-7
    frequency_step = span / MAX_POINTS_PER_RANGE  # largest change of omega/omega_top per step
    notes = []

    found = None
    for frequency in np.geomspace(low, high, START_ATTEMPTS):
        omega = 2 * np.pi * frequency
        q, converged, _, norm = _newton(_linear_guess(omega, model, basis), omega, model,
                                        basis, scale)
        if converged:
            found = frequency, q, norm
            break
    if found is None:
        notes.append(f"no periodic solution found at any of {START_ATTEMPTS} frequencies from "
                     f"{low:g} to {high:g} Hz (Newton's residual {norm:.2g}){_table_note(model)}; "
                     "try more harmonics or a larger friction_velocity")
        return _curve([], [], model, harmonics, notes)
    frequency, q, norm = found
    if frequency > low:
        notes.append(f"the continuation started at {frequency:.4g} Hz (Newton failed below) "
                     "and went both ways from there")
    omega = 2 * np.pi * frequency
    u = np.append(q / scale, omega / omega_scale)
    _, d_q, d_omega = _residual(q, omega, model, basis)
    towards = np.zeros(u.size)
    towards[-1] = 1.0
    tangent = _tangent(d_q, d_omega, scale, omega_scale, towards)
    first = _point(u, scale, omega_scale, model, basis, norm)
    follow = dict(model=model, basis=basis, scale=scale, omega_scale=omega_scale, ds=ds,
                  ds_min=ds_min, frequency_step=frequency_step, notes=notes)
    below, below_tangents = [], []
    if frequency > low:
        below, below_tangents = _follow(u, -tangent, lambda w: w > 2 * np.pi * low,
                                        max_points // 2, **follow)
    above, above_tangents = _follow(u, tangent, lambda w: w < 2 * np.pi * high,
                                    max_points - len(below) - 1, **follow)
    # one list in rising arclength: the part below reversed (its tangents too)
    points = below[::-1] + [first] + above
    tangents = [-t for t in below_tangents[::-1]] + [tangent[-1]] + above_tangents
    if len(points) >= max_points:
        notes.append(f"stopped after {max_points} points (`max_points`)")
    return _curve(points, tangents, model, harmonics, notes)


def _follow(u, tangent, inside, max_points, *, model, basis, scale, omega_scale, ds, ds_min,
            frequency_step, notes):
    """Pseudo-arclength steps from ``u`` along ``tangent`` while ``inside(omega)``; returns
    the new points and the frequency components of their tangents."""
    points, tangents = [], []
    while len(points) < max_points and inside(u[-1] * omega_scale):
        u_new, ok, iterations = _corrector(u + ds * tangent, tangent, model, basis, scale,
                                           omega_scale)
        if ok:
            q_new, omega_new = u_new[:-1] * scale, u_new[-1] * omega_scale
            _, d_q, d_omega = _residual(q_new, omega_new, model, basis)
            new_tangent = _tangent(d_q, d_omega, scale, omega_scale, tangent)
            # small turns and frequency steps: no jump to another branch, a smooth drawing
            ok = (new_tangent @ tangent > MIN_TANGENT_COSINE and omega_new > 0
                  and abs(u_new[-1] - u[-1]) <= frequency_step)
        if not ok:
            ds *= 0.5
            if ds < ds_min:
                notes.append(f"continuation stopped at {u[-1] * omega_scale / (2 * np.pi):.4g} "
                             "Hz: the corrector no longer converges (a steep friction "
                             f"transition or a branch point{_table_note(model)}); try more "
                             "harmonics or a larger friction_velocity")
                break
            continue
        u, tangent = u_new, new_tangent
        points.append(_point(u, scale, omega_scale, model, basis, 0.0))
        tangents.append(tangent[-1])
        ds *= 1.5 if iterations <= 3 else 1.0 if iterations <= 6 else 0.5
    return points, tangents


def _table_note(model):
    """What a refusing spring table adds to a note on Newton's failure: its range [m]."""
    low, high = (-np.inf, np.inf) if model.spring_law is None else model.spring_law.domain
    if np.isfinite(low) or np.isfinite(high):
        return (f", or the motion leaves the spring's table [{low:g}, {high:g}] m "
                "(outside='refuse': measure it wider or build it with outside='extend')")
    return ""


def _point(u, scale, omega_scale, model, basis, norm):
    """The solution at the scaled unknowns ``u`` (coefficients, then omega)."""
    omega = u[-1] * omega_scale
    return _solution(u[:-1] * scale, omega / (2 * np.pi), model, True, 0, norm)
