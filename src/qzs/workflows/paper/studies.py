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
:func:`qzs.engine.step_choice.choose` on one lockstep probe of them all
(docs/model.md §7).
"""
import dataclasses
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from qzs._validation import known_keys, read_toml, worker_count
from qzs.defaults import ANALYSIS, FREQUENCY_SCALES, SIMULATION
from qzs.errors import ParameterError
from qzs.iotools.result_files import save_by_extension, save_doc, suffixes_of
from qzs.iotools.shipped import resolve_shipped, shipped_files
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import EXCITATION_OPTIONS
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters
from qzs.workflows.paper.cases import (RUN_UNITS, STATS_UNITS, CaseResult, StudyCase,
                                       case_inputs, column_unit, lockstep_key, run_case,
                                       run_lockstep)

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["CLAIMS", "Study", "StudyCase", "StudyPlan", "StudyResult", "CaseResult",
           "load_study", "shipped_studies", "plan_studies", "run_plan", "run_studies",
           "run_study", "RUN_UNITS", "STATS_UNITS", "column_unit"]

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

    #: The extensions :meth:`save` accepts.
    save_suffixes = suffixes_of(dataset=True, record=True)

    def summary(self) -> str:
        """The study as text: its kind, its step, then each case (:meth:`CaseResult.summary`).

        Returns
        -------
        str
        """
        head = [f"study {self.study.name!r} ({self.study.kind}{', quick' if self.quick else ''}"
                f"): {self.study.title}; {len(self.cases)} cases, {self.seconds:.3g} s"]
        if self.step:
            head.append(f"  step dt = {self.step['dt']:.6g} s ({self.step['source']})")
        return "\n".join([*head, *(case.summary() for case in self.cases)])

    def to_record(self) -> dict[str, Any]:
        """The study as ``metrics.json`` holds it: title, time [s], run settings, the cases'
        rows (:func:`qzs.workflows.findings.tables.study_record`).

        Returns
        -------
        dict
        """
        from qzs.workflows.findings.tables import study_record

        return study_record(self)

    def to_xarray(self) -> "xr.Dataset":
        """The curves its figures draw, as ``<study>_curves.nc`` holds them
        (:func:`qzs.workflows.paper.curves.study_dataset`: on ``case`` and ``frequency``
        [Hz], with the cases' parameters and the run settings with units), or the spring
        study's points and fitted law.

        Returns
        -------
        xarray.Dataset
        """
        from qzs.workflows.paper.curves import study_dataset

        return study_dataset(self, quick=self.quick, run_units=RUN_UNITS)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """The study's first figure (:func:`qzs.workflows.findings.figures.view_figure`):
        its cases' transmissibility [dB] against frequency [Hz], or the spring's
        characteristic.

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (a .png also as .svg).
        title : str, optional
            Figure title; default the study's.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default the view's own, else
            ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.workflows.findings.figures import view_figure

        return view_figure(self, None, path, frequency_scale, title)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray, record=self.to_record)

    save.__doc__ = save_doc("``.nc``, ``.csv``, ``.mat`` (:meth:`to_xarray`: the study's "
                            "curves, as ``qzs paper`` writes them) or ``.json`` "
                            "(:meth:`to_record`: the study's entry of ``metrics.json``)")


@dataclass(frozen=True, kw_only=True)
class StudyPlan:
    """Studies resolved to run together: their cases with their steps chosen.

    Attributes
    ----------
    studies : tuple of Study
        The definitions, in order.
    cases : tuple of tuple of StudyCase
        Each study's cases, in definition order, every simulated one with its step ``dt`` [s].
    steps : tuple of dict
        Each study's step record (:attr:`StudyResult.step`).
    quick : bool
        Whether the runs are the quick ones.
    spring : SpringLaw or None
        The spring law of every case; None: the MagSpring's tanh.
    """

    studies: tuple
    cases: tuple
    steps: tuple
    quick: bool
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
    known_keys(document, allowed, "the study file", f"{str(path)!r}: ", noun="table")
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


def _study_cases(study, quick, dt=None, spring=None):
    """A study's cases (:class:`StudyCase`), their steps not yet chosen (``dt`` None: the
    file's, else chosen by :func:`_choose_steps`; ``spring`` the isolator's law, None for the
    MagSpring's tanh)."""
    analysis = {**ANALYSIS, **study.analysis}
    if quick:
        analysis["fft_length"] = analysis["quick_fft_length"]
        analysis["n_averages"] = min(analysis["n_averages"], analysis["quick_n_averages"])
    if study.kind == "processing":
        analysis["n_averages"] = int(study.options.get("n_averages", analysis["n_averages"]))
        if quick:
            analysis["n_averages"] = min(analysis["n_averages"], analysis["quick_n_averages"])
    if study.kind == "spring_characteristic":
        return (StudyCase(kind=study.kind, label="MagSpring" if spring is None else spring.kind,
                          settings={}, options=study.options, spring=spring),)
    simulation = {"dt": None, "solver": SIMULATION["solver"], **study.simulation,
                  **({} if dt is None else {"dt": dt})}
    return tuple(StudyCase(
        kind=study.kind, label=case.get("label", f"case {i + 1}"),
        settings={**study.defaults, **{k: v for k, v in case.items() if k != "label"}},
        excitation=dict(study.excitation), analysis=analysis, solver=simulation["solver"],
        dt=simulation["dt"], step_source="given" if dt is not None else
        ("file" if "dt" in study.simulation else "chosen"), options=study.options,
        spring=spring) for i, case in enumerate(study.cases))


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
        of cases sharing an excitation, :func:`qzs.engine.step_choice.choose`);
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
    from qzs._validation import renamed_keyword

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)
    plan = plan_studies(studies, quick=quick, workers=workers, progress=progress, dt=dt,
                        tolerance=tolerance, spring=spring)
    return run_plan(plan, workers=workers, progress=progress, lockstep=lockstep)


def plan_studies(studies, *, quick=False, workers=None, progress=True, dt=None,
                 tolerance=None, spring=None, tolerance_db=None):
    """Resolve studies to run together: their inputs checked, their steps chosen.

    Parameters
    ----------
    studies : sequence of Study
        The definitions (:func:`load_study`).
    quick : bool
        Shorter runs (fewer, shorter Welch segments).
    workers : int, optional
        Cores for the step's choice; default all.
    progress : bool
        Show the step choice's progress.
    dt : float, optional
        Integration step [s] of every case; default a file's, else chosen.
    tolerance : float, optional
        Tolerance on the transmissibility [dB] the chosen step meets; not with ``dt``.
    spring : SpringLaw, optional
        The spring law of every case; default the MagSpring's tanh.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    StudyPlan

    Raises
    ------
    ParameterError
        Both ``dt`` and ``tolerance``, or a non-positive one.
    """
    from qzs.engine.step_choice import step_request

    request = step_request(dt=dt, tolerance=tolerance, tolerance_db=tolerance_db)
    dt = None if dt is None else float(request.dt)
    given = IsolatorParameters(spring=spring).spring_law  # validated
    spring = None if given == IsolatorParameters().spring_law else given  # the MagSpring: None
    per_study = [_study_cases(study, quick, dt, spring) for study in studies]
    cases, steps = _choose_steps(per_study, request, worker_count(workers), progress)
    return StudyPlan(studies=tuple(studies), cases=cases, steps=steps, quick=quick,
                     spring=spring)


def run_plan(plan, *, workers=None, progress=True, lockstep=True):
    """Run a resolved :class:`StudyPlan` (:func:`plan_studies`): all its cases in parallel.

    Parameters
    ----------
    plan : StudyPlan
        The studies, their cases and steps.
    workers : int, optional
        Cores, as for :func:`run_studies`.
    progress : bool
        Show a progress bar over cases.
    lockstep : bool
        Share steps between cases through the batch kernel.

    Returns
    -------
    list of StudyResult
    """
    from qzs.engine.progress import progress_bar

    entries = [(i, j, case) for i, cases in enumerate(plan.cases)
               for j, case in enumerate(cases)]
    results = [[None] * len(cases) for cases in plan.cases]
    workers = worker_count(workers)
    groups, single = {}, []
    for entry in entries:
        if lockstep and entry[2].simulated:
            groups.setdefault(lockstep_key(entry[2]), []).append(entry)
        else:
            single.append(entry)
    for key in [key for key, members in groups.items() if len(members) == 1]:
        single += groups.pop(key)
    bar = progress_bar(total=len(entries), unit="case", desc="studies", disable=not progress)
    start = time.perf_counter()
    pool = None
    try:
        futures = {}
        if single and workers > 1:  # alongside the batches; a batch's analysis overlaps them
            pool = ProcessPoolExecutor(max_workers=min(workers, len(single)))
            futures = {pool.submit(run_case, case): (i, j) for i, j, case in single}
        elif single:
            for i, j, case in single:
                results[i][j] = run_case(case)
                bar.update()
        for members in groups.values():
            cases = run_lockstep([case for _, _, case in members], workers, progress)
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
    return [StudyResult(study, cases, plan.quick, sum(c.seconds for c in cases) or elapsed,
                        step, plan.spring)
            for study, cases, step in zip(plan.studies, results, plan.steps)]


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
    """Choose the step of every simulated case without one.

    The cases that share their chirp, sample rate and solver (a lockstep batch) get one
    step: :func:`qzs.engine.step_choice.choose` of ``request`` (a
    :class:`~qzs.engine.step_choice.StepRequest`: its tolerance, else the default) on a batch
    probe of their distinct cases.

    Returns
    -------
    cases : tuple of tuple of StudyCase
        ``per_study`` with each chosen step in its case (:func:`dataclasses.replace`).
    steps : tuple of dict
        Each study's :func:`_step_record`.
    """
    from qzs.engine.accuracy_batch import BatchProbe
    from qzs.engine.step_choice import choose

    groups = {}
    for i, cases in enumerate(per_study):
        for j, case in enumerate(cases):
            if case.simulated and case.dt is None:
                _, _, excitation, rate = case_inputs(case)
                key = (excitation, float(rate), case.solver)
                groups.setdefault(key, []).append((i, j))
    choices = {}
    for group, ((excitation, rate, solver), members) in enumerate(groups.items()):
        start = time.perf_counter()
        index = {}
        for i, j in members:
            isolator, controller, _, _ = case_inputs(per_study[i][j])
            index.setdefault((isolator, controller), []).append((i, j))
        choice = choose(request, BatchProbe(
            cases=list(index), excitation=excitation, solver=solver, sample_rate=rate,
            workers=workers, labels=[per_study[i][j].label for (i, j), *_ in index.values()]),
            fallback=True, progress=progress, cache=True)
        seconds = time.perf_counter() - start
        for c, same in enumerate(index.values()):
            for place in same:
                choices[place] = (choice, c, seconds, group)
    resolved = tuple(tuple(dataclasses.replace(case, dt=choices[i, j][0].dt)
                           if (i, j) in choices else case for j, case in enumerate(cases))
                     for i, cases in enumerate(per_study))
    return resolved, tuple(_step_record(cases, [choices.get((i, j)) for j in range(len(cases))])
                           for i, cases in enumerate(resolved))


def _step_record(cases, choices):
    """How a study's step was set (:attr:`StudyResult.step`); empty without a simulation.

    ``choices``: per case, ``(choice, its index in the choice, seconds, group)`` or None
    (its step not chosen)."""
    simulated = [(case, chosen) for case, chosen in zip(cases, choices) if case.simulated]
    if not simulated:
        return {}
    first, chosen = simulated[0]
    record = {"dt": float(first.dt), "source": first.step_source}
    if chosen is not None and not chosen[0].met:
        choice, _, seconds, group = chosen
        record.update(source="fallback", tolerance_db=choice.tolerance, notes=[choice.unmet_note],
                      unmet=[case.label for case, _ in simulated], seconds=seconds,
                      group=group)
    elif chosen is not None:
        choice, _, seconds, group = chosen
        mine = [(case.label, place[1]) for case, place in simulated]
        errors = [choice.case_errors[c] for _, c in mine if c not in choice.unmet]
        record.update(tolerance_db=choice.tolerance,
                      estimated_error_db=max(errors) if errors else float("nan"),
                      reference_dt=choice.reference_dt, probe_duration=choice.probe_duration,
                      unmet=[label for label, c in mine if c in choice.unmet],
                      notes=list(choice.notes), seconds=seconds, group=group,
                      cached=choice.cached)
    return record
