"""Friction law fitted to an imposed-motion test (the paper's Instron tests, eq. 3)."""
import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from qzs._validation import integer, non_negative_real, positive_real, strictly_increasing
from qzs.errors import DataError, FitError, ParameterError
from qzs.identify._protocol import FitProtocol, interval_attributes
from qzs.identify._statistics import fit_covariance, finite_samples, student_quantile
from qzs.model.isolator import IsolatorParameters, friction_force
from qzs.model.registry import unit_of

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["FrictionFit", "fit_friction", "FRICTION_PARAMETERS", "FORCE_SIGNS"]


FRICTION_PARAMETERS = ("stiction_force", "coulomb_force", "stribeck_decay", "viscous_damping",
                       "offset")
FORCE_SIGNS = ("auto", "applied", "reaction")


def friction_unit(name: str) -> str:
    """The unit of an estimate of :data:`FRICTION_PARAMETERS` (the offset's: N).

    Parameters
    ----------
    name : str
        One of :data:`FRICTION_PARAMETERS`.

    Returns
    -------
    str
    """
    return "N" if name == "offset" else unit_of(name)


@dataclass(frozen=True, eq=False)
class FrictionFit(FitProtocol):
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
    intervals : Mapping[str, tuple of float]
        Each estimate of :data:`FRICTION_PARAMETERS` -> its (low, high) confidence interval
        at ``confidence``, in its unit (``(0, 0)`` for an offset not fitted).
    confidence : float
        Level of the intervals [-] (0.95).
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
    intervals: Mapping[str, tuple]
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

    def friction_force(self, velocity: ArrayLike) -> float | NDArray[np.float64]:
        """Fitted sliding friction on the payload [N] at ``velocity`` [m/s] (docs/model.md §3 sign).

        Parameters
        ----------
        velocity : float or array_like
            Relative (slip) velocity [m/s].

        Returns
        -------
        float or ndarray
            Friction force on the payload [N] (eq. 3 with the fitted parameters).
        """

        return friction_force(velocity, self.to_isolator())

    def to_isolator(self, isolator: IsolatorParameters | None = None) -> IsolatorParameters:
        """``isolator`` (default Table 1) with the fitted friction parameters.

        Parameters
        ----------
        isolator : IsolatorParameters, optional
            The other parameters; Table 1 defaults if omitted.

        Returns
        -------
        IsolatorParameters
            A copy with ``stiction_force``, ``coulomb_force``, ``stribeck_decay`` and
            ``viscous_damping`` replaced (the ``offset`` is not a model parameter).
        """
        return dataclasses.replace(isolator or IsolatorParameters(),
                                   **{n: getattr(self, n) for n in FRICTION_PARAMETERS[:4]})

    _figure = "plot_friction_fit"

    def estimates(self) -> dict[str, float]:
        """The estimates of :data:`FRICTION_PARAMETERS` by name (the keys of ``intervals``).

        Returns
        -------
        dict of str to float
            Forces [N], ``stribeck_decay`` [s/m], ``viscous_damping`` [N*s/m].
        """
        return {name: getattr(self, name) for name in FRICTION_PARAMETERS}

    def summary(self) -> str:
        """The fit as text: each estimate with its interval, the residual, the samples.

        Returns
        -------
        str
        """
        lines = [f"friction fit (eq. 3): {self.n_used} samples used, {self.n_excluded} "
                 f"excluded as stick; force read as {self.force_sign}"]
        for name, value in self.estimates().items():
            low, high = self.intervals[name]
            unit = friction_unit(name)
            lines.append(f"  {name} = {value:.6g} {unit}  [{low:.4g}, {high:.4g}] {unit} "
                         f"({100 * self.confidence:g} %)")
        lines.append(f"  residual rms {self.residual_rms:.4g} N")
        return "\n".join(lines)

    def to_record(self) -> dict[str, Any]:
        """The fit as plain data (what :meth:`save` writes as JSON; NaN as null).

        Returns
        -------
        dict
        """
        return {"kind": "friction", "parameters": self.estimates(),
                "intervals": {k: list(v) for k, v in self.intervals.items()},
                "units": {name: friction_unit(name) for name in FRICTION_PARAMETERS},
                "confidence": self.confidence, "force_sign": self.force_sign,
                "residual_rms": self.residual_rms, "residual_rms_units": "N",
                "n_used": self.n_used, "n_excluded": self.n_excluded}

    def to_xarray(self) -> "xr.Dataset":
        """The test as an ``xarray.Dataset`` on ``time`` (CF-1.10, units on every variable).

        ``velocity`` [m/s], ``friction`` and ``residual`` [N], the ``used`` flag; the
        estimates, their intervals (``<name>_lower``, ``<name>_upper``) and units, and
        ``confidence_level`` as global attributes.

        Returns
        -------
        xarray.Dataset
        """
        from qzs.iotools.schema import Schema, Variable, time_coordinate, to_dataset

        schema = Schema(kind="a friction fit", dimensions={"time": None},
                        coordinates=(time_coordinate(),), variables=(
            Variable(name="velocity", dims=("time",), units="m/s",
                     long_name="smoothed velocity of the carriage"),
            Variable(name="friction", dims=("time",), units="N",
                     long_name="measured force spent on friction (-F_friction)"),
            Variable(name="residual", dims=("time",), units="N",
                     long_name="measured minus fitted friction force"),
            Variable(name="used", dims=("time",), units="1", dtype="int8",
                     flag_meanings="excluded used",
                     long_name="1 where the sample is fitted (faster than the threshold)",
                     order=("units", "flag_values", "flag_meanings", "long_name"))))
        values = {"time": self.time, "velocity": self.velocity, "friction": self.friction,
                  "residual": self.residual, "used": self.used}
        attrs = {"title": "friction fit (qzs.fit_friction, eq. 3)",
                 "force_sign": self.force_sign, "residual_rms": self.residual_rms,
                 "residual_rms_units": "N", **interval_attributes(self, friction_unit)}
        return to_dataset(schema, values, attrs)


def _smoothed_derivatives(time, displacement, window, polyorder, tolerance):
    """Savitzky-Golay velocity and acceleration on a uniform time base."""
    from scipy.signal import savgol_filter

    strictly_increasing("time", time, DataError, "sort the data and drop duplicates")
    steps = np.diff(time)
    step = float(np.median(steps))
    jitter = float(np.max(np.abs(steps - step))) / step
    if jitter > tolerance:
        raise DataError(f"`time` is not uniformly sampled (relative jitter {jitter:.3g} > "
                        f"{tolerance:g}); resample it first (qzs.iotools.rig: resample = true).")
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


def fit_friction(time: ArrayLike, displacement: ArrayLike, force: ArrayLike, *,
                 spring: tuple[float, float] | IsolatorParameters | None = None,
                 mass: float | None = None, exclude_below_velocity: float = 2e-3,
                 force_sign: str = "auto", fit_offset: bool = True,
                 smoothing_window: float = 0.02, polyorder: int = 3, confidence: float = 0.95,
                 tolerance: float = 1e-3) -> FrictionFit:
    """Fit the friction law (eq. 3) to a dynamic test: imposed displacement, measured force.

    The test machine drives the carriage through ``z(t)`` and measures the force it
    applies, ``F``. By Newton's law on the carriage (docs/model.md §1 signs; gravity and the
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
    polyorder = integer("polyorder", polyorder, 2)
    t, z, f = (finite_samples(n, v) for n, v in (("time", time), ("displacement", displacement),
                                          ("force", force)))
    if not t.size == z.size == f.size:
        raise DataError(f"`time`, `displacement` and `force` must have the same length, got "
                        f"{t.size}, {z.size} and {f.size}.")
    if t.size < 20:
        raise DataError(f"a friction fit needs at least 20 samples, got {t.size}.")
    threshold = non_negative_real("exclude_below_velocity", exclude_below_velocity,
                                  fix="a velocity in m/s")
    student_quantile(confidence, 1)  # validates `confidence` before the work
    smoothing_window = positive_real("smoothing_window", smoothing_window,
                                     fix="a window in s, e.g. 0.02")
    if mass is not None:
        mass = positive_real("mass", mass, fix="in kg, or None to leave out the inertia")
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
    _, decay, c = best  # type: ignore[misc]  # set by the first of the 41 decays
    start = np.array([max(c[0], 0.0), max(c[1], 0.0), decay, max(c[2], 0.0), *c[3:]])
    lower = [0.0, 0.0, 0.0, 0.0, -np.inf][:n_parameters]
    solution = optimize.least_squares(residual, start, bounds=(lower, np.inf), x_scale="jac",
                                      max_nfev=2000)
    if not solution.success:
        raise FitError(f"the friction fit did not converge ({solution.message}); check the "
                       "force sign, the spring and that the test covers low and high speeds.")
    p = solution.x
    covariance, dof = fit_covariance(solution.jac, solution.fun, n_parameters)
    t_student = student_quantile(confidence, dof)
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
