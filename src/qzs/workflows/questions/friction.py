"""The paper's second open question, "remove stiction", as a study of friction compensation.

The motor sits in parallel with the guide and can cancel a fraction ``a`` of its friction law
(:class:`qzs.FrictionCompensation`, docs/model.md §5.1). This study runs the paper's isolator
(Table 1, the paper's PI gains, no damping) under one chirp for every fraction of a grid over
[0, 1.5], in one lockstep batch through the lanes, beside the same isolator without stiction
(``Fs = Fc``: the Stribeck peak gone), and reads off

- the isolation onset [Hz] and the RMS transmissibility over 1-3 Hz [-] (the band where the
  paper's Fig. 7 shows stiction's penalty), the stick events and the motor's RMS force [N];
- the stiction penalty, what the isolator without stiction does better, and the share of it
  each fraction removes;
- where it starts to hunt: predicted by the describing function of the net friction law
  (:func:`qzs.analysis.control_design.predict_sliding_cycle`; the smallest fraction with a
  stable cycle, by bisection) and simulated (the base at rest, the payload released sliding:
  does it keep moving?), on the paper's loop and on a stiff loop where the describing function
  holds (``breakaway_ratio > 1.5``, ``distortion < 0.03``: docs/model.md §5.1 states 2 % for the
  cycle's velocity amplitude and frequency there), whose simulated cycles are measured against
  the prediction.

:func:`friction_answer` turns the table into the verdict; it reads numbers only, so a test
can hand it constructed ones.
"""
import dataclasses
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from qzs.analysis.control_design.describing_functions import predict_sliding_cycle
from qzs.engine.simulate import simulate
from qzs.model.controller import ControllerParameters, FrictionCompensation
from qzs.model.excitation import Chirp, Sine
from qzs.model.isolator import InitialState, IsolatorParameters
from qzs.workflows.questions.common import (Answer, ChirpPlan, band_transmissibility, check_step,
                                            finite, run_chirp_cases)

__all__ = ["QUESTION", "STATEMENT", "BAND", "FRACTIONS", "plan", "compensated",
           "hunting_boundary", "released_run", "measure_cycle", "friction_answer",
           "run_friction_study", "DF_TOLERANCE", "HUNTING_RIGS"]

QUESTION = "friction_compensation"
STATEMENT = ('Future work will attempt "to remove stiction in the system to achieve better '
             'isolation performance" (Section 5).')
#: The band of the paper's stiction penalty (Fig. 7) [Hz].
BAND = (1.0, 3.0)
#: The compensation fractions of the full and the quick study [-].
FRACTIONS = {False: (0.0, 0.25, 0.5, 0.75, 1.0, 1.1, 1.25, 1.4, 1.5),
             True: (0.0, 0.5, 1.0, 1.5)}
#: The describing function's stated accuracy (docs/model.md §5.1): relative error of the
#: cycle's velocity amplitude and frequency when ``breakaway_ratio > 1.5`` and
#: ``distortion < 0.03``.
DF_TOLERANCE = {"relative": 0.02, "breakaway_ratio": 1.5, "distortion": 0.03}
#: Shares of the penalty for the verdict, of the smaller of the two (T over the band, the
#: isolation onset): "yes" from the first, "partly" from the second.
SHARES = (0.8, 0.2)
#: Peak-to-peak relative position [m] in the second half of a run at rest above which the
#: payload hunts (it does not come to rest).
HUNT_STROKE = 2e-4
#: The loops the hunting boundary is predicted and simulated on: name -> (isolator,
#: controller without compensation, options of its FrictionCompensation). The paper's, and a
#: stiff one without the amplifier's high-pass whose compensation takes the whole law (its
#: viscous part too), where the payload slides through its reversals (docs/model.md §5.1).
HUNTING_RIGS = {
    "paper loop": (IsolatorParameters(), ControllerParameters(), {}),
    "stiff loop (Kp = 2000 N/m, Kd = 60 N*s/m, Fs = 2 N, the whole law)": (
        IsolatorParameters(stiction_force=2.0),
        ControllerParameters(pi_kp=2000.0, damping_gain=60.0, velocity_highpass=0.0),
        {"viscous_damping": None}),
}


def plan(quick=False, dt=1e-4):
    """The chirp and Welch settings: 10 mm (the paper's), 0.2-5 Hz.

    Parameters
    ----------
    quick : bool
        60 s and 2048-point segments (0.1 Hz bins) instead of 300 s and 4096 points.
    dt : float
        Integration step [s] (the paper's 1e-4 by default).

    Returns
    -------
    ChirpPlan
    """
    duration, fft = (60.0, 2048) if quick else (300.0, 4096)
    return ChirpPlan(Chirp(amplitude=0.010, f0=0.2, f1=5.0, duration=duration, fade_in=2.0),
                     sample_rate=200.0, fft_length=fft, dt=dt)


def compensated(controller, fraction, **options):
    """``controller`` with a compensation of ``fraction``; 0 adds no block at all.

    Parameters
    ----------
    controller : ControllerParameters
        The loop without compensation.
    fraction : float
        Fraction of the friction law compensated [-], in [0, 1.5].
    **options
        Other fields of the :class:`~qzs.FrictionCompensation`.

    Returns
    -------
    ControllerParameters
    """
    if fraction == 0:
        return controller
    return controller + FrictionCompensation(fraction=fraction, **options)


def hunting_boundary(isolator, controller, high=1.5, tolerance=5e-3, options=None):
    """The smallest compensation fraction with a stable sliding cycle, by bisection [-].

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant.
    controller : ControllerParameters
        The loop without compensation.
    high : float
        The largest fraction looked at [-].
    tolerance : float
        Width of the final bracket [-].
    options : dict, optional
        Other fields of the :class:`~qzs.FrictionCompensation`.

    Returns
    -------
    float
        The fraction; NaN if none up to ``high`` hunts.
    """
    def hunts(a):
        return predict_sliding_cycle(isolator, compensated(controller, a,
                                                           **(options or {}))).hunts

    if not hunts(high):
        return math.nan
    low = 0.0
    if hunts(low):
        return 0.0
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if hunts(middle) else (middle, high)
    return high


def measure_cycle(time, velocity, position):
    """The cycle in the second half of a run: amplitude, frequency and first harmonic.

    Parameters
    ----------
    time : ndarray
        Sample times [s].
    velocity : ndarray
        Relative velocity [m/s].
    position : ndarray
        Relative position [m].

    Returns
    -------
    dict
        ``stroke`` (peak-to-peak position [m]), ``velocity_amplitude`` (first harmonic of the
        velocity at the measured period [m/s]) and ``frequency`` [Hz] (mean period between
        upward zero crossings), NaN with fewer than three crossings.
    """
    late = time >= 0.5 * time[-1]
    t, v, z = time[late], velocity[late], position[late]
    out = {"stroke": float(z.max() - z.min()), "velocity_amplitude": math.nan,
           "frequency": math.nan}
    up = np.flatnonzero((v[:-1] < 0) & (v[1:] >= 0))
    if up.size < 3:
        return out
    crossings = t[up] - v[up] * (t[up + 1] - t[up]) / (v[up + 1] - v[up])
    period = (crossings[-1] - crossings[0]) / (crossings.size - 1)
    whole = slice(up[0], up[-1])
    phase = np.exp(-2j * np.pi * t[whole] / period)
    first = 2 * abs(np.trapezoid(v[whole] * phase, t[whole])) / (t[whole][-1] - t[whole][0])
    out.update(velocity_amplitude=float(first), frequency=float(1 / period))
    return out


def released_run(isolator, controller, prediction, *, duration, dt):
    """The base at rest, the payload released sliding: does it come to rest?

    Released at the setpoint with 1.5 times the predicted cycle's velocity amplitude
    (0.02 m/s where none is predicted), as the describing function's tests do.

    Parameters
    ----------
    isolator : IsolatorParameters
        The plant.
    controller : ControllerParameters
        The loop, its compensation included.
    prediction : SlidingCycle
        :func:`predict_sliding_cycle` of the loop.
    duration : float
        Simulated time [s].
    dt : float
        Integration step [s].

    Returns
    -------
    dict
        :func:`measure_cycle`'s values, ``hunts`` (the second half's stroke exceeds
        :data:`HUNT_STROKE`), ``locked_fraction`` of the second half [-], ``stop_contacts``.
    """
    kick = 1.5 * prediction.velocity_amplitude if prediction.hunts else 0.02
    run = simulate(Sine(amplitude=0.0, frequency=1.0, fade_in=0.0), isolator, controller,
                   duration=duration, dt=dt, sample_rate=1000.0,
                   initial_state=InitialState(relative_velocity=kick, locked=False))
    cycle = measure_cycle(run.time, run.relative_velocity, run.relative_position)
    late = run.time >= 0.5 * duration
    cycle.update(hunts=bool(cycle["stroke"] > HUNT_STROKE),
                 locked_fraction=float(np.mean(run.locked[late])),
                 stop_contacts=int(run.run["stop_contacts"]), release_velocity=kick)
    return cycle


def _hunting_rows(fractions, quick, dt, workers, progress=False):
    """Prediction and released run per rig and fraction, and each rig's predicted boundary
    (with ``progress``, a bar over them: about 15 s of work after the chirps)."""
    from qzs.engine.progress import progress_bar

    duration = 20.0 if quick else 40.0
    tasks = [(rig, a) for rig in HUNTING_RIGS for a in fractions]
    bar = progress_bar(total=len(tasks) + len(HUNTING_RIGS), unit="run",
                       desc="hunting at rest (released runs, boundaries)", disable=not progress)

    def one(task):
        rig, a = task
        isolator, controller, options = HUNTING_RIGS[rig]
        loop = compensated(controller, a, **options)
        prediction = predict_sliding_cycle(isolator, loop)
        return prediction, released_run(isolator, loop, prediction, duration=duration, dt=dt)

    rows = []
    with bar, ThreadPoolExecutor(max_workers=workers) as pool:
        rows, boundaries = _collect(tasks, pool.map(one, tasks), fractions, bar)
    return rows, boundaries


def _collect(tasks, results, fractions, bar):
    """The hunting rows from each task's prediction and released run, then the boundaries."""
    rows = []
    for (rig, a), (prediction, measured) in zip(tasks, results):
        bar.update(1)
        regime = (prediction.hunts and prediction.breakaway_ratio
                  > DF_TOLERANCE["breakaway_ratio"]
                  and prediction.distortion < DF_TOLERANCE["distortion"])
        row = {"rig": rig, "fraction": a, "predicted": prediction.hunts,
               "predicted_velocity_amplitude": prediction.velocity_amplitude,
               "predicted_frequency": prediction.frequency,
               "breakaway_ratio": prediction.breakaway_ratio,
               "distortion": prediction.distortion, "in_tolerance_regime": bool(regime),
               **{f"simulated_{k}": v for k, v in measured.items()}}
        if regime and finite(measured["velocity_amplitude"], measured["frequency"]):
            row["amplitude_error"] = abs(measured["velocity_amplitude"]
                                         / prediction.velocity_amplitude - 1)
            row["frequency_error"] = abs(measured["frequency"] / prediction.frequency - 1)
            row["within_tolerance"] = bool(max(row["amplitude_error"],
                                               row["frequency_error"])
                                           <= DF_TOLERANCE["relative"])
        else:
            row["amplitude_error"] = row["frequency_error"] = math.nan
            row["within_tolerance"] = None
            row["tolerance_reason"] = (
                "no cycle predicted" if not prediction.hunts else
                f"outside the describing function's stated range (breakaway ratio "
                f"{prediction.breakaway_ratio:.3g} <= {DF_TOLERANCE['breakaway_ratio']:g} "
                f"or distortion {prediction.distortion:.3g} >= "
                f"{DF_TOLERANCE['distortion']:g}): the payload sticks at its reversals"
                if regime is False and prediction.hunts else
                "the simulated run has no cycle to measure")
        rows.append(row)
    boundaries = {}
    for rig, (isolator, controller, options) in HUNTING_RIGS.items():
        simulated = [r["fraction"] for r in rows if r["rig"] == rig and r["simulated_hunts"]]
        boundaries[rig] = {"predicted": hunting_boundary(isolator, controller,
                                                         high=max(fractions), options=options),
                           "simulated": min(simulated) if simulated else math.nan}
        bar.update(1)
    return rows, boundaries


def friction_answer(table, reference, hunting, boundary):
    """The verdict: how much of the stiction penalty the motor removes, where it hunts.

    Parameters
    ----------
    table : list of dict
        One row per fraction (ascending): ``fraction`` [-], ``band_rms`` (T over 1-3 Hz [-]),
        ``isolation_onset`` [Hz], ``stick_events``, ``motor_force_rms`` [N],
        ``stop_contacts``.
    reference : dict
        The isolator without stiction: ``band_rms`` [-] and ``isolation_onset`` [Hz].
    hunting : dict
        Fraction -> the paper loop hunts at rest there (simulated), for the table's fractions.
    boundary : dict
        ``predicted`` and ``simulated`` fractions where the paper loop starts to hunt (NaN:
        none up to the largest).

    Returns
    -------
    Answer
    """
    def undecidable(why):
        return Answer(QUESTION, STATEMENT, "not decidable", "undefined: " + why, why)

    rows = sorted(table, key=lambda r: r["fraction"])
    if not rows or rows[0]["fraction"] != 0:
        return undecidable("the table has no uncompensated case (fraction 0)")
    none = rows[0]
    if not finite(none["band_rms"], reference["band_rms"]):
        return undecidable("T over the band is undefined (no trusted bin) for the "
                           "uncompensated isolator or the one without stiction")
    penalty = none["band_rms"] - reference["band_rms"]
    if penalty <= 0:
        return undecidable(f"stiction costs nothing over the band here (T {none['band_rms']:.3g} "
                           f"with it, {reference['band_rms']:.3g} without): no penalty to remove")
    usable = [r for r in rows if not hunting.get(r["fraction"], False)
              and r["stop_contacts"] == 0 and finite(r["band_rms"])]
    best = min(usable, key=lambda r: r["band_rms"])
    share = (none["band_rms"] - best["band_rms"]) / penalty
    shares = [share]
    onset_text = ""
    if finite(none["isolation_onset"], reference["isolation_onset"], best["isolation_onset"]):
        onset_gap = none["isolation_onset"] - reference["isolation_onset"]
        if onset_gap > 0:
            shares.append((none["isolation_onset"] - best["isolation_onset"]) / onset_gap)
            onset_text = (f"; the isolation onset moves from {none['isolation_onset']:.3g} Hz to "
                          f"{best['isolation_onset']:.3g} Hz, {shares[-1]:.0%} of the way to "
                          f"the {reference['isolation_onset']:.3g} Hz without stiction")
    least = min(shares)  # the verdict takes the penalty it removes least of
    label = "yes" if least >= SHARES[0] else "partly" if least >= SHARES[1] else "no"
    predicted, simulated = boundary["predicted"], boundary["simulated"]
    hunt_text = ("it starts to hunt at rest at a = " + (f"{simulated:g}" if finite(simulated)
                                                        else "none of those run")
                 + " (simulated), the describing function predicts a sliding cycle from a = "
                 + (f"{predicted:.3g}" if finite(predicted) else "none"))
    answer = (f"{'Most' if label == 'yes' else 'Some' if label == 'partly' else 'Little'} of "
              f"it: compensating a = {best['fraction']:g} of the friction law removes "
              f"{share:.0%} of the stiction penalty on T over {BAND[0]:g}-{BAND[1]:g} Hz"
              + (f" and {shares[1]:.0%} of its penalty on the isolation onset" if len(shares) > 1
                 else "") + "; " + hunt_text)
    evidence = (f"RMS T over {BAND[0]:g}-{BAND[1]:g} Hz: {none['band_rms']:.4g} uncompensated, "
                f"{reference['band_rms']:.4g} without stiction (Fs = Fc), penalty "
                f"{penalty:.3g}; best without hunting or stop contact: {best['band_rms']:.4g} at "
                f"a = {best['fraction']:g} (stick events {none['stick_events']:g} -> "
                f"{best['stick_events']:g}, motor RMS force {none['motor_force_rms']:.3g} -> "
                f"{best['motor_force_rms']:.3g} N){onset_text}. The compensation is 0 while the "
                "payload sticks (it acts on the measured slip velocity): it lowers the friction "
                "a slipping payload feels, never the breakaway force Fs that locks it, and the "
                "penalty is the locking.")
    return Answer(QUESTION, STATEMENT, label, answer, evidence)


def run_friction_study(quick=False, *, dt=1e-4, workers=None, progress=False):
    """Run the friction-compensation study (module docstring).

    Parameters
    ----------
    quick : bool
        Fewer fractions, a shorter chirp and shorter runs at rest.
    dt : float
        Integration step of every run [s] (the paper's 1e-4 by default).
    workers : int, optional
        Threads; default all cores.
    progress : bool
        Show the batch's progress bar.

    Returns
    -------
    dict
        ``table`` (one row per fraction), ``reference`` (without stiction), ``curves``
        (:class:`CaseCurve` per case, the reference last), ``hunting`` (rows per rig and
        fraction), ``boundaries``, ``answer`` (:class:`Answer`), ``plan``.
    """
    check_step(dt)
    fractions = FRACTIONS[bool(quick)]
    chirp = plan(quick, dt)
    isolator, controller, _ = HUNTING_RIGS["paper loop"]
    smooth = dataclasses.replace(isolator, stiction_force=isolator.coulomb_force)
    labels = [f"a = {a:g}" for a in fractions] + ["without stiction (Fs = Fc)"]
    cases = [(isolator, compensated(controller, a)) for a in fractions] + [(smooth, controller)]
    curves = run_chirp_cases(labels, cases, chirp, workers=workers, progress=progress)
    rows = [_row(a, curve) for a, curve in zip(fractions, curves)]
    reference = _row(math.nan, curves[-1])
    hunting, boundaries = _hunting_rows(fractions, quick, dt, workers, progress)
    paper = {r["fraction"]: r["simulated_hunts"] for r in hunting if r["rig"] == "paper loop"}
    answer = friction_answer(rows, reference, paper, boundaries["paper loop"])
    return {"table": rows, "reference": reference, "curves": curves, "hunting": hunting,
            "boundaries": boundaries, "answer": answer, "plan": chirp, "quick": bool(quick)}


def _row(fraction, curve):
    return {"fraction": fraction, "band_rms": band_transmissibility(curve, BAND),
            "isolation_onset": curve.metrics["isolation_onset"],
            "isolation_onset_reason": curve.reasons.get("isolation_onset", ""),
            "stick_events": curve.stats["stick_events"],
            "motor_force_rms": curve.stats["motor_force_rms"],
            "stop_contacts": curve.stats["stop_contacts"],
            "locked_fraction": curve.stats["locked_fraction"]}
