"""Write an open-question study: its figures (PNG and SVG), ``study.json`` and ``report.html``.

Every file through :func:`qzs.iotools.files.atomic_path` (a failed write leaves none
half-written); the report states the verdict first, then the figures and the tables the
verdict rests on, and how the runs were made.
"""
import dataclasses
import html
from pathlib import Path

from qzs._format import html_figure, html_head, html_table, json_ready, json_text, number
from qzs.iotools.files import atomic_path

__all__ = ["write_question"]

_STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222}img{max-width:100%}table{border-collapse:collapse;font-size:0.85em}
td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#f4f4f4}
.verdict{border-left:6px solid #888;padding:0.5em 1em;background:#f8f8f8}
.yes{border-color:#2a7}.partly{border-color:#d90}.no{border-color:#c33}"""


def _cell(value):
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or value is None:
        return str(value)
    return number(value, 4)


def write_question(result, folder, figures, tables, *, title, how):
    """Write one study's outputs into ``folder`` (created if missing).

    Parameters
    ----------
    result : dict
        The study's result, with ``answer`` (:class:`~qzs.workflows.questions.common.Answer`);
        written as ``study.json`` (figures and curves left out).
    folder : str or Path
        The output folder.
    figures : dict of str to (matplotlib.figure.Figure, str)
        File stem -> (figure, caption).
    tables : list of (str, list of dict)
        Heading -> rows, for the report.
    title : str
        The report's title.
    how : str
        How the runs were made, for the report (plain text).

    Returns
    -------
    dict of str to Path
        ``report``, ``json`` and one entry per figure (its PNG).
    """
    import matplotlib.pyplot as plt

    from qzs.viz.figures import save_figure

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = {}
    for name, (figure, _) in figures.items():
        save_figure(figure, folder / f"{name}.png", also_svg=True)
        plt.close(figure)
        written[name] = folder / f"{name}.png"
    record = {key: value for key, value in result.items() if key not in ("curves", "plan")}
    record["answer"] = result["answer"].to_dict()
    # a designed controller as its fields (matrices, inputs, sample time)
    record = json_ready(record, other=lambda item: dataclasses.asdict(item)
                        if dataclasses.is_dataclass(item) else str(item))
    with atomic_path(folder / "study.json") as tmp:
        tmp.write_text(json_text(record), encoding="utf-8")
    written["json"] = folder / "study.json"
    e = html.escape
    answer = result["answer"]
    parts = [html_head(title, _STYLE), f"<h1>{e(title)}</h1>",
             f"<div class='verdict {e(answer.label.split()[0])}'><b>Paper:</b> "
             f"{e(answer.statement)}<br><b>Here: {e(answer.label)}</b>: {e(answer.answer)}"
             f"<br><small>{e(answer.evidence)}</small></div>"]
    for name, (_, caption) in figures.items():
        parts.append(html_figure(written[name], name, e(caption)))
    for heading, rows in tables:
        if not rows:
            continue
        headers = list(rows[0])
        parts.append(f"<h2>{e(heading)}</h2>")
        parts.append(html_table(headers, [[_cell(r.get(h)) for h in headers] for r in rows]))
    parts.append(f"<h2>How it was run</h2><p>{e(how)}</p></body></html>")
    with atomic_path(folder / "report.html") as tmp:
        tmp.write_text("\n".join(parts), encoding="utf-8")
    written["report"] = folder / "report.html"
    return written
