"""Chosen model parameters fitted to a measured transmissibility curve through the simulator."""
import dataclasses
import time as _time
from dataclasses import dataclass
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize

from qzs._validation import integer, known_keys
from qzs.analysis.spectral import transmissibility
from qzs.defaults import EXCITATION
from qzs.engine.prepare import steps_per_sample
from qzs.engine.simulate import simulate
from qzs.errors import DataError, FitError, ParameterError, SimulationError
from qzs.identify._statistics import (fit_covariance, finite_samples, profile_threshold,
                                      student_quantile)
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS, numeric_parameters

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["TransmissibilityFit", "fit_transmissibility"]

_JITTER_SIZE = 0.02  # relative parameter change that redraws the stick-slip pattern


@dataclass(frozen=True, eq=False)
class TransmissibilityFit:
    """Result of :func:`fit_transmissibility`.

    Attributes
    ----------
    parameters : Mapping[str, float]
        Fitted values of the free parameters (registry names and SI units, docs/model.md §11).
    intervals : Mapping[str, tuple]
        Name -> (low, high) confidence interval (fitted in log space, so asymmetric),
        measurement noise and stick-slip jumps included (see :func:`fit_transmissibility`).
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

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """Measured and fitted curves (:func:`qzs.viz.identify.plot_transmissibility_fit`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (a .png also as .svg).
        title : str, optional
            Figure title; default none.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.identify import plot_transmissibility_fit

        return plot_transmissibility_fit(self, path=path, title=title or "",
                                         frequency_scale=frequency_scale)


def _free_parameters(free, isolator, controller, initial):
    """Validated free names, their owners and starting values."""
    sections = {"isolator": isolator, "controller": controller}
    owners = {name: sections[PARAMETERS[name].section] for name in numeric_parameters()}
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
    known_keys(initial, free, "`initial`", noun="parameter", options=("initial",),
               fix="give a start only for the parameters in `free`")
    start = {name: float(initial.get(name, getattr(owners[name], name))) for name in free}
    for name, value in start.items():
        if not value > 0:
            raise ParameterError(f"the fit works on log(parameter): the start of {name!r} must "
                                 f"be > 0, got {value!r}; pass initial={{{name!r}: ...}}.")
    return free, start


def _bounds(free, start, bounds, isolator):
    bounds = dict(bounds or {})
    known_keys(bounds, free, "`bounds`", noun="parameter", options=("bounds",),
               fix="give bounds only for the parameters in `free`")
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


def _polish(residual, x, jacobian, lower, upper, points, width):
    """A profile scan of each parameter around ``x`` (log space): the best point seen.

    Stick-slip makes the cost a staircase, on which the optimiser can stop on a
    poor step; each parameter is scanned over ``x_i +- width`` (``points`` values),
    the others refitted to first order through the Jacobian, and the fit moves to
    the lowest cost found (then evaluated without approximation).
    """
    r = residual(x)
    best_cost, best = float(r @ r), x.copy()
    for i in range(x.size):
        others = np.delete(jacobian, i, axis=1)
        for value in np.linspace(x[i] - width, x[i] + width, points):
            value = float(np.clip(value, lower[i], upper[i]))
            if value == x[i]:
                continue
            trial = best.copy()
            trial[i] = value
            r = residual(trial)
            if others.size:  # the others follow to first order
                shift = np.linalg.lstsq(others, -r, rcond=None)[0]
                trial[np.arange(x.size) != i] = np.clip(
                    trial[np.arange(x.size) != i] + shift, np.delete(lower, i),
                    np.delete(upper, i))
                r = residual(trial)
            cost = float(r @ r)
            if cost < best_cost:
                best_cost, best = cost, trial
    return best


def _jitter_covariance(residual, x, jacobian, samples, size, lower, upper, seed=0):
    """Covariance [log units^2] of the estimate caused by the model's stick-slip jumps.

    A small change of the parameters (``size``, relative) adds or removes stick
    events, and the simulated curve jumps by a pattern unrelated to the smooth
    trend the Jacobian describes. Each of ``samples`` random changes ``d`` gives
    such a pattern, ``p = r(x + d) - r(x) - J d``, and the shift
    ``-(J^T J)^-1 J^T p`` it causes in a linearised least-squares estimate; their
    mean outer product is the jumps' share of the estimate's covariance (the
    measured curve's own pattern is as unrelated to the fitted one's).
    """
    rng = np.random.default_rng(seed)
    r0 = residual(x)
    pinv = np.linalg.pinv(jacobian)
    shifts = []
    for _ in range(samples):
        step = size * rng.choice([-1.0, 1.0], size=x.size) * rng.uniform(0.5, 1.0, x.size)
        step = np.clip(x + step, lower, upper) - x  # within the bounds (e.g. Fs >= Fc)
        pattern = residual(x + step) - r0 - jacobian @ step
        shifts.append(-pinv @ pattern)
    shifts = np.array(shifts)
    return shifts.T @ shifts / samples


def fit_transmissibility(frequency: ArrayLike, magnitude: ArrayLike,
                         free: Sequence[str] = ("viscous_damping", "stiction_force"), *,
                         isolator: IsolatorParameters | None = None,
                         controller: ControllerParameters | None = None,
                         bounds: Mapping[str, tuple[float, float]] | None = None,
                         initial: Mapping[str, float] | None = None,
                         band: tuple[float, float] | None = None,
                         excitation: Chirp | None = None, duration: float = 60.0,
                         dt: float = 5e-4, sample_rate: float | None = None,
                         fft_length: int = 1024, confidence: float = 0.95,
                         max_simulations: int = 100, scan_points: int = 9,
                         diff_step: float = 0.05,
                         jitter_samples: int = 16) -> TransmissibilityFit:
    """Fit chosen model parameters to a measured transmissibility curve.

    Each evaluation simulates the isolator under a chirp covering the band
    (:func:`qzs.simulate`), estimates its transmissibility from base and payload
    acceleration (:func:`qzs.analysis.spectral.transmissibility`, PSD ratio) and interpolates it
    onto the measured frequencies; ``scipy.optimize.least_squares`` minimises the
    differences of the natural logs of the two amplitude ratios over the parameters'
    logs (all free parameters must be positive). The rest stay as given.

    **Cost**: ``scan_points`` simulations per free parameter for the initial scan, then
    one per residual and ``len(free)`` more per Jacobian (finite differences), then 8
    per free parameter for the polish (16 when others are free too) and
    ``jitter_samples`` for the intervals: measured 50-100 simulations for one free
    parameter, 90-170 for two. The default 60 s chirp at
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
    Jacobian uses a relative step ``diff_step`` wide enough to bridge the jumps. After
    the optimiser, a profile scan of each parameter over +-20 % (9 simulations each,
    the others following to first order) moves the fit to the lowest cost it finds:
    the optimiser can stop on a poor step of the staircase (the estimate of
    ``stiction_force`` was 6-18 % off the truth in synthetic tests).

    **Intervals.** The local Student-t interval of the Jacobian (noise only) ignores
    the jumps: for ``stiction_force`` it held the truth in 7 of 12 synthetic tests. So
    each interval also carries the jumps' share of the uncertainty, measured on the
    model: ``jitter_samples`` random changes of the parameters by 1-2 % redraw the
    stick-slip pattern, and the spread of the shifts those patterns cause in a
    linearised least-squares estimate is added to the noise's covariance; the
    Student-t quantile uses the Welch-Satterthwaite degrees of freedom of the sum
    (few samples, wider interval). Smooth parameters keep intervals close to the
    local ones. Measured coverage of the 95 % intervals, docs/model.md §12.

    Parameters
    ----------
    frequency, magnitude : array_like, shape (n,)
        Measured curve: frequencies [Hz] and amplitude ratio [-].
    free : sequence of str
        Parameters to fit, by their registry names (IsolatorParameters or
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
    jitter_samples : int
        Simulations that measure the stick-slip jumps' share of the intervals, and
        switch on the profile polish; 0 gives the local (noise-only) intervals and no
        polish, cheaper but too narrow for friction parameters.

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
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    f, measured = finite_samples("frequency", frequency), finite_samples("magnitude", magnitude)
    if f.shape != measured.shape:
        raise DataError(f"`frequency` and `magnitude` must have the same length, got {f.size} "
                        f"and {measured.size}.")
    top = f.max() if excitation is None else min(f.max(), excitation.max_frequency)
    low, high = (1.0, top) if band is None else band
    keep = (f >= low) & (f <= high) & (f > 0)
    f, measured = f[keep], measured[keep]
    free, start = _free_parameters(free, isolator, controller, initial)
    integer("jitter_samples", jitter_samples, 0)
    if f.size < len(free) + 2:
        raise DataError(f"only {f.size} points of the curve lie in the band [{low:g}, {high:g}] "
                        f"Hz; fitting {len(free)} parameter(s) needs at least {len(free) + 2}.")
    if np.any(measured <= 0):
        raise DataError(f"`magnitude` has {np.count_nonzero(measured <= 0)} values <= 0 in the "
                        "band; the fit compares logs, drop those bins or narrow `band`.")
    if excitation is None:
        excitation = Chirp(amplitude=EXCITATION["amplitude"], f0=0.0, f1=max(20.0, float(high)),
                           duration=duration)
    if excitation.max_frequency < high:
        raise ParameterError(f"the chirp ends at {excitation.max_frequency:g} Hz, below the band's "
                             f"top {high:g} Hz; extend `excitation` or narrow `band`.")
    if sample_rate is None:
        sample_rate = 1.0 / (dt * steps_per_sample(5.0 * excitation.max_frequency, dt,
                                                   rounding="down"))
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
    covariance, dof = fit_covariance(solution.jac, solution.fun, len(free))
    x_hat = solution.x
    variance = np.diag(covariance).copy()
    quantiles = np.full(len(free), student_quantile(confidence, dof))
    if jitter_samples:
        x_hat = _polish(residual, x_hat, solution.jac, lower, upper, 9, 0.2)
        jitter = np.diag(_jitter_covariance(residual, x_hat, solution.jac, int(jitter_samples),
                                            _JITTER_SIZE, lower, upper))
        total = variance + jitter
        with np.errstate(divide="ignore", invalid="ignore"):  # Welch-Satterthwaite
            effective = total ** 2 / (variance ** 2 / dof + jitter ** 2 / int(jitter_samples))
        quantiles = np.array([student_quantile(confidence, max(float(v), 1.0))
                              if np.isfinite(v) else student_quantile(confidence, dof)
                              for v in effective])
        variance = total
    half = quantiles * np.sqrt(np.clip(variance, 0, np.inf))
    ends = [(x - h, x + h) for x, h in zip(x_hat, half)]
    log_fitted, iso, ctrl = model(x_hat)
    values = {n: float(np.exp(x)) for n, x in zip(free, x_hat)}
    with np.errstate(over="ignore"):
        intervals = {n: (float(np.exp(lo)), float(np.exp(hi))) for n, (lo, hi) in zip(free, ends)}
    rms = float(np.sqrt(np.mean((log_fitted - log_measured) ** 2)))
    return TransmissibilityFit(MappingProxyType(values), MappingProxyType(intervals), confidence,
                               iso, ctrl, excitation, f, measured, np.exp(log_fitted), rms,
                               counter["n"], _time.perf_counter() - began)
