"""One case of a study: its inputs, its run (alone or in a lockstep batch), its analysis.

A :class:`StudyCase` is resolved by :func:`qzs.workflows.paper.studies.plan_studies` (its
step chosen) and run here: simulated (:func:`run_case` alone, :func:`run_lockstep` with the
cases that share its chirp and step), reduced to its transmissibility curve over the trusted
bins, its metrics and statistics (:class:`CaseResult`); the spring's characteristic is
measured and fitted instead (docs/model.md §3.1, §10).
"""
import dataclasses
import time
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from qzs.analysis.linear import linearize
from qzs.analysis.spectral import (band_mask, highpass, required_duration, transmissibility,
                                   transmissibility_metrics)
from qzs.analysis.statistics import run_statistics
from qzs.defaults import REPORTED_FREQUENCIES, SIMULATION
from qzs.engine.simulate import simulate
from qzs.identify.spring import fit_spring
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp
from qzs.model.isolator import IsolatorParameters, spring_force
from qzs.model.registry import law_parameters, parameter_value, update_parameters
from qzs.model.springs import PolynomialSpring

__all__ = ["StudyCase", "CaseResult", "RUN_UNITS", "STATS_UNITS", "run_case", "case_inputs",
           "lockstep_key", "run_lockstep"]

#: The unit of each entry of :attr:`CaseResult.run` (None: a word, no unit; "1": a count or
#: a ratio).
RUN_UNITS = MappingProxyType({
    "solver": None, "dt": "s", "sample_rate": "Hz", "chirp_amplitude": "m", "chirp_f0": "Hz",
    "chirp_f1": "Hz", "chirp_duration": "s", "window": None, "fft_length": "1",
    "n_averages": "1", "overlap": "1", "coherence_min": "1", "base_share_min": "1"})
#: The unit of each entry of :attr:`CaseResult.stats`.
STATS_UNITS = MappingProxyType({
    "stop_contacts": "1", "z_min": "m", "z_max": "m", "z_final": "m", "locked_fraction": "1",
    "motor_force_rms": "N", "duration": "s", "steps": "1", "n_averages": "1",
    "fft_length": "1", "steps_per_second": "1/s", "locked_fraction_below_half_hz": "1"})

@dataclass(frozen=True, kw_only=True)
class StudyCase:
    """One case of a study, resolved: everything a worker needs to run it (picklable).

    Attributes
    ----------
    kind : {"transmissibility", "processing", "spring_characteristic"}
        Its study's kind.
    label : str
        The case's label.
    settings : dict
        Its parameter overrides (registry names -> values), the study's defaults included.
    excitation : dict
        The chirp's options (``[excitation]``; ``duration`` [s] optional).
    analysis : dict
        :data:`qzs.defaults.ANALYSIS` with the study's overrides and the quick run's
        ``fft_length`` [samples] and ``n_averages``.
    solver : str
        The integration scheme.
    dt : float or None
        Integration step [s]; None until chosen (:func:`plan_studies`).
    step_source : {"chosen", "given", "file"}
        Where the step comes from.
    options : dict
        The study's ``[spring]`` and ``[processing]`` tables.
    spring : SpringLaw or None
        The isolator's spring law; None: the MagSpring's tanh.
    """

    kind: str
    label: str
    settings: dict
    excitation: dict = field(default_factory=dict)
    analysis: dict = field(default_factory=dict)
    solver: str = SIMULATION["solver"]
    dt: float | None = None
    step_source: str = "chosen"
    options: dict = field(default_factory=dict)
    spring: Any = None

    @property
    def simulated(self):
        """Whether the case is simulated (every kind but the spring's characteristic)."""
        return self.kind != "spring_characteristic"


@dataclass
class CaseResult:
    """What one case of a study produced (small: safe to send between processes).

    Attributes
    ----------
    label : str
        The case's label.
    settings : dict
        Its parameter overrides (registry names -> values), defaults included.
    frequency : ndarray
        Frequencies of the transmissibility curve over the analysed band [Hz].
    magnitude : ndarray
        Transmissibility, amplitude ratio [-], at ``frequency``.
    phase : ndarray
        Phase of payload relative to base [rad] (of the cross spectrum), at ``frequency``.
    coherence : ndarray
        Magnitude-squared coherence [-] at ``frequency``.
    trusted : ndarray of bool
        The bins of ``frequency`` metrics may use
        (:attr:`TransmissibilityEstimate.trusted <qzs.analysis.spectral.TransmissibilityEstimate>`).
    metrics : dict
        Metrics of the trusted bins (:meth:`TransmissibilityMetrics.to_dict
        <qzs.analysis.spectral.TransmissibilityMetrics.to_dict>`), NaN where undefined; for
        the spring study, the fitted ``spring_force`` and ``spring_shape``.
    reasons : dict
        For each NaN metric, why it is undefined.
    stats : dict
        Run statistics (stop contacts, stroke, time locked, Welch settings, speed); units
        in :data:`STATS_UNITS`.
    run : dict
        How the case was run and analysed: ``solver``, ``dt`` [s], ``sample_rate`` [Hz],
        the chirp's ``chirp_amplitude`` [m], ``chirp_f0``, ``chirp_f1`` [Hz] and
        ``chirp_duration`` [s], ``window``, ``fft_length`` [samples], ``n_averages``,
        ``overlap`` [-], ``coherence_min`` and ``base_share_min`` [-] (:data:`RUN_UNITS`).
    linear : dict
        The linearised model: natural frequencies [Hz], damping ratio [-] and its
        ``magnitude`` at ``frequency``.
    extra : dict
        What the kind adds: the experiment-style curve with its coherence, trusted
        bins, metrics and reasons (``processing``), or the spring's data and fit
        (``spring_characteristic``).
    seconds : float
        Time spent on the case [s].
    """

    label: str
    settings: dict
    frequency: np.ndarray | None = None
    magnitude: np.ndarray | None = None
    coherence: np.ndarray | None = None
    trusted: np.ndarray | None = None
    metrics: dict = field(default_factory=dict)
    reasons: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)
    run: dict = field(default_factory=dict)
    linear: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)
    seconds: float = 0.0
    phase: np.ndarray | None = None


def run_case(case):
    """Run one :class:`StudyCase` (its step chosen); top-level so process pools can call it.

    Parameters
    ----------
    case : StudyCase
        A simulated case with its step.

    Returns
    -------
    CaseResult
    """
    start = time.perf_counter()
    if not case.simulated:
        result = _spring_case(case)
    else:
        result = _transmissibility_case(case)
    result.seconds = time.perf_counter() - start
    return result


def case_inputs(case):
    """``(isolator, controller, excitation, sample rate [Hz])`` of a simulated case.

    Parameters
    ----------
    case : StudyCase
        A simulated case.

    Returns
    -------
    tuple
    """
    analysis = case.analysis
    isolator, controller = update_parameters(IsolatorParameters(spring=case.spring),
                                             ControllerParameters(), case.settings)
    rate = analysis["sample_rate"]
    duration = case.excitation.get("duration") or required_duration(
        analysis["fft_length"], analysis["n_averages"], rate, analysis["overlap"])
    excitation = Chirp(**{k: v for k, v in case.excitation.items() if k != "duration"},
                       duration=duration)
    return isolator, controller, excitation, rate


def _transmissibility_case(case):
    isolator, controller, excitation, rate = case_inputs(case)
    run = simulate(excitation, isolator, controller, sample_rate=rate, dt=case.dt,
                   solver=case.solver)
    return _analyse_case(case, run, isolator, controller, excitation, rate)


def _analyse_case(case, run, isolator, controller, excitation, rate):
    """A case's curve, metrics and statistics from its run (a single or a lockstep run)."""
    analysis = case.analysis
    duration = excitation.duration
    welch = dict(fft_length=analysis["fft_length"], overlap=analysis["overlap"],
                 coherence_min=analysis["coherence_min"],
                 base_share_min=analysis["base_share_min"],
                 highpass_factor=analysis["highpass_factor"])
    estimate = transmissibility(run.base_acceleration, run.payload_acceleration, rate, **welch)
    low, high = analysis["band"]
    keep = band_mask(estimate.frequency, low, high)
    frequency = estimate.frequency[keep]
    magnitude = estimate.magnitude[keep]
    result = CaseResult(case.label, case.settings, frequency, magnitude,
                        estimate.coherence[keep], estimate.trusted[keep],
                        phase=estimate.phase[keep])
    result.metrics, result.reasons = _metrics(estimate, keep)
    result.run = dict(solver=case.solver, dt=float(case.dt),
                      sample_rate=float(rate), chirp_amplitude=excitation.amplitude,
                      chirp_f0=excitation.f0, chirp_f1=excitation.f1,
                      chirp_duration=float(duration), window="hann",
                      fft_length=estimate.fft_length, n_averages=estimate.n_averages,
                      overlap=float(analysis["overlap"]),
                      coherence_min=estimate.coherence_min,
                      base_share_min=estimate.base_share_min)
    z = run.relative_position
    statistics = run_statistics(z, run.motor_force, run.locked,
                                0.5 * (run.run["stop_low"] + run.run["stop_high"]))
    result.stats = dict(stop_contacts=run.run["stop_contacts"], z_min=statistics["z_min"],
                        z_max=statistics["z_max"], z_final=float(z[-1]),
                        locked_fraction=statistics["locked_fraction"],
                        motor_force_rms=statistics["motor_force_rms"],
                        duration=float(duration), steps=run.run["steps"],
                        n_averages=estimate.n_averages, fft_length=estimate.fft_length,
                        steps_per_second=run.steps_per_second,
                        locked_fraction_below_half_hz=_locked_below(run, excitation, 0.5))
    model = linearize(isolator, controller)
    result.linear = dict(undamped_natural_frequency=model.undamped_natural_frequency,
                         natural_frequency=model.natural_frequency,
                         damping_ratio=model.damping_ratio,
                         magnitude=model.transmissibility(frequency))
    if case.kind == "processing":
        result.extra = _experiment_processing(run, rate, welch, case.options, (low, high))
    return result


#: What a lockstep case keeps of its run: the series :func:`_analyse_case` reads (the time is
#: the batch's, one array for every case: the kernel's own time channel, step times dt).
_LOCKSTEP_CHANNELS = ("base_acceleration", "payload_acceleration", "relative_position",
                      "motor_force", "locked")
#: And, for a ``processing`` case, the velocities the experiment measured.
_PROCESSING_CHANNELS = ("base_velocity", "payload_velocity")


@dataclass(frozen=True)
class _LockstepRun:
    """One case of a lockstep batch, with the parts of a SimulationResult the analysis reads."""

    time: np.ndarray
    base_acceleration: np.ndarray
    payload_acceleration: np.ndarray
    relative_position: np.ndarray
    motor_force: np.ndarray
    locked: np.ndarray
    base_velocity: np.ndarray
    payload_velocity: np.ndarray
    run: dict
    steps_per_second: float


def lockstep_key(case):
    """Cases with equal keys share every step of their runs: same chirp, rate, step, solver.

    Parameters
    ----------
    case : StudyCase
        A simulated case with its step.

    Returns
    -------
    tuple
    """
    _, _, excitation, rate = case_inputs(case)
    return excitation, float(rate), float(case.dt), case.solver


def run_lockstep(cases, workers, progress):
    """Simulate cases that share their excitation and step through the lockstep batch kernel.

    The batch kernel gives every case the numbers :func:`qzs.simulate` gives it, to
    the last bit (:mod:`qzs.engine.lanes`), so the curves and metrics are those of
    the one-case path. The cases' analyses run in ``workers`` threads.

    Parameters
    ----------
    cases : list of StudyCase
        Cases with equal :func:`lockstep_key`.
    workers : int
        Threads for the kernel and the analyses.
    progress : bool
        Show the batch's progress bar over simulated time.

    Returns
    -------
    list of CaseResult
        In the order of ``cases``.
    """
    from concurrent.futures import ThreadPoolExecutor

    from qzs.engine.batch import simulate_batch
    from qzs.errors import SimulationError

    inputs = [case_inputs(case) for case in cases]
    _, _, excitation, rate = inputs[0]
    channels = _LOCKSTEP_CHANNELS
    if any(case.kind == "processing" for case in cases):
        channels += _PROCESSING_CHANNELS
    # cases with equal parameters in several studies (the paper's Table 1 case with the
    # passive gains is in three) are one run: integrated once, analysed per case
    index = {}
    run_of = [index.setdefault((isolator, controller), len(index))
              for isolator, controller, _, _ in inputs]
    distinct = list(index)
    batch = simulate_batch(distinct, excitation, dt=cases[0].dt, solver=cases[0].solver,
                           sample_rate=rate, channels=channels, workers=workers,
                           progress=progress)
    for case, b in zip(cases, run_of):
        if batch.messages[b]:
            raise SimulationError(f"{case.label}: {batch.messages[b]}")
    share = batch.elapsed / len(cases)

    def analyse(c):
        start = time.perf_counter()
        isolator, controller, _, _ = inputs[c]
        b = run_of[c]
        series = {name: batch.channels[name][b] if name in batch.channels else None
                  for name in (*_LOCKSTEP_CHANNELS, *_PROCESSING_CHANNELS)}
        run = _LockstepRun(time=batch.time, **series, steps_per_second=batch.steps_per_second,
                           run=dict(stop_low=float(batch.stop_limits[b, 0]),
                                    stop_high=float(batch.stop_limits[b, 1]),
                                    stop_contacts=int(batch.stats["stop_contacts"][b]),
                                    steps=int(batch.stats["steps"][b])))
        result = _analyse_case(cases[c], run, isolator, controller, excitation, rate)
        result.seconds = share + time.perf_counter() - start
        return result

    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(analyse, range(len(cases))))


def _locked_below(run, chirp, frequency):
    """Fraction of the time the payload is locked while the chirp is below ``frequency`` [Hz]."""
    below = chirp.frequency_at(run.time) < frequency
    return float(run.locked[below].mean()) if below.any() else float("nan")


def _experiment_processing(run, rate, welch, options, band):
    """Velocities through the charge amplifier's high-pass, as the experiment measured them."""
    corner = float(options.get("highpass", 1.0))
    base_velocity = highpass(run.base_velocity, corner, rate)
    payload_velocity = highpass(run.payload_velocity, corner, rate)
    estimate = transmissibility(base_velocity, payload_velocity, rate, highpass_corner=corner,
                                **welch)
    keep = band_mask(estimate.frequency, *band)
    metrics, reasons = _metrics(estimate, keep)
    return dict(frequency=estimate.frequency[keep], magnitude=estimate.magnitude[keep],
                phase=estimate.phase[keep], coherence=estimate.coherence[keep],
                trusted=estimate.trusted[keep],
                metrics=metrics, reasons=reasons, highpass=corner,
                untrusted_below=estimate.untrusted_below, n_averages=estimate.n_averages)


def _metrics(estimate, keep):
    """Metrics of the estimate's trusted bins within ``keep``: (values, reasons) dicts."""
    metrics = transmissibility_metrics(estimate.frequency[keep], estimate.magnitude[keep],
                                       trusted=estimate.trusted[keep],
                                       at_frequencies=REPORTED_FREQUENCIES,
                                       highpass_corner=estimate.highpass_corner,
                                       untrusted_factor=estimate.highpass_factor)
    values = metrics.to_dict()
    values["trusted_from"], values["trusted_to"] = metrics.trusted_range
    return values, dict(metrics.reasons)


def _spring_case(case):
    """The spring's characteristic: the law measured with noise, and fitted.

    The MagSpring (the paper's Fig. 5): its tanh fitted, ``spring_force`` and
    ``spring_shape``. Another law (``case.spring``, docs/model.md §3.1): measured the
    same way (noise a share of the MagSpring's plateau force) and fitted as its own kind
    (:func:`qzs.identify.fit_spring`; a polynomial of its degree about its centre), its
    fitted parameters by their registry names
    (``spring.<field>``) and the fit's RMS residual.
    """
    options = case.options
    truth = IsolatorParameters()
    law = case.spring
    rng = np.random.default_rng(int(options.get("seed", 5)))
    z = np.linspace(options.get("displacement_min", -0.1), options.get("displacement_max", 0.1),
                    int(options.get("points", 41)))
    force = spring_force(z, truth) if law is None else law.force(z)
    measured = force + rng.normal(0.0, float(options.get("noise", 0.01)) * truth.spring_force,
                                  z.size)
    if law is None:
        fit = fit_spring(z, measured)
        result = CaseResult("MagSpring", {})
        result.extra = dict(displacement=z, force=measured, fit=dataclasses.asdict(fit),
                            true_force_amplitude=truth.spring_force,
                            true_shape=truth.spring_shape)
        result.metrics = {"spring_force": fit.spring_force, "spring_shape": fit.spring_shape}
        return result
    shape = ({"degree": max(law.coefficients.size - 1, 1), "center": law.center}
             if isinstance(law, PolynomialSpring) else {})  # its own powers, about its centre
    fit = fit_spring(z, measured, law=law.kind, **shape)
    result = CaseResult(law.kind, {})
    result.extra = dict(displacement=z, force=measured, law_fit=fit, true_law=law)
    result.metrics = {"spring_residual_rms": fit.residual_rms}
    if fit.kind == "tanh":  # another MagSpring: its a and b, as the paper's
        result.metrics.update(spring_force=fit.spring_force, spring_shape=fit.spring_shape)
    elif fit.law is not None:  # else fit.undefined["law"] says why (the report shows it)
        fitted = IsolatorParameters(spring=fit.law)
        result.metrics.update({name: parameter_value(fitted, None, name)
                               for name in law_parameters(fit.law)})
    return result
