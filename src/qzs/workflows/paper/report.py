"""``qzs paper``: run the paper's studies, draw its figures, decide its claims from the data.

The verdicts, tables, figures and HTML are the rooms of :mod:`qzs.workflows.findings`; this
module runs the studies and writes their files.

Writes to an output folder: one figure per paper figure (PNG and SVG), the curves behind
each study's figures as data (``<study>_curves.nc`` and ``<study>_curves.csv``,
:mod:`qzs.workflows.paper.curves`), ``metrics.json`` and ``metrics.csv`` (per study and case,
with a units row), and ``report.html``,
which states how every curve was computed, puts each figure beside the paper's claims
the study names (docs/model.md §13, "What the paper reports") and says, from the numbers,
whether each claim is reproduced.

Every number comes from the trusted bins of a curve (docs/model.md §10); a metric those
bins do not define is NaN in the data (empty in the CSV, null in the JSON) with its
reason in the column ``<metric>_reason`` beside it, and a dash with a footnote in the
report. A trend claim (a quantity rising with a swept parameter) is decided over every
case, ordered by that parameter, and needs at least three cases; with fewer it is
"not decidable".
"""
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from qzs._format import json_ready, json_text
from qzs._validation import worker_count
from qzs.iotools.files import write_text
from qzs.iotools.writer import write_table
from qzs.model.springs import SpringLaw
from qzs.viz.figures import check_frequency_scale
from qzs.workflows.findings.figures import curve_files, curves_of, draw_studies, figure_names
from qzs.workflows.findings.html import paper_html
from qzs.workflows.findings.tables import (claims_record, document_head, metric_rows,
                                           run_settings, study_record, with_reasons)
from qzs.workflows.findings.verdicts import (CLAIMS, TREND_CLAIMS, Verdict, damping_changes,
                                             decide_claims)
from qzs.workflows.paper.curves import write_curves
from qzs.workflows.paper.report_spring import spring_record
from qzs.workflows.paper.report_step import step_record
from qzs.workflows.paper.studies import (StudyResult, column_unit, load_study, run_studies,
                                         shipped_studies)

__all__ = ["CLAIMS", "TREND_CLAIMS", "Verdict", "decide_claims", "damping_changes",
           "curves_of", "paper_summary", "write_paper_outputs", "run_paper"]

#: Free space [bytes] the output folder must have before the studies run: a generous bound
#: of the report, its figures (PNG) and metrics.
PAPER_BYTES = 20_000_000


def write_paper_outputs(study_results, folder, *, quick=False, wall_seconds=None,
                        workers=None, frequency_scale=None, progress=False):
    """Write figures, curves, ``metrics.json``, ``metrics.csv`` and ``report.html`` into ``folder``.

    The curves of each transmissibility study go to ``<study>_curves.nc`` and
    ``<study>_curves.csv`` (:func:`curves_of`); ``metrics.csv`` has a units row under its
    column names (:func:`column_unit`).

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    folder : str or Path
        Output folder, created if missing.
    quick : bool
        Whether the runs were the quick ones (recorded in the metrics and the report).
    wall_seconds : float, optional
        Wall time of the runs [s], recorded in the metrics and the report.
    workers : int, optional
        Processes drawing the figures; default all cores. 1 draws them in-process.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of every figure; default each view's own, else
        ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    progress : bool
        Show a progress bar: one step per study's figures, per study's curves, and per
        file of metrics and report.

    Returns
    -------
    list of Verdict
        As :func:`decide_claims` gives them.

    Raises
    ------
    ParameterError
        ``workers`` not a positive integer.
    """
    workers = worker_count(workers, len(study_results))  # checked before anything is written
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    from qzs.engine.progress import progress_bar

    with progress_bar(total=2 * len(study_results) + 3, unit="part",
                      desc="figures and report", disable=not progress, leave=False) as bar:
        return _write_outputs(study_results, folder, quick, wall_seconds, workers,
                              frequency_scale, bar)


def _write_outputs(study_results, folder, quick, wall_seconds, workers, frequency_scale, bar):
    """:func:`write_paper_outputs` once its arguments are checked, advancing ``bar``."""
    verdicts = decide_claims(study_results)
    figures = draw_studies(study_results, folder, workers, frequency_scale, bar,
                    meanwhile=lambda: _write_tables(study_results, folder, quick,
                                                    wall_seconds, verdicts, bar))
    write_text(folder / "report.html",
               paper_html(study_results, figures, verdicts, quick, wall_seconds))
    bar.update(1)
    return verdicts


def _write_tables(study_results, folder, quick, wall_seconds, verdicts, bar):
    """``metrics.json``, ``metrics.csv`` and each study's curves, advancing ``bar``."""
    rows = metric_rows(study_results)
    document = {**document_head(quick, wall_seconds),
                "studies": {r.study.name: study_record(r) for r in study_results},
                "claims": claims_record(verdicts), "step": step_record(study_results),
                "spring": spring_record(study_results)}
    write_text(folder / "metrics.json", json_text(document))
    bar.update(1)
    write_table(rows, folder / "metrics.csv", units=column_unit)
    bar.update(1)
    for result in study_results:
        write_curves(curves_of(result, quick=quick), folder, result.study.name)
        bar.update(1)


def paper_summary(study_results: Sequence[StudyResult], verdicts: Sequence[Verdict],
                  folder: str | Path, *, quick: bool = False,
                  wall_seconds: float | None = None) -> dict[str, Any]:
    """What ``qzs paper --json`` prints: claims, per-case metrics, output paths.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    verdicts : sequence of Verdict
        Their claims, decided (:func:`decide_claims`).
    folder : str or Path
        The output folder the report was written to.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float, optional
        Wall time of the runs [s].

    Returns
    -------
    dict
        JSON-ready (NaN as None, the reason beside it as ``<metric>_reason``):
        ``qzs_version``, ``quick``, ``wall_seconds``, ``claims`` (claim, study,
        statement, verdict, evidence), ``studies`` (name -> title, seconds, settings,
        cases with their metrics), ``step`` (:func:`~qzs.workflows.paper.report_step.step_record`), ``outputs`` (report,
        metrics_json, metrics_csv, figures: PNG and SVG paths, curves: the
        ``<study>_curves.nc`` and ``.csv`` files).
    """
    folder = Path(folder)
    studies = {}
    for result in study_results:
        cases = []
        for case in result.cases:
            entry = {"case": case.label, "parameters": dict(case.settings)}
            entry.update(with_reasons(case.metrics, case.reasons))
            if "metrics" in case.extra:
                entry.update(with_reasons(case.extra["metrics"], case.extra.get("reasons", {}),
                                           prefix="processed."))
            for key in ("stop_contacts", "locked_fraction", "locked_fraction_below_half_hz"):
                if key in case.stats:
                    entry[key] = case.stats[key]
            cases.append(entry)
        studies[result.study.name] = {"title": result.study.title, "seconds": result.seconds,
                                      "settings": run_settings(result), "cases": cases}
    figures = [str(folder / f"{name}{suffix}") for result in study_results
               for name in figure_names(result) for suffix in (".png", ".svg")]
    return json_ready({
        **document_head(quick, wall_seconds),
        "claims": claims_record(verdicts), "studies": studies,
        "step": step_record(study_results), "spring": spring_record(study_results),
        "outputs": {"report": str(folder / "report.html"),
                    "metrics_json": str(folder / "metrics.json"),
                    "metrics_csv": str(folder / "metrics.csv"), "figures": figures,
                    "curves": [str(path) for result in study_results
                               for path in curve_files(result, folder)]}})


def run_paper(definitions: Sequence[str | Path] | None = None,
              folder: str | Path = "results/paper", *, quick: bool = False,
              workers: int | None = None, progress: bool = True,
              argument: str = "folder", dt: float | None = None,
              tolerance: float | None = None,
              frequency_scale: str | None = None, spring: SpringLaw | None = None,
              tolerance_db: float | None = None
              ) -> tuple[list[StudyResult], list[Verdict], float]:
    """Run studies and write their report (``qzs paper``, ``qzs study``).

    Parameters
    ----------
    definitions : sequence of str or Path, optional
        Study files or shipped study names; default every shipped study (the paper).
    folder : str or Path
        Output folder of the figures, metrics and ``report.html``.
    quick : bool
        Shorter runs (fewer, shorter Welch segments).
    workers : int, optional
        Cores: threads of the lockstep kernel, worker processes of the other cases and of
        the figures; default all cores.
    progress : bool
        Show a progress bar over cases.
    argument : str
        How the caller names ``folder`` in messages (``"--out"`` on the command line).
    dt : float, optional
        Integration step [s] of every case, as given (the paper's: 1e-4); default chosen
        for ``tolerance`` (a study file's ``[simulation] dt`` is kept).
    tolerance : float, optional
        Tolerance on the transmissibility [dB] the chosen step meets; default
        :data:`qzs.defaults.ACCURACY`. Not with ``dt``.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of every figure (``--frequency-axis``); default each view's own,
        else ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    spring : SpringLaw, optional
        The spring law of every case (docs/model.md §3.1; ``--spring``); default the
        MagSpring's tanh, the paper's.
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    results : list of StudyResult
    verdicts : list of Verdict
    wall_seconds : float
        Wall time of the whole [s]: the runs, the figures, the curves and the report (the
        metrics and the report record the runs' alone).

    Raises
    ------
    OutputPathError
        ``folder`` is a file, or cannot be created or written (checked before any study
        runs: on a cold cache they take minutes).
    ParameterError
        A study file is invalid, or both ``dt`` and ``tolerance`` are given.
    """
    import time

    from qzs._validation import renamed_keyword
    from qzs.iotools.paths import check_output_path

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)

    check_output_path(folder, argument=argument, suffixes=None, directory=True,
                      estimated_bytes=PAPER_BYTES)
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale, argument="frequency_scale")
    paths = shipped_studies() if definitions is None else definitions
    studies = [load_study(p) for p in paths]
    start = time.perf_counter()
    results = run_studies(studies, quick=quick, workers=workers, progress=progress, dt=dt,
                          tolerance=tolerance, spring=spring)
    wall = time.perf_counter() - start
    verdicts = write_paper_outputs(results, folder, quick=quick, wall_seconds=wall,
                                   workers=workers, frequency_scale=frequency_scale,
                                   progress=progress)
    return results, verdicts, time.perf_counter() - start
