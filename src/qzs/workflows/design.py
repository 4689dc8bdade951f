"""``qzs design``: PI and damping gains for the isolator, searched by simulation (docs/design.md).

From the isolator's parameters and a description of the disturbance (a base motion, payload
force steps, ranges of stiction and payload mass), :func:`design_controller` finds

1. the smallest PI gains (``Ki = ratio*Kp``, the ratio of the given controller) that keep the
   payload inside the spring's constant-force band and off the stops in every case, by
   simulation: a log grid of ``Kp``, then bisection between the last failing and the first
   passing gain above which every grid gain passes;
2. whether the PI loop hunts at rest (describing functions of
   :func:`qzs.analysis.control_design.predict_hunting`, and simulations that confirm or refute
   them);
3. the damping gain that minimises a transmissibility cost over a band (RMS or peak), within
   the linear stability bound and the sampled loop's margins;
4. the sampled loop's margins at the controller's rate with a delay, and the rate the design
   needs;
5. why active damping "did not help much" in the paper: the cost's change with damping
   against the charge amplifier's high-pass, the guide's viscous friction, the controller
   rate (simulated) and a delay (the linear sampled model: the simulator has none);
6. the static design (:func:`qzs.analysis.control_design.static_design`).

Three families of cases, each over the ends of the stiction and mass ranges (and the middle
stiction, unless ``quick``):

``base``
    The base motion alone, from the default start (the integral preloaded for the case's own
    weight). Run through :func:`qzs.simulate_batch`, every gain and case in one lockstep batch.
``step``
    The base motion plus a payload force step ``dF`` [N] (upward positive) at ``t = 0``: the
    integral starts ``dF/Ki`` above its preload, which adds ``dF`` to the motor's force exactly
    as a load change would (both are constant and add before the saturation; the anti-windup
    sees the same command while the motor is not saturated). ``simulate_batch`` starts every
    case from the default state, so these run through :func:`qzs.simulate` with an
    ``InitialState``, in threads (the kernel releases the GIL).
``hunting``
    The base at rest, the payload stuck off the setpoint at the plateau the describing
    function predicts for its hunting cycle (at least 1 mm, at most half the stroke), the
    loop in balance: the integral winds up, the payload breaks away, and hunts or settles.
"""
import dataclasses
import html
import json
import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from qzs import defaults
from qzs._validation import worker_count
from qzs._version import __version__
from qzs.analysis import control_design as cd
from qzs.analysis.spectral import band_mask, transmissibility
from qzs.engine.accuracy import choose_step
from qzs.engine.batch import simulate_batch
from qzs.engine.simulate import simulate
from qzs.errors import ParameterError, SimulationError, ToleranceNotMetError
from qzs.iotools.files import atomic_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine
from qzs.model.isolator import InitialState, IsolatorParameters, spring_force, spring_stiffness
from qzs.model.registry import model_inputs

__all__ = ["DesignCase", "DesignResult", "design_controller", "COSTS", "FAMILIES",
           "transmissibility_cost", "design_text"]

#: Transmissibility costs over the band: RMS of the amplitude ratio over the trusted bins
#: (equally spaced in frequency: the payload's RMS acceleration per RMS of a base acceleration
#: white over the band), or its largest value.
COSTS = ("rms", "peak")
#: Case families (see the module's text).
FAMILIES = ("base", "step", "hunting")
#: Output rate of the design's runs [Hz] (ten times the default band's top).
SAMPLE_RATE = 200.0
#: Welch segment length of the cost [samples]: quick and full.
FFT_LENGTH = {True: 2048, False: 8192}
#: Length of the quick runs' chirp [s] (the same sweep, ten times faster than the paper's).
QUICK_CHIRP = 200.0
#: Proportional gains tried first [N/m]: quick and full.
KP_GRID = {True: tuple(np.geomspace(1.0, 1000.0, 7)), False: tuple(np.geomspace(1.0, 1000.0, 10))}
#: Bisection steps between the bracketing gains: quick and full.
BISECTIONS = {True: 3, False: 5}
#: Longest hunting run [s]: quick and full.
HUNTING_MAX = {True: 600.0, False: 1500.0}
#: Damping gains tried in the coarse pass (besides 0) and the refinement: quick and full.
DAMPING_POINTS = {True: (5, 3), False: (7, 4)}
#: Largest damping gain tried by default [N*s/m]: ten times the guide's viscous friction.
#: The model has no sensor noise, motor bandwidth or structural mode, which bound a real
#: gain: beyond this it is not to be trusted.
DAMPING_GAIN_MAX = 1000.0
#: Largest step of the PI search's runs [s] (see _stroke_step).
STROKE_STEP_MAX = 2.5e-3
#: Least share of the band's bins that must be trusted for a cost to be defined [-].
TRUSTED_SHARE_MIN = 0.5
#: Controller rates [Hz] of the margin table and the rate experiments.
RATES = (20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0)
#: Delays [s] of the linear delay experiment.
DELAYS = (0.0, 0.001, 0.002, 0.005)


def _float(name, value, *, minimum=None, strict=False, fix=""):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"`{name}` must be a number, got {value!r}{fix}.")
    value = float(value)
    if not math.isfinite(value) or (minimum is not None and (
            value < minimum or (strict and value == minimum))):
        bound = "" if minimum is None else (f" > {minimum:g}" if strict else f" >= {minimum:g}")
        raise ParameterError(f"`{name}` must be a finite number{bound}, got {value!r}{fix}.")
    return value


def _pair(name, value, unit, *, minimum=0.0, example="(1, 2)"):
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be two numbers (low, high) in {unit}, got "
                             f"{value!r}; e.g. {example}.") from None
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise ParameterError(f"`{name}` must satisfy {minimum:g} <= low <= high (finite, in "
                             f"{unit}), got {value!r}; e.g. {example}.")
    return (low, high)


# ---------------------------------------------------------------- cases
@dataclass(frozen=True)
class DesignCase:
    """One case of the PI search.

    Attributes
    ----------
    family : {"base", "step", "hunting"}
        What disturbs the payload (see the module's text).
    stiction_force : float
        Breakaway friction of this case [N].
    mass : float
        Moving mass of this case [kg].
    force_step : float
        Payload force step at t = 0 [N], upward positive (``step`` cases; else 0).
    """

    family: str
    stiction_force: float
    mass: float
    force_step: float = 0.0

    @property
    def label(self):
        """A short description for tables."""
        text = f"{self.family}: Fs {self.stiction_force:g} N, m {self.mass:g} kg"
        if self.family == "step":
            text += f", dF {self.force_step:+g} N"
        return text

    def isolator(self, nominal):
        """The nominal isolator with this case's stiction and mass.

        Parameters
        ----------
        nominal : IsolatorParameters
            Every other parameter.

        Returns
        -------
        IsolatorParameters
        """
        return dataclasses.replace(nominal, stiction_force=self.stiction_force, mass=self.mass)

    def run_inputs(self, nominal, controller, excitation, duration, quick=False):
        """What a single run of this case simulates (``step`` and ``hunting`` cases).

        Parameters
        ----------
        nominal : IsolatorParameters
            Every parameter but this case's stiction and mass.
        controller : ControllerParameters
            The gains tried (``pi_ki`` must be positive).
        excitation : Chirp, RandomExcitation or DisplacementRecord
            The design's base motion (``base`` and ``step`` cases).
        duration : float
            Its simulated length [s].
        quick : bool
            The quick design's hunting runs are at most 600 s long, else 1500 s.

        Returns
        -------
        excitation : object
            The base motion (at rest for a ``hunting`` case).
        isolator : IsolatorParameters
        initial_state : InitialState or None
            ``None`` for a ``base`` case (the default start).
        duration : float
            Simulated time [s].
        """
        isolator = self.isolator(nominal)
        if self.family == "base":
            return excitation, isolator, None, duration
        if self.family == "step":
            integral = _preload(isolator, controller) + self.force_step / controller.pi_ki
            return excitation, isolator, InitialState(pi_integral=integral), duration
        offset, length = _hunting_start(isolator, controller, HUNTING_MAX[bool(quick)])
        return QUIET, isolator, InitialState(
            relative_position=controller.position_setpoint + offset), length


def _levels(low, high, count):
    if high == low:
        return (low,)
    return (low, high) if count == 2 else tuple(np.linspace(low, high, count))


def _cases(stiction_range, mass_range, force_steps, quick):
    """Stiction at its range's ends (and middle unless quick), mass at its ends: the effects of
    both are monotone in what was measured, stiction's strongly (the hunting plateau grows
    with it), so the ends bound them and the middle checks it."""
    plants = [(fs, m) for fs in _levels(*stiction_range, 2 if quick else 3)
              for m in _levels(*mass_range, 2)]
    cases = [DesignCase("base", fs, m) for fs, m in plants]
    cases += [DesignCase("step", fs, m, step) for fs, m in plants for step in force_steps]
    cases += [DesignCase("hunting", fs, m) for fs, m in plants]
    return cases


def _preload(isolator, controller):
    """The integral [m*s] the default start preloads (docs/model.md §5)."""
    z_ref = controller.position_setpoint
    needed = isolator.mass * isolator.gravity - float(spring_force(z_ref, isolator))
    needed = float(np.clip(needed, -isolator.motor_force_max, isolator.motor_force_max))
    return needed / controller.pi_ki


QUIET = Sine(amplitude=0.0, frequency=1.0, fade_in=0.0)


def _loop_stiffness(isolator, controller):
    """``k(z_ref) + Kp`` [N/m]."""
    return float(spring_stiffness(controller.position_setpoint, isolator)) + controller.pi_kp


def _hunting_start(isolator, controller, maximum):
    """Release offset [m] and duration [s] of a hunting case at these gains."""
    d = 0.5 * cd.slip_jump(isolator, controller)[0]
    k_total = _loop_stiffness(isolator, controller)
    if d > 0 and k_total > 0:
        offset = d / k_total
        period = 4 * (isolator.stiction_force - d) * k_total / (controller.pi_ki * d)
    else:
        offset, period = 0.005, 30.0
    offset = float(np.clip(offset, 0.001, 0.5 * isolator.stroke_half))
    first = isolator.stiction_force / (controller.pi_ki * offset)
    return offset, float(np.clip(first + 4 * period, 30.0, maximum))


@dataclass
class _Settings:
    """The validated inputs every stage shares."""

    isolator: IsolatorParameters
    controller: ControllerParameters
    excitation: object
    duration: float
    stiction_range: tuple
    mass_range: tuple
    force_steps: tuple
    band: tuple
    cost: str
    controller_rate: float
    delay: float
    quick: bool
    dt: float
    dt_note: str
    sample_rate: float
    fft_length: int
    ratio: float
    stroke_band: tuple
    stroke_dt: float
    damping_gain_max: float
    gain_margin_min: float
    phase_margin_min: float
    workers: int
    progress: bool

    def controller_at(self, kp, kd=None):
        return dataclasses.replace(self.controller, pi_kp=float(kp), pi_ki=float(self.ratio * kp),
                                   damping_gain=self.controller.damping_gain if kd is None
                                   else float(kd), controller_rate=self.controller_rate)


def _stats_row(case, z_min, z_max, contacts, failed, settings, message=""):
    z_ref = settings.controller.position_setpoint
    low, high = settings.stroke_band
    usage = max((z_max - z_ref) / (high - z_ref), (z_ref - z_min) / (z_ref - low)) \
        if not failed else math.inf
    return {"case": case.label, "family": case.family, "z_min": float(z_min),
            "z_max": float(z_max), "stop_contacts": int(contacts), "failed": bool(failed),
            "usage": float(usage), "passes": bool(not failed and contacts == 0 and usage <= 1.0),
            "message": message}


def _single(case, controller, settings):
    """Run one ``step`` or ``hunting`` case; its stroke statistics."""
    excitation, isolator, initial, duration = case.run_inputs(
        settings.isolator, controller, settings.excitation, settings.duration, settings.quick)
    try:
        result = simulate(excitation, isolator, controller, duration=duration,
                          dt=settings.stroke_dt, sample_rate=settings.sample_rate,
                          initial_state=initial)
    except SimulationError as error:
        return _stats_row(case, math.nan, math.nan, 0, True, settings, str(error))
    z = result.relative_position
    return _stats_row(case, z.min(), z.max(), result.run["stop_contacts"], False, settings)


def _run_cases(cases, gains, settings, bar=None):
    """Stroke statistics of every case at every gain: ``rows[g][c]``.

    ``gains`` are ``(Kp, Kd)`` pairs; ``base`` cases go through one lockstep batch, the others
    through threads of single runs.
    """
    controllers = [settings.controller_at(kp, kd) for kp, kd in gains]
    rows = [[None] * len(cases) for _ in gains]
    base = [(g, c) for g in range(len(gains)) for c, case in enumerate(cases)
            if case.family == "base"]
    if base:
        batch = simulate_batch([(cases[c].isolator(settings.isolator), controllers[g])
                                for g, c in base], settings.excitation,
                               duration=settings.duration, dt=settings.stroke_dt,
                               sample_rate=settings.sample_rate, channels=(),
                               workers=settings.workers)
        for i, (g, c) in enumerate(base):
            rows[g][c] = _stats_row(cases[c], batch.stats["z_min"][i], batch.stats["z_max"][i],
                                    batch.stats["stop_contacts"][i], bool(batch.status[i]),
                                    settings, batch.messages[i])
        if bar is not None:
            bar.update(len(base))
    singles = [(g, c) for g in range(len(gains)) for c, case in enumerate(cases)
               if case.family != "base"]

    def run(task):
        g, c = task
        return g, c, _single(cases[c], controllers[g], settings)

    with ThreadPoolExecutor(max_workers=settings.workers) as pool:
        for g, c, row in pool.map(run, singles):
            rows[g][c] = row
            if bar is not None:
                bar.update(1)
    return rows


def _summary(kp, kd, settings, rows):
    worst = max(rows, key=lambda r: r["usage"])
    return {"pi_kp": float(kp), "pi_ki": float(settings.ratio * kp), "damping_gain": float(kd),
            "passes": all(r["passes"] for r in rows), "usage": float(worst["usage"]),
            "worst_case": worst["case"], "z_min": float(min(r["z_min"] for r in rows)),
            "z_max": float(max(r["z_max"] for r in rows)),
            "stop_contacts": int(sum(r["stop_contacts"] for r in rows)),
            "failed_cases": int(sum(r["failed"] for r in rows))}


def _search_pi(cases, settings, kd, bar=None, below=None):
    """Grid then bisection in Kp; returns the search record.

    ``below``: ``(Kp, rows)`` of a gain known to fail at this ``kd``; the grid then starts
    above it (the repeat with the chosen damping gain, which only ever needed more).
    """
    grid = list(KP_GRID[settings.quick])
    if below is None:
        rows = _run_cases(cases, [(kp, kd) for kp in grid], settings, bar)
    else:  # upwards from the known failure, one gain at a time, to the first that passes
        above = [g for g in grid if g > below[0] * (1 + 1e-9)] or [grid[-1]]
        grid, rows = [float(below[0])], [below[1]]
        for kp in above:
            (found,) = _run_cases(cases, [(kp, kd)], settings, bar)
            grid.append(kp)
            rows.append(found)
            if all(r["passes"] for r in found):
                break
    table = [_summary(kp, kd, settings, r) for kp, r in zip(grid, rows)]
    details = {kp: r for kp, r in zip(grid, rows)}
    passes = [t["passes"] for t in table]
    record = {"grid": [float(g) for g in grid], "damping_gain": float(kd), "found": False,
              "reason": "", "pi_kp": math.nan, "pi_ki": math.nan, "failing_kp": math.nan,
              "monotone_on_grid": True, "started_above": None if below is None
              else float(below[0])}
    if not passes[-1]:
        record["reason"] = (f"no proportional gain up to {grid[-1]:g} N/m keeps every case in "
                            "the constant-force band and off the stops; widen the band, narrow "
                            "the ranges or soften the disturbance")
        record["table"] = table
        record["details"] = details
        record["family_kp"] = _family_gains(details)
        return record
    first = len(grid) - 1
    while first > 0 and passes[first - 1]:
        first -= 1
    record["monotone_on_grid"] = all(passes[first:]) and not any(passes[:first])
    if first == 0:
        record.update(found=True, pi_kp=float(grid[0]), pi_ki=float(settings.ratio * grid[0]),
                      reason=f"the lowest gain tried, {grid[0]:g} N/m, passes: the smallest gain "
                             f"lies below it (not searched)")
        record["table"] = table
        record["details"] = details
        record["family_kp"] = _family_gains(details)
        return record
    low, high = grid[first - 1], grid[first]
    for _ in range(BISECTIONS[settings.quick]):
        mid = math.sqrt(low * high)
        (mid_rows,) = _run_cases(cases, [(mid, kd)], settings, bar)
        table.append(_summary(mid, kd, settings, mid_rows))
        details[mid] = mid_rows
        if table[-1]["passes"]:
            high = mid
        else:
            low = mid
    table.sort(key=lambda t: t["pi_kp"])
    record.update(found=True, pi_kp=float(high), pi_ki=float(settings.ratio * high),
                  failing_kp=float(low), table=table, details=details)
    record["family_kp"] = _family_gains(details)
    return record


def _family_gains(details):
    """Per family, the smallest gain tried from which on every gain tried passes [N/m]."""
    out = {}
    gains = sorted(details)
    for family in FAMILIES:
        passes = [all(r["passes"] for r in details[kp] if r["family"] == family) for kp in gains]
        if not any(r["family"] == family for r in details[gains[0]]):
            continue
        value = math.nan
        for kp, ok in zip(reversed(gains), reversed(passes)):
            if not ok:
                break
            value = kp
        out[family] = float(value)
    return out


# ---------------------------------------------------------------- transmissibility cost
def transmissibility_cost(base_acceleration, payload_acceleration, sample_rate, *, band,
                          cost="rms", fft_length=FFT_LENGTH[True]):
    """The design's transmissibility cost of one run, from its trusted bins.

    Parameters
    ----------
    base_acceleration : array_like
        Base acceleration samples [m/s^2].
    payload_acceleration : array_like
        Payload acceleration samples [m/s^2].
    sample_rate : float
        Their rate [Hz].
    band : tuple of float
        Band of the cost [Hz, Hz].
    cost : {"rms", "peak"}
        RMS of the amplitude ratio over the trusted bins of the band, or its largest value.
    fft_length : int
        Welch segment length [samples].

    Returns
    -------
    value : float
        The cost [-]; NaN when fewer than half the band's bins are trusted.
    share : float
        Share of the band's bins that are trusted [-].
    estimate : TransmissibilityEstimate
        The curve it was read from.
    """
    estimate = transmissibility(base_acceleration, payload_acceleration, sample_rate,
                                fft_length=fft_length)
    inside = band_mask(estimate.frequency, *band)
    keep = band_mask(estimate.frequency, *band, trusted=estimate.trusted)
    share = float(keep.sum() / max(inside.sum(), 1))
    if share < TRUSTED_SHARE_MIN:
        return math.nan, share, estimate
    t = estimate.magnitude[keep]
    value = float(np.sqrt(np.mean(t ** 2))) if cost == "rms" else float(np.max(t))
    return value, share, estimate


def _linear_cost(frequency, isolator, controller, settings, *, rate=None, delay=None):
    t = cd.sampled_transmissibility(frequency, isolator, controller,
                                    rate=settings.controller_rate if rate is None else rate,
                                    delay=settings.delay if delay is None else delay)
    return float(np.sqrt(np.mean(t ** 2))) if settings.cost == "rms" else float(np.max(t))


def _band_grid(band):
    return np.linspace(max(band[0], 1e-3), band[1], 400)


def _costs(pairs, settings):
    """Simulated costs of ``(isolator, controller)`` pairs, one lockstep batch."""
    batch = simulate_batch(pairs, settings.excitation, duration=settings.duration,
                           dt=settings.dt, sample_rate=settings.sample_rate,
                           workers=settings.workers)
    out = []
    for i in range(len(pairs)):
        if batch.status[i]:
            out.append((math.nan, 0.0, None, batch.messages[i], math.nan))
            continue
        value, share, estimate = transmissibility_cost(
            batch.channels["base_acceleration"][i], batch.channels["payload_acceleration"][i],
            settings.sample_rate, band=settings.band, cost=settings.cost,
            fft_length=settings.fft_length)
        reason = "" if math.isfinite(value) else (
            f"only {100 * share:.0f} % of the band's bins are trusted (coherence below the "
            "threshold: the payload barely responds to the base there)")
        out.append((value, share, estimate, reason, float(batch.stats["motor_force_rms"][i])))
    return out


def _damping_bound(settings, kp):
    """Largest damping gain [N*s/m] inside the linear bound and the sampled loop's margins."""
    controller = settings.controller_at(kp, 0.0)
    routh = cd.damping_gain_limits(settings.isolator, controller)
    cap = settings.damping_gain_max
    notes = []
    high = cap
    if math.isfinite(routh[1]):
        notes.append(f"linear stability (Routh-Hurwitz with the {controller.velocity_highpass:g} "
                     f"Hz high-pass): Kd < {routh[1]:.4g} N*s/m")
        high = min(high, routh[1])
    elif math.isnan(routh[1]):
        return 0.0, ["no damping gain is linearly stable at these PI gains"], routh

    def ok(kd):
        return cd.loop_margins(settings.isolator, settings.controller_at(kp, kd),
                               settings.controller_rate, settings.delay).meets(
            settings.gain_margin_min, settings.phase_margin_min)

    if ok(high):
        bound = high
    else:
        low = 0.0
        if not ok(low):
            return 0.0, notes + ["even Kd = 0 misses the margins"], routh
        for _ in range(40):
            mid = 0.5 * (low + high)
            low, high = (mid, high) if ok(mid) else (low, mid)
            if high - low < 1e-3 * high:
                break
        bound = low
        rate = (f"{settings.controller_rate:g} Hz" if settings.controller_rate > 0
                else "continuous")
        notes.append(f"margins ({settings.gain_margin_min:g} dB, {settings.phase_margin_min:g} "
                     f"deg; {rate}, delay {settings.delay:g} s): Kd <= {bound:.4g} N*s/m")
    if bound >= cap:
        notes.append(f"the search's cap: Kd <= {cap:g} N*s/m (`damping_gain_max`)")
    return float(bound), notes, routh


def _search_damping(settings, kp, bar=None):
    bound, notes, routh = _damping_bound(settings, kp)
    coarse, fine = DAMPING_POINTS[settings.quick]
    record = {"bound": bound, "bound_notes": notes, "routh_limits": list(routh), "rows": [],
              "chosen": 0.0, "at_bound": False, "reason": ""}
    if bound <= 0:
        record["reason"] = "no admissible damping gain above 0: " + "; ".join(notes)
        return record, {}
    gains = [0.0] + list(np.geomspace(max(1.0, bound / 100), bound, coarse))
    curves = {}

    def evaluate(values):
        pairs = [(settings.isolator, settings.controller_at(kp, kd)) for kd in values]
        frequency = _band_grid(settings.band)
        for kd, (value, share, estimate, reason, motor) in zip(values,
                                                                _costs(pairs, settings)):
            linear = _linear_cost(frequency, settings.isolator, settings.controller_at(kp, kd),
                                  settings)
            record["rows"].append({"damping_gain": float(kd), "cost": value,
                                   "trusted_share": share, "linear_cost": linear,
                                   "motor_force_rms": motor, "reason": reason})
            if estimate is not None:
                curves[float(kd)] = estimate
            if bar is not None:
                bar.update(1)

    evaluate(gains)
    rows = sorted(record["rows"], key=lambda r: r["damping_gain"])
    finite = [r for r in rows if math.isfinite(r["cost"])]
    if not finite:
        record["reason"] = "no damping gain has a defined cost (too few trusted bins)"
        return record, curves
    best = min(range(len(rows)), key=lambda i: rows[i]["cost"] if math.isfinite(rows[i]["cost"])
               else math.inf)
    left = rows[max(best - 1, 0)]["damping_gain"]
    right = rows[min(best + 1, len(rows) - 1)]["damping_gain"]
    if right > left:
        if left > 0:
            refine = list(np.geomspace(left, right, fine + 2)[1:-1])
        else:
            refine = list(np.linspace(left, right, fine + 2)[1:-1])
        refine = [kd for kd in refine if all(abs(kd - r["damping_gain"]) > 1e-9 * max(kd, 1)
                                             for r in rows)]
        if refine:
            evaluate(refine)
    rows = sorted(record["rows"], key=lambda r: r["damping_gain"])
    record["rows"] = rows
    best_row = min((r for r in rows if math.isfinite(r["cost"])), key=lambda r: r["cost"])
    record["chosen"] = best_row["damping_gain"]
    record["at_bound"] = bool(best_row["damping_gain"] >= 0.999 * bound)
    if record["at_bound"]:
        record["reason"] = ("the cost still falls at the bound: the gain is set by the bound "
                            "(" + "; ".join(notes) + "), not by the cost")
    return record, curves


# ---------------------------------------------------------------- hunting
def _hunting_run(isolator, controller, settings):
    """Simulate the loop at rest from the predicted cycle; measure amplitude and period."""
    prediction = cd.predict_hunting(isolator, controller)
    offset, _ = _hunting_start(isolator, controller, HUNTING_MAX[settings.quick])
    period = prediction.relay_period if math.isfinite(prediction.relay_period) else 60.0
    first = isolator.stiction_force / (controller.pi_ki * offset) if controller.pi_ki > 0 \
        else 30.0
    duration = float(np.clip(first + 8 * period, 300.0, 1.5 * HUNTING_MAX[settings.quick]))
    try:
        result = simulate(QUIET, isolator, controller, duration=duration, dt=settings.dt,
                          sample_rate=settings.sample_rate,
                          initial_state=InitialState(
                              relative_position=controller.position_setpoint + offset))
    except SimulationError as error:
        return prediction, {"hunts": False, "failed": True, "message": str(error)}, None
    t, zeta = result.time, result.relative_position - controller.position_setpoint
    locked = np.asarray(result.locked, bool)
    breaks = t[1:][locked[:-1] & ~locked[1:]]
    late = t >= 0.5 * duration
    late_breaks = breaks[breaks >= 0.5 * duration]
    hunts = late_breaks.size >= 4
    amplitude = 0.5 * float(zeta[late].max() - zeta[late].min()) if hunts else 0.0
    period_sim = 2 * float(np.median(np.diff(late_breaks))) if hunts else math.nan
    measured = {"hunts": bool(hunts), "failed": False, "amplitude": amplitude,
                "period": period_sim, "upper": float(zeta[late].max()),
                "lower": float(zeta[late].min()), "breakaways": int(breaks.size),
                "stop_contacts": int(result.run["stop_contacts"]), "duration": duration,
                "release_offset": offset,
                "final_offset": float(zeta[-1])}
    if not hunts:
        measured["amplitude_reason"] = ("the payload stopped slipping: fewer than 4 breakaways "
                                        "in the run's second half")
    every = max(1, t.size // 3000)
    series = (t[::every], zeta[::every])
    return prediction, measured, series


def _check_hunting(settings, kp, kd, bar=None):
    """Hunting at rest: the PI loop alone (Kd = 0) and the final design, per stiction value."""
    values = sorted({settings.stiction_range[0], settings.isolator.stiction_force,
                     settings.stiction_range[1]})
    loops = [("PI loop alone", 0.0)] + ([("final design", float(kd))] if kd > 0 else [])
    tasks = [(name, gain, fs) for name, gain in loops for fs in values]
    rows, series = [], {}

    def run(task):
        name, gain, fs = task
        isolator = dataclasses.replace(settings.isolator, stiction_force=fs)
        return task, _hunting_run(isolator, settings.controller_at(kp, gain), settings)

    with ThreadPoolExecutor(max_workers=settings.workers) as pool:
        for (name, gain, fs), (prediction, measured, trace) in pool.map(run, tasks):
            confirmed = None
            if not measured.get("failed"):
                confirmed = prediction.hunts == measured["hunts"]
            memoryless = len(prediction.friction_intersections) > 0
            rows.append({"loop": name, "damping_gain": gain, "stiction_force": fs,
                         "prediction": prediction.to_dict(), "simulation": measured,
                         "relay_confirmed": confirmed,
                         "memoryless_confirmed": (None if measured.get("failed") else
                                                  memoryless == measured["hunts"])})
            if trace is not None and gain == 0.0:
                series[fs] = trace
            if bar is not None:
                bar.update(1)
    rows.sort(key=lambda r: (r["damping_gain"], r["stiction_force"]))
    z_ref = settings.controller.position_setpoint
    half = min(z_ref - settings.stroke_band[0], settings.stroke_band[1] - z_ref)
    high = dataclasses.replace(settings.isolator, stiction_force=settings.stiction_range[1])
    controller = settings.controller_at(kp, 0.0)
    needed = cd.hunting_stiffness(high, controller, half)
    return {"rows": rows, "kp_for_band": float(needed), "band_half_width": half,
            "loop": _hunting_locus(high, controller)}, series


def _hunting_locus(isolator, controller):
    """The integral loop's Nyquist locus and the element's -1/N, for the figure."""
    prediction = cd.predict_hunting(isolator, controller)
    if prediction.relay_output <= 0 or controller.pi_ki <= 0:
        return None
    g = cd.integral_loop(isolator, controller)
    omega = np.logspace(-3, 1, 400)
    response = cd.frequency_response(g, omega)
    d, h = prediction.relay_output, prediction.switching_force
    amplitude = h * (1 + np.logspace(-6, 1.3, 200))
    import control

    element = control.relay_hysteresis_nonlinearity(d, h)
    minus_inverse = -1 / control.describing_function(element, amplitude)
    point = None
    if prediction.hunts:
        point = complex(-1 / element.describing_function(prediction.integral_force_amplitude))
    return {"omega": omega, "loop": response, "amplitude": amplitude,
            "minus_inverse": minus_inverse, "intersection": point,
            "stiction_force": isolator.stiction_force}


# ---------------------------------------------------------------- margins
def _margins(settings, kp, kd):
    controller = settings.controller_at(kp, kd)
    design = cd.loop_margins(settings.isolator, controller, settings.controller_rate,
                             settings.delay)
    continuous = cd.loop_margins(settings.isolator, controller, 0.0, 0.0)
    table = [cd.loop_margins(settings.isolator, controller, rate, settings.delay).to_dict()
             for rate in RATES]
    needed, reason = cd.required_controller_rate(
        settings.isolator, controller, settings.delay, gain_margin_min=settings.gain_margin_min,
        phase_margin_min=settings.phase_margin_min)
    needed0, reason0 = cd.required_controller_rate(
        settings.isolator, controller, 0.0, gain_margin_min=settings.gain_margin_min,
        phase_margin_min=settings.phase_margin_min)
    by_delay = []
    for delay in sorted({*DELAYS, settings.delay}):
        rate, why = cd.required_controller_rate(
            settings.isolator, controller, delay, gain_margin_min=settings.gain_margin_min,
            phase_margin_min=settings.phase_margin_min)
        continuous_delayed = cd.loop_margins(settings.isolator, controller, 0.0, delay)
        by_delay.append({"delay": delay, "required_rate": rate, "reason": why,
                         "continuous_gain_margin": continuous_delayed.gain_margin,
                         "continuous_phase_margin": continuous_delayed.phase_margin})
    return {"design": design.to_dict(), "continuous": continuous.to_dict(), "table": table,
            "by_delay": by_delay,
            "required_rate": needed, "required_rate_reason": reason,
            "required_rate_without_delay": needed0, "required_rate_without_delay_reason": reason0,
            "meets": design.meets(settings.gain_margin_min, settings.phase_margin_min)}


# ---------------------------------------------------------------- why damping did not help
def _divides(rate, dt):
    ratio = 1.0 / (rate * dt)
    return rate * dt <= 1 + 1e-12 and abs(ratio - round(ratio)) < 1e-6 * ratio


def _why(settings, kp, kd_chosen, damping_rows=(), bar=None):
    base_iso, base_ctrl = settings.isolator, settings.controller_at(kp, 0.0)
    variants = [("baseline", "baseline", base_iso, base_ctrl)]
    hp0 = base_ctrl.velocity_highpass
    for corner in (0.0, 0.1, 1.0, 3.0):
        if corner != hp0:
            variants.append(("high-pass", f"{corner:g} Hz", base_iso,
                             dataclasses.replace(base_ctrl, velocity_highpass=corner)))
    cv0 = base_iso.viscous_damping
    for cv in (10.0, 30.0, 100.0, 300.0):
        if cv != cv0:
            variants.append(("viscous friction", f"{cv:g} N*s/m",
                             dataclasses.replace(base_iso, viscous_damping=cv), base_ctrl))
    rates = [0.0] + [r for r in (1000.0, 200.0, 100.0, 50.0) if _divides(r, settings.dt)]
    for rate in rates:
        if rate != settings.controller_rate:
            variants.append(("controller rate", "continuous" if rate == 0 else f"{rate:g} Hz",
                             base_iso, dataclasses.replace(base_ctrl, controller_rate=rate)))
    moderate = float(cv0)
    gains = sorted({0.0, moderate, float(kd_chosen)})
    sweep = sorted({0.0, *(g for g in (20.0, 50.0, 200.0, 500.0, 1000.0)
                           if g <= settings.damping_gain_max), *gains})
    plan = [(v, g) for v, variant in enumerate(variants)
            for g in (sweep if variant[0] == "baseline" else gains)]
    pairs = [(variants[v][2], dataclasses.replace(variants[v][3], damping_gain=g))
             for v, g in plan]
    costs = dict(zip(plan, _costs(pairs, settings)))
    if bar is not None:
        bar.update(len(pairs))
    frequency = _band_grid(settings.band)
    rows = []
    for v, (factor, value, iso, ctrl) in enumerate(variants):
        reference = costs[(v, 0.0)][0]
        linear_reference = _linear_cost(frequency, iso, ctrl, settings,
                                        rate=ctrl.controller_rate, delay=0.0)
        for g in (sweep if factor == "baseline" else gains):
            if g == 0:
                continue
            cost = costs[(v, g)][0]
            damped = dataclasses.replace(ctrl, damping_gain=g)
            linear = _linear_cost(frequency, iso, damped, settings, rate=ctrl.controller_rate,
                                  delay=0.0)
            change = 20 * math.log10(cost / reference) if (
                math.isfinite(cost) and math.isfinite(reference) and reference > 0) else math.nan
            rows.append({"factor": factor, "value": value, "damping_gain": g,
                         "viscous_damping": iso.viscous_damping,
                         "velocity_highpass": ctrl.velocity_highpass,
                         "controller_rate": ctrl.controller_rate, "cost_undamped": reference,
                         "cost_damped": cost, "change_db": change,
                         "linear_change_db": 20 * math.log10(linear / linear_reference),
                         "reason": "" if math.isfinite(change) else
                         "a cost is undefined (too few trusted bins)"})
    delay_rows = []
    for delay in DELAYS:
        for g in gains:
            if g == 0:
                continue
            reference = _linear_cost(frequency, base_iso, base_ctrl, settings, delay=delay)
            damped = _linear_cost(frequency, base_iso, dataclasses.replace(base_ctrl,
                                                                        damping_gain=g),
                                  settings, delay=delay)
            delay_rows.append({"delay": delay, "damping_gain": g,
                               "controller_rate": settings.controller_rate,
                               "linear_change_db": 20 * math.log10(damped / reference)})
    return {"rows": rows, "delay_rows": delay_rows, "gains": [g for g in gains if g > 0],
            "answer": _why_answer(rows, delay_rows, moderate, kd_chosen, settings,
                                  damping_rows)}


def _pick(rows, factor, value_key, gain):
    return [(r[value_key], r["change_db"], r["linear_change_db"]) for r in rows
            if r["factor"] in (factor, "baseline") and r["damping_gain"] == gain]


def _why_answer(rows, delay_rows, moderate, chosen, settings, damping_rows=()):
    """The answer to the paper's open question, in sentences built from the numbers."""
    def base(gain):
        found = [r for r in rows if r["factor"] == "baseline" and r["damping_gain"] == gain]
        return found[0] if found else None

    ref = base(moderate)
    if ref is None or not math.isfinite(ref["change_db"]):
        return "undefined: the baseline's cost is undefined (too few trusted bins)"
    cost = "RMS" if settings.cost == "rms" else "peak"
    cv = ref["viscous_damping"]
    lines = [
        f"At the paper's operating point (Cv = {cv:g} N*s/m, {ref['velocity_highpass']:g} Hz "
        f"high-pass, the given PI gains Kp = {settings.controller.pi_kp:g} N/m, Ki = "
        f"{settings.controller.pi_ki:g} N/(m*s)) a damping gain equal to the guide's viscous "
        f"friction, Kd = {moderate:g} N*s/m, changes the {cost} transmissibility over "
        f"{settings.band[0]:g}-{settings.band[1]:g} Hz by {ref['change_db']:+.2f} dB (linear "
        f"model {ref['linear_change_db']:+.2f} dB)."]
    sweep = sorted((r for r in rows if r["factor"] == "baseline"), key=lambda r: r["damping_gain"])
    if sweep:
        lines.append("Against the damping gain: " + ", ".join(
            f"Kd = {r['damping_gain']:g}: {r['change_db']:+.2f} dB" for r in sweep
            if math.isfinite(r["change_db"])) + ".")
        better = [r["damping_gain"] for r in sweep if math.isfinite(r["change_db"])
                  and r["change_db"] <= -3.0]
        if better:
            lines.append(f"A 3 dB improvement takes Kd >= {better[0]:.3g} N*s/m of those tried "
                         f"({better[0] / cv:.2g} times Cv).")
    lines.append(
        "Why: the guide's viscous friction acts on the relative velocity and carries the base's "
        "motion into the payload; above the isolation onset the linear model gives "
        "T = Cv/sqrt((Cv + Kd)^2 + (m w)^2), so a skyhook gain only dilutes a transmission "
        "the friction already sets, and matters once Kd is comparable with Cv.")
    spread = {}
    texts = []
    for factor, key, unit in (("viscous friction", "viscous_damping", "N*s/m"),
                              ("high-pass", "velocity_highpass", "Hz"),
                              ("controller rate", "controller_rate", "Hz")):
        found = sorted(_pick(rows, factor, key, moderate), key=lambda x: (x[0] == 0, x[0])
                       if factor == "controller rate" else x[0])
        finite = [(v, c) for v, c, _ in found if math.isfinite(c)]
        if len(finite) > 1:
            spread[factor] = max(c for _, c in finite) - min(c for _, c in finite)
            texts.append(f"{factor}: " + ", ".join(
                (f"{v:g} {unit}" if not (factor == "controller rate" and v == 0)
                 else "continuous") + f" {c:+.2f} dB" for v, c in finite))
    delays = [r for r in delay_rows if r["damping_gain"] == moderate]
    if delays:
        spread["delay"] = (max(r["linear_change_db"] for r in delays)
                           - min(r["linear_change_db"] for r in delays))
        texts.append("delay (linear sampled model; the simulator has none): " + ", ".join(
            f"{1e3 * r['delay']:g} ms {r['linear_change_db']:+.2f} dB" for r in delays))
    if texts:
        lines.append(f"What Kd = {moderate:g} N*s/m achieves against each factor (simulated "
                     "unless stated): " + "; ".join(texts) + ".")
    if spread:
        ranked = sorted(spread.items(), key=lambda kv: -kv[1])
        lines.append("Ranked by how much they change it: " + ", ".join(
            f"{k} {v:.2f} dB" for k, v in ranked) + f". The {ranked[0][0]} matters most; "
            + ", ".join(k for k, _ in ranked[1:]) + " change the benefit by less.")
    return " ".join(lines)


# ---------------------------------------------------------------- the result
@dataclass(frozen=True)
class DesignResult:
    """What :func:`design_controller` found, with the evidence for each choice.

    Attributes
    ----------
    gains : dict
        The chosen ``pi_kp`` [N/m], ``pi_ki`` [N/(m*s)] and ``damping_gain`` [N*s/m].
    settings : dict
        The problem as solved: ranges, force steps, band, cost, rate, delay, step, excitation.
    static : StaticDesign
        The static design at the setpoint.
    pi_search : dict
        The PI search: ``table`` (one row per gain tried), ``pi_kp`` and the failing gain just
        below it, the cases and the band.
    stability : RouthHurwitz
        The linear stability of the chosen gains, closed form against python-control.
    hunting : dict
        Describing-function predictions and simulations at rest, per stiction value.
    damping : dict
        The damping search: a row per gain (``damping_gain`` [N*s/m], simulated and linear
        cost [-], ``motor_force_rms`` [N]), the bound [N*s/m] and why.
    margins : dict
        Margins of the sampled loop at the design's rate and delay, over rates, and the
        rate the design needs.
    why : dict
        The experiments on why damping did not help much, and the answer.
    verification : dict
        Every case of the PI search at the final gains.
    seconds : dict
        Wall time of each stage [s].
    series : dict
        Curves and time series for the figures (not in :meth:`to_dict`).
    """

    gains: dict
    settings: dict
    static: object
    pi_search: dict
    stability: object
    hunting: dict
    damping: dict
    margins: dict
    why: dict
    verification: dict
    seconds: dict
    series: dict = field(default_factory=dict, repr=False)

    def to_dict(self):
        """Everything but the figures' series, as JSON-ready data (NaN and inf as None).

        Returns
        -------
        dict
        """
        pi = {k: v for k, v in self.pi_search.items() if k != "details"}
        hunting = {k: v for k, v in self.hunting.items() if k != "loop"}
        return _json_ready({"qzs_version": __version__, "gains": self.gains,
                            "settings": self.settings, "static": self.static.to_dict(),
                            "pi_search": pi, "stability": self.stability.to_dict(),
                            "hunting": hunting, "damping": self.damping,
                            "margins": self.margins, "why": self.why,
                            "verification": self.verification, "seconds": self.seconds})

    def summary(self):
        """The design in a few lines of text (what ``qzs design`` prints).

        Returns
        -------
        str
        """
        return design_text(self)

    def plot(self):
        """Draw every figure of the design.

        Returns
        -------
        dict of str to matplotlib.figure.Figure
            Figure name -> figure.
        """
        from qzs.viz.design import plot_design

        return plot_design(self)

    def save(self, folder):
        """Write ``report.html``, ``design.json`` and the figures (PNG and SVG) into ``folder``.

        Each file is written atomically (a temporary file renamed onto it).

        Parameters
        ----------
        folder : str or Path
            The output folder, created if missing.

        Returns
        -------
        dict of str to Path
            ``report``, ``json`` and one entry per figure (its PNG).
        """
        import matplotlib.pyplot as plt

        from qzs.iotools.paths import check_output_path
        from qzs.viz.design import plot_design
        from qzs.viz.figures import save_figure

        folder = check_output_path(folder, argument="folder", suffixes=None, directory=True)
        folder.mkdir(parents=True, exist_ok=True)
        written = {}
        for name, figure in plot_design(self).items():
            path = folder / f"{name}.png"
            save_figure(figure, path, also_svg=True)
            plt.close(figure)
            written[name] = path
        record = self.to_dict()
        with atomic_path(folder / "design.json") as tmp:
            tmp.write_text(json.dumps(record, indent=2, allow_nan=False), encoding="utf-8")
        written["json"] = folder / "design.json"
        with atomic_path(folder / "report.html") as tmp:
            tmp.write_text(_html(self, record, written), encoding="utf-8")
        written["report"] = folder / "report.html"
        return written


def _json_ready(value):
    if isinstance(value, dict):
        return {str(k): _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, complex):
        return [_json_ready(value.real), _json_ready(value.imag)]
    if isinstance(value, np.ndarray):
        return _json_ready(value.tolist())
    if isinstance(value, Path):
        return str(value)
    return value


# ---------------------------------------------------------------- the design
def _excitation(excitation, quick):
    if excitation is None:
        excitation = Chirp()
    if not isinstance(excitation, (Chirp, RandomExcitation, DisplacementRecord)):
        raise ParameterError(f"`excitation` must be a Chirp, RandomExcitation or "
                             f"DisplacementRecord (a base motion of finite length), got "
                             f"{type(excitation).__name__}; a sine has no band to judge a "
                             "transmissibility over.")
    duration = excitation.duration
    if quick and isinstance(excitation, Chirp) and excitation.duration > QUICK_CHIRP:
        excitation = dataclasses.replace(excitation, duration=QUICK_CHIRP)
        duration = QUICK_CHIRP
    elif quick:
        duration = min(duration, QUICK_CHIRP)
    return excitation, float(duration)


def _stroke_step(settings):
    """The step [s] of the PI search's runs: the coarsest stable one up to STROKE_STEP_MAX.

    Their statistic, the largest excursion, is far less sensitive to the step than the
    transmissibility: measured on the quick design's 16 cases at three gain sets, the band's
    use agreed within 0.9 % of the band between 0.625 ms and 2.5 ms (docs/design.md).
    """
    from qzs.engine.stability import stability_test

    stiffest = settings.controller_at(max(KP_GRID[settings.quick]),
                                      max(settings.damping_gain_max,
                                          settings.controller.damping_gain))
    light = dataclasses.replace(settings.isolator, mass=settings.mass_range[0],
                                stiction_force=settings.stiction_range[1])
    stable = stability_test(light, stiffest, defaults.SIMULATION["solver"])
    for k in range(1, 10_000):
        step = 1.0 / (settings.sample_rate * k)
        if step > STROKE_STEP_MAX or not stable(step):
            continue
        if settings.controller_rate > 0 and not _divides(settings.controller_rate, step):
            continue
        return max(step, settings.dt)
    return settings.dt


def _choose_dt(settings, kp_probe):
    """The accuracy-driven step, chosen on the extreme controllers (docs/model.md decision 26)."""
    probes = [(dataclasses.replace(settings.isolator, stiction_force=settings.stiction_range[1]),
               settings.controller_at(kp_probe, 0.0)),
              (settings.isolator, settings.controller_at(kp_probe, settings.damping_gain_max))]
    steps, notes = [], []
    for isolator, controller in probes:
        try:
            choice = choose_step(settings.excitation, isolator, controller,
                                 tolerance_db=defaults.ACCURACY["tolerance_db"],
                                 sample_rate=settings.sample_rate, band=settings.band)
        except ToleranceNotMetError as error:
            notes.append(f"Kd = {controller.damping_gain:g} N*s/m: {error}")
            continue
        steps.append(choice.dt)
        notes.append(f"Kd = {controller.damping_gain:g} N*s/m, Fs = {isolator.stiction_force:g} "
                     f"N: {choice.dt:.3g} s (estimated error {choice.error:.2g} dB)")
    if not steps:
        return defaults.SIMULATION["dt"], ("no probed case meets the tolerance; the paper's "
                                           "step: " + "; ".join(notes))
    return min(steps), ("accuracy-driven step (tolerance "
                        f"{defaults.ACCURACY['tolerance_db']:g} dB over the band), the smallest "
                        "of: " + "; ".join(notes))


def design_controller(isolator=None, controller=None, *, excitation=None, stiction_range=None,
                      mass_range=None, force_steps=(-2.0, 2.0), band=(1.0, 20.0), cost="rms",
                      controller_rate=None, delay=0.0, quick=False, dt=None,
                      damping_gain_max=DAMPING_GAIN_MAX, gain_margin_min=cd.GAIN_MARGIN_MIN,
                      phase_margin_min=cd.PHASE_MARGIN_MIN, workers=None, progress=False):
    """Design the PI and damping gains of the isolator by simulation (docs/design.md).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        The nominal plant; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Setpoint, high-pass, the ratio ``Ki/Kp`` the search keeps, and the damping gain of the
        PI search (default 0); defaults if omitted.
    excitation : Chirp, RandomExcitation or DisplacementRecord, optional
        The base motion; default the paper's chirp (``quick``: its first 200 s as a sweep
        over the same band in 200 s).
    stiction_range : tuple of float, optional
        Stiction forces [N, N]; default half to one and a half times the isolator's.
    mass_range : tuple of float, optional
        Moving masses [kg, kg]; default the isolator's mass +-0.2 kg.
    force_steps : sequence of float
        Payload force steps [N], upward positive (the integral starts off its preload by
        ``dF/Ki``); default +-2 N (about the weight deficit the integral carries).
    band : tuple of float
        Band of the transmissibility cost [Hz, Hz]; default 1-20 Hz.
    cost : {"rms", "peak"}
        Transmissibility cost minimised by the damping gain.
    controller_rate : float, optional
        Controller rate [Hz] with zero-order hold; 0 continuous; default the controller's.
    delay : float
        Delay from sampling to the motor force [s] for the margins (the simulator has none).
    quick : bool
        Shorter runs, fewer cases (the ranges' ends only), a coarser search.
    dt : float, optional
        Integration step [s]; default the accuracy-driven step
        (:func:`~qzs.engine.accuracy.choose_step`, 0.01 dB over the band).
    damping_gain_max : float
        Largest damping gain tried [N*s/m].
    gain_margin_min : float
        Least gain margin of the sampled loop [dB].
    phase_margin_min : float
        Least phase margin of the sampled loop [deg].
    workers : int, optional
        Threads; default all cores.
    progress : bool
        Show progress bars.

    Returns
    -------
    DesignResult

    Raises
    ------
    ParameterError
        A bad argument, before any simulation.
    """
    began = time.perf_counter()
    isolator, controller = model_inputs(isolator, controller)
    if controller.pi_kp <= 0 or controller.pi_ki <= 0:
        raise ParameterError(
            f"the search keeps the controller's ratio Ki/Kp; `pi_kp` ({controller.pi_kp:g} N/m) "
            f"and `pi_ki` ({controller.pi_ki:g} N/(m*s)) must both be positive (e.g. pi_kp=50, "
            "pi_ki=20: a PI zero at 0.064 Hz).")
    excitation, duration = _excitation(excitation, bool(quick))
    stiction_range = ((0.5 * isolator.stiction_force, 1.5 * isolator.stiction_force)
                      if stiction_range is None else _pair("stiction_range", stiction_range, "N",
                                                           example="(5, 15)"))
    if stiction_range[0] < isolator.coulomb_force:
        raise ParameterError(
            f"`stiction_range` starts at {stiction_range[0]:g} N, below the Coulomb friction "
            f"({isolator.coulomb_force:g} N); the breakaway force cannot be below it: start the "
            f"range at {isolator.coulomb_force:g} N or more.")
    mass_range = ((max(0.1, isolator.mass - 0.2), isolator.mass + 0.2) if mass_range is None
                  else _pair("mass_range", mass_range, "kg", minimum=1e-9, example="(6.2, 6.6)"))
    if mass_range[0] <= 0:
        raise ParameterError(f"`mass_range` must be positive masses in kg, got {mass_range!r}.")
    try:
        steps = tuple(_float("force_steps", s) for s in force_steps)
    except TypeError:
        raise ParameterError(f"`force_steps` must be a sequence of forces in N, got "
                             f"{force_steps!r}; e.g. (-2, 2).") from None
    band = _pair("band", band, "Hz", example="(1, 20)")
    if band[0] <= 0:
        raise ParameterError(f"`band` must start above 0 Hz, got {band!r}; e.g. (1, 20).")
    top = excitation.max_frequency if not isinstance(excitation, RandomExcitation) else \
        excitation.f_high
    if band[1] > top * (1 + 1e-9):
        raise ParameterError(f"`band` ({band[0]:g}, {band[1]:g}) Hz reaches above the base "
                             f"motion's highest frequency ({top:g} Hz): nothing there is "
                             "excited; lower the band's top.")
    if cost not in COSTS:
        raise ParameterError(f"`cost` must be one of {', '.join(COSTS)}, got {cost!r}.")
    rate = controller.controller_rate if controller_rate is None else _float(
        "controller_rate", controller_rate, minimum=0.0, fix=" (Hz; 0 for continuous)")
    delay = _float("delay", delay, minimum=0.0, fix=" (seconds)")
    damping_gain_max = _float("damping_gain_max", damping_gain_max, minimum=0.0, strict=True)
    gain_margin_min = _float("gain_margin_min", gain_margin_min, minimum=0.0)
    phase_margin_min = _float("phase_margin_min", phase_margin_min, minimum=0.0)
    workers = worker_count(workers)
    sample_rate = SAMPLE_RATE if band[1] <= SAMPLE_RATE / 5 else float(
        100 * math.ceil(band[1] * 5 / 100))
    stroke_band = cd.constant_force_band(isolator, controller)
    for fs in stiction_range:  # the case parameters must be valid before anything runs
        for m in mass_range:
            DesignCase("base", fs, m).isolator(isolator)
    settings = _Settings(
        isolator=isolator, controller=controller, excitation=excitation, duration=duration,
        stiction_range=stiction_range, mass_range=mass_range, force_steps=steps, band=band,
        cost=cost, controller_rate=rate, delay=delay, quick=bool(quick), dt=math.nan,
        dt_note="", sample_rate=sample_rate, fft_length=FFT_LENGTH[bool(quick)],
        ratio=controller.pi_ki / controller.pi_kp, stroke_band=stroke_band,
        damping_gain_max=damping_gain_max, gain_margin_min=gain_margin_min,
        phase_margin_min=phase_margin_min, workers=workers, progress=bool(progress),
        stroke_dt=math.nan)
    if rate > 0:
        cd.sampled_loop(isolator, controller, rate, delay)  # validates the rate
    n_fft = int(round(duration * sample_rate))
    if n_fft < 2 * settings.fft_length:
        raise ParameterError(
            f"the base motion ({duration:g} s at {sample_rate:g} Hz) is too short for the "
            f"cost's Welch segments of {settings.fft_length} samples; give at least "
            f"{2 * settings.fft_length / sample_rate:g} s.")
    if dt is None:
        settings.dt, settings.dt_note = _choose_dt(settings, controller.pi_kp)
    else:
        settings.dt = _float("dt", dt, minimum=0.0, strict=True, fix=" (seconds)")
        settings.dt_note = "given"
    if rate > 0 and not _divides(rate, settings.dt):
        raise ParameterError(f"`controller_rate` ({rate:g} Hz) must divide 1/dt "
                             f"({1 / settings.dt:g} Hz); choose e.g. {1 / settings.dt:g} Hz or "
                             "a whole fraction of it.")
    settings.stroke_dt = settings.dt if dt is not None else _stroke_step(settings)

    from tqdm.auto import tqdm

    seconds = {"choose_step": time.perf_counter() - began}
    cases = _cases(stiction_range, mass_range, steps, bool(quick))
    per_gain = len(cases)
    search_runs = per_gain * (len(KP_GRID[bool(quick)]) + BISECTIONS[bool(quick)])
    coarse, fine = DAMPING_POINTS[bool(quick)]

    def search(kd, desc, below=None):
        bar = tqdm(total=search_runs, unit="run", desc=desc, disable=not progress, leave=False)
        try:
            return _search_pi(cases, settings, kd, bar, below)
        finally:
            bar.close()

    def damp(kp):
        bar = tqdm(total=1 + coarse + fine, unit="run", desc="damping gain",
                   disable=not progress, leave=False)
        try:
            return _search_damping(settings, kp, bar)
        finally:
            bar.close()

    def verify(kp, kd):
        bar = tqdm(total=per_gain, unit="run", desc="verification", disable=not progress,
                   leave=False)
        try:
            (rows,) = _run_cases(cases, [(kp, kd)], settings, bar)
        finally:
            bar.close()
        return {"summary": _summary(kp, kd, settings, rows), "rows": rows}

    clock = time.perf_counter()
    pi = search(controller.damping_gain, "PI gains")
    seconds["pi_search"] = time.perf_counter() - clock
    kp = pi["pi_kp"] if pi["found"] else controller.pi_kp
    clock = time.perf_counter()
    damping, curves = damp(kp)
    kd = damping["chosen"]
    seconds["damping_search"] = time.perf_counter() - clock
    clock = time.perf_counter()
    verification = verify(kp, kd)
    verification["repeated"] = False
    seconds["verification"] = time.perf_counter() - clock
    first_pass, first_search = None, None
    if pi["found"] and not verification["summary"]["passes"] and kd != controller.damping_gain:
        # the damping loop changed what the cases need: search again with it, once
        clock = time.perf_counter()
        first_pass = {"pi_kp": kp, "damping_gain": kd,
                      "verification": verification["summary"]}
        first_search = pi
        again = search(kd, "PI gains with Kd", below=(kp, verification["rows"]))
        if again["found"]:
            pi, kp = again, again["pi_kp"]
            damping, curves = damp(kp)
            kd = damping["chosen"]
            verification = verify(kp, kd)
            verification["repeated"] = True
        seconds["repeat"] = time.perf_counter() - clock
    verification["first_pass"] = first_pass

    clock = time.perf_counter()
    bar = tqdm(total=6, unit="run", desc="hunting", disable=not progress, leave=False)
    try:
        hunting, traces = _check_hunting(settings, kp, kd, bar)
    finally:
        bar.close()
    seconds["hunting"] = time.perf_counter() - clock

    clock = time.perf_counter()
    margins = _margins(settings, kp, kd)
    seconds["margins"] = time.perf_counter() - clock

    clock = time.perf_counter()
    bar = tqdm(total=40, unit="run", desc="why damping", disable=not progress, leave=False)
    try:
        why = _why(settings, controller.pi_kp, kd, damping["rows"], bar)
    finally:
        bar.close()
    seconds["why"] = time.perf_counter() - clock

    final = settings.controller_at(kp, kd)
    stability = cd.routh_hurwitz(isolator, final)
    static = cd.static_design(isolator, controller, mass_range=mass_range)
    seconds["total"] = time.perf_counter() - began
    gains = {"pi_kp": float(kp), "pi_ki": float(settings.ratio * kp), "damping_gain": float(kd)}
    series = {"damping_curves": {k: (v.frequency, v.magnitude, v.trusted)
                                 for k, v in curves.items()},
              "hunting_traces": traces, "hunting_loop": hunting.get("loop"),
              "pi_details": pi.get("details", {}),
              "pi_details_first": (first_search or {}).get("details", {})}
    record_settings = {
        "isolator": isolator.to_dict(), "controller": controller.to_dict(),
        "excitation": {"kind": type(excitation).__name__,
                       **{f.name: getattr(excitation, f.name)
                          for f in dataclasses.fields(excitation)
                          if not isinstance(getattr(excitation, f.name), np.ndarray)},
                       "units": {f.name: f.metadata.get("unit", "")
                                 for f in dataclasses.fields(excitation)}},
        "duration": duration, "stiction_range": list(stiction_range),
        "mass_range": list(mass_range), "force_steps": list(steps), "band": list(band),
        "cost": cost, "controller_rate": rate, "delay": delay, "quick": bool(quick),
        "dt": settings.dt, "dt_note": settings.dt_note, "stroke_dt": settings.stroke_dt,
        "sample_rate": sample_rate,
        "fft_length": settings.fft_length, "integral_ratio": settings.ratio,
        "stroke_band": list(stroke_band), "damping_gain_max": damping_gain_max,
        "gain_margin_min": gain_margin_min, "phase_margin_min": phase_margin_min,
        "cases": [c.label for c in cases], "workers": workers}
    pi_record = dict(pi)
    pi_record["cases"] = len(cases)
    if first_search is not None:
        pi_record["first_search"] = {k: v for k, v in first_search.items() if k != "details"}
    return DesignResult(gains=gains, settings=record_settings, static=static,
                        pi_search=pi_record, stability=stability, hunting=hunting,
                        damping=damping, margins=margins, why=why, verification=verification,
                        seconds=seconds, series=series)


# ---------------------------------------------------------------- text and report
def _fmt(value, digits=4, unit=""):
    if isinstance(value, float) and math.isinf(value):
        return "infinite"
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "undefined"
    text = f"{value:.{digits}g}"
    return f"{text} {unit}".rstrip()


def design_text(result):
    """The design's summary for people: gains, evidence in numbers, answers.

    Parameters
    ----------
    result : DesignResult
        The design.

    Returns
    -------
    str
    """
    g, s = result.gains, result.settings
    pi = result.pi_search
    lines = [f"qzs design ({'quick' if s['quick'] else 'full'}; {result.seconds['total']:.0f} s)",
             f"  gains            Kp = {_fmt(g['pi_kp'])} N/m, Ki = {_fmt(g['pi_ki'])} N/(m*s), "
             f"Kd = {_fmt(g['damping_gain'])} N*s/m"]
    band = s["stroke_band"]
    if pi["found"]:
        lines.append(f"  PI search        smallest Kp keeping {pi['cases']} cases in "
                     f"[{1e3 * band[0]:.1f}, {1e3 * band[1]:.1f}] mm and off the stops: "
                     f"{_fmt(pi['pi_kp'])} N/m (fails at {_fmt(pi['failing_kp'])} N/m)")
    else:
        lines.append(f"  PI search        {pi['reason']}")
    v = result.verification["summary"]
    lines.append(f"  verification     final gains: {'pass' if v['passes'] else 'FAIL'} "
                 f"(worst use of the band {100 * v['usage']:.0f} %: {v['worst_case']})")
    st = result.static
    lines.append(f"  static           spring {st.spring_force_at_setpoint:.2f} N at the setpoint "
                 f"(carries {st.balanced_mass:.3f} kg), deficit {st.static_deficit:+.2f} N, "
                 f"motor force left {st.motor_force_left:.1f} N of {st.motor_force_max:g} N")
    rh = result.stability
    lines.append(f"  stability        Routh-Hurwitz {'stable' if rh.stable else 'UNSTABLE'} "
                 f"(python-control poles agree: {rh.agrees}); Kd range "
                 f"[{_fmt(rh.damping_gain_limits[0])}, {_fmt(rh.damping_gain_limits[1])}] N*s/m, "
                 f"Ki < {_fmt(rh.integral_gain_limit)} N/(m*s)")
    for row in result.hunting["rows"]:
        p, m = row["prediction"], row["simulation"]
        sim = (f"hunts, +-{1e3 * m['amplitude']:.1f} mm, period {_fmt(m['period'], 3)} s"
               if m.get("hunts") else "settles")
        pred = (f"hunts, plateau {1e3 * p['amplitude']:.1f} mm, period {_fmt(p['period'], 3)} s "
                f"(relay {_fmt(p['relay_period'], 3)} s)" if p["hunts"] else "no hunting")
        lines.append(f"  hunting          {row['loop']}, Fs = {row['stiction_force']:g} N: "
                     f"DF {pred}; simulated {sim}")
    cycles = sum(len(row["prediction"]["friction_intersections"])
                 for row in result.hunting["rows"])
    memoryless = ("no cycle in any row" if cycles == 0 else
                  f"{cycles} cycle(s) over the rows")
    lines.append(f"                   (the friction law alone as a describing function predicts "
                 f"{memoryless}; Kp keeping the predicted plateau in the band at the highest "
                 f"stiction: {_fmt(result.hunting['kp_for_band'])} N/m)")
    d = result.damping
    lines.append(f"  damping          Kd = {_fmt(d['chosen'])} N*s/m minimises the "
                 f"{s['cost']} cost over {s['band'][0]:g}-{s['band'][1]:g} Hz"
                 + (f" ({d['reason']})" if d["reason"] else ""))
    mg = result.margins
    design = mg["design"]
    rate = f"{s['controller_rate']:g} Hz" if s["controller_rate"] > 0 else "continuous"
    lines.append(f"  margins          {rate}, delay {s['delay']:g} s: gain "
                 f"{_fmt(design['gain_margin'], 3)} dB, phase {_fmt(design['phase_margin'], 3)} "
                 f"deg; needed rate {_fmt(mg['required_rate'], 3, 'Hz')}"
                 + (f" ({mg['required_rate_reason']})" if mg["required_rate_reason"] else ""))
    lines.append(f"  why damping      {result.why['answer']}")
    return "\n".join(lines)


_STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222}section{border-top:1px solid #ccc;padding-top:1em;margin-top:2em}
figure{margin:1em 0}figure img{width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#444}table{border-collapse:collapse;font-size:.85em;margin:.5em 0}
td,th{border:1px solid #ddd;padding:.2em .5em;text-align:right}th{background:#eee}
td:first-child,th:first-child{text-align:left}.answer{padding:.6em 1em;border-left:6px solid
#2a8a2a;background:#f7f7f7}.warn{border-color:#c0392b}pre{white-space:pre-wrap;font-size:.85em}"""


def _table(headers, rows):
    e = html.escape
    out = ["<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in headers) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join(f"<td>{e(str(c))}</td>" for c in row) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _figure(written, name, caption):
    e = html.escape
    if name not in written:
        return ""
    png = Path(written[name]).name
    svg = Path(written[name]).with_suffix(".svg").name
    return (f"<figure><a href='{e(png)}'><img src='{e(png)}' alt='{e(name)}'></a>"
            f"<figcaption>{e(caption)} Full size: <a href='{e(png)}'>PNG</a>, "
            f"<a href='{e(svg)}'>SVG</a>.</figcaption></figure>")


def _html(result, record, written):
    e = html.escape
    g, s = result.gains, result.settings
    st = result.static
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>qzs design</title>"
             f"<style>{_STYLE}</style></head><body>",
             "<h1>Semi-active QZS isolator: controller design</h1>",
             f"<p>qzs {e(__version__)}; {'quick' if s['quick'] else 'full'} design, "
             f"{result.seconds['total']:.0f} s. Method and decisions: docs/design.md. Every "
             "number comes from simulations of the nonlinear model (stick-slip friction, stops, "
             "saturation) unless it says linear.</p>",
             "<h2>Chosen gains</h2>",
             _table(["quantity", "value", "unit", "evidence"], [
                 ["Kp", _fmt(g["pi_kp"]), "N/m", "PI search (smallest passing gain)"],
                 ["Ki", _fmt(g["pi_ki"]), "N/(m*s)", f"Ki/Kp = {s['integral_ratio']:g} 1/s kept"],
                 ["Kd", _fmt(g["damping_gain"]), "N*s/m", "damping search (least cost"
                  + (", at the bound)" if result.damping.get("at_bound") else ")")]]),
             f"<pre>{e(design_text(result))}</pre>"]
    parts.append("<section><h2>Problem</h2>" + _table(["setting", "value"], [
        ["base motion", f"{s['excitation']['kind']} "
                        + ", ".join(f"{k} = {v} {s['excitation']['units'].get(k, '')}".rstrip()
                                    for k, v in s["excitation"].items()
                                    if k not in ("kind", "units"))],
        ["simulated", f"{s['duration']:g} s, dt = {s['dt']:.3g} s ({s['dt_note']}), output "
                      f"{s['sample_rate']:g} Hz"],
        ["stiction range [N]", f"{s['stiction_range'][0]:g} - {s['stiction_range'][1]:g}"],
        ["mass range [kg]", f"{s['mass_range'][0]:g} - {s['mass_range'][1]:g}"],
        ["force steps [N] (upward +)", ", ".join(f"{x:+g}" for x in s["force_steps"]) or "none"],
        ["stroke band [mm]", f"{1e3 * s['stroke_band'][0]:.1f} to {1e3 * s['stroke_band'][1]:.1f} "
                             "(the constant-force region about the setpoint)"],
        ["cost", f"{s['cost']} of T over the trusted bins of {s['band'][0]:g}-{s['band'][1]:g} "
                 f"Hz (Welch {s['fft_length']} samples)"],
        ["controller", (f"{s['controller_rate']:g} Hz" if s["controller_rate"] > 0 else
                        "continuous") + f", delay {s['delay']:g} s (margins only)"],
        ["cases", f"{len(s['cases'])}: " + "; ".join(s["cases"])]]) + "</section>")
    parts.append("<section><h2>Static design</h2>" + _table(["quantity", "value"], [
        ["spring force at the setpoint [N]", f"{st.spring_force_at_setpoint:.3f}"],
        ["payload the spring alone carries [kg]", _fmt(st.balanced_mass)],
        ["weight m*g [N]", f"{st.weight:.3f}"],
        ["static deficit m*g - F_spring [N]", f"{st.static_deficit:+.3f}"],
        ["motor force left for control [N]", f"{st.motor_force_left:.2f} of {st.motor_force_max:g}"],
        ["least force left over the mass range [N]", f"{st.motor_force_left_min:.2f}"],
        ["payloads spring + motor can hold [kg]",
         f"{_fmt(st.holdable_mass[0])} - {_fmt(st.holdable_mass[1])}"],
        ["spring force over the constant-force band [N]",
         f"{st.spring_force_band[0]:.2f} - {st.spring_force_band[1]:.2f}"],
        ["moving mass without the paper's 5.5 kg [kg]", _fmt(st.moving_mass_without_added)],
        ["its static deficit [N]", _fmt(st.deficit_without_added)]])
        + _figure(written, "static_design", "Motor force needed to hold a payload at the "
                  "setpoint against its mass, with the motor's limits.") + "</section>")
    pi = result.pi_search
    rows = [[_fmt(t["pi_kp"]), _fmt(t["pi_ki"]), "pass" if t["passes"] else "fail",
             f"{100 * t['usage']:.0f}" if math.isfinite(t["usage"]) else "diverged",
             f"{1e3 * t['z_min']:.1f}", f"{1e3 * t['z_max']:.1f}", t["stop_contacts"],
             t["worst_case"]] for t in pi.get("table", [])]
    parts.append("<section><h2>PI gains</h2><p>" + e(
        f"Smallest Kp (Ki = {s['integral_ratio']:g}*Kp) keeping every case inside the band and "
        f"off the stops: {_fmt(pi['pi_kp'])} N/m; {_fmt(pi['failing_kp'])} N/m fails. "
        + (pi["reason"] or "")) + "</p>"
        + _table(["Kp [N/m]", "Ki [N/(m*s)]", "all cases", "band used [%]", "z min [mm]",
                  "z max [mm]", "stop contacts", "worst case"], rows)
        + _figure(written, "pi_search", "Largest excursion above and below the setpoint over "
                  "every case, against the proportional gain.") + "</section>")
    rh = result.stability
    conditions = [[text, f"{value:.4g}", "holds" if holds else "violated"]
                  for text, value, holds in rh.conditions]
    parts.append(
        "<section><h2>Linear stability</h2><p>Characteristic polynomial (fractions cleared) "
        "m s^4 + (m w + Cv + Kd) s^3 + (Cv w + k + Kp) s^2 + ((k + Kp) w + Ki) s + Ki w, "
        "w = 2 pi f_hp: coefficients " + e(", ".join(f"{c:.5g}" for c in rh.coefficients))
        + ". Routh-Hurwitz conditions:</p>" + _table(["condition", "value", ""], conditions)
        + "<p>" + e(f"Closed form: stable = {rh.stable}; python-control's poles: largest real "
                    f"part {rh.largest_real_part:.4g} 1/s (agree: {rh.agrees}). Stable Kd at these "
                    f"PI gains: {_fmt(rh.damping_gain_limits[0])} to "
                    f"{_fmt(rh.damping_gain_limits[1])} N*s/m; Ki < "
                    f"{_fmt(rh.integral_gain_limit)} N/(m*s); Kp > "
                    f"{_fmt(rh.proportional_gain_minimum)} N/m.") + "</p></section>")
    hunt_rows = []
    for row in result.hunting["rows"]:
        p, m = row["prediction"], row["simulation"]
        hunt_rows.append([f"{row['stiction_force']:g}", "yes" if p["hunts"] else "no",
                          _fmt(1e3 * p["amplitude"] if p["amplitude"] is not None else None, 3),
                          _fmt(p["period"], 3), _fmt(p["relay_period"], 3),
                          "yes" if m.get("hunts") else "no",
                          _fmt(1e3 * m["amplitude"], 3) if m.get("hunts") else "-",
                          _fmt(m.get("period"), 3) if m.get("hunts") else "-",
                          len(p["friction_intersections"]),
                          {True: "confirmed", False: "refuted", None: "-"}[row["relay_confirmed"]]])
    parts.append(
        "<section><h2>Hunting at rest</h2><p>Describing functions (python-control): the "
        "friction law alone, as a function of slip velocity, predicts no limit cycle for a "
        "stable loop; the payload and its friction as a stick-slip relay in the integral loop "
        "predicts one. Simulation: the base at rest, the payload stuck at the predicted plateau "
        "with the loop in balance.</p>" + _table(
            ["Fs [N]", "relay DF: hunts", "plateau [mm]", "DF period [s]", "relay period [s]",
             "simulated: hunts", "amplitude [mm]", "period [s]", "memoryless DF cycles",
             "relay DF"], hunt_rows)
        + "<p>" + e(f"Kp keeping the predicted plateau inside the band at the highest stiction: "
                    f"{_fmt(result.hunting['kp_for_band'])} N/m.") + "</p>"
        + _figure(written, "hunting", "Top: the integral loop's Nyquist curve and the stick-slip "
                  "relay's -1/N. Bottom: simulated position at rest.") + "</section>")
    d = result.damping
    d_rows = [[_fmt(r["damping_gain"]), _fmt(r["cost"]), _fmt(r["linear_cost"]),
               f"{100 * r['trusted_share']:.0f}", _fmt(r["motor_force_rms"], 3), r["reason"]]
              for r in d["rows"]]
    parts.append("<section><h2>Damping gain</h2><p>" + e(
        f"Bound: {_fmt(d['bound'])} N*s/m (" + "; ".join(d["bound_notes"]) + f"). Chosen: "
        f"{_fmt(d['chosen'])} N*s/m. {d['reason']}") + "</p>"
        + _table(["Kd [N*s/m]", "cost (simulated)", "cost (linear)", "bins trusted [%]",
                  "motor force RMS [N]", "note"], d_rows)
        + _figure(written, "damping", "Cost against the damping gain, and the transmissibility "
                  "without damping and at the chosen gain.") + "</section>")
    mg = result.margins
    m_rows = [[f"{t['rate']:g}", "yes" if t["stable"] else "no", _fmt(t["gain_margin"], 3),
               _fmt(t["phase_margin"], 3), _fmt(t["gain_crossover_frequency"], 3)]
              for t in mg["table"]]
    parts.append("<section><h2>Sampled loop</h2><p>" + e(
        f"At the design's rate and delay: gain margin {_fmt(mg['design']['gain_margin'], 3)} dB, "
        f"phase margin {_fmt(mg['design']['phase_margin'], 3)} deg; continuous: "
        f"{_fmt(mg['continuous']['gain_margin'], 3)} dB, "
        f"{_fmt(mg['continuous']['phase_margin'], 3)} deg. Rate needed for "
        f"{s['gain_margin_min']:g} dB and {s['phase_margin_min']:g} deg: "
        f"{_fmt(mg['required_rate'], 3, 'Hz')} with the delay, "
        f"{_fmt(mg['required_rate_without_delay'], 3, 'Hz')} without. "
        f"{mg['required_rate_reason']}") + "</p>"
        + _table(["rate [Hz]", "stable", "gain margin [dB]", "phase margin [deg]",
                  "crossover [Hz]"], m_rows)
        + _table(["delay [ms]", "needed rate [Hz]", "continuous: gain margin [dB]",
                  "continuous: phase margin [deg]"],
                 [[f"{1e3 * r['delay']:g}", _fmt(r["required_rate"], 3),
                   _fmt(r["continuous_gain_margin"], 3), _fmt(r["continuous_phase_margin"], 3)]
                  for r in mg.get("by_delay", [])])
        + _figure(written, "margins", "Margins of the sampled loop against the controller "
                  "rate.") + "</section>")
    w = result.why
    w_rows = [[r["factor"], r["value"], _fmt(r["damping_gain"]), _fmt(r["cost_undamped"]),
               _fmt(r["cost_damped"]), _fmt(r["change_db"], 3), _fmt(r["linear_change_db"], 3)]
              for r in w["rows"]]
    parts.append("<section><h2>Why active damping did not help much</h2>"
                 f"<div class='answer'>{e(w['answer'])}</div>"
                 + _table(["factor", "value", "Kd [N*s/m]", "cost Kd = 0", "cost damped",
                           "change [dB]", "linear [dB]"], w_rows)
                 + _figure(written, "damping_effect", "Change of the cost with damping against "
                           "each factor: simulated (markers), linear (lines).") + "</section>")
    parts.append("<section><h2>Run</h2>" + _table(["stage", "seconds"], [
        [k, f"{v:.1f}"] for k, v in result.seconds.items()]) + "</section></body></html>")
    return "\n".join(parts)
