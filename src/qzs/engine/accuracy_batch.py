"""One accuracy-driven step for many cases at once: the step of a lockstep batch (docs/model.md §7).

:func:`choose_batch_step` is :func:`qzs.engine.accuracy.choose_step`'s search (the same probe,
measure, candidates and Richardson estimate) with every case probed at once, each candidate
one lockstep batch of the cases still searched; the paper's studies and sweeps take their
step from it.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from qzs import defaults
from qzs.engine.accuracy import (MEASURE_UNITS, SAFETY, StepChoice, _bound_notes, _estimate,
                                 _order_notes, _probe_settings, tolerance_measure, admissible_step,
                                 step_error)
from qzs.errors import ParameterError, ToleranceNotMetError

__all__ = ["BATCH_MAX_HALVINGS", "BatchStepChoice", "choose_batch_step"]

#: Halvings :func:`choose_batch_step` tries at most by default: candidates down to
#: ``dt_0/8`` (125 us at a 1 kHz output, about the paper's 1e-4 s), compared with runs down
#: to ``dt_0/32``. A case no candidate meets is reported, and the step comes from the others.
BATCH_MAX_HALVINGS = 5


@dataclass(frozen=True)
class BatchStepChoice(StepChoice):
    """The outcome of :func:`choose_batch_step`: one step for every case of a lockstep batch.

    Attributes
    ----------
    dt : float
        The chosen step [s]: the finest of the cases' coarsest steps meeting the tolerance.
    error : float
        The largest estimated error over the cases that met the tolerance ([dB] or [m]).
    measure : str
        As for :class:`StepChoice`.
    tolerance : float
        The tolerance asked for, in the unit of ``measure``.
    reference_dt : float
        The finest step integrated on the probe for the case(s) that set ``dt`` [s].
    stability_limit : float
        The smallest over the cases of the solver's largest stable step [s].
    sample_rate : float
        Output rate [Hz]; ``dt`` divides its period.
    solver : str
        The integrator.
    probe : object
        The excitation integrated to choose the step.
    probe_duration : float
        Length of the probe [s].
    band : tuple of float
        Frequency band [Hz] of the transmissibility measure (None for the state).
    history : tuple
        ``(dt, difference, estimate)`` per step tried, the largest difference and estimate
        over the cases still searched at that step.
    notes : tuple of str
        What the caller should know (the limit that bound the step, the unmet cases).
    case_errors : tuple of float
        Each case's estimated error at the coarsest step that met the tolerance for it
        (``dt`` is that step or finer), in the unit of ``measure``; inf for a case no
        candidate met, NaN for one without a trusted bin in the band on the probe.
    case_steps : tuple of float
        That coarsest step [s] per case (NaN: none).
    unmet : tuple of int
        Indices of the cases no candidate met, or without a trusted bin: ``dt`` comes from
        the others, and their response depends on the step (see ``notes``).
    met : bool
        True: a batch choice always meets the tolerance for the cases that set it (none
        meeting it raises :class:`~qzs.errors.ToleranceNotMetError`).
    cached : bool
        False: batch choices are not kept in the step cache.
    """

    case_errors: tuple = ()
    case_steps: tuple = ()
    unmet: tuple = ()


@dataclass(frozen=True)
class _ProbeRun:
    """The series :func:`step_error` reads, of one case of a batch probe run."""

    base_acceleration: np.ndarray
    payload_acceleration: np.ndarray
    relative_position: np.ndarray
    run: dict
    estimates: dict = field(default_factory=dict)  # fft length -> its transmissibility


def choose_batch_step(cases, excitation=None, *, tolerance_db=None, tolerance_state=None,
                      solver=defaults.SIMULATION["solver"],
                      sample_rate=defaults.SIMULATION["sample_rate"], band=None,
                      probe_duration=None, fft_length=None, max_halvings=BATCH_MAX_HALVINGS,
                      safety=SAFETY, workers=None, progress=False, labels=None):
    """One step for many cases sharing an excitation: the coarsest meeting the tolerance
    for every case (docs/model.md §7).

    The method of :func:`choose_step` (same probe, measure, candidates and Richardson
    estimate) with every case probed at once: each candidate ``dt_j`` is one lockstep
    batch (:func:`~qzs.engine.batch.simulate_batch`) of the cases still searched, so that
    17 cases cost about what one does. ``dt_0`` is the largest step admissible for every
    case. A case leaves the search at the first candidate whose estimate times ``safety``
    meets the tolerance; the step is the finest of these. A case no candidate meets (its
    differences do not shrink: stop contacts or a stick-slip pattern each refinement
    redraws) does not hold the others back: it is listed in ``unmet`` and a note says so.
    A case leaves the search early, unmet, when its estimate exceeds the tolerance by more
    than the scheme's order could close by the finest candidate (``2**order`` per halving):
    the paper's case without PI, 9 dB at 1 ms against the 0.005 dB needed, would otherwise
    take three more probe runs at ever finer steps.

    Parameters
    ----------
    cases : sequence of (IsolatorParameters, ControllerParameters)
        The parameter sets, as for :func:`~qzs.engine.batch.simulate_batch`.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        The full runs' shared excitation; default the paper's chirp.
    tolerance_db : float, optional
        Tolerance on the transmissibility [dB], as for :func:`choose_step`.
    tolerance_state : float, optional
        Tolerance on the relative position [m], as for :func:`choose_step`. Give exactly
        one of the two tolerances.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.
    sample_rate : float
        Output rate [Hz] of the runs the step is for; the step divides its period.
    band : tuple of float, optional
        Band of interest [Hz], as for :func:`choose_step`.
    probe_duration : float, optional
        Length of the probe [s] (see :func:`probe_excitation`).
    fft_length : int, optional
        Welch segment length [samples] of the probe's transmissibility.
    max_halvings : int
        Halvings of ``dt_0`` tried at most [-] (default :data:`BATCH_MAX_HALVINGS`).
    safety : float
        Factor [-] (>= 1) between the estimate and the tolerance, as for :func:`choose_step`.
    workers : int, optional
        Threads of the batch kernel; default all cores.
    progress : bool
        Show a progress bar over the probe batches.
    labels : sequence of str, optional
        Names of the cases in the notes; default ``case 0``, ``case 1``, ...

    Returns
    -------
    BatchStepChoice

    Raises
    ------
    ParameterError
        No case, both or neither tolerance, a non-positive one, a band outside the
        excitation.
    ToleranceNotMetError
        No candidate meets the tolerance for any case.
    SimulationError
        A case diverges on the probe.
    """
    from qzs.engine.batch import simulate_batch
    from qzs.engine.prepare import resolving_step, run_inputs, steps_per_sample
    from qzs.engine.stability import largest_stable_step, stability_test
    from qzs.errors import SimulationError

    measure, tolerance = tolerance_measure(tolerance_db, tolerance_state)
    cases = [run_inputs(None, *pair)[1:] for pair in cases]
    if not cases:
        raise ParameterError("`cases` must hold at least one (isolator, controller) pair.")
    excitation = run_inputs(excitation)[0]
    order, sample_rate, band, probe, duration = _probe_settings(
        excitation, measure, solver, sample_rate, band, probe_duration, fft_length, safety,
        max_halvings)

    tests = [stability_test(isolator, controller, solver) for isolator, controller in cases]
    limit = min(largest_stable_step(isolator, controller, solver)
                for isolator, controller in cases)
    resolving = resolving_step(probe, duration)
    rates = sorted({controller.controller_rate for _, controller in cases})

    def stable(dt):
        return dt <= resolving and all(test(dt) for test in tests)

    def divides(dt):  # several sampled controllers: each period a whole number of steps
        try:
            for rate in rates:
                if rate > 0:
                    steps_per_sample(rate, dt, "controller_rate")
        except ParameterError:
            return False
        return True

    if len(rates) == 1:
        dt0, k0 = admissible_step(sample_rate, rates[0], stable)
    else:
        dt0, k0 = admissible_step(sample_rate, 0.0, lambda dt: stable(dt) and divides(dt))
    notes = _bound_notes(dt0, k0, sample_rate, limit, resolving, measure,
                         probe is not excitation)

    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=max_halvings + 1, unit="batch", desc="choosing dt", leave=False)
    runs = {}

    def run(j, members):
        kept = runs.setdefault(j, {})
        missing = [c for c in members if c not in kept]
        if not missing:
            return
        batch = simulate_batch([cases[c] for c in missing], probe, duration=duration,
                               dt=dt0 / 2 ** j, sample_rate=sample_rate, solver=solver,
                               channels=("base_acceleration", "payload_acceleration",
                                         "relative_position"), workers=workers)
        for row, c in enumerate(missing):
            if batch.messages[row]:
                raise SimulationError(f"{labels[c]} diverged on the {duration:g} s probe at "
                                      f"dt = {dt0 / 2 ** j:.3g} s: {batch.messages[row]}")
            kept[c] = _ProbeRun(**{name: batch.channels[name][row] for name in
                                   ("base_acceleration", "payload_acceleration",
                                    "relative_position")},
                                run={"sample_rate": sample_rate})
        if bar is not None:
            bar.update(1)

    differences = {}

    def difference(j, c):
        if (j, c) not in differences:
            differences[j, c] = step_error(runs[j][c], runs[j + 1][c], measure, band=band,
                                           fft_length=fft_length)
        return differences[j, c]

    n = len(cases)
    labels = [f"case {c}" for c in range(n)] if labels is None else [str(x) for x in labels]
    if len(labels) != n:
        raise ParameterError(f"`labels` must name each of the {n} cases, got {len(labels)}.")
    searched, met, best, history, untrusted, hopeless = list(range(n)), {}, {}, [], [], []
    try:
        for j in range(max_halvings - 1):
            if not searched:
                break
            for level in (j, j + 1, j + 2):
                run(level, searched)
            pairs = {c: (difference(j, c), difference(j + 1, c)) for c in searched}
            untrusted += [c for c, (d, d_next) in pairs.items()
                          if not (np.isfinite(d) and np.isfinite(d_next))]
            estimates = {c: _estimate(d, d_next, order) for c, (d, d_next) in pairs.items()
                         if c not in untrusted}
            if estimates:
                history.append((dt0 / 2 ** j, max(pairs[c][0] for c in estimates),
                                max(estimates.values())))
            left = max_halvings - 2 - j  # candidates finer than dt_j still to compare
            for c, estimate in estimates.items():
                best[c] = min(best.get(c, math.inf), estimate)
                if safety * estimate <= tolerance:
                    met[c] = (j, estimate)
                elif safety * estimate > tolerance * 2.0 ** (order * left):
                    hopeless.append(c)  # even at the scheme's order no candidate left meets it
            searched = [c for c in searched
                        if c not in met and c not in untrusted and c not in hopeless]
    finally:
        if bar is not None:
            bar.close()
    unit = MEASURE_UNITS[measure]
    if not met:
        raise ToleranceNotMetError(tolerance, unit, dt0 / 2 ** (max_halvings - 1),
                                   min(best.values(), default=math.inf), safety)
    j = max(level for level, _ in met.values())
    deciding = min(c for c, (level, _) in met.items() if level == j)
    notes += _order_notes(differences[j, deciding], differences[j + 1, deciding], order)
    unmet = tuple(sorted(set(range(n)) - set(met)))
    failed = sorted(searched + hopeless)
    if failed:
        notes.append(
            f"{'; '.join(labels[c] for c in failed)}: no step down to "
            f"{dt0 / 2 ** (max_halvings - 2):.3g} s meets {tolerance:g} {unit} (best estimate "
            + ", ".join(f"{best.get(c, math.inf):.2g} {unit}" for c in failed)
            + "; an estimate that even the scheme's order could not bring within the tolerance "
            "by the finest candidate ends the search early): their response depends on the step "
            "(stop contacts or a stick-slip pattern each refinement redraws); the step is the "
            "other cases'")
    if untrusted:
        notes.append(f"{'; '.join(labels[c] for c in sorted(set(untrusted)))}: no bin of "
                     f"the band ({band[0]:g}, {band[1]:g}) Hz is trusted on the {duration:g} s "
                     "probe, so no error is measured; the step is the other cases'")
    case_errors = tuple(float(met[c][1]) if c in met else
                        (math.nan if c in untrusted else math.inf) for c in range(n))
    case_steps = tuple(dt0 / 2 ** met[c][0] if c in met else math.nan for c in range(n))
    return BatchStepChoice(
        dt=dt0 / 2 ** j, error=float(max(e for _, e in met.values())), measure=measure,
        tolerance=tolerance, reference_dt=dt0 / 2 ** (j + 2), stability_limit=float(limit),
        sample_rate=sample_rate, solver=solver, probe=probe, probe_duration=float(duration),
        band=band, history=tuple(history), notes=tuple(notes), case_errors=case_errors,
        case_steps=case_steps, unmet=unmet)
