"""One accuracy-driven step for many cases at once: the step of a lockstep batch (docs/model.md §7).

:func:`choose_batch_step` is :func:`qzs.engine.accuracy.choose_step`'s search (the same probe,
measure, candidates and Richardson estimate) with every case probed at once, each candidate
one lockstep batch of the cases still searched; the paper's studies and sweeps take their
step from it.
"""
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qzs import defaults
from qzs.engine.accuracy import probe_settings, shortened_chirp, step_error
from qzs.engine.step_choice import ProbeSettings, admissible_step
from qzs.engine.step_search import SAFETY, StepChoice
from qzs.errors import ParameterError

__all__ = ["BATCH_MAX_HALVINGS", "BatchStepChoice", "choose_batch_step", "BatchProbe"]

#: The record of a batch's step: the one record, :class:`~qzs.engine.step_search.StepChoice`
#: (its ``case_errors``, ``case_steps`` and ``unmet`` filled in).
BatchStepChoice = StepChoice

#: Halvings :func:`choose_batch_step` tries at most by default: candidates down to
#: ``dt_0/8`` (125 us at a 1 kHz output, about the paper's 1e-4 s), compared with runs down
#: to ``dt_0/32``. A case no candidate meets is reported, and the step comes from the others.
BATCH_MAX_HALVINGS = 5


@dataclass(frozen=True)
class _ProbeRun:
    """The series :func:`step_error` reads, of one case of a batch probe run."""

    base_acceleration: np.ndarray
    payload_acceleration: np.ndarray
    relative_position: np.ndarray
    run: dict
    estimates: dict = field(default_factory=dict)  # fft length -> its transmissibility


def choose_batch_step(cases, excitation=None, *, tolerance=None, tolerance_state=None,
                      solver=defaults.SIMULATION["solver"],
                      sample_rate=defaults.SIMULATION["sample_rate"], band=None,
                      probe_duration=None, fft_length=None, max_halvings=BATCH_MAX_HALVINGS,
                      safety=SAFETY, finest=None, fallback=False, workers=None, progress=False,
                      labels=None, cache=False, tolerance_db=None):
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
    tolerance : float, optional
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
    finest : float, optional
        The finest candidate [s]; the fallback step too.
    fallback : bool
        Where no candidate meets the tolerance for any case, return the one fallback of
        :func:`~qzs.engine.step_search.search_step` instead of raising.
    workers : int, optional
        Threads of the batch kernel; default all cores.
    progress : bool
        Show a progress bar over the probe batches.
    labels : sequence of str, optional
        Names of the cases in the notes; default ``case 0``, ``case 1``, ...
    cache : bool
        Read the choice from, and keep it in, the step cache on disk
        (:mod:`qzs.engine.step_cache`, keyed by every input above but ``workers`` and
        ``progress``, which change no bit of it, and by the code that chooses): a repeated
        ``qzs paper`` skips its probes (1.2 s of the paper's 12 s). The studies and sweeps
        use it.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

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
    from qzs.engine.step_choice import choose, step_request

    request = step_request(tolerance=tolerance, tolerance_state=tolerance_state,
                           tolerance_db=tolerance_db, required=True)
    return choose(request, BatchProbe(
        cases=cases, excitation=excitation, solver=solver, sample_rate=sample_rate, band=band,
        probe_duration=probe_duration, fft_length=fft_length, max_halvings=max_halvings,
        safety=safety, workers=workers, labels=labels),
        fallback=fallback, finest=finest, progress=progress, cache=cache)


@dataclass(frozen=True, kw_only=True)
class BatchProbe(ProbeSettings):
    """The probe of a lockstep batch: the inputs of :func:`choose_batch_step` but the
    tolerance; nothing computed until :func:`qzs.engine.step_choice.choose` calls
    :meth:`build` for a chosen step.

    Attributes
    ----------
    cases : sequence of (IsolatorParameters, ControllerParameters)
        The lanes sharing the step.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord or None
        Their shared excitation (None: the paper's chirp).
    solver : str
        The integrator.
    sample_rate : float
        Output rate [Hz] of the run the step is for.
    band : tuple of float or None
        Band [Hz] of the transmissibility measure (None: the excitation's).
    probe_duration : float or None
        Length of the probe [s] (None: the default).
    fft_length : int or None
        Welch segment length [samples] of the probe's transmissibility.
    max_halvings : int
        Halvings of the admissible start tried at most [-].
    safety : float
        Factor [-] between the estimate and the tolerance.
    workers : int or None
        Threads of the batch kernel (None: all cores).
    labels : sequence of str or None
        The cases' names in the notes.
    """

    cases: Any
    fft_length: int | None = None
    max_halvings: int = BATCH_MAX_HALVINGS
    workers: int | None = None
    labels: Any = None

    def _build(self, measure):
        from qzs.engine.prepare import run_inputs
        from qzs.engine.step_choice import Probe

        cases = [run_inputs(None, *pair)[1:] for pair in self.cases]
        if not cases:
            raise ParameterError("`cases` must hold at least one (isolator, controller) pair.")
        excitation = run_inputs(self.excitation)[0]
        order, sample_rate, band, probe, duration = probe_settings(
            excitation, measure, self.solver, self.sample_rate, self.band, self.probe_duration,
            self.fft_length, self.safety, self.max_halvings)
        n = len(cases)
        labels = ([f"case {c}" for c in range(n)] if self.labels is None
                  else [str(x) for x in self.labels])
        fft_length = self.fft_length
        return Probe(
            measure=measure, order=order, sample_rate=sample_rate, solver=self.solver,
            excitation=probe, duration=duration, band=band,
            shortened=shortened_chirp(excitation, duration, sample_rate),
            start=lambda: _batch_start(cases, probe, duration, self.solver, sample_rate),
            run=_batch_run(cases, probe, duration, sample_rate, self.solver, self.workers,
                           labels),
            compare=lambda coarse, fine: step_error(coarse, fine, measure, band=band,
                                                    fft_length=fft_length),
            cases=n, labels=labels,
            key=dict(batch=True, cases=cases, excitation=excitation, solver=self.solver,
                     sample_rate=sample_rate, band=band, probe_duration=self.probe_duration,
                     fft_length=fft_length, labels=labels),
            max_halvings=self.max_halvings, safety=self.safety,
            search=dict(give_up_early=True, per_case=True, unit_name="batch"))


def _batch_start(cases, probe, duration, solver, sample_rate):
    """The batch's stability limit, resolving step and admissible start (``Probe.start``):
    the largest step admissible for every case."""
    from qzs.engine.prepare import divides, resolving_step
    from qzs.engine.stability import largest_stable_step, stability_test

    tests = [stability_test(isolator, controller, solver) for isolator, controller in cases]
    limit = min(largest_stable_step(isolator, controller, solver)
                for isolator, controller in cases)
    resolving = resolving_step(probe, duration)
    rates = sorted({rate for _, controller in cases for rate in controller.sample_rates}
                   or {0.0})

    def stable(dt):
        return dt <= resolving and all(test(dt) for test in tests)

    def divides_all(dt):  # several sampled controllers: each period a whole number of steps
        return all(divides(rate, dt) for rate in rates if rate > 0)

    if len(rates) == 1:
        dt0, k0 = admissible_step(sample_rate, rates[0], stable)
    else:
        dt0, k0 = admissible_step(sample_rate, 0.0, lambda dt: stable(dt) and divides_all(dt))
    return limit, resolving, dt0, k0


def _batch_run(cases, probe, duration, sample_rate, solver, workers, labels):
    """``Probe.run`` of a batch: one lockstep batch of the listed cases at a step."""
    from qzs.engine.batch import simulate_batch
    from qzs.errors import SimulationError

    names = ("base_acceleration", "payload_acceleration", "relative_position")

    def run(dt, members):
        batch = simulate_batch([cases[c] for c in members], probe, duration=duration, dt=dt,
                               sample_rate=sample_rate, solver=solver, channels=names,
                               workers=workers)
        for row, c in enumerate(members):
            if batch.messages[row]:
                raise SimulationError(f"{labels[c]} diverged on the {duration:g} s probe at "
                                      f"dt = {dt:.3g} s: {batch.messages[row]}")
        return [_ProbeRun(**{name: batch.channels[name][row] for name in names},
                          run={"sample_rate": sample_rate}) for row in range(len(members))]

    return run
