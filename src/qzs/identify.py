"""Model identification from test-rig data (paper Section 2.1.2).

- :func:`fit_spring`: the MagSpring's static force-displacement pairs -> ``a``, ``b`` of
  ``F = -a*tanh(b*z)`` with confidence intervals, in either displacement convention.
- :func:`fit_friction`: a dynamic test with imposed displacement and measured force (the
  paper's Instron tests) -> stiction, Coulomb, Stribeck and viscous friction (eq. 3).
- :func:`fit_transmissibility`: chosen model parameters fitted to a measured
  transmissibility curve through the simulator.

All intervals are Student-t intervals on the covariance ``s^2 (J^T J)^-1`` of the
least-squares Jacobian ``J`` at the optimum (``s^2`` the residual variance): they assume
independent residuals of equal variance, and are local (linearised) intervals.
"""
import dataclasses
import time as _time
import warnings
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from scipy import optimize, stats

from qzs._validation import finite_series
from qzs.errors import DataError, ParameterError

__all__ = ["SpringFit", "fit_spring", "FrictionFit", "fit_friction", "plot_friction_fit",
           "TransmissibilityFit", "fit_transmissibility", "FitError", "FitWarning"]

CONVENTIONS = ("model", "test_machine")


@dataclass(frozen=True)
class SpringFit:
    """Result of :func:`fit_spring`.

    Attributes
    ----------
    spring_force, spring_shape : float
        ``a`` [N] and ``b`` [1/m] in the model's convention (MODEL.md: ``F = -a*tanh(b*z)``,
        z upward, a > 0 for a restoring spring).
    spring_force_interval, spring_shape_interval : tuple of float
        Confidence intervals at ``confidence``.
    confidence : float
        Confidence level of the intervals.
    convention : str
        Displacement convention of the input data: ``"model"`` (z = x - y, the spring
        pushes up when compressed, as MODEL.md) or ``"test_machine"`` (displacement
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

    def as_paper_reports(self):
        """``(a, b)`` as the test machine's convention would print them (paper Fig. 5)."""
        return -self.spring_force, self.spring_shape


def fit_spring(displacement, force, *, convention="model", confidence=0.95):
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
    _student(confidence, 1)  # validates `confidence` before the work
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
    errors = np.sqrt(np.clip(np.diag(covariance), 0, np.inf)) * _student(confidence,
                                                                         max(z.size - 2, 1))
    scale = 1.4826 * np.median(np.abs(residual - np.median(residual)))
    outliers = tuple(int(i) for i in np.flatnonzero(np.abs(residual) > 4 * max(scale, 1e-300)))
    a, b = params
    if b < 0:  # tanh is odd: (a, b) and (-a, -b) are the same law
        a, b = -a, -b
    return SpringFit(float(a), float(b), (float(a - errors[0]), float(a + errors[0])),
                     (float(b - errors[1]), float(b + errors[1])), confidence, convention,
                     float(np.sqrt(np.mean(residual ** 2))), outliers)


class FitError(RuntimeError):
    """A least-squares fit did not converge, or its inputs cannot determine the parameters."""


class FitWarning(UserWarning):
    """A fit converged but some parameters are poorly determined by the data."""


def _covariance(jacobian, residual, n_parameters):
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


def _student(confidence, dof):
    if not 0 < confidence < 1:
        raise ParameterError(f"`confidence` must be in (0, 1), got {confidence!r}.")
    return float(stats.t.ppf(0.5 + confidence / 2, dof))


def _series(name, values):
    return finite_series(name, values, DataError,
                         "clean or interpolate them first (qzs.readers can, nan = 'interpolate')")


# ---------------------------------------------------------------- friction
FRICTION_PARAMETERS = ("stiction_force", "coulomb_force", "stribeck_decay", "viscous_damping",
                       "offset")
FORCE_SIGNS = ("auto", "applied", "reaction")


@dataclass(frozen=True, eq=False)
class FrictionFit:
    """Result of :func:`fit_friction`: eq. (3) parameters with confidence intervals.

    Attributes
    ----------
    stiction_force, coulomb_force : float
        Fs and Fc [N].
    stribeck_decay : float
        Cbc [s/m].
    viscous_damping : float
        Cv [N*s/m].
    offset : float
        Constant force [N] (load-cell zero, weight not carried by the spring); 0 if not fitted.
    intervals : Mapping[str, tuple]
        Parameter name -> (low, high) confidence interval at ``confidence``.
    confidence : float
        Level of the intervals.
    force_sign : {"applied", "reaction"}
        How the force was read: the force the machine applies to the carriage along the
        displacement (``"applied"``) or its opposite (``"reaction"``).
    residual_rms : float
        RMS of the force residuals over the samples used [N].
    n_used, n_excluded : int
        Samples fitted, and samples left out as near-zero velocity (stick).
    time, velocity, friction, residual : ndarray
        Per sample: time [s], the smoothed velocity [m/s], the measured force left once
        inertia, spring and offset are removed (the force the machine spends on friction,
        ``-F_friction`` [N]), and its residual [N] (NaN where excluded).
    used : ndarray of bool
        Samples used in the fit.
    """

    stiction_force: float
    coulomb_force: float
    stribeck_decay: float
    viscous_damping: float
    offset: float
    intervals: object
    confidence: float
    force_sign: str
    residual_rms: float
    n_used: int
    n_excluded: int
    time: np.ndarray
    velocity: np.ndarray
    friction: np.ndarray
    residual: np.ndarray
    used: np.ndarray

    def friction_force(self, velocity):
        """Fitted sliding friction on the payload [N] at ``velocity`` [m/s] (MODEL.md sign)."""
        from qzs.model import friction_force

        return friction_force(velocity, self.to_isolator())

    def to_isolator(self, isolator=None):
        """``isolator`` (default Table 1) with the fitted friction parameters."""
        from qzs.model import IsolatorParameters

        return dataclasses.replace(isolator or IsolatorParameters(),
                                   **{n: getattr(self, n) for n in FRICTION_PARAMETERS[:4]})

    def plot(self, path=None, title=""):
        """Friction against velocity with the fit, and residuals (:func:`plot_friction_fit`)."""
        return plot_friction_fit(self, path=path, title=title)


def _smoothed_derivatives(time, displacement, window, polyorder, tolerance):
    """Savitzky-Golay velocity and acceleration on a uniform time base."""
    from scipy.signal import savgol_filter

    steps = np.diff(time)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise DataError(f"`time` must be strictly increasing; sample {i + 1} ({time[i + 1]!r} s) "
                        f"follows {time[i]!r} s. Sort the data and drop duplicates.")
    step = float(np.median(steps))
    jitter = float(np.max(np.abs(steps - step))) / step
    if jitter > tolerance:
        raise DataError(f"`time` is not uniformly sampled (relative jitter {jitter:.3g} > "
                        f"{tolerance:g}); resample it first (qzs.readers: resample = true).")
    samples = max(int(round(window / step)) | 1, polyorder + 2 | 1)
    if samples > time.size:
        raise DataError(f"the smoothing window ({samples} samples = {samples * step:g} s) is "
                        f"longer than the data ({time.size} samples); reduce `smoothing_window`.")
    velocity = savgol_filter(displacement, samples, polyorder, deriv=1, delta=step)
    acceleration = savgol_filter(displacement, samples, polyorder, deriv=2, delta=step)
    return velocity, acceleration, samples * step


def _spring_pair(spring):
    if spring is None:
        return 0.0, 0.0
    if hasattr(spring, "spring_force") and hasattr(spring, "spring_shape"):
        return float(spring.spring_force), float(spring.spring_shape)
    try:
        a, b = (float(x) for x in spring)
    except (TypeError, ValueError):
        raise ParameterError(f"`spring` must be (a [N], b [1/m]), an IsolatorParameters or "
                             f"None, got {spring!r}.") from None
    return a, b


def _friction_columns(speed, decay):
    """Design of the linear part: Fc*1 + dF*exp(-Cbc*|v|) + Cv*|v| (times sign(v)) + offset."""
    return np.column_stack([np.ones_like(speed), np.exp(-decay * speed), speed])


def fit_friction(time, displacement, force, *, spring=None, mass=None,
                 exclude_below_velocity=2e-3, force_sign="auto", fit_offset=True,
                 smoothing_window=0.02, polyorder=3, confidence=0.95, tolerance=1e-3):
    """Fit the friction law (eq. 3) to a dynamic test: imposed displacement, measured force.

    The test machine drives the carriage through ``z(t)`` and measures the force it
    applies, ``F``. By Newton's law on the carriage (MODEL.md signs; gravity and the
    load cell's zero go into ``offset``)::

        F = m*a - F_spring(z) - F_friction(v) + offset
          = m*a + a_s*tanh(b*z) + [Fc + (Fs - Fc)*exp(-Cbc*|v|)]*sign(v) + Cv*v + offset

    so the machine does positive work against friction. Data recorded with the opposite
    sign (the reaction on the machine, or the displacement counted the other way) are
    detected by ``force_sign="auto"`` from the sign of that work and flipped; reversing
    both displacement and force leaves the law unchanged (it is odd in ``z`` and ``v``).

    Velocity ``v`` and acceleration ``a`` come from the displacement by a
    Savitzky-Golay smoothing differentiator (``scipy.signal.savgol_filter``: a local
    polynomial of order ``polyorder`` over ``smoothing_window``, differentiated).
    Samples with ``|v| < exclude_below_velocity`` are left out: there the carriage sticks
    or reverses and friction is anywhere in ``[-Fs, Fs]``. The model is linear in
    Fc, Fs - Fc, Cv and the offset for a given Cbc: a grid over Cbc gives the start, then
    ``scipy.optimize.least_squares`` fits all with Fc, Fs - Fc, Cbc, Cv >= 0.

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times [s], strictly increasing, uniform.
    displacement : array_like, shape (n,)
        Imposed displacement z [m] (model convention for the spring's ``z``).
    force : array_like, shape (n,)
        Measured force [N].
    spring : (float, float) or IsolatorParameters, optional
        MagSpring ``(a [N], b [1/m])`` attached during the test, in the model's
        convention; None (default) if no spring acts.
    mass : float, optional
        Moving mass [kg] for the inertial force ``m*a``; None neglects inertia.
    exclude_below_velocity : float
        Speed [m/s] below which samples are excluded; default 2 mm/s.
    force_sign : {"auto", "applied", "reaction"}
        Sign convention of ``force`` (see above).
    fit_offset : bool
        Fit a constant force offset (default True); requires motion both ways.
    smoothing_window : float
        Length of the Savitzky-Golay window [s] (rounded to an odd number of samples).
    polyorder : int
        Order of the local polynomial (>= 2).
    confidence : float
        Level of the confidence intervals.
    tolerance : float
        Allowed relative jitter of the sample interval.

    Returns
    -------
    FrictionFit

    Raises
    ------
    DataError
        Mismatched lengths, NaN samples, non-increasing or non-uniform time, fewer than
        20 samples left after the exclusion, motion in one direction only.
    FitError
        The least-squares fit did not converge.
    """
    if force_sign not in FORCE_SIGNS:
        raise ParameterError(f"`force_sign` must be one of {FORCE_SIGNS}, got {force_sign!r}.")
    if not isinstance(polyorder, (int, np.integer)) or polyorder < 2:
        raise ParameterError(f"`polyorder` must be an integer >= 2, got {polyorder!r}.")
    t, z, f = (_series(n, v) for n, v in (("time", time), ("displacement", displacement),
                                          ("force", force)))
    if not t.size == z.size == f.size:
        raise DataError(f"`time`, `displacement` and `force` must have the same length, got "
                        f"{t.size}, {z.size} and {f.size}.")
    if t.size < 20:
        raise DataError(f"a friction fit needs at least 20 samples, got {t.size}.")
    threshold = float(exclude_below_velocity)
    if not threshold >= 0:
        raise ParameterError(f"`exclude_below_velocity` must be >= 0 [m/s], got {threshold!r}.")
    _student(confidence, 1)  # validates `confidence` before the work
    if not float(smoothing_window) > 0:
        raise ParameterError(f"`smoothing_window` must be positive [s], got {smoothing_window!r}.")
    if mass is not None and not float(mass) > 0:
        raise ParameterError(f"`mass` must be positive [kg] or None, got {mass!r}.")
    velocity, acceleration, window = _smoothed_derivatives(t, z, float(smoothing_window),
                                                           int(polyorder), tolerance)
    a_s, b_s = _spring_pair(spring)
    inertia = 0.0 if mass is None else float(mass) * acceleration
    used = np.abs(velocity) >= threshold
    n_used = int(np.count_nonzero(used))
    if force_sign == "auto":
        force_sign = "applied" if np.sum((f * velocity)[used]) >= 0 else "reaction"
    sign = 1.0 if force_sign == "applied" else -1.0
    measured = sign * f - inertia - a_s * np.tanh(b_s * z)  # = -F_friction(v) + offset
    n_parameters = 5 if fit_offset else 4
    if n_used < max(20, 3 * n_parameters):
        raise DataError(f"only {n_used} of {t.size} samples move faster than "
                        f"`exclude_below_velocity` = {threshold:g} m/s; a friction fit needs "
                        "at least 20: record more cycles or lower the threshold.")
    v, y = velocity[used], measured[used]
    if fit_offset and (np.all(v > 0) or np.all(v < 0)):
        raise DataError("the carriage moves in one direction only: Coulomb friction and the "
                        "force offset cannot be told apart; record motion both ways or pass "
                        "fit_offset=False.")
    direction, speed = np.sign(v), np.abs(v)

    def design(decay):
        columns = _friction_columns(speed, decay) * direction[:, None]
        return np.column_stack([columns, np.ones_like(v)]) if fit_offset else columns

    def residual(p):  # p = Fc, Fs - Fc, Cbc, Cv[, offset]
        linear = np.array([p[0], p[1], p[3], *p[4:]])
        return design(p[2]) @ linear - y

    scale = 1.0 / max(np.percentile(speed, 90), 1e-9)
    best = None
    for decay in scale * np.logspace(-1, 3, 41):
        coefficients = np.linalg.lstsq(design(decay), y, rcond=None)[0]
        cost = float(np.sum((design(decay) @ coefficients - y) ** 2))
        if best is None or cost < best[0]:
            best = (cost, decay, coefficients)
    _, decay, c = best
    start = np.array([max(c[0], 0.0), max(c[1], 0.0), decay, max(c[2], 0.0), *c[3:]])
    lower = [0.0, 0.0, 0.0, 0.0, -np.inf][:n_parameters]
    solution = optimize.least_squares(residual, start, bounds=(lower, np.inf), x_scale="jac",
                                      max_nfev=2000)
    if not solution.success:
        raise FitError(f"the friction fit did not converge ({solution.message}); check the "
                       "force sign, the spring and that the test covers low and high speeds.")
    p = solution.x
    covariance, dof = _covariance(solution.jac, solution.fun, n_parameters)
    t_student = _student(confidence, dof)
    gradients = {"coulomb_force": [1, 0, 0, 0, 0], "stiction_force": [1, 1, 0, 0, 0],
                 "stribeck_decay": [0, 0, 1, 0, 0], "viscous_damping": [0, 0, 0, 1, 0],
                 "offset": [0, 0, 0, 0, 1]}
    values = dict(coulomb_force=p[0], stiction_force=p[0] + p[1], stribeck_decay=p[2],
                  viscous_damping=p[3], offset=p[4] if fit_offset else 0.0)
    intervals = {}
    for name, gradient in gradients.items():
        g = np.array(gradient[:n_parameters], float)
        k = np.flatnonzero(g)
        half = t_student * np.sqrt(max(g[k] @ covariance[np.ix_(k, k)] @ g[k], 0.0)) \
            if k.size else 0.0
        intervals[name] = (float(values[name] - half), float(values[name] + half))
    full_residual = np.full(t.size, np.nan)
    full_residual[used] = solution.fun
    return FrictionFit(**{k: float(v) for k, v in values.items()},
                       intervals=MappingProxyType(intervals), confidence=confidence,
                       force_sign=force_sign,
                       residual_rms=float(np.sqrt(np.mean(solution.fun ** 2))), n_used=n_used,
                       n_excluded=int(t.size - n_used), time=t, velocity=velocity,
                       friction=measured - values["offset"], residual=full_residual, used=used)


def plot_friction_fit(fit, *, path=None, title=""):
    """Friction force against velocity with the fitted law, and the residuals against time.

    Parameters
    ----------
    fit : FrictionFit
    path : str or Path, optional
        Write the figure there (a .png also as .svg).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.plotting import new_figure, save_figure

    fig, axes = new_figure(2, height=3.0, sharex=False)
    top, bottom = axes
    v, used = fit.velocity, fit.used
    top.plot(v[~used] * 1e3, fit.friction[~used], ".", ms=2, color="0.7",
             label=f"excluded (stick, {fit.n_excluded})")
    top.plot(v[used] * 1e3, fit.friction[used], ".", ms=2, color="C0",
             label=f"measured ({fit.n_used})")
    grid = np.linspace(v.min(), v.max(), 801)
    grid = np.concatenate([grid[grid < 0], [np.nan], grid[grid > 0]])  # break at v = 0
    top.plot(grid * 1e3, -fit.friction_force(grid), "-", color="C3", lw=1.2,
             label=(f"fit: Fs = {fit.stiction_force:.3g} N, Fc = {fit.coulomb_force:.3g} N, "
                    f"Cbc = {fit.stribeck_decay:.3g} s/m, Cv = {fit.viscous_damping:.3g} N*s/m"))
    top.set_xlabel("velocity v [mm/s]")
    top.set_ylabel("force against friction -F_friction [N]")
    top.legend(fontsize="small", loc="upper left")
    bottom.plot(fit.time, fit.residual, ".", ms=2, color="C0")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xlabel("time [s]")
    bottom.set_ylabel(f"residual [N] (rms {fit.residual_rms:.3g})")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    top.set_title(title)
    if path is not None:
        save_figure(fig, path, also_svg=True)
    return fig


# ---------------------------------------------------------------- transmissibility
@dataclass(frozen=True, eq=False)
class TransmissibilityFit:
    """Result of :func:`fit_transmissibility`.

    Attributes
    ----------
    parameters : Mapping[str, float]
        Fitted values of the free parameters (MODEL.md names and units).
    intervals : Mapping[str, tuple]
        Name -> (low, high) confidence interval (fitted in log space, so asymmetric).
    confidence : float
        Level of the intervals.
    isolator, controller : IsolatorParameters, ControllerParameters
        The full parameter sets with the fitted values.
    excitation : Chirp
        The chirp simulated at every evaluation.
    frequency, measured, fitted : ndarray
        The fitted band [Hz], the measured and the fitted model's amplitude ratio [-].
    residual_rms : float
        RMS of ``ln(fitted / measured)`` [-] (about the relative error).
    n_simulations : int
        Simulations run (cost: each is one ``qzs.simulate`` of the chirp).
    elapsed : float
        Wall time of the fit [s].
    """

    parameters: object
    intervals: object
    confidence: float
    isolator: object
    controller: object
    excitation: object
    frequency: np.ndarray
    measured: np.ndarray
    fitted: np.ndarray
    residual_rms: float
    n_simulations: int
    elapsed: float

    def plot(self, path=None, title=""):
        """Measured and fitted curves (``qzs.plotting.plot_transmissibility``)."""
        from qzs.plotting import plot_transmissibility

        fitted = ", ".join(f"{k} = {v:.3g}" for k, v in self.parameters.items())
        curves = [{"label": "measured", "frequency": self.frequency, "magnitude": self.measured},
                  {"label": f"fitted model ({fitted})", "frequency": self.frequency,
                   "magnitude": self.fitted}]
        return plot_transmissibility(curves, frequency_range=(0.0, float(self.frequency[-1])),
                                     title=title, path=path)


def _free_parameters(free, isolator, controller, initial):
    """Validated free names, their owners and starting values."""
    owners = {}
    for obj in (isolator, controller):
        for f in dataclasses.fields(obj):
            if isinstance(getattr(obj, f.name), float) and f.name not in ("stop_center",):
                owners[f.name] = obj
    if isinstance(free, str):
        free = (free,)
    free = tuple(free)
    if not free or len(set(free)) != len(free):
        raise ParameterError(f"`free` must name one or more distinct parameters, got {free!r}.")
    unknown = [name for name in free if name not in owners]
    if unknown:
        raise ParameterError(f"`free` has unknown or non-numeric parameter(s) {unknown}; "
                             f"choose from {sorted(owners)}.")
    initial = dict(initial or {})
    extra = sorted(set(initial) - set(free))
    if extra:
        raise ParameterError(f"`initial` names {extra}, which are not in `free` {free}.")
    start = {name: float(initial.get(name, getattr(owners[name], name))) for name in free}
    for name, value in start.items():
        if not value > 0:
            raise ParameterError(f"the fit works on log(parameter): the start of {name!r} must "
                                 f"be > 0, got {value!r}; pass initial={{{name!r}: ...}}.")
    return free, start


def _bounds(free, start, bounds, isolator):
    bounds = dict(bounds or {})
    extra = sorted(set(bounds) - set(free))
    if extra:
        raise ParameterError(f"`bounds` names {extra}, which are not in `free` {free}.")
    low, high = [], []
    for name in free:
        lo, hi = bounds.get(name, (start[name] / 20.0, start[name] * 20.0))
        if name == "stiction_force" and "coulomb_force" not in free and name not in bounds:
            lo = max(lo, isolator.coulomb_force, 1e-9)
        if not 0 < lo <= start[name] <= hi:
            raise ParameterError(f"`bounds` for {name!r} must satisfy 0 < low <= start <= high, "
                                 f"got ({lo!r}, {hi!r}) with start {start[name]!r}.")
        low.append(np.log(lo))
        high.append(np.log(hi) + (1e-12 if hi == lo else 0.0))
    return np.array(low), np.array(high)


def fit_transmissibility(frequency, magnitude, free=("viscous_damping", "stiction_force"), *,
                         isolator=None, controller=None, bounds=None, initial=None, band=None,
                         excitation=None, duration=60.0, dt=5e-4, sample_rate=None,
                         fft_length=1024, confidence=0.95, max_simulations=100,
                         scan_points=9, diff_step=0.05):
    """Fit chosen model parameters to a measured transmissibility curve.

    Each evaluation simulates the isolator under a chirp covering the band
    (:func:`qzs.simulate`), estimates its transmissibility from base and payload
    acceleration (:func:`qzs.spectral.transmissibility`, PSD ratio) and interpolates it
    onto the measured frequencies; ``scipy.optimize.least_squares`` minimises the
    differences of the natural logs of the two amplitude ratios over the parameters'
    logs (all free parameters must be positive). The rest stay as given.

    **Cost**: ``scan_points`` simulations per free parameter for the initial scan, then
    one per residual and ``len(free)`` more per Jacobian (finite differences): measured
    20-50 simulations for one free parameter, 40-120 for two. The default 60 s chirp at
    ``dt`` = 5e-4 s is 1.2e5 steps, about 0.05 s each (after numba compiled), so a fit
    takes 1-5 s; the 250 s chirp of ``examples/`` about 0.2 s each.
    A short chirp sweeps faster than the paper's 2000 s one (transients and stick-slip
    differ a little near the resonance): pass ``excitation`` with the experiment's
    amplitude and band, and a longer ``duration``, for the final numbers. The coarse
    FFT (``fft_length`` at the decimated ``sample_rate``) smooths sharp peaks.

    **Stick-slip makes the cost jumpy**: a small change of the friction forces adds or
    removes a stick event, and the simulated curve jumps by about 1 % (rms of the log)
    between plateaus. A first pass scans each free parameter over its bounds
    (``scan_points`` simulations each) to avoid the plateaus' local minima, and the
    Jacobian uses a relative step ``diff_step`` wide enough to bridge the jumps. The
    intervals are local: smooth parameters (``viscous_damping``, gains) get honest
    ones; ``stiction_force``'s true uncertainty is the plateau width (about 10 %),
    wider than its interval.

    Parameters
    ----------
    frequency, magnitude : array_like, shape (n,)
        Measured curve: frequencies [Hz] and amplitude ratio [-].
    free : sequence of str
        Parameters to fit, by their MODEL.md names (IsolatorParameters or
        ControllerParameters fields).
    isolator, controller : IsolatorParameters, ControllerParameters, optional
        Values of everything else, and the start of the free ones (Table 1 defaults).
    bounds : dict, optional
        Name -> (low, high); default (start/20, start*20), and ``stiction_force`` at least
        ``coulomb_force``.
    initial : dict, optional
        Name -> start value, overriding ``isolator``/``controller``.
    band : (float, float), optional
        Frequency band fitted [Hz]; default from 1 Hz to the top of the curve (or of
        ``excitation``'s sweep, if lower): below
        about 1 Hz a short chirp gives few cycles and the stuck payload's breakaways make
        the estimate erratic. Leave out a band the measurement cannot be trusted in
        (charge-amplifier high-pass: below 1.5x its corner).
    excitation : Chirp, optional
        Chirp simulated; default 10 mm from 0 Hz to the band's top (at least 20 Hz),
        lasting ``duration``.
    duration : float
        Length of the default chirp [s].
    dt : float
        Integration step [s].
    sample_rate : float, optional
        Rate of the simulated output [Hz]; default at least 5x the chirp's top frequency.
    fft_length : int
        Welch segment length at ``sample_rate`` [samples].
    confidence : float
        Level of the confidence intervals.
    max_simulations : int
        Upper bound on the optimiser's residual evaluations (the scan's and the
        Jacobian's simulations come on top); reaching it raises :class:`FitError`.
    scan_points : int
        Points of the initial coordinate scan per free parameter (0: no scan).
    diff_step : float
        Relative finite-difference step of the Jacobian (of the parameters' logs).

    Returns
    -------
    TransmissibilityFit

    Raises
    ------
    ParameterError
        Unknown free parameter, bad bounds or options.
    DataError
        Bad curve, or fewer points in the band than free parameters + 2.
    FitError
        The fit did not converge within ``max_simulations``, or a trial simulation failed.
    """
    from qzs.control import ControllerParameters
    from qzs.errors import SimulationError
    from qzs.excitation import Chirp
    from qzs.model import IsolatorParameters
    from qzs.simulate import simulate
    from qzs.spectral import transmissibility

    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    f, measured = _series("frequency", frequency), _series("magnitude", magnitude)
    if f.shape != measured.shape:
        raise DataError(f"`frequency` and `magnitude` must have the same length, got {f.size} "
                        f"and {measured.size}.")
    top = f.max() if excitation is None else min(f.max(), excitation.max_frequency)
    low, high = (1.0, top) if band is None else band
    keep = (f >= low) & (f <= high) & (f > 0)
    f, measured = f[keep], measured[keep]
    free, start = _free_parameters(free, isolator, controller, initial)
    if f.size < len(free) + 2:
        raise DataError(f"only {f.size} points of the curve lie in the band [{low:g}, {high:g}] "
                        f"Hz; fitting {len(free)} parameter(s) needs at least {len(free) + 2}.")
    if np.any(measured <= 0):
        raise DataError(f"`magnitude` has {np.count_nonzero(measured <= 0)} values <= 0 in the "
                        "band; the fit compares logs, drop those bins or narrow `band`.")
    if excitation is None:
        excitation = Chirp(amplitude=0.010, f0=0.0, f1=max(20.0, float(high)), duration=duration)
    if excitation.max_frequency < high:
        raise ParameterError(f"the chirp ends at {excitation.max_frequency:g} Hz, below the band's "
                             f"top {high:g} Hz; extend `excitation` or narrow `band`.")
    if sample_rate is None:
        sample_rate = 1.0 / (dt * max(1, int(1.0 / (dt * 5.0 * excitation.max_frequency))))
    lower, upper = _bounds(free, start, bounds, isolator)
    log_measured = np.log(measured)
    counter = {"n": 0}

    def model(x):
        values = dict(zip(free, np.exp(x)))
        iso = dataclasses.replace(isolator, **{k: v for k, v in values.items()
                                               if hasattr(isolator, k)})
        ctrl = dataclasses.replace(controller, **{k: v for k, v in values.items()
                                                  if hasattr(controller, k)})
        counter["n"] += 1
        try:
            run = simulate(excitation, iso, ctrl, duration=excitation.duration, dt=dt,
                           sample_rate=sample_rate)
        except SimulationError as error:
            raise FitError(f"a trial simulation failed at {values}: {error}; "
                           "narrow `bounds`.") from None
        estimate = transmissibility(run.base_acceleration, run.payload_acceleration,
                                    sample_rate, fft_length=fft_length)
        curve = np.log(np.maximum(estimate.magnitude[1:], 1e-12))
        return np.interp(f, estimate.frequency[1:], curve), iso, ctrl

    def residual(x):
        return model(x)[0] - log_measured

    began = _time.perf_counter()
    x0 = np.clip(np.log([start[n] for n in free]), lower, upper)
    if scan_points:  # one pass of coordinate scans: stick-slip makes the cost jumpy
        best = float(np.sum(residual(x0) ** 2))
        for i in range(len(free)):
            for value in np.linspace(lower[i], upper[i], int(scan_points)):
                trial = x0.copy()
                trial[i] = value
                cost = float(np.sum(residual(trial) ** 2))
                if cost < best:
                    best, x0 = cost, trial
    solution = optimize.least_squares(residual, x0, bounds=(lower, upper), diff_step=diff_step,
                                      x_scale=1.0, max_nfev=max_simulations)
    if solution.status <= 0:
        raise FitError(f"the transmissibility fit did not converge after {counter['n']} "
                       f"simulations ({solution.message}); raise `max_simulations`, fit fewer "
                       "parameters or give a closer `initial`.")
    covariance, dof = _covariance(solution.jac, solution.fun, len(free))
    half = _student(confidence, dof) * np.sqrt(np.clip(np.diag(covariance), 0, np.inf))
    log_fitted, iso, ctrl = model(solution.x)
    values = {n: float(np.exp(x)) for n, x in zip(free, solution.x)}
    with np.errstate(over="ignore"):
        intervals = {n: (float(np.exp(x - h)), float(np.exp(x + h)))
                     for n, x, h in zip(free, solution.x, half)}
    return TransmissibilityFit(MappingProxyType(values), MappingProxyType(intervals), confidence,
                               iso, ctrl, excitation, f, measured, np.exp(log_fitted),
                               float(np.sqrt(np.mean(solution.fun ** 2))), counter["n"],
                               _time.perf_counter() - began)
