"""One frequency of the steady-state response: simulated period by period until periodic.

The isolator runs under a sine one period per call (:class:`qzs.engine.periodic.PeriodicRun`)
until the state at the start of a period agrees with the one a period before (or two or
three: a sub-harmonic response) within a tolerance, the extrapolated remainder of a geometric
approach too (docs/response.md §1-3). The last period(s) then give the point: a single-bin
DFT per harmonic of the output samples (§2).
"""
import math
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from qzs.model.excitation import Sine
from qzs.workflows.response.result import ResponsePoint

__all__ = ["steps_for", "SAMPLES_PER_PERIOD", "PERIODIC_TOLERANCE", "CONSECUTIVE_PERIODS",
           "MAX_PERIOD_MULTIPLE", "SweepPlan", "FrequencyRun"]

#: Output samples per period [-]: the DFT's length per period. A multiple of the kernels'
#: exact-sine period (256 steps), so a period is a whole number of kernel chunks and the
#: numbers are those of one uncut run (docs/model.md §9).
SAMPLES_PER_PERIOD = 256
#: Default tolerance of periodicity [-]: the state's change over a period, relative to the
#: base's amplitude (displacement, velocity, integral), and its extrapolated remainder.
PERIODIC_TOLERANCE = 1e-6
#: Successive periods that must meet the tolerance [-].
CONSECUTIVE_PERIODS = 3
#: Largest sub-harmonic order looked for [-]: period-2 and period-3 responses.
MAX_PERIOD_MULTIPLE = 3
#: A period-m response needs every shorter period's state change above this many
#: tolerances [-]: far from settling, not merely slower.
SUBHARMONIC_SEPARATION = 1000.0
#: Scaled state changes below this are round-off: the response repeats exactly [-].
ROUND_OFF = 1e-11


@dataclass(frozen=True, kw_only=True)
class SweepPlan:
    """What every frequency of a steady-state sweep shares, resolved (its step chosen).

    Attributes
    ----------
    amplitude : float
        The base's displacement amplitude [m].
    isolator : IsolatorParameters
        The isolator.
    controller : ControllerParameters
        Its controller.
    dt : float
        The largest integration step [s] (each frequency's divides its period).
    solver : str
        The integration scheme.
    periodic_tolerance : float
        Periodicity tolerance [-]: scaled state change per period.
    max_periods : int
        Most periods simulated per frequency.
    max_time : float
        Most simulated time per frequency [s].
    fade_in : float
        Fade-in of a start from rest [s].
    harmonics : int
        Harmonics of the output read [-].
    """

    amplitude: float
    isolator: Any
    controller: Any
    dt: float
    solver: str
    periodic_tolerance: float
    max_periods: int
    max_time: float
    fade_in: float
    harmonics: int

    def at(self, direction, frequency, carried=None):
        """The run of one frequency of a sweep.

        Parameters
        ----------
        direction : {"up", "down"}
            The sweep it belongs to.
        frequency : float
            The excitation's frequency [Hz].
        carried : CarriedState, optional
            The previous frequency's final state; None: start from rest.

        Returns
        -------
        FrequencyRun
        """
        return FrequencyRun(plan=self, direction=direction, frequency=frequency,
                            carried=carried)


@dataclass(frozen=True, kw_only=True)
class FrequencyRun:
    """One frequency of a sweep: the plan, the sweep's direction, where it starts.

    Attributes
    ----------
    plan : SweepPlan
        What every frequency shares.
    direction : {"up", "down"}
        The sweep it belongs to.
    frequency : float
        The excitation's frequency [Hz].
    carried : CarriedState or None
        The previous frequency's final state (:class:`~qzs.engine.periodic.CarriedState`);
        None: start from rest.
    """

    plan: SweepPlan
    direction: str
    frequency: float
    carried: Any = None


def steps_for(frequency, dt):
    """Integration steps per period at ``frequency`` for a largest step ``dt`` [-].

    The fewest multiple of :data:`SAMPLES_PER_PERIOD` whose step ``1/(frequency*steps)``
    is at most ``dt``: every period is then a whole number of steps and of output samples.

    Parameters
    ----------
    frequency : float
        Excitation frequency [Hz].
    dt : float
        Largest integration step [s].

    Returns
    -------
    int
    """
    blocks = max(1, math.ceil(1.0 / (frequency * dt * SAMPLES_PER_PERIOD) - 1e-9))
    return SAMPLES_PER_PERIOD * blocks


def _scaled_distance(a, b, scale):
    """Largest scaled difference of two period-boundary states; inf if the modes differ."""
    if a[1] != b[1]:
        return math.inf
    return float(np.max(np.abs(a[0] - b[0]) / scale))


def _remaining(history, multiple):
    """Estimated distance of the last state from the periodic limit [-].

    ``history`` holds the scaled changes ``d_k = |s_k - s_{k-multiple}|``; with the
    per-period contraction ``rho`` (the largest ratio of successive changes) the rest of
    a geometric approach is ``d_k rho^m / (1 - rho^m)``. Changes below round-off count as
    zero. Returns inf where the changes do not shrink.
    """
    values = [0.0 if d <= ROUND_OFF else d for d in list(history)[-CONSECUTIVE_PERIODS:]]
    last = values[-1]
    if last == 0.0:
        return 0.0
    rho = 0.0
    for previous, current in zip(values, values[1:]):
        if current == 0.0:
            continue
        if previous == 0.0:
            return math.inf
        rho = max(rho, current / previous)
    if rho >= 1.0:
        return math.inf
    contraction = rho ** multiple
    return last * contraction / (1.0 - contraction)


def _period_multiple(changes, tolerance):
    """The period multiple the response has settled on, 0 if none (docs/response.md §3).

    Period m when, over the last :data:`CONSECUTIVE_PERIODS` periods, every m-period change
    is within ``tolerance``, so is the extrapolated rest of the approach
    (:func:`_remaining`), and every shorter period's last change stays above
    :data:`SUBHARMONIC_SEPARATION` tolerances (a period-1 response approached slowly can
    meet the 2-period test a little before the 1-period one: it is not period 2). m = 1
    is tried first.

    Parameters
    ----------
    changes : mapping of int to sequence of float
        For m = 1 .. :data:`MAX_PERIOD_MULTIPLE`, the scaled changes ``d_m`` of the periods
        so far (oldest first; only the last :data:`CONSECUTIVE_PERIODS` count) [-].
    tolerance : float
        Tolerance of periodicity [-].

    Returns
    -------
    int
    """
    for m in range(1, MAX_PERIOD_MULTIPLE + 1):
        history = list(changes[m])[-CONSECUTIVE_PERIODS:]
        shorter_apart = all(changes[j] and changes[j][-1] > SUBHARMONIC_SEPARATION * tolerance
                            for j in range(1, m))
        if (len(history) == CONSECUTIVE_PERIODS and max(history) <= tolerance
                and _remaining(history, m) <= tolerance and shorter_apart):
            return m
    return 0


_STATE_NAMES = {"relative_position": "the relative position",
                "relative_velocity": "the relative velocity",
                "highpass_state": "the high-pass state", "pi_integral": "the PI integral"}


def _dominant(boundaries, scale, names):
    """Which state changed most (scaled) over the last period, for a reason."""
    if len(boundaries) < 2:
        return "unknown"
    change = np.abs(boundaries[-1][0] - boundaries[-2][0]) / scale
    name = _STATE_NAMES[names[int(np.argmax(change))]]
    if boundaries[-1][1] != boundaries[-2][1]:
        name += ", and the stick/slip mode differs"
    return name


def _dft(values, bins):
    """Complex amplitudes of ``values`` (samples of whole periods, from phase 0) at ``bins``."""
    n = values.size
    phase = np.exp(-2j * np.pi * np.outer(bins, np.arange(n)) / n)
    return (2.0 / n) * (phase @ values)


def _analyse(rows, flags, period_count, amplitude, motor_force_max, harmonic_count):
    """The steady-state quantities of ``period_count`` whole periods of output rows."""
    from qzs.engine.channels import CHANNELS, FLAGS

    # the kernel records at the end of each block: the last row is at phase 2*pi*count,
    # i.e. phase 0; rolled to the front, row j is at phase 2*pi*j/samples*count
    rows = np.roll(rows, 1, axis=0)
    flags = np.roll(flags, 1, axis=0)
    m = period_count
    x, y, z = (rows[:, CHANNELS[name][0]]
               for name in ("payload_displacement", "base_displacement", "relative_position"))
    fundamental = _dft(y, [m])[0]
    harmonic_bins = [m * k for k in range(1, harmonic_count + 1)]
    payload = _dft(x, harmonic_bins)
    ratio = payload[0] / fundamental
    # acceleration harmonic k = -(k w)^2 x_k: k^2 |x_k| / |y_1| (exact for periodic motion)
    harmonics = tuple(float(k * k * abs(payload[k - 1]) / abs(fundamental))
                      for k in range(2, harmonic_count + 1))
    sub = 0.0
    if m > 1:
        sub_bins = [j for j in range(1, m * harmonic_count) if j % m]
        values = np.abs(_dft(x, sub_bins)) * (np.array(sub_bins) / m) ** 2 / abs(fundamental)
        sub = float(values.max())
    command = rows[:, CHANNELS["pi_force"][0]] + rows[:, CHANNELS["damping_force"][0]]
    return dict(transmissibility=float(abs(ratio)), phase=float(np.angle(ratio)),
                harmonics=harmonics, subharmonic=sub,
                relative_amplitude=float(abs(_dft(z, [m])[0])),
                relative_peak=float(0.5 * np.ptp(z)), mean_relative_position=float(z.mean()),
                locked_fraction=float(np.mean(flags[:, FLAGS["locked"][0]])),
                saturated_fraction=float(np.mean(np.abs(command) >= motor_force_max)))


def _nan_values(harmonic_count):
    nan = math.nan
    return dict(transmissibility=nan, phase=nan, harmonics=(nan,) * (harmonic_count - 1),
                subharmonic=nan, relative_amplitude=nan, relative_peak=nan,
                mean_relative_position=nan, locked_fraction=nan, saturated_fraction=nan,
                stop_contacts=nan)


def _run_frequency(task):
    """Simulate one frequency until periodic (runs in a worker process or inline).

    ``task``: a :class:`FrequencyRun`. Returns ``(point, carried)``: the
    :class:`~qzs.workflows.response.result.ResponsePoint` and the final state to start the
    next frequency from (None after a divergence).
    """
    from qzs.engine.periodic import PeriodicRun
    from qzs.engine.channels import CHANNELS, FLAGS

    started = time.perf_counter()
    plan = task.plan
    frequency, amplitude = task.frequency, plan.amplitude
    period = 1.0 / frequency
    steps = steps_for(frequency, plan.dt)
    dt = period / steps
    carried = task.carried
    fade_periods = 0 if carried is not None else math.ceil(plan.fade_in * frequency - 1e-9)
    # base y = A sin(w t + pi/2) = A cos(w t): every period starts at the crest, where the
    # base velocity is zero, so a state carried from another frequency starts with the same
    # base displacement and velocity as it ended with (docs/response.md §4)
    excitation = Sine(amplitude=amplitude, frequency=frequency, phase=0.5 * math.pi,
                      fade_in=fade_periods * period)
    run = PeriodicRun(excitation, plan.isolator, plan.controller, period=period, dt=dt,
                      sample_rate=frequency * SAMPLES_PER_PERIOD, solver=plan.solver,
                      carried=carried)
    harmonic_count = plan.harmonics
    omega = 2 * math.pi * frequency
    # the states that act on the motion: z and v; the high-pass state where the damping
    # loop feeds it back; the PI integral where Ki > 0 (without its gain the integral of a
    # payload held off the setpoint grows for ever, and the motion is periodic all the same)
    controller = plan.controller
    state_names = ["relative_position", "relative_velocity"]
    scale = [amplitude, amplitude * omega]
    if controller.damping_gain > 0 and controller.velocity_highpass > 0:
        state_names.append("highpass_state")
        scale.append(amplitude * omega)
    if controller.pi_ki > 0:
        state_names.append("pi_integral")
        scale.append(amplitude / omega)
    scale = np.array(scale)
    keep = MAX_PERIOD_MULTIPLE
    rows, marks = run.output_buffers(keep)
    boundaries = deque(maxlen=MAX_PERIOD_MULTIPLE + 1)
    contacts = deque(maxlen=MAX_PERIOD_MULTIPLE + 1)
    changes = {m: deque(maxlen=CONSECUTIVE_PERIODS) for m in range(1, MAX_PERIOD_MULTIPLE + 1)}
    tolerance = plan.periodic_tolerance
    motor_force_max = plan.isolator.motor_force_max
    multiple, periods, residual, reason = 0, 0, math.inf, ""
    cap = max(min(plan.max_periods, math.floor(plan.max_time * frequency)),
              fade_periods + CONSECUTIVE_PERIODS + MAX_PERIOD_MULTIPLE + 1)
    for periods in range(1, cap + 1):
        slot = periods % keep
        if run.advance(rows[slot], marks[slot]):
            reason = "diverged: " + run.divergence()
            point = ResponsePoint(direction=task.direction, frequency=frequency,
                                  **_nan_values(harmonic_count), period_multiple=0,
                                  periods=periods, settle_time=periods * period,
                                  residual=math.nan, converged=False, reason=reason,
                                  start="continued" if carried is not None else "rest", dt=dt,
                                  seconds=time.perf_counter() - started)
            return point, None
        boundaries.append((run.state_of(state_names), run.mode))
        contacts.append(run.stop_contacts)
        if periods <= fade_periods:
            continue
        for m in range(1, MAX_PERIOD_MULTIPLE + 1):
            if len(boundaries) > m and periods - m >= fade_periods:
                changes[m].append(_scaled_distance(boundaries[-1], boundaries[-1 - m], scale))
        residual = changes[1][-1] if changes[1] else math.inf
        multiple = _period_multiple(changes, tolerance)
        if multiple:
            residual = changes[multiple][-1]
            break
    start = "continued" if carried is not None else "rest"
    if multiple:
        order = [(periods - multiple + 1 + i) % keep for i in range(multiple)]
        values = _analyse(np.concatenate([rows[i] for i in order]),
                          np.concatenate([marks[i] for i in order]), multiple, amplitude,
                          motor_force_max, harmonic_count)
        values["stop_contacts"] = (contacts[-1] - contacts[-1 - multiple]) / multiple
    else:
        values = _nan_values(harmonic_count)
        last = periods % keep
        z = rows[last][:, CHANNELS["relative_position"][0]]
        offset = float(np.mean(z)) - controller.position_setpoint
        reason = (f"not periodic after {periods} periods ({periods * period:.4g} s): the state "
                  f"still changed by {residual:.2g} (relative to the base's amplitude; mostly "
                  f"{_dominant(boundaries, scale, state_names)}) over the last period, and no "
                  "period-2 or period-3 response either (in the last period the payload was "
                  f"locked {100 * np.mean(marks[last][:, FLAGS['locked'][0]]):.0f} % of the "
                  f"time, its mean "
                  f"{1e3 * offset:+.3g} mm from the setpoint); raise `max_periods` or "
                  "`max_time`, or the response is quasi-periodic or chaotic")
    point = ResponsePoint(direction=task.direction, frequency=frequency, **values,
                          period_multiple=multiple, periods=periods,
                          settle_time=periods * period, residual=float(residual),
                          converged=bool(multiple), reason=reason, start=start, dt=dt,
                          seconds=time.perf_counter() - started)
    return point, run.carry()

