"""The paper's ``report.html``: claims, each study's settings, figures, verdicts and table."""
import html
from pathlib import Path


from qzs._format import html_figure, html_head, html_table
from qzs._version import __version__
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, passive_natural_frequency
from qzs.model.registry import format_value, unit_of, update_parameters
from qzs.workflows.paper.report_spring import spring_fit_html, spring_statement
from qzs.workflows.paper.report_step import step_statement
from qzs.workflows.paper.studies import RUN_UNITS
from qzs.workflows.findings.figures import curve_files
from qzs.workflows.findings.tables import metric_cell, run_settings
from qzs.workflows.findings.verdicts import case_value

__all__ = ["PAPER_CHIRP_DURATION", "paper_html", "settings_table", "case_table"]

_STYLE = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;
color:#222}section{border-top:1px solid #ccc;padding-top:1em;margin-top:2em}
figure{margin:1em 0}figure img{width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#444}
.claim{padding:.6em 1em;margin:.6em 0;border-left:6px solid #999;background:#f7f7f7}
.reproduced{border-color:#2a8a2a}.not{border-color:#c0392b}.partly{border-color:#d4a017}
.undecidable{border-color:#777}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0}td,th{border:1px solid #ddd;
padding:.2em .5em;text-align:right}th{background:#eee}td:first-child,th:first-child{text-align:left}
.notes{font-size:.85em;color:#444}"""

_CSS = {"reproduced": "reproduced", "not reproduced": "not", "partly reproduced": "partly",
        "not decidable": "undecidable"}

#: The run settings a study's section lists: key of :attr:`CaseResult.run
#: <qzs.workflows.paper.studies.CaseResult>` -> name (units from
#: :data:`qzs.workflows.paper.studies.RUN_UNITS`).
#: The chirp length the paper states [s] (a report that differs says why).
PAPER_CHIRP_DURATION = 2000.0
_RUN_ROWS = (("solver", "solver"), ("dt", "time step"), ("sample_rate", "sample rate"),
             ("chirp_amplitude", "chirp amplitude"), ("chirp_f0", "chirp from"),
             ("chirp_f1", "chirp to"), ("chirp_duration", "chirp duration"),
             ("window", "window"), ("fft_length", "FFT length [samples]"),
             ("n_averages", "averages"), ("overlap", "overlap"),
             ("coherence_min", "trusted: coherence at least"),
             ("base_share_min", "trusted: base power share at least"))


def paper_html(study_results, figures, verdicts, quick, wall_seconds):
    """The paper's ``report.html``: claims, then per study its settings, figures, verdicts, table.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run.
    figures : dict
        Study name -> its drawn figures (:func:`~qzs.workflows.findings.figures.draw_studies`).
    verdicts : sequence of Verdict
        The claims decided.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float or None
        Wall time of the runs [s].

    Returns
    -------
    str
    """
    e = html.escape
    parts = [html_head("qzs paper report", _STYLE),
             "<h1>Semi-active QZS isolator: the paper's studies, reproduced</h1>",
             f"<p>qzs {e(__version__)}; {'quick' if quick else 'full-length'} runs"
             + (f"; wall time {wall_seconds:.1f} s" if wall_seconds else "") +
             f". <b>Spring</b>: {e(spring_statement(study_results))}"
             f". <b>Integration step</b>: {e(step_statement(study_results))}</p><p>"
             "Transmissibility is the amplitude ratio sqrt(S_payload/S_base) of the "
             "accelerations (Welch averages of Hann-windowed segments), shown in dB. Dashed: the "
             "linearised model (frictionless guide, viscous damping only). Each study's run "
             "settings are listed in its section.</p>",
             "<p><b>Trusted bins</b> (docs/model.md §10): a frequency bin is used only where "
             "the magnitude-squared coherence of base and payload reaches the threshold given "
             "in each study's settings (there the PSD ratio exceeds the coherent response by at "
             "most 1/sqrt(threshold)), where the base put a non-negligible share of its own "
             "power, above 0 Hz, and above 1.5 times a measurement high-pass corner. Untrusted "
             "bins are drawn faint and never enter a metric or a claim: a metric they would "
             "decide is shown as a dash, with the reason in the notes below the table.</p>",
             "<h2>Claims</h2><ul>"]
    for v in verdicts:
        parts.append(f"<li><b>{e(v.label)}</b>: {e(v.statement)} "
                     f"(<a href='#{e(v.study)}'>{e(v.study)}</a>)</li>")
    parts.append("</ul>")
    for result in study_results:
        study = result.study
        parts.append(f"<section id='{e(study.name)}'><h2>{e(study.title)}</h2>"
                     f"<p>{len(result.cases)} case(s), {result.seconds:.1f} s of simulation "
                     f"and analysis; definition <code>{e(Path(study.source).name)}</code>.</p>")
        if study.kind != "spring_characteristic":
            parts.append(settings_table(result))
        for name, path, notes in figures.get(study.name, []):
            caption = [f"<b>{e(name)}</b>."]
            if study.kind != "spring_characteristic":
                caption.append("Solid: trusted bins; faint: untrusted bins. Lower panel: "
                               "coherence of base and payload.")
            caption.extend(e(note) for note in notes)
            parts.append(html_figure(path, name, " ".join(caption)))
        files = [p.name for p in curve_files(result, ".")]
        if files:
            links = " and ".join(f"<a href='{e(f)}'>{e(f)}</a>" for f in files)
            what = ("the measured points and the fitted law at them"
                    if study.kind == "spring_characteristic" else
                    "per case and frequency the transmissibility, its phase, the coherence, "
                    "the trusted flag and the linearised model, the case's parameters beside it")
            parts.append(f"<p class='notes'>The curves of these figures as data: {links} "
                         f"(NetCDF CF-1.10; CSV with a units row under the column names): "
                         f"{e(what)}.</p>")
        for verdict in verdicts:
            if verdict.study != study.name:
                continue
            parts.append(f"<div class='claim {_CSS[verdict.label]}'><b>Paper:</b> "
                         f"{e(verdict.statement)}<br><b>Here: {e(verdict.label)}</b>: "
                         f"{e(verdict.evidence)}</div>")
        parts.append(case_table(result))
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _duration_note(settings):
    """Why the chirp is not the paper's 2000 s: it lasts what its Welch averages need."""
    keys = ("chirp_duration", "n_averages", "fft_length", "sample_rate", "overlap")
    if any(isinstance(settings.get(k), (list, type(None))) for k in keys) \
            or settings["chirp_duration"] == PAPER_CHIRP_DURATION:
        return ""
    return (f"<p class='notes'>Chirp duration {settings['chirp_duration']:.6g} s, not the "
            f"paper's {PAPER_CHIRP_DURATION:g} s: the record lasts what "
            f"{settings['n_averages']} complete Welch averages of {settings['fft_length']} "
            f"samples at {settings['sample_rate']:g} Hz with overlap {settings['overlap']:g} "
            "need (qzs.analysis.spectral.required_duration).</p>")


def settings_table(result):
    """A study's run settings and its cases' parameters, as HTML tables.

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    str
        HTML.
    """
    settings = run_settings(result)
    head, cells = [], []
    for key, name in _RUN_ROWS:
        if key not in settings:
            continue
        unit = RUN_UNITS[key] if RUN_UNITS[key] != "1" else ""
        value = settings[key]
        text = ", ".join(format_value(v) for v in value) if isinstance(value, list) \
            else format_value(value)
        head.append(f"{name} [{unit}]" if unit else name)
        cells.append(text)
    names = list(dict.fromkeys(k for c in result.cases for k in c.settings))
    parameters = html_table(["case", *(f"{n} [{unit_of(n)}]" for n in names)],
                            ([case.label, *(format_value(case_value(case, n)) for n in names)]
                             for case in result.cases))
    return "\n".join(["<p>Run settings (every case):</p>",
                      html_table(head, [cells], separator="") + _duration_note(settings),
                      parameters + "<p class='notes'>Every other parameter at its default "
                      "(Table 1, docs/model.md §11; <code>qzs params</code>).</p>"])


_TABLE = (("trusted_from", "trusted from [Hz]"), ("resonance_frequency", "peak of T at [Hz]"),
          ("resonance_peak", "T at peak [-]"), ("isolation_onset", "isolation onset [Hz]"),
          ("minus_3db_frequency", "-3 dB [Hz]"), ("rolloff_db_per_decade", "roll-off [dB/decade]"),
          ("transmissibility_at_1_hz", "T(1 Hz) [-]"), ("transmissibility_at_4_hz", "T(4 Hz) [-]"),
          ("transmissibility_at_12_hz", "T(12 Hz) [-]"))


def case_table(result):
    """A study's metrics per case, a dash and a note where undefined, as HTML.

    Parameters
    ----------
    result : StudyResult
        A study.

    Returns
    -------
    str
        HTML.
    """
    e = html.escape
    if result.study.kind == "spring_characteristic":
        return spring_fit_html(result)
    notes = {}

    def cell(metrics, reasons, name):
        return metric_cell(metrics.get(name, float("nan")), reasons.get(name, "not computed"),
                           notes, dash="&mdash;", text=lambda value: f"{value:.3g}")

    head = ["case", *(title for _, title in _TABLE), "stop contacts", "locked [%]",
            "f_n with PI [Hz]"]
    entries = [(case.label, case.metrics, case.reasons, case) for case in result.cases]
    if result.study.kind == "processing":
        case = result.cases[0]
        entries.append((f"{case.label}, experiment-style", case.extra["metrics"],
                        case.extra.get("reasons", {}), case))
    table = []
    for label, metrics, reasons, case in entries:
        s = case.stats
        table.append([e(label), *(cell(metrics, reasons, name) for name, _ in _TABLE),
                      e(f"{s['stop_contacts']}"), e(f"{100 * s['locked_fraction']:.1f}"),
                      e(f"{case.linear['undamped_natural_frequency']:.3g}")])
    isolator, controller = update_parameters(IsolatorParameters(spring=result.spring),
                                             ControllerParameters(), result.cases[0].settings)
    rows = [html_table(head, table, cells_html=True)]
    if notes:
        rows.append("<ol class='notes'>" + "".join(f"<li>{e(reason)}</li>" for reason in notes)
                    + "</ol>")
    rows.append("<p class='notes'>f_n with PI: sqrt((k + Kp)/m)/2pi, the linearised loop's undamped "
            "natural frequency, the PI's proportional gain Kp acting as a spring; the paper's "
            "\"about 0.08 Hz\" is the passive isolator's (Kp = 0): "
            f"{passive_natural_frequency(isolator, controller.position_setpoint):.3g} Hz for "
            f"{e(result.cases[0].label)}.</p>")
    return "\n".join(rows)
