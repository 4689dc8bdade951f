"""The paper's numerical studies as declarative TOML definitions, and their runner.

A study file has a ``[study]`` table (name, title, kind, claims, views), optional
``[defaults]`` parameter overrides shared by its cases, ``[[case]]`` tables (a
``label`` and parameter overrides (names of ``qzs params``)), and optional ``[excitation]``,
``[analysis]`` and ``[simulation]`` tables. The shipped files live in
``qzs/workflows/paper/study_files/*.toml``: copy one, edit it, run it with ``qzs study FILE.toml``.

Kinds:

``transmissibility``
    Each case: a constant-amplitude chirp sized for the wanted Welch averages,
    simulated, reduced to its transmissibility curve and metrics.
``processing``
    As above, and also processed like the experiment: velocities through the
    charge amplifier's high-pass, the experiment's averages.
``spring_characteristic``
    The MagSpring's static characteristic and its tanh fit (no simulation).

``[study] claims`` names, by id, the paper's claims the study's cases decide (the keys of
:data:`CLAIMS`; docs/model.md §13); an unknown id is an error. Each curve keeps which of
its bins are trusted (docs/model.md §10), and every metric comes from those bins only.

The integration step: a ``[simulation] dt`` in the file, or ``dt`` given to
:func:`run_studies` (``qzs paper --dt``), is used as it is; otherwise the cases that share
an excitation get one step, the coarsest that keeps every one's transmissibility within
``tolerance`` (default :data:`qzs.defaults.ACCURACY`), chosen by
:func:`qzs.engine.accuracy_batch.choose_batch_step` on one lockstep probe of them all
(docs/model.md §7).
"""
import dataclasses
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from qzs._validation import known_keys, read_toml, worker_count
from qzs.analysis.linear import linearize
from qzs.analysis.spectral import (band_mask, highpass, required_duration, transmissibility,
                                   transmissibility_metrics)
from qzs.analysis.statistics import run_statistics
from qzs.defaults import ANALYSIS, FREQUENCY_SCALES, REPORTED_FREQUENCIES, SIMULATION
from qzs.engine.simulate import simulate
from qzs.errors import ParameterError
from qzs.identify.spring import fit_spring
from qzs.iotools.shipped import resolve_shipped, shipped_files
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import EXCITATION_OPTIONS, Chirp
from qzs.model.isolator import IsolatorParameters, spring_force
from qzs.model.springs import PolynomialSpring
from qzs.model.registry import law_parameters, parameter_value, update_parameters

__all__ = ["CLAIMS", "Study", "StudyResult", "CaseResult", "load_study", "shipped_studies",
           "run_studies", "run_study", "RUN_UNITS", "STATS_UNITS", "column_unit"]

KINDS = ("transmissibility", "processing", "spring_characteristic")
#: Folder of the shipped study files, inside the package.
SHIPPED = "workflows/paper/study_files"
#: The paper's claims a study may name in ``[study] claims``, by id: what the paper states
#: (docs/model.md §13). :data:`qzs.workflows.paper.report.CLAIMS` decides each from the cases of
#: the studies that name it.
CLAIMS = MappingProxyType({
    "resonance_masked": "Passive resonance about 0.08 Hz, masked by stiction.",
    "pi_resonance_range": "PI moves the resonance within 0.08-0.45 Hz.",
    "stiction_low_frequency": "More stiction: higher transmissibility at low frequency, "
                              "narrower isolation band.",
    "viscous_high_frequency": "Above about 3 Hz the viscous friction governs: more Cv, "
                              "higher transmissibility.",
    "pi_low_frequency": "High PI gains spoil low-frequency isolation; gains should be just "
                        "high enough to hold z.",
    "no_pi_stops": "Without the PI loop the payload drifts to the hard stops (Section 4.1).",
    "damping_small_effect": "Active damping did not help much.",
    "experiment_shape": "Experiment: resonance peaks below 3.5 Hz, roll-off from 4 Hz, "
                        "transmissibility 0.3 at 12 Hz.",
})
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
# Keys of the optional tables (the sample rate is the analysis's).
_TABLE_KEYS = {"excitation": EXCITATION_OPTIONS["chirp"], "analysis": (*ANALYSIS, "duration"),
               "simulation": ("dt", "solver")}


@dataclass(frozen=True)
class Study:
    """A study definition (see the module docstring for the TOML layout).

    Attributes
    ----------
    name : str
        Short name (``[study] name``), used to find its results and claims.
    title : str
        Title of its figures; default the name.
    kind : {"transmissibility", "processing", "spring_characteristic"}
        What each case computes (see the module docstring).
    cases : tuple of dict
        The ``[[case]]`` tables: a ``label`` and parameter overrides.
    claims : tuple of str
        Ids of the paper's claims its cases decide (keys of :data:`CLAIMS`).
    views : tuple of dict
        Figures to draw: ``figure`` (file stem), ``frequency_range`` [Hz] and
        optionally ``frequency_scale`` (``"log"``, the default, or ``"linear"``).
    defaults : dict
        Parameter overrides shared by every case (``[defaults]``).
    excitation : dict
        Options of the chirp (``[excitation]``).
    analysis : dict
        Overrides of :data:`qzs.defaults.ANALYSIS`, and ``duration`` (``[analysis]``).
    simulation : dict
        ``dt`` and ``solver`` (``[simulation]``).
    options : dict
        The ``[spring]`` and ``[processing]`` tables, merged.
    source : str
        The file it was read from.
    """

    name: str
    title: str
    kind: str
    cases: tuple
    claims: tuple = ()
    views: tuple = ()
    defaults: dict = field(default_factory=dict)
    excitation: dict = field(default_factory=dict)
    analysis: dict = field(default_factory=dict)
    simulation: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    source: str = ""


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


@dataclass
class StudyResult:
    """The cases of one study, in definition order, and the wall time spent on them.

    Attributes
    ----------
    study : Study
        The definition run.
    cases : list of CaseResult
        Its cases, in definition order.
    quick : bool
        Whether the runs were the quick ones.
    seconds : float
        Time spent on its cases [s], summed over them (they may run in parallel).
    step : dict
        How the integration step was set (:func:`_step_record`): ``dt`` [s], ``source``
        (``"chosen"``, ``"given"``, ``"file"``, or ``"fallback"``: no step met the tolerance
        for any case of the batch, which runs at the paper's dt = 1e-4 s, with ``unmet``,
        ``notes`` and ``tolerance_db``) and, for a chosen step, ``tolerance_db``,
        ``estimated_error_db`` (the largest over the cases that met it), ``reference_dt``
        [s], ``probe_duration`` [s], ``unmet`` (labels of the cases no step met: their
        response depends on the step), ``notes``, ``seconds`` (time of the choice) [s] and
        ``group`` (studies with equal numbers share the choice).
    spring : SpringLaw or None
        The spring law every case ran (docs/model.md §3.1); None: the MagSpring's tanh.
    """

    study: Study
    cases: list
    quick: bool
    seconds: float = 0.0
    step: dict = field(default_factory=dict)
    spring: Any = None


def shipped_studies():
    """Paths of the study definitions shipped with qzs, in the paper's order."""
    return shipped_files(SHIPPED)


def load_study(path):
    """Read and validate a study definition (a path, or the name of a shipped study).

    Parameters
    ----------
    path : str or Path
        A study file, or the name of a shipped one (e.g. ``"stiction"``).

    Returns
    -------
    Study

    Raises
    ------
    ParameterError
        Missing file, unknown table or key, bad kind, no case, an invalid parameter, or
        an unknown claim id.
    """
    path = resolve_shipped(path, SHIPPED, "study", "studies")
    document = read_toml(path, "study file", empty=(
        "write the study's tables into it (copy a shipped study file of "
        "qzs/workflows/paper/study_files and edit it)"))
    allowed = {"study", "defaults", "case", "excitation", "analysis", "simulation", "spring",
               "processing"}
    unknown = set(document) - allowed
    if unknown:
        raise ParameterError(f"{str(path)!r}: unknown table(s) {sorted(unknown)}; allowed are "
                             f"{sorted(allowed)}.")
    head = document.get("study")
    if not isinstance(head, dict) or "name" not in head or "kind" not in head:
        raise ParameterError(f"{str(path)!r} needs a [study] table with `name` and `kind`.")
    kind = head["kind"]
    if kind not in KINDS:
        raise ParameterError(f"{str(path)!r}: `kind` must be one of {KINDS}, got {kind!r}.")
    cases = tuple(document.get("case", ()))
    if kind != "spring_characteristic" and not cases:
        raise ParameterError(f"{str(path)!r} defines no [[case]]; add at least one.")
    defaults = dict(document.get("defaults", {}))
    for i, case in enumerate(cases):
        settings = {k: v for k, v in case.items() if k != "label"}
        try:  # validate every case now, not in a worker later
            update_parameters(IsolatorParameters(), ControllerParameters(),
                              {**defaults, **settings})
        except ParameterError as error:
            raise ParameterError(f"{str(path)!r}, case {i + 1}: {error}") from None
    for table, keys in _TABLE_KEYS.items():
        known_keys(document.get(table, {}), keys, f"[{table}]", f"{str(path)!r}: ")
    claims = head.get("claims", [])
    if not isinstance(claims, list) or not all(isinstance(c, str) for c in claims):
        raise ParameterError(f"{str(path)!r}: [study] `claims` must be a list of claim ids, "
                             f"got {claims!r}; known ids are {sorted(CLAIMS)}.")
    for claim in claims:
        if claim not in CLAIMS:
            raise ParameterError(f"{str(path)!r}: unknown claim id {claim!r} in [study] claims; "
                                 f"known ids are {sorted(CLAIMS)}.")
    views = tuple(head.get("view", ()))
    for view in views:
        scale = view.get("frequency_scale")
        if scale is not None and scale not in FREQUENCY_SCALES:
            raise ParameterError(f"{str(path)!r}: [[study.view]] {view.get('figure')!r} has "
                                 f"frequency_scale = {scale!r}; use one of "
                                 f"{', '.join(FREQUENCY_SCALES)} or leave it out (log).")
    options = {**document.get("spring", {}), **document.get("processing", {})}
    return Study(name=head["name"], title=head.get("title", head["name"]), kind=kind,
                 cases=cases, claims=tuple(claims), views=views,
                 defaults=defaults, excitation=dict(document.get("excitation", {})),
                 analysis=dict(document.get("analysis", {})),
                 simulation=dict(document.get("simulation", {})), options=options,
                 source=str(path))


def _tasks(study, quick, dt=None, spring=None):
    """One picklable task per case: everything a worker needs to run it (``dt`` None: the
    file's, else chosen later by :func:`_choose_steps`; ``spring`` the isolator's law, None
    for the MagSpring's tanh)."""
    analysis = {**ANALYSIS, **study.analysis}
    if quick:
        analysis["fft_length"] = analysis["quick_fft_length"]
        analysis["n_averages"] = min(analysis["n_averages"], analysis["quick_n_averages"])
    if study.kind == "processing":
        analysis["n_averages"] = int(study.options.get("n_averages", analysis["n_averages"]))
        if quick:
            analysis["n_averages"] = min(analysis["n_averages"], analysis["quick_n_averages"])
    if study.kind == "spring_characteristic":
        return [dict(kind=study.kind, label="MagSpring" if spring is None else spring.kind,
                     settings={}, options=study.options, spring=spring)]
    return [dict(kind=study.kind, label=case.get("label", f"case {i + 1}"),
                 settings={**study.defaults, **{k: v for k, v in case.items() if k != "label"}},
                 excitation=dict(study.excitation), analysis=analysis,
                 simulation={"dt": None, "solver": SIMULATION["solver"], **study.simulation,
                             **({} if dt is None else {"dt": dt})},
                 step_source="given" if dt is not None else
                 ("file" if "dt" in study.simulation else "chosen"), options=study.options,
                 spring=spring)
            for i, case in enumerate(study.cases)]


def run_case(task):
    """Run one case (a task from :func:`_tasks`); top-level so process pools can call it."""
    start = time.perf_counter()
    if task["kind"] == "spring_characteristic":
        result = _spring_case(task)
    else:
        result = _transmissibility_case(task)
    result.seconds = time.perf_counter() - start
    return result


def _case_inputs(task):
    """``(isolator, controller, excitation, sample rate [Hz])`` of a simulated case."""
    analysis = task["analysis"]
    isolator, controller = update_parameters(IsolatorParameters(spring=task["spring"]),
                                             ControllerParameters(), task["settings"])
    rate = analysis["sample_rate"]
    duration = task["excitation"].get("duration") or required_duration(
        analysis["fft_length"], analysis["n_averages"], rate, analysis["overlap"])
    excitation = Chirp(**{k: v for k, v in task["excitation"].items() if k != "duration"},
                       duration=duration)
    return isolator, controller, excitation, rate


def _transmissibility_case(task):
    isolator, controller, excitation, rate = _case_inputs(task)
    run = simulate(excitation, isolator, controller, sample_rate=rate, **task["simulation"])
    return _analyse_case(task, run, isolator, controller, excitation, rate)


def _analyse_case(task, run, isolator, controller, excitation, rate):
    """A case's curve, metrics and statistics from its run (a single or a lockstep run)."""
    analysis = task["analysis"]
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
    result = CaseResult(task["label"], task["settings"], frequency, magnitude,
                        estimate.coherence[keep], estimate.trusted[keep],
                        phase=estimate.phase[keep])
    result.metrics, result.reasons = _metrics(estimate, keep)
    result.run = dict(solver=task["simulation"]["solver"], dt=float(task["simulation"]["dt"]),
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
    if task["kind"] == "processing":
        result.extra = _experiment_processing(run, rate, welch, task["options"], (low, high))
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


def _lockstep_key(task):
    """Cases with equal keys share every step of their runs: same chirp, rate, step, solver."""
    _, _, excitation, rate = _case_inputs(task)
    return excitation, float(rate), float(task["simulation"]["dt"]), task["simulation"]["solver"]


def _run_lockstep(tasks, workers, progress):
    """Simulate cases that share their excitation and step through the lockstep batch kernel.

    The batch kernel gives every case the numbers :func:`qzs.simulate` gives it, to
    the last bit (:mod:`qzs.engine.lanes`), so the curves and metrics are those of
    the one-case path. The cases' analyses run in ``workers`` threads.

    Parameters
    ----------
    tasks : list of dict
        Tasks of :func:`_tasks` with equal :func:`_lockstep_key`.
    workers : int
        Threads for the kernel and the analyses.
    progress : bool
        Show the batch's progress bar over simulated time.

    Returns
    -------
    list of CaseResult
        In the order of ``tasks``.
    """
    from concurrent.futures import ThreadPoolExecutor

    from qzs.engine.batch import simulate_batch
    from qzs.errors import SimulationError

    inputs = [_case_inputs(task) for task in tasks]
    _, _, excitation, rate = inputs[0]
    simulation = tasks[0]["simulation"]
    channels = _LOCKSTEP_CHANNELS
    if any(task["kind"] == "processing" for task in tasks):
        channels += _PROCESSING_CHANNELS
    # cases with equal parameters in several studies (the paper's Table 1 case with the
    # passive gains is in three) are one run: integrated once, analysed per task
    index = {}
    run_of = [index.setdefault((isolator, controller), len(index))
              for isolator, controller, _, _ in inputs]
    distinct = list(index)
    batch = simulate_batch(distinct, excitation, dt=simulation["dt"],
                           solver=simulation["solver"], sample_rate=rate, channels=channels,
                           workers=workers, progress=progress)
    for task, b in zip(tasks, run_of):
        if batch.messages[b]:
            raise SimulationError(f"{task['label']}: {batch.messages[b]}")
    share = batch.elapsed / len(tasks)

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
        result = _analyse_case(tasks[c], run, isolator, controller, excitation, rate)
        result.seconds = share + time.perf_counter() - start
        return result

    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(analyse, range(len(tasks))))


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


def _spring_case(task):
    """The spring's characteristic: the law measured with noise, and fitted.

    The MagSpring (the paper's Fig. 5): its tanh fitted, ``spring_force`` and
    ``spring_shape``. Another law (``task["spring"]``, docs/model.md §3.1): measured the
    same way (noise a share of the MagSpring's plateau force) and fitted as its own kind
    (:func:`qzs.identify.fit_spring`; a polynomial of its degree about its centre), its
    fitted parameters by their registry names
    (``spring.<field>``) and the fit's RMS residual.
    """
    options = task["options"]
    truth = IsolatorParameters()
    law = task["spring"]
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


def run_studies(studies, *, quick=False, workers=None, progress=True, lockstep=True, dt=None,
                tolerance=None, spring=None, tolerance_db=None):
    """Run several studies, all their cases in parallel.

    Cases that share their chirp, sample rate, step and solver (the paper's
    transmissibility studies all do) go through the lockstep batch kernel together,
    which gives each the numbers of its own :func:`qzs.simulate` run, to the last
    bit; the others run one per process, alongside.

    Parameters
    ----------
    studies : sequence of Study
        The definitions (:func:`load_study`).
    quick : bool
        Shorter runs (fewer, shorter Welch segments) for a fast look.
    workers : int, optional
        Cores to use (threads of the batch kernel, worker processes of the other
        cases); default the machine's core count. 1 runs everything in-process.
    progress : bool
        Show a progress bar over cases (and one over simulated time for a batch).
    lockstep : bool
        Share steps between cases through the batch kernel; False runs every case
        through the one-case driver, one per process (the same numbers, slower).
    dt : float, optional
        Integration step [s] of every case (the paper's: 1e-4); default a file's
        ``[simulation] dt``, else chosen for ``tolerance``.
    tolerance : float, optional
        Tolerance on the transmissibility [dB] the chosen step meets (one step per group
        of cases sharing an excitation, :func:`qzs.engine.accuracy_batch.choose_batch_step`);
        default :data:`qzs.defaults.ACCURACY`. Not with ``dt``.
    spring : SpringLaw, optional
        The spring law of every case (docs/model.md §3.1); default the MagSpring's tanh (the
        paper's: a ``TanhSpring`` of Table 1's numbers is the default, another tanh runs
        with its own). The spring study then measures and fits that law.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    list of StudyResult

    Raises
    ------
    ParameterError
        Both ``dt`` and ``tolerance``, or a non-positive one.
    """
    from qzs.engine.progress import progress_bar
    from qzs.engine.step_choice import step_request

    request = step_request(dt=dt, tolerance=tolerance, tolerance_db=tolerance_db)
    dt = request.dt
    given = IsolatorParameters(spring=spring).spring_law  # validated
    spring = None if given == IsolatorParameters().spring_law else given  # the MagSpring: None
    per_study = [_tasks(study, quick, dt, spring) for study in studies]
    steps = _choose_steps(per_study, request, worker_count(workers), progress)
    tasks = [(i, j, task) for i, study_tasks in enumerate(per_study)
             for j, task in enumerate(study_tasks)]
    results = [[None] * len(study_tasks) for study_tasks in per_study]
    workers = worker_count(workers)
    groups, single = {}, []
    for entry in tasks:
        if lockstep and entry[2]["kind"] in ("transmissibility", "processing"):
            groups.setdefault(_lockstep_key(entry[2]), []).append(entry)
        else:
            single.append(entry)
    for key in [key for key, members in groups.items() if len(members) == 1]:
        single += groups.pop(key)
    bar = progress_bar(total=len(tasks), unit="case", desc="studies", disable=not progress)
    start = time.perf_counter()
    pool = None
    try:
        futures = {}
        if single and workers > 1:  # alongside the batches; a batch's analysis overlaps them
            pool = ProcessPoolExecutor(max_workers=min(workers, len(single)))
            futures = {pool.submit(run_case, task): (i, j) for i, j, task in single}
        elif single:
            for i, j, task in single:
                results[i][j] = run_case(task)
                bar.update()
        for members in groups.values():
            cases = _run_lockstep([task for _, _, task in members], workers,
                                  progress)
            for (i, j, _), case in zip(members, cases):
                results[i][j] = case
            bar.update(len(members))
        for future in as_completed(futures):
            i, j = futures[future]
            results[i][j] = future.result()
            bar.update()
    finally:
        bar.close()
        if pool is not None:
            pool.shutdown(cancel_futures=True)
    elapsed = time.perf_counter() - start
    return [StudyResult(study, cases, quick, sum(c.seconds for c in cases) or elapsed, step,
                        spring)
            for study, cases, step in zip(studies, results, steps)]


def run_study(study, **options):
    """Run one study (a :class:`Study`, a path or a shipped name); see :func:`run_studies`.

    Parameters
    ----------
    study : Study, str or Path
        The definition, a study file or the name of a shipped study.
    **options
        ``quick``, ``workers`` and ``progress``, as for :func:`run_studies`.

    Returns
    -------
    StudyResult
    """
    if not isinstance(study, Study):
        study = load_study(study)
    return run_studies([study], **options)[0]


def _choose_steps(per_study, request, workers, progress):
    """Fill in the step of every task without one; returns each study's :func:`_step_record`.

    The tasks that share their chirp, sample rate and solver (a lockstep batch) get one
    step: :func:`qzs.engine.step_choice.choose` of ``request`` (a
    :class:`~qzs.engine.step_choice.StepRequest`; its tolerance, else the default) on a batch
    probe of their distinct cases.
    """
    from qzs.engine.accuracy_batch import BatchProbe
    from qzs.engine.step_choice import choose

    groups = {}
    for tasks in per_study:
        for task in tasks:
            if task.get("simulation", {}).get("dt", 0) is None:
                _, _, excitation, rate = _case_inputs(task)
                key = (excitation, float(rate), task["simulation"]["solver"])
                groups.setdefault(key, []).append(task)
    choices = {}
    for group, ((excitation, rate, solver), tasks) in enumerate(groups.items()):
        start = time.perf_counter()
        index = {}
        for task in tasks:
            isolator, controller, _, _ = _case_inputs(task)
            index.setdefault((isolator, controller), []).append(task)
        choice = choose(request, BatchProbe(
            cases=list(index), excitation=excitation, solver=solver, sample_rate=rate,
            workers=workers, labels=[members[0]["label"] for members in index.values()]),
            fallback=True, progress=progress, cache=True)
        seconds = time.perf_counter() - start
        for c, members in enumerate(index.values()):
            for task in members:
                task["simulation"]["dt"] = choice.dt
                choices[id(task)] = (choice, c, seconds, group)
    return [_step_record(tasks, choices) for tasks in per_study]


def _step_record(tasks, choices):
    """How a study's step was set (:attr:`StudyResult.step`); empty without a simulation."""
    simulated = [task for task in tasks if "simulation" in task]
    if not simulated:
        return {}
    first = simulated[0]
    record = {"dt": float(first["simulation"]["dt"]), "source": first["step_source"]}
    if id(first) in choices and not choices[id(first)][0].met:
        choice, _, seconds, group = choices[id(first)]
        record.update(source="fallback", tolerance_db=choice.tolerance, notes=[choice.unmet_note],
                      unmet=[task["label"] for task in simulated], seconds=seconds,
                      group=group)
    elif id(first) in choices:
        choice, _, seconds, group = choices[id(first)]
        mine = [(task["label"], choices[id(task)][1]) for task in simulated]
        errors = [choice.case_errors[c] for _, c in mine if c not in choice.unmet]
        record.update(tolerance_db=choice.tolerance,
                      estimated_error_db=max(errors) if errors else float("nan"),
                      reference_dt=choice.reference_dt, probe_duration=choice.probe_duration,
                      unmet=[label for label, c in mine if c in choice.unmet],
                      notes=list(choice.notes), seconds=seconds, group=group,
                      cached=choice.cached)
    return record


#: Units of the metrics table's own columns (:func:`column_unit`).
_COLUMN_UNITS = {"study": "", "case": "", "linear_undamped_natural_frequency": "Hz",
                 "seconds": "s", "spring_residual_rms": "N"}


def column_unit(name):
    """The unit of a column of ``metrics.csv`` (its units row), from where it is defined.

    Parameters come from :mod:`qzs.model.registry` (``param.<name>``), metrics from
    :func:`qzs.analysis.spectral.metric_unit` (the spring's fitted ``spring_force`` and
    ``spring_shape`` from the registry), statistics and run settings from
    :data:`STATS_UNITS` and :data:`RUN_UNITS`.

    Parameters
    ----------
    name : str
        The column's name.

    Returns
    -------
    str
        The unit; ``""`` for a text column (labels, reasons, the solver's name).

    Raises
    ------
    KeyError
        A column no definition gives a unit for (a programming error).
    """
    if name.endswith("_reason") or name in _COLUMN_UNITS:
        return _COLUMN_UNITS.get(name, "")
    from qzs.model.registry import unit_of

    for prefix, units in (("run.", RUN_UNITS), ("param.", None), ("processed.", None)):
        if name.startswith(prefix):
            key = name[len(prefix):]
            if units is not None:
                return units[key] or ""
            return unit_of(key) if prefix == "param." else column_unit(key)
    from qzs.analysis.spectral import metric_unit
    from qzs.model.registry import ALL_PARAMETERS, unit_of

    unit = metric_unit(name) or STATS_UNITS.get(name)
    if unit is None and name in ALL_PARAMETERS:
        unit = unit_of(name)
    if unit is None:
        raise KeyError(f"metrics.csv column {name!r} has no unit in any definition.")
    return unit
