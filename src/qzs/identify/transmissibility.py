"""Chosen model parameters fitted to a measured transmissibility curve through the simulator."""
import dataclasses
import time as _time
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from scipy import optimize

from qzs.analysis.spectral import transmissibility
from qzs.engine.prepare import steps_per_sample
from qzs.engine.simulate import simulate
from qzs.errors import DataError, FitError, ParameterError, SimulationError
from qzs.identify._statistics import fit_covariance, finite_samples, student_quantile
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import PARAMETERS, numeric_parameters

__all__ = ["TransmissibilityFit", "fit_transmissibility"]


@dataclass(frozen=True, eq=False)
class TransmissibilityFit:
    """Result of :func:`fit_transmissibility`.

    Attributes
    ----------
    parameters : Mapping[str, float]
        Fitted values of the free parameters (registry names and SI units, docs/model.md §11).
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
        """Measured and fitted curves (:func:`qzs.viz.identify.plot_transmissibility_fit`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (a .png also as .svg).
        title : str
            Figure title.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.identify import plot_transmissibility_fit

        return plot_transmissibility_fit(self, path=path, title=title)


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
    acceleration (:func:`qzs.analysis.spectral.transmissibility`, PSD ratio) and interpolates it
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
    half = student_quantile(confidence, dof) * np.sqrt(np.clip(np.diag(covariance), 0, np.inf))
    log_fitted, iso, ctrl = model(solution.x)
    values = {n: float(np.exp(x)) for n, x in zip(free, solution.x)}
    with np.errstate(over="ignore"):
        intervals = {n: (float(np.exp(x - h)), float(np.exp(x + h)))
                     for n, x, h in zip(free, solution.x, half)}
    return TransmissibilityFit(MappingProxyType(values), MappingProxyType(intervals), confidence,
                               iso, ctrl, excitation, f, measured, np.exp(log_fitted),
                               float(np.sqrt(np.mean(solution.fun ** 2))), counter["n"],
                               _time.perf_counter() - began)
