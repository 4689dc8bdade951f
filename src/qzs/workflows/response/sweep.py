"""The steady-state response: the sweeps up and down asked for, checked before any work.

:func:`steady_state_response` checks its arguments, chooses the step (for an accuracy, on a
chirp over the band) and the time cap per frequency, then runs the sweeps
(:mod:`~qzs.workflows.response.pool`) beside the harmonic balance and the chirp, and
gathers a :class:`~qzs.workflows.response.result.SteadyStateResponse`.
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from qzs import defaults
from qzs._validation import choice, integer, positive_real, worker_count
from qzs.errors import CountLimitError, ParameterError
from qzs.model.excitation import Chirp
from qzs.workflows.response.chirp import _run_chirp
from qzs.workflows.response.frequency import (CONSECUTIVE_PERIODS, MAX_PERIOD_MULTIPLE,
                                              PERIODIC_TOLERANCE, SAMPLES_PER_PERIOD, SweepPlan)
from qzs.workflows.response.pool import _run_chains
from qzs.workflows.response.result import SteadyStateResponse

if TYPE_CHECKING:
    from qzs.model.controller import ControllerParameters
    from qzs.model.isolator import IsolatorParameters

__all__ = ["steady_state_response", "settle_time_cap", "response_step", "DIRECTIONS",
           "MAX_PERIODS"]

#: Sweep directions: ``up`` (rising frequency), ``down`` (falling), ``both`` (one of each).
DIRECTIONS = ("up", "down", "both")
#: Periods simulated at most per frequency [-] (a safety cap; the time cap usually ends it).
MAX_PERIODS = 100_000
#: By default a frequency may run this many of the linearised closed loop's slowest time
#: constants [-] (a linear decay from O(1) is then below 1e-13) before it is reported
#: unconverged: settling takes time constants, not periods (docs/response.md §3).
SETTLE_TIME_CONSTANTS = 30.0
#: The default time cap [s] is at least this, and this where the linear loop has no
#: decaying slowest mode (a pole at 0).
MIN_TIME = 60.0
#: ... and at most this [s].
MAX_TIME = 3600.0
#: Smallest ``periodic_tolerance``: the scaled state change of a periodic response is the
#: rounding of the state itself (about 1e-13 of its scale over a period), never below.
SMALLEST_PERIODIC_TOLERANCE = 1e-12
#: Default fade-in [s] of the first frequency of a sweep (rounded up to whole periods).
FADE_IN = 2.0
#: Default highest harmonic reported [-] (2..this).
HARMONICS = 5
#: A frequency needs at least this many integration steps per period at ``dt`` [-]: a
#: tenth of the step's Nyquist rate (the simulate summary warns below 20 as well).
MIN_STEPS_PER_PERIOD = 20
#: Most frequencies one response steps through [-]: each is a simulation of many periods,
#: and the list is checked before anything is built, so 1e8 of them fail at once.
MAX_FREQUENCIES = 10_000


def _frequencies(frequencies):
    try:
        values = np.asarray(frequencies, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"`frequencies` must be numbers in Hz, got {frequencies!r}.") from None
    if values.size == 0:
        raise ParameterError("`frequencies` is empty; give at least one frequency in Hz.")
    if values.size > MAX_FREQUENCIES:
        raise CountLimitError("frequencies", values.size, MAX_FREQUENCIES, "frequencies",
                              "give fewer, or split the band into several responses")
    bad = values[~np.isfinite(values) | (values <= 0)]
    if bad.size:
        raise ParameterError(f"`frequencies` must be positive and finite, got "
                             f"{float(bad[0])!r} Hz; drop it or give a positive frequency.")
    values = np.unique(values)
    return values


def _check_step(dt, frequencies, isolator, controller, solver):
    from qzs.engine.stability import largest_stable_step, stability_test

    if not stability_test(isolator, controller, solver)(dt):
        limit = largest_stable_step(isolator, controller, solver)
        raise ParameterError(f"`dt` ({dt!r} s) is too large for a stable {solver} integration "
                             f"of this model; the largest stable step is {limit:.3g} s. "
                             "Reduce `dt`.")
    top = frequencies[-1]
    if top * dt * MIN_STEPS_PER_PERIOD > 1.0 + 1e-9:
        raise ParameterError(
            f"`frequencies` reach {top:g} Hz, above a tenth of the Nyquist rate of the step "
            f"dt = {dt:g} s ({1 / (MIN_STEPS_PER_PERIOD * dt):g} Hz, {MIN_STEPS_PER_PERIOD} "
            f"steps per period); lower `dt` to at most {1 / (MIN_STEPS_PER_PERIOD * top):.3g} "
            "s or drop the higher frequencies.")


def _check_cap(frequencies, direction, dt, max_periods, max_time):
    """Refuse caps under which the frequencies that never settle would take more than a day.

    Each frequency runs at most ``min(max_periods / f, max_time)`` seconds; the step is at
    most ``dt`` and at most a :data:`SAMPLES_PER_PERIOD`-th of the highest frequency's
    period, so the count of steps is a lower bound and a refusal is certain.
    """
    from qzs.engine.driver import BEST_STEP_SECONDS, LONGEST_RUN

    frequencies = np.asarray(frequencies, dtype=float)
    longest = min(math.inf if dt is None else dt,
                  1.0 / (SAMPLES_PER_PERIOD * float(frequencies.max())))
    if not longest > 0:
        raise ParameterError(
            f"`frequencies` reach {frequencies.max():g} Hz: {SAMPLES_PER_PERIOD} samples per "
            "period need a step shorter than any number holds; give frequencies of the "
            "isolator's range (up to a few hundred Hz).")
    # whole periods: at least the settling test's, however short max_time is
    least = CONSECUTIVE_PERIODS + MAX_PERIOD_MULTIPLE + 1
    with np.errstate(over="ignore"):
        periods = np.maximum(np.minimum(max_periods, np.floor(max_time * frequencies)), least)
        simulated = float((periods / frequencies).sum())
    simulated *= 2 if direction == "both" else 1
    seconds = simulated / longest * BEST_STEP_SECONDS["single"]
    if seconds > LONGEST_RUN:
        raise ParameterError(
            f"`max_periods` = {max_periods} and `max_time` = {max_time:g} s let the "
            f"{frequencies.size} frequencies (from {frequencies.min():g} Hz, at least {least} "
            f"whole periods each) run {simulated:.3g} s of simulated time, at least "
            f"{seconds / 86_400:.3g} days of computing at dt <= {longest:.3g} s even at the "
            f"kernel's best speed, should they not settle; lower `max_time` (its default, "
            f"{MIN_TIME:g}-{MAX_TIME:g} s from the loop's time constants, is enough for a "
            "settling loop) or `max_periods`, or raise the lowest frequency.")


def settle_time_cap(isolator=None, controller=None):
    """Default simulated time at most per frequency [s].

    :data:`SETTLE_TIME_CONSTANTS` times the slowest time constant of the linearised closed
    loop (:func:`qzs.analysis.linear.linearize`, frictionless), clipped to
    [:data:`MIN_TIME`, :data:`MAX_TIME`]: 115 s for the paper's default loop (Kp = 50 N/m,
    Ki = 20 N/(m s): slowest pair at -0.26 1/s), 900 s for its stiction study's Kp = 5 N/m,
    Ki = 2 N/(m s) (-0.033 1/s). Friction changes how fast a response settles, but a
    response still changing after this long is on no decay the loop explains: a PI loop
    hunting against stiction, or a quasi-periodic or chaotic motion.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters.
    controller : ControllerParameters, optional
        PI and damping loops.

    Returns
    -------
    float
    """
    from qzs.analysis.linear import linearize

    try:
        poles = np.asarray(linearize(isolator, controller).poles)
    except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - defensive
        return MAX_TIME
    decay = -poles.real
    decay = decay[decay > 1e-9]
    if decay.size < poles.size or decay.size == 0:
        return MIN_TIME if decay.size == 0 else MAX_TIME
    return float(np.clip(SETTLE_TIME_CONSTANTS / decay.min(), MIN_TIME, MAX_TIME))


def response_step(frequencies, amplitude, isolator, controller, *, solver, tolerance=None,
                  sample_rate=None, progress=False, tolerance_db=None):
    """The accuracy-driven step of a stepped-sine response: a chirp over its band.

    The one call (:func:`qzs.engine.step_choice.choose`, with the one fallback) on a probe of
    a 60 s chirp of the response's amplitude from the lowest frequency (0.8 times it for one
    frequency) to the highest, at an output rate of at least ``MIN_STEPS_PER_PERIOD`` samples
    per period of the highest, measured over that band.

    Parameters
    ----------
    frequencies : ndarray
        The response's frequencies [Hz], ascending.
    amplitude : float
        Base displacement amplitude [m].
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    solver : str
        The integrator.
    tolerance : float, optional
        Tolerance on the transmissibility [dB]; default ``qzs.defaults.ACCURACY``'s.
    sample_rate : float, optional
        The probe's output rate [Hz]; default the larger of the default rate and
        ``MIN_STEPS_PER_PERIOD`` per period of the highest frequency.
    progress : bool
        Show the probe runs' progress.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    StepChoice
        The record (``met`` False, ``error`` NaN and the unmet sentence for the fallback).
    """
    from qzs.engine.accuracy import SingleProbe
    from qzs.engine.step_choice import choose, step_request

    request = step_request(tolerance=tolerance, tolerance_db=tolerance_db)
    low, high = float(frequencies[0]), float(frequencies[-1])
    if sample_rate is None:
        sample_rate = max(defaults.SIMULATION["sample_rate"], math.ceil(MIN_STEPS_PER_PERIOD * high))
    if low == high:
        low = 0.8 * high
    probe = Chirp(amplitude=amplitude, f0=low, f1=high, duration=60.0,
                  fade_in=min(2.0 / low, 15.0))
    return choose(request, SingleProbe(excitation=probe, isolator=isolator,
                                       controller=controller, solver=solver,
                                       sample_rate=sample_rate, band=(low, high)),
                  fallback=True, progress=progress, cache=True)


def steady_state_response(frequencies: ArrayLike,
                          amplitude: float = defaults.EXCITATION["amplitude"],
                          isolator: IsolatorParameters | None = None,
                          controller: ControllerParameters | None = None, *,
                          direction: str = "both", dt: float | None = None,
                          tolerance: float | None = None,
                          solver: str = defaults.SIMULATION["solver"],
                          periodic_tolerance: float = PERIODIC_TOLERANCE,
                          max_periods: int = MAX_PERIODS, max_time: float | None = None,
                          fade_in: float = FADE_IN, harmonics: int = HARMONICS,
                          harmonic_balance: bool = True, friction_velocity: float | None = None,
                          balance_harmonics: int | None = None, compare_chirp: bool = False,
                          workers: int | None = None,
                          progress: bool = False,
                          tolerance_db: float | None = None) -> SteadyStateResponse:
    """Steady-state frequency response by stepped-sine simulation.

    Each sweep (``up``: rising frequency, ``down``: falling) starts from rest at its first
    frequency with a fade-in and continues each later frequency from the previous one's
    final state, the base at its crest (zero velocity) at the junction. At each frequency
    the isolator is simulated period by period until the state (z, v, high-pass state, PI
    integral, and the stick/slip mode) at the start of a period agrees with the one a
    period before (or two or three: a sub-harmonic response) within ``periodic_tolerance``
    for 3 periods in a row, the extrapolated remainder of a geometric approach too. The
    last period(s) then give the fundamental amplitude ratio (a single-bin DFT of 256
    samples per period: exact for a periodic signal up to aliasing of harmonics above
    127), the harmonics, relative amplitude, locked share and stop contacts. A frequency
    that does not settle within ``max_periods`` is NaN with its reason.

    The two sweeps run in parallel processes (each is sequential: every frequency starts
    from the last); the harmonic balance and the chirp, if asked, run beside them.

    Parameters
    ----------
    frequencies : array_like
        Frequencies [Hz], positive; sorted, duplicates dropped.
    amplitude : float
        Base displacement amplitude [m].
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted. A sampled controller is not supported.
    direction : {"both", "up", "down"}
        Sweeps to run.
    dt : float, optional
        Largest integration step [s]; each frequency uses the largest step at most this
        with a whole number of output samples per period. Default: chosen for
        ``tolerance`` (:func:`response_step`, on a chirp over the band).
    tolerance : float, optional
        Accuracy of the chosen step [dB]; default 0.01 (``qzs.defaults.ACCURACY``). Not
        with ``dt``.
    solver : {"ode3", "rk4", "euler"}
        Integrator.
    periodic_tolerance : float
        Periodicity tolerance [-]: scaled state change per period (z by the base amplitude
        A, velocities by A*w, the integral by A/w).
    max_periods : int
        Periods at most per frequency [-].
    max_time : float, optional
        Simulated time at most per frequency [s] (whichever cap comes first; at least the
        fade-in and the few periods the tests need). Default :func:`settle_time_cap`: 30
        of the linearised loop's slowest time constants, within 60 to 3600 s.
    fade_in : float
        Fade-in of each sweep's first frequency [s], rounded up to whole periods.
    harmonics : int
        Highest harmonic reported [-] (2..harmonics; at most 64).
    harmonic_balance : bool
        Also follow the smooth model by harmonic balance over the range.
    friction_velocity : float, optional
        Regularisation velocity of the smooth model's friction [m/s]; default
        :data:`qzs.analysis.harmonic_balance.FRICTION_VELOCITY`.
    balance_harmonics : int, optional
        Harmonics of the harmonic balance [-]; default
        :data:`qzs.analysis.harmonic_balance.DEFAULT_HARMONICS`.
    compare_chirp : bool
        Also simulate the paper's chirp for this case and estimate its transmissibility
        (:func:`~qzs.workflows.response.chirp.chirp_transmissibility`; 2000 s of simulated
        time for 0-20 Hz).
    workers : int, optional
        Processes [-]; default the tasks that can run at once, at most the core count.
        1 runs everything in this process.
    progress : bool
        Show a progress bar over frequencies.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    SteadyStateResponse

    Raises
    ------
    ParameterError
        Invalid input, found before any simulation: frequencies not positive and finite,
        more than :data:`MAX_FREQUENCIES` of them (:class:`~qzs.errors.CountLimitError`) or
        above a tenth of the step's Nyquist rate, a non-positive amplitude, an unknown
        direction, both ``dt`` and ``tolerance``, an unstable ``dt``, a sampled
        controller.
    """
    started = time.perf_counter()
    frequencies = _frequencies(frequencies)

    import qzs.analysis.harmonic_balance as hb
    from qzs.analysis.linear import linearize
    from qzs.engine.prepare import run_inputs

    amplitude = positive_real("amplitude", amplitude)
    _, isolator, controller = run_inputs(None, isolator, controller)
    direction = choice("direction", direction, DIRECTIONS)
    from qzs.engine.stability import SOLVERS

    solver = choice("solver", solver, tuple(SOLVERS))
    from qzs.engine.step_choice import step_request

    request = step_request(dt=dt, tolerance=tolerance, tolerance_db=tolerance_db)
    if dt is not None:
        dt = positive_real("dt", dt)
    periodic_tolerance = positive_real("periodic_tolerance", periodic_tolerance)
    if not SMALLEST_PERIODIC_TOLERANCE <= periodic_tolerance < 0.1:
        raise ParameterError(f"`periodic_tolerance` must be from {SMALLEST_PERIODIC_TOLERANCE:g} "
                             f"(below it the state's own rounding never meets it, and the run "
                             f"goes on to its cap) up to 0.1, got {periodic_tolerance!r}; 1e-6 "
                             "is the default.")
    max_periods = integer("max_periods", max_periods, CONSECUTIVE_PERIODS + MAX_PERIOD_MULTIPLE + 1)
    if max_time is not None:
        max_time = positive_real("max_time", max_time)
    _check_cap(frequencies, direction, dt, max_periods,
               settle_time_cap(isolator, controller) if max_time is None else max_time)
    fade_in = float(fade_in)
    if not math.isfinite(fade_in) or fade_in < 0:
        raise ParameterError(f"`fade_in` must be a non-negative number of seconds, got "
                             f"{fade_in!r}.")
    harmonics = integer("harmonics", harmonics, 2)
    if harmonics > SAMPLES_PER_PERIOD // 4:
        raise ParameterError(f"`harmonics` must be at most {SAMPLES_PER_PERIOD // 4} (the "
                             f"{SAMPLES_PER_PERIOD} samples per period), got {harmonics}.")
    friction_velocity = hb.FRICTION_VELOCITY if friction_velocity is None else positive_real(
        "friction_velocity", friction_velocity)
    balance_harmonics = hb.DEFAULT_HARMONICS if balance_harmonics is None else integer(
        "balance_harmonics", balance_harmonics, 1)
    if workers is not None:
        workers = integer("workers", workers, 1)
    if controller.controller_rate > 0:
        raise ParameterError(
            f"`controller_rate` ({controller.controller_rate!r} Hz) > 0: a sampled controller "
            "adds its own period, which divides no excitation period in general, so the "
            "response is not periodic; set controller_rate=0 (continuous) for the steady "
            "state.")
    notes = []
    step = None
    if dt is None:
        step = response_step(frequencies, amplitude, isolator, controller, solver=solver,
                             tolerance=request.tolerance, progress=progress)
        dt = step.dt
        notes.append(f"dt <= {step.line()}, on a {step.probe.f0:g}-{step.probe.f1:g} Hz chirp "
                     "probe")
    _check_step(dt, frequencies, isolator, controller, solver)
    if max_time is None:
        max_time = settle_time_cap(isolator, controller)
    chains = {"up": list(frequencies), "down": list(frequencies[::-1])}
    chains = {d: chains[d] for d in (("up", "down") if direction == "both" else (direction,))}
    base = SweepPlan(amplitude=amplitude, isolator=isolator, controller=controller, dt=dt,
                     solver=solver, periodic_tolerance=periodic_tolerance,
                     max_periods=max_periods, max_time=max_time, fade_in=fade_in,
                     harmonics=harmonics)
    extra = {}
    if harmonic_balance:
        low, high = float(frequencies[0]), float(frequencies[-1])
        if low == high:
            low, high = 0.9 * low, 1.1 * high
        extra["balance"] = (_run_balance, dict(
            isolator=isolator, controller=controller, amplitude=amplitude,
            friction_velocity=friction_velocity, range=(low, high), harmonics=balance_harmonics))
    if compare_chirp:
        extra["chirp"] = (_run_chirp, dict(amplitude=amplitude, isolator=isolator,
                                           controller=controller, top=float(frequencies[-1]),
                                           dt=min(dt, defaults.SIMULATION["dt"] * 10),
                                           solver=solver))
    concurrent = len(chains) + len(extra)
    if workers is None:  # an explicit count is the user's; the default, no more than there is to do
        workers = worker_count(None, concurrent)
    settings = {"periodic_tolerance": periodic_tolerance, "max_periods": max_periods,
                "max_time": max_time, "samples_per_period": SAMPLES_PER_PERIOD, "fade_in": fade_in,
                "harmonics": harmonics, "workers": workers}
    points, outcomes = _run_chains(chains, base, extra, workers, progress)
    balance, note = outcomes.get("balance", (None, ""))
    if note:
        notes.append(note)
    linear = {}
    try:
        grid = (np.geomspace(frequencies[0], frequencies[-1], 400) if frequencies.size > 1
                else frequencies)
        model = linearize(isolator, controller)
        linear = {"frequency": grid,
                  "transmissibility": np.asarray(model.transmissibility(grid), dtype=float),
                  "at_frequencies": np.asarray(model.transmissibility(frequencies),
                                               dtype=float)}
    except (ValueError, np.linalg.LinAlgError) as error:  # pragma: no cover - defensive
        notes.append(f"no linear model: {error}")
    unconverged = [p for p in points if not p.converged]
    if unconverged:
        where = "; ".join(
            f"{d} {min(p.frequency for p in unconverged if p.direction == d):g}-"
            f"{max(p.frequency for p in unconverged if p.direction == d):g} Hz"
            for d in chains if any(p.direction == d for p in unconverged))
        notes.append(f"{len(unconverged)} point(s) NaN ({where}); e.g. {unconverged[0].direction} "
                     f"{unconverged[0].frequency:g} Hz: {unconverged[0].reason}")
    return SteadyStateResponse(points=tuple(points), frequencies=frequencies,
                               amplitude=amplitude, isolator=isolator, controller=controller,
                               solver=solver, dt=dt, step=step, settings=settings,
                               balance=balance, linear=linear,
                               chirp=outcomes.get("chirp"), notes=tuple(notes),
                               elapsed=time.perf_counter() - started)


def _run_balance(task):
    """Harmonic balance over the range (a worker task); returns ``(curve, note)``."""
    from qzs.analysis.harmonic_balance import SmoothModel, frequency_response_curve

    try:
        model = SmoothModel.from_parameters(task["isolator"], task["controller"],
                                            amplitude=task["amplitude"],
                                            friction_velocity=task["friction_velocity"])
        curve = frequency_response_curve(model, task["range"], harmonics=task["harmonics"])
    except (ParameterError, np.linalg.LinAlgError, FloatingPointError) as error:
        return None, f"harmonic balance failed: {error}"
    if curve.frequency.size < 2:
        return None, "harmonic balance: " + "; ".join(curve.notes)
    note = ("harmonic balance: " + "; ".join(curve.notes)) if curve.notes else ""
    return curve, note

