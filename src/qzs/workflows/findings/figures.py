"""The report's figures: each study's views drawn from its curves, and the curves as data."""
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path


from qzs._version import __version__
from qzs.model.registry import format_value
from qzs.viz.transmissibility import overlap_notes, plot_transmissibility
from qzs.workflows.paper.curves import CURVE_SUFFIXES, curves_dataset
from qzs.workflows.paper.report_spring import draw_spring, spring_curves
from qzs.workflows.paper.studies import RUN_UNITS
from qzs.workflows.findings.tables import run_settings
from qzs.workflows.findings.verdicts import case_value

__all__ = ["figure_curves", "curves_of", "draw_views", "draw_studies", "curve_files",
           "figure_names"]


def figure_curves(result):
    """The curves a study's figures draw, each with its case's ``parameters`` and ``phase``.

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    list of dict
    """
    cases = result.cases
    names = list(dict.fromkeys(k for c in cases for k in c.settings))

    def parameters(case):
        return {name: case_value(case, name) for name in names}

    if result.study.kind == "processing":
        case = cases[0]
        return [dict(label=f"ideal: accelerations, {case.stats['n_averages']} averages",
                     frequency=case.frequency, magnitude=case.magnitude, trusted=case.trusted,
                     coherence=case.coherence, linear=case.linear.get("magnitude"),
                     phase=case.phase, parameters=parameters(case)),
                dict(label=f"experiment-style: velocities through the "
                           f"{case.extra['highpass']:g} Hz high-pass, "
                           f"{case.extra['n_averages']} averages",
                     frequency=case.extra["frequency"], magnitude=case.extra["magnitude"],
                     trusted=case.extra.get("trusted"), coherence=case.extra.get("coherence"),
                     phase=case.extra.get("phase"), parameters=parameters(case))]
    return [dict(label=c.label, frequency=c.frequency, magnitude=c.magnitude, trusted=c.trusted,
                 coherence=c.coherence, linear=c.linear.get("magnitude"), phase=c.phase,
                 parameters=parameters(c)) for c in cases]


def curves_of(result, *, quick=False):
    """A study's curves as a dataset (:func:`qzs.workflows.paper.curves.curves_dataset`).

    The curves its figures draw, on ``case`` and ``frequency``, with each case's
    parameters as coordinates and the run settings, study and definition as attributes;
    for the spring's characteristic, its points and fitted law
    (:func:`qzs.workflows.paper.curves.spring_dataset`).

    Parameters
    ----------
    result : StudyResult
        A study.
    quick : bool
        Whether the runs were the quick ones (an attribute).

    Returns
    -------
    xarray.Dataset
    """
    attrs = {"title": result.study.title, "study": result.study.name,
             "definition": Path(result.study.source).name if result.study.source else "",
             "quick": int(bool(quick)), "source": f"qzs {__version__} (qzs paper / qzs study)"}
    if result.study.kind == "spring_characteristic":
        return spring_curves(result, attrs)
    for key, value in run_settings(result).items():
        attrs[key] = (", ".join(format_value(v) for v in value) if isinstance(value, list)
                      else value)
        if RUN_UNITS.get(key):
            attrs[f"{key}_units"] = RUN_UNITS[key]
    return curves_dataset(figure_curves(result), attrs)


def draw_views(result, folder, frequency_scale=None):
    """Draw a study's views.

    Parameters
    ----------
    result : StudyResult
        A study.
    folder : Path
        Where the figures go (PNG and SVG).
    frequency_scale : {"log", "linear"}, optional
        Overrides the views' own (``--frequency-axis``); else a view's ``frequency_scale``
        or the default (log).

    Returns
    -------
    list of tuple
        ``(figure name, png path, caption notes)`` per view.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    study = result.study
    if study.kind == "spring_characteristic":
        path = folder / "fig05_spring.png"
        plt.close(draw_spring(result, path))
        return [("fig05_spring", path, [])]
    drawn = []
    curves = figure_curves(result)
    coherence_min = result.cases[0].run.get("coherence_min") if result.cases[0].run else None
    for view in study.views:
        untrusted = None
        if study.kind == "processing":
            untrusted = result.cases[0].extra.get("untrusted_below",
                                                  1.5 * result.cases[0].extra["highpass"])
        span = tuple(view["frequency_range"])
        path = folder / f"{view['figure']}.png"
        options = {} if coherence_min is None else {"coherence_min": coherence_min}
        fig = plot_transmissibility(curves, frequency_range=span,
                                    frequency_scale=frequency_scale or view.get(
                                        "frequency_scale"),
                                    title=study.title, path=path, untrusted_below=untrusted,
                                    **options)
        plt.close(fig)
        drawn.append((view["figure"], path, overlap_notes(curves, frequency_range=span)))
    return drawn


def curve_files(result, folder):
    """The data files of a study's curves.

    Parameters
    ----------
    result : StudyResult
        A study.
    folder : str or Path
        The output folder.

    Returns
    -------
    list of Path
    """
    return [Path(folder) / f"{result.study.name}_curves{suffix}" for suffix in CURVE_SUFFIXES]


def figure_names(result):
    """The file stems of a study's figures.

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    list of str
    """
    if result.study.kind == "spring_characteristic":
        return ["fig05_spring"]
    return [view["figure"] for view in result.study.views]


def draw_studies(study_results, folder, workers, frequency_scale=None, bar=None, meanwhile=None):
    """Every study's figures (:func:`draw_views`), in ``workers`` processes if more than one.

    Matplotlib holds the GIL, so figures draw in parallel only in processes; 0.3-0.7 s
    a figure, 5 s for the paper's on one core. ``bar`` (a progress bar, optional) advances
    by one as each study's figures are drawn. ``meanwhile`` (optional, no arguments) runs
    in this process while the others draw (after the figures with one worker): the
    paper's tables and curves (1.3 s) fill the time in which one drawing process has no
    study left.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    folder : Path
        Where the figures go.
    workers : int
        Drawing processes; 1 draws in this one.
    frequency_scale : {"log", "linear"}, optional
        As for :func:`draw_views`.
    bar : progress bar, optional
        Advanced by one per study drawn.
    meanwhile : callable, optional
        Run here while the others draw.

    Returns
    -------
    dict
        Study name -> :func:`draw_views`'s list.
    """
    step = (lambda: None) if bar is None else (lambda: bar.update(1))
    if workers <= 1:
        drawn = {}
        for r in study_results:
            drawn[r.study.name] = draw_views(r, folder, frequency_scale)
            step()
        if meanwhile is not None:
            meanwhile()
        return drawn
    # the studies with most views first, so that no process is left with two at the end
    order = sorted(study_results, key=lambda r: -len(r.study.views or [None]))
    with ProcessPoolExecutor(max_workers=workers) as pool:
        drawn = {r.study.name: pool.submit(draw_views, r, folder, frequency_scale)
                 for r in order}
        if meanwhile is not None:
            meanwhile()
        for _ in as_completed(drawn.values()):
            step()
        return {r.study.name: drawn[r.study.name].result() for r in study_results}
