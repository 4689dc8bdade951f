"""The report's figures: each study's views drawn from its curves, and the curves as data
(:mod:`qzs.workflows.paper.curves`)."""
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from qzs.viz.transmissibility import overlap_notes, plot_transmissibility
from qzs.workflows.paper.curves import (CURVE_SUFFIXES, case_curves, figure_curves,
                                        study_dataset)
from qzs.workflows.paper.report_spring import draw_spring
from qzs.workflows.paper.studies import RUN_UNITS

__all__ = ["figure_curves", "case_curves", "curves_of", "view_figure", "case_figure",
           "draw_views", "draw_studies", "curve_files", "figure_names"]


def curves_of(result, *, quick=False):
    """A study's curves as a dataset (:func:`qzs.workflows.paper.curves.study_dataset`, the
    run settings' units :data:`qzs.workflows.paper.cases.RUN_UNITS`).

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
    return study_dataset(result, quick=quick, run_units=RUN_UNITS)


def view_figure(result, view=None, path=None, frequency_scale=None, title=None):
    """One view of a study (its first by default; the spring's figure for the spring study).

    Parameters
    ----------
    result : StudyResult
        A study.
    view : dict, optional
        One of ``result.study.views``; default the first (the band analysed if none).
    path : str or Path, optional
        Write the figure there (PNG and SVG).
    frequency_scale : {"log", "linear"}, optional
        Overrides the view's own; else the view's or the default (log).
    title : str, optional
        Default the study's title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    study = result.study
    title = study.title if title is None else title
    if study.kind == "spring_characteristic":
        return draw_spring(result.cases[0], path, title)
    first = result.cases[0]
    if view is None:
        view = (study.views[0] if study.views else
                {"frequency_range": (0.0, float(first.frequency[-1]))})
    untrusted = None
    if study.kind == "processing":
        untrusted = first.extra.get("untrusted_below", 1.5 * first.extra["highpass"])
    coherence_min = first.run.get("coherence_min") if first.run else None
    options = {} if coherence_min is None else {"coherence_min": coherence_min}
    return plot_transmissibility(figure_curves(result),
                                 frequency_range=tuple(view["frequency_range"]),
                                 frequency_scale=frequency_scale or view.get("frequency_scale"),
                                 title=title, path=path, untrusted_below=untrusted, **options)


def case_figure(case, path=None, frequency_scale=None, title=None):
    """One case's curves (:func:`case_curves`) over its band, or a spring case's figure.

    Parameters
    ----------
    case : CaseResult
        The case.
    path : str or Path, optional
        Write the figure there (PNG and SVG).
    frequency_scale : {"log", "linear"}, optional
        Default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).
    title : str, optional
        Default the case's label.

    Returns
    -------
    matplotlib.figure.Figure
    """
    title = case.label if title is None else title
    if case.frequency is None:
        return draw_spring(case, path, title)
    options = {"coherence_min": case.run["coherence_min"]} if "coherence_min" in case.run \
        else {}
    untrusted = (case.extra.get("untrusted_below", 1.5 * case.extra["highpass"])
                 if "highpass" in case.extra else None)
    return plot_transmissibility(case_curves(case), frequency_range=(0.0, float(
        case.frequency[-1])), frequency_scale=frequency_scale, title=title, path=path,
        untrusted_below=untrusted, **options)


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
        plt.close(view_figure(result, path=path))
        return [("fig05_spring", path, [])]
    drawn = []
    curves = figure_curves(result)
    for view in study.views:
        path = folder / f"{view['figure']}.png"
        plt.close(view_figure(result, view, path, frequency_scale))
        drawn.append((view["figure"], path,
                      overlap_notes(curves, frequency_range=tuple(view["frequency_range"]))))
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
