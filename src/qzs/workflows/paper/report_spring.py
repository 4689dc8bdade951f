"""The spring of the paper's studies, as the report states it (docs/workflows/paper.md).

The law every case ran (the MagSpring's tanh, the paper's, by default; another given to
``qzs paper --spring``, docs/model.md §3.1): as one sentence (:func:`spring_statement`, for
``report.html`` and the console) and as a record (:func:`spring_record`, for
``metrics.json``); and the spring study's fit as the report shows it: its figure
(:func:`draw_spring`) and its paragraph (:func:`spring_fit_html`); its curves are
:func:`qzs.workflows.paper.curves.spring_curves`.
"""
from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from qzs.model.isolator import IsolatorParameters
from qzs.viz.identify import plot_spring_fit, plot_spring_law_fit
from qzs.workflows.paper.curves import spring_curves  # noqa: F401  (its room before)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from qzs.model.springs import SpringLaw
    from qzs.workflows.paper.cases import CaseResult
    from qzs.workflows.paper.studies import StudyResult

__all__ = ["spring_statement", "spring_record", "draw_spring", "spring_curves",
           "spring_fit_html"]


def _spring_law(study_results: Sequence[StudyResult]) -> SpringLaw:
    """The law the studies ran (one for all, ``run_studies``): the MagSpring's by default."""
    law = next((r.spring for r in study_results if r.spring is not None), None)
    return IsolatorParameters(spring=law).spring_law


def spring_statement(study_results: Sequence[StudyResult]) -> str:
    """One sentence: the spring law every case ran (docs/model.md §3, §3.1).

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies.

    Returns
    -------
    str
    """
    law = _spring_law(study_results)
    given = any(r.spring is not None for r in study_results)  # run_studies: None is Table 1's
    default = ("given with --spring, not the paper's MagSpring: the claims are this law's"
               if given else "the paper's, the default")
    return f"{law.describe()} ({default})"


def spring_record(study_results: Sequence[StudyResult]) -> dict[str, Any]:
    """The spring law every case ran as plain data: ``{"law": kind, field: [value, unit]}``.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies.

    Returns
    -------
    dict
    """
    return {name: value if name == "law" else [value, unit]
            for name, (value, unit) in _spring_law(study_results).parameters().items()}


def draw_spring(case: CaseResult, path: Path | None, title: str) -> Figure:
    """The spring study's figure (the paper's Fig. 5): the points and the fitted law.

    Parameters
    ----------
    case : CaseResult
        The spring study's case.
    path : Path or None
        The PNG to write (an SVG beside it); None: none.
    title : str
        The figure's title (the study's).

    Returns
    -------
    matplotlib.figure.Figure
    """
    extra = case.extra
    if "law_fit" in extra:
        return plot_spring_law_fit(extra["law_fit"], path=path, title=title)
    return plot_spring_fit(extra["displacement"], extra["force"], extra["fit"]["spring_force"],
                           extra["fit"]["spring_shape"], path=path, title=title)


def spring_fit_html(result: StudyResult) -> str:
    """The spring study's paragraph in ``report.html``: the fit and what it should find.

    Parameters
    ----------
    result : StudyResult
        The spring study's result.

    Returns
    -------
    str
    """
    e = html.escape
    extra = result.cases[0].extra
    if "law_fit" in extra:
        return (f"<p>The spring's law, measured with noise and fitted as its kind "
                f"(<code>qzs.fit_spring</code>): true {e(extra['true_law'].describe())}; "
                f"fitted:</p><pre>{e(extra['law_fit'].summary())}</pre>")
    fit = extra["fit"]
    (a_low, a_high), (b_low, b_high) = (fit["intervals"][name] for name in ("plateau", "shape"))
    return (f"<p>Fit (model convention, F = -a tanh(b z)): a = {fit['spring_force']:.3f} N "
            f"[{a_low:.3f}, {a_high:.3f}], b = {fit['spring_shape']:.2f} 1/m [{b_low:.2f}, "
            f"{b_high:.2f}] (95 %); Table 1: a = 60.84 N, "
            "b = 78.10 1/m. The paper's Fig. 5 prints a = -60.84 N in the test machine's "
            "displacement convention.</p>")
