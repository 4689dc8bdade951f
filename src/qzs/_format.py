"""How numbers are shown: in decibels, as text, as JSON and CSV, in report tables.

Figures, reports (``report.html`` of ``qzs paper`` and ``qzs design``, ``report.md`` of
``qzs hexapod study`` and ``qzs experiment``), the command line's summaries and the
metrics files all show numbers through these helpers, so that they say the same thing
the same way: NaN and inf as JSON's null and as an empty CSV cell, an undefined value
in words or as a dash with a numbered footnote giving the reason.
"""
import csv
import html
import io
import json
import math
import numbers
from collections.abc import Mapping
from pathlib import Path

import numpy as np

__all__ = ["UndefinedValue", "DIMENSIONLESS", "with_unit", "unit_label", "decibels", "number",
           "json_ready", "json_text", "csv_text", "html_head", "html_table", "html_figure",
           "markdown_table", "footnoted", "step_line", "STEP_RECORD_UNITS", "format_bytes"]

#: Units of a step record's entries (:meth:`qzs.engine.step_search.StepChoice.attributes`).
STEP_RECORD_UNITS = {"step": "", "step_error_db": "dB", "step_tolerance_db": "dB",
                     "step_error_m": "m", "step_tolerance_m": "m", "step_band_low": "Hz",
                     "step_band_high": "Hz", "step_reference_dt": "s",
                     "step_probe_duration": "s", "step_reason": ""}


class UndefinedValue(float):
    """A NaN that says why it is undefined: ``math.isnan`` is true, ``reason`` the why.

    Its ``repr`` is ``nan (the reason)``, so a printed dict of metrics explains each of its
    NaNs; ``str`` and number formats give ``nan``, and arithmetic gives plain NaN floats.

    Parameters
    ----------
    reason : str
        Why the value is undefined.
    """

    reason: str

    def __new__(cls, reason: str) -> "UndefinedValue":
        value = super().__new__(cls, math.nan)
        value.reason = str(reason)
        return value

    def __repr__(self) -> str:
        return f"nan ({self.reason})"

    def __str__(self) -> str:
        return "nan"

    def __reduce__(self):
        return type(self), (self.reason,)


#: Units that mean "no unit": CF's ``1`` (ratios, counts, flags), ``-`` and none.
DIMENSIONLESS = frozenset({"", "1", "-"})


def with_unit(text, unit):
    """A number's text and its unit, the one notation everywhere: ``0.25 m``, and a
    dimensionless value bare (``0.1715``, never ``0.1715 1``).

    Parameters
    ----------
    text : str
        The number as text.
    unit : str or None
        Its unit (``"1"``, ``"-"``, ``""`` or None: dimensionless).

    Returns
    -------
    str
    """
    return text if unit is None or unit in DIMENSIONLESS else f"{text} {unit}"


def unit_label(name, unit):
    """A quantity's name and its unit in brackets, for axes, headings and labels:
    ``stroke [m]``, and ``[-]`` for a dimensionless one (never ``[1]``).

    Parameters
    ----------
    name : str
        The quantity.
    unit : str or None
        Its unit (``"1"``, ``"-"``, ``""`` or None: dimensionless).

    Returns
    -------
    str
    """
    return f"{name} [{'-' if unit is None or unit in DIMENSIONLESS else unit}]"


def step_line(run):
    """How a run's step was chosen, in one line, from its step record's entries.

    The one way every summary, report and console line shows a step (docs/model.md §7): from
    a run's entries or a file's attributes read back (``dt`` and the entries of
    :meth:`qzs.engine.step_search.StepChoice.attributes`).

    Parameters
    ----------
    run : mapping
        ``dt`` [s] and the step record's entries (``step`` missing: given).

    Returns
    -------
    str
    """
    kind = run.get("step", "given")
    if kind == "given":
        return f"dt = {run['dt']:g} s, given (no error estimate)"
    key, unit = ("db", "dB") if "step_tolerance_db" in run else ("m", "m")
    band = ""
    if "step_band_low" in run:
        band = f" over {run['step_band_low']:g}-{run['step_band_high']:g} Hz"
    if kind == "accuracy-driven":
        return (f"dt = {run['dt']:g} s, accuracy-driven: estimated error "
                f"{run['step_error_' + key]:.2g} {unit}{band} (tolerance "
                f"{run['step_tolerance_' + key]:g} {unit}, reference dt "
                f"{run['step_reference_dt']:.3g} s, {run['step_probe_duration']:g} s probe)")
    return f"dt = {run['dt']:g} s, fallback: {run['step_reason']}"


def decibels(ratio, floor=None):
    """An amplitude ratio in decibels, ``20 log10 |ratio|`` [dB].

    Parameters
    ----------
    ratio : float, complex or array_like
        Amplitude ratio [-], real or complex (a magnitude in some unit gives dB re 1 of
        that unit).
    floor : float, optional
        Smallest magnitude converted [-]: smaller ones, 0 included, give
        ``decibels(floor)`` (so that a figure can draw them). Without it 0 gives -inf.

    Returns
    -------
    float or ndarray
        A float for a number (:func:`math.log10`), an array of the shape of ``ratio``
        otherwise (:func:`numpy.log10`); NaN stays NaN.
    """
    if isinstance(ratio, numbers.Number):
        magnitude = abs(ratio)
        if floor is not None and magnitude < floor:
            magnitude = floor
        return 20 * math.log10(magnitude) if magnitude != 0 else -math.inf
    values = np.asarray(ratio)
    magnitude = np.abs(values if np.iscomplexobj(values) else values.astype(float, copy=False))
    with np.errstate(divide="ignore", invalid="ignore"):
        if floor is not None:
            magnitude = np.maximum(magnitude, floor)
        return 20 * np.log10(magnitude)


def number(value, digits=3, unit="", *, undefined="undefined", infinite=None):
    """``value`` as text: ``digits`` significant digits (format ``g``) and its unit.

    Parameters
    ----------
    value : float, int, bool or None
        What to show; anything else is shown as its ``str``.
    digits : int
        Significant digits of a float [-].
    unit : str
        Appended after a space to a number shown (not to ``undefined``).
    undefined : str
        What None and NaN say (``"undefined"``; a report table's dash).
    infinite : str, optional
        What +-inf says; default ``undefined``.

    Returns
    -------
    str
        A bool as ``"yes"`` or ``"no"``, an integer with all its digits.
    """
    if value is None:
        return undefined
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        text = f"{value}"
    elif isinstance(value, (float, np.floating)):
        if math.isnan(value):
            return undefined
        if math.isinf(value):
            return undefined if infinite is None else infinite
        text = f"{value:.{digits}g}"
    else:
        return str(value)
    return with_unit(text, unit)


def json_ready(value, other=None):
    """``value`` in plain JSON types, for ``json.dumps(..., allow_nan=False)``.

    Mappings (keys as strings), lists, tuples and sets item by item, a numpy array as
    nested lists; a bool, an integer and a float (numpy's too) as ``bool``, ``int`` and
    ``float``, NaN and +-inf as None; a complex number as ``[real, imag]``; a path as its
    string. None and strings stay as they are.

    Parameters
    ----------
    value : object
        What to convert.
    other : callable, optional
        ``other(item)`` converts an item of none of those types; default: kept as it is
        (``json.dumps`` then refuses it).

    Returns
    -------
    object
    """
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, Mapping):
        return {str(k): json_ready(v, other) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [json_ready(v, other) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist(), other)
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, (complex, np.complexfloating)):
        return [json_ready(value.real), json_ready(value.imag)]
    if isinstance(value, Path):
        return str(value)
    return value if other is None else other(value)


def json_text(value, indent=2):
    """Strict JSON text of ``value``: :func:`json_ready`'s conversion, NaN and inf as null.

    Parameters
    ----------
    value : object
        What to write (a metrics document).
    indent : int
        Spaces per level of nesting.

    Returns
    -------
    str
    """
    return json.dumps(json_ready(value), indent=indent, allow_nan=False)


def csv_text(rows):
    """Rows of a table (dicts) as CSV text: a header of every key, in the order met.

    A key a row lacks, and a float that is NaN or +-inf, is an empty cell.

    Parameters
    ----------
    rows : sequence of dict
        Column name -> value.

    Returns
    -------
    str
    """
    columns = list(dict.fromkeys(key for row in rows for key in row))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns)
    writer.writeheader()
    writer.writerows({key: "" if isinstance(value, (float, np.floating))
                      and not math.isfinite(value) else value for key, value in row.items()}
                     for row in rows)
    return buffer.getvalue()


def html_head(title, style):
    """The start of an HTML page, through ``<body>``.

    Parameters
    ----------
    title : str
        The page's title (escaped).
    style : str
        Its CSS.

    Returns
    -------
    str
    """
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
            f"</title><style>{style}</style></head><body>")


def html_table(headers, rows, *, cells_html=False, separator="\n"):
    """An HTML table: one header row, then a row per item of ``rows``.

    Parameters
    ----------
    headers : sequence of str
        Column titles (escaped).
    rows : iterable of sequence
        The cells, each escaped as its ``str``, or put in as they are if ``cells_html``.
    cells_html : bool
        The cells are HTML already (escaped by the caller, with markup such as a footnote).
    separator : str
        Between the table's lines (``""`` puts the table on one line).

    Returns
    -------
    str
    """
    cell = (lambda c: c) if cells_html else (lambda c: html.escape(str(c)))
    lines = ["<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in headers) + "</tr>"]
    lines += ["<tr>" + "".join(f"<td>{cell(c)}</td>" for c in row) + "</tr>" for row in rows]
    lines.append("</table>")
    return separator.join(lines)


def html_figure(path, name, caption):
    """A figure of a report: its PNG linked to itself, the caption, links to PNG and SVG.

    Parameters
    ----------
    path : str or Path
        The PNG, beside the page; its SVG has the same name.
    name : str
        The image's alternative text (escaped).
    caption : str
        The caption, HTML (escaped by the caller).

    Returns
    -------
    str
    """
    e = html.escape
    png, svg = Path(path).name, Path(path).with_suffix(".svg").name
    return (f"<figure><a href='{e(png)}'><img src='{e(png)}' alt='{e(name)}'></a>"
            f"<figcaption>{caption} Full size: <a href='{e(png)}'>PNG</a>, "
            f"<a href='{e(svg)}'>SVG</a>.</figcaption></figure>")


def markdown_table(headers, rows):
    """A Markdown table as lines: the header, the rule, a line per item of ``rows``.

    Parameters
    ----------
    headers : sequence of str
        Column titles.
    rows : iterable of sequence
        The cells, each shown as its ``str`` (Markdown, unescaped).

    Returns
    -------
    list of str
    """
    return (["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
            + ["| " + " | ".join(str(c) for c in row) + " |" for row in rows])


def footnoted(mark, reason, notes):
    """``mark`` with the number of the footnote that gives ``reason``, as HTML.

    Parameters
    ----------
    mark : str
        What stands in the cell (a dash).
    reason : str
        The footnote's text.
    notes : dict
        Reason -> number, in the order the reasons were first met; gains ``reason``
        (numbered next) if it is new.

    Returns
    -------
    str
        ``mark<sup>number</sup>``.
    """
    return f"{mark}<sup>{notes.setdefault(reason, len(notes) + 1)}</sup>"


def format_bytes(count):
    """A byte count for people: ``1.5 GiB``.

    Parameters
    ----------
    count : int or float
        Bytes [B].

    Returns
    -------
    str
    """
    value = float(count)
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(value) < 1024 or unit == "TiB":
            return f"{value:.0f} {unit}" if unit == "B" else f"{value:.1f} {unit}"
        value /= 1024
    return f"{value:.1f} TiB"  # pragma: no cover
