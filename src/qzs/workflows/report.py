"""``qzs paper``: run the paper's studies, draw its figures, decide its claims from the data.

Writes to an output folder: one figure per paper figure (PNG and SVG),
``metrics.json`` and ``metrics.csv`` (per study and case), and ``report.html``,
which puts each figure beside the paper's claim (docs/model.md §13, "What the paper
reports") and says, from the numbers, whether the claim is reproduced.
"""
import csv
import html
import io as _io
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from qzs._version import __version__
from qzs.analysis.spectral import band_mask
from qzs.iotools.files import atomic_path
from qzs.model.isolator import IsolatorParameters, passive_natural_frequency
from qzs.workflows.studies import load_study, run_studies, shipped_studies
from qzs.viz.identify import plot_spring_fit
from qzs.viz.transmissibility import plot_transmissibility

__all__ = ["CLAIMS", "Verdict", "decide_claims", "write_paper_outputs", "run_paper"]


@dataclass(frozen=True)
class Verdict:
    """Whether a claim is reproduced (True/False, None if partly), with the numbers.

    Attributes
    ----------
    claim : str
        The claim's id, a key of :data:`CLAIMS`.
    statement : str
        What the paper states.
    reproduced : bool or None
        True if reproduced, False if not, None if partly.
    evidence : str
        The numbers the decision rests on.
    """

    claim: str
    statement: str
    reproduced: object
    evidence: str

    @property
    def label(self):
        """``"reproduced"``, ``"not reproduced"`` or ``"partly reproduced"``."""
        return {True: "reproduced", False: "not reproduced", None: "partly reproduced"}[
            self.reproduced]


def _band_mean(case, low, high):
    keep = band_mask(case.frequency, low, high)
    return float(np.mean(case.magnitude[keep])) if keep.any() else float("nan")


def _band_max(case, low, high):
    keep = band_mask(case.frequency, low, high)
    return float(np.max(case.magnitude[keep])) if keep.any() else float("nan")


def _at(case, frequency):
    return float(np.interp(frequency, case.frequency, case.magnitude))


def _non_decreasing(values):
    return all(b >= a for a, b in zip(values, values[1:]))


def _fmt(values, digits=3):
    return ", ".join(f"{v:.{digits}g}" for v in values)


def _resonance_masked(results):
    fn = passive_natural_frequency(IsolatorParameters(), -0.060)
    cases = results["stiction"].cases
    locked = [c.stats["locked_fraction_below_half_hz"] for c in cases]
    masked = all(f >= 0.9 for f, c in zip(locked, cases) if c.settings["stiction_force"] >= 5)
    ok = 0.07 <= fn <= 0.09 and masked
    peaks = [_band_max(c, 0.0, 1.0) for c in cases]
    return ok, (f"linearised passive natural frequency {fn:.3f} Hz; fraction of time locked "
                f"while the chirp is below 0.5 Hz ({', '.join(c.label for c in cases)}): "
                f"{_fmt(locked)} (masked if >= 0.9 for Fs >= 5 N: a locked payload moves with "
                f"the base, T = 1, no resonance). The Welch estimate's spikes below 1 Hz "
                f"(max T {_fmt(peaks)}) are not a resonance: the chirp puts almost no base "
                "acceleration there, while stick-slip later in the run adds broadband payload "
                "content to every segment")


def _pi_resonance_range(results):
    cases = [c for c in results["pi_gains"].cases if c.settings.get("pi_kp", 0) <= 50]
    fns = [c.linear["undamped_natural_frequency"] for c in cases]
    ok = all(0.075 <= f <= 0.46 for f in fns)
    return ok, (f"undamped natural frequency sqrt((k + Kp)/m)/2pi for Kp <= 50 N/m "
                f"({', '.join(c.label for c in cases)}): {_fmt(fns)} Hz; paper: 0.08-0.45 Hz")


def _stiction_low_frequency(results):
    cases = results["stiction"].cases
    low = [_band_mean(c, 1.0, 3.0) for c in cases]
    onset = [c.metrics["isolation_onset"] for c in cases]
    onset_ok = _non_decreasing([o if np.isfinite(o) else np.inf for o in onset])
    ok = _non_decreasing(low) and onset_ok
    return ok, (f"mean T over 1-3 Hz for {', '.join(c.label for c in cases)}: {_fmt(low)} "
                f"(must rise with Fs); isolation onset: {_fmt(onset)} Hz (must not fall)")


def _viscous_high_frequency(results):
    cases = results["viscous"].cases
    rows = {f: [_at(c, f) for c in cases] for f in (8.0, 12.0, 16.0)}
    ok = all(all(b > a for a, b in zip(v, v[1:])) for v in rows.values())
    text = "; ".join(f"T({f:g} Hz) = {_fmt(v)}" for f, v in rows.items())
    return ok, f"{text} for {', '.join(c.label for c in cases)} (must rise with Cv)"


def _pi_low_frequency(results):
    cases = results["pi_gains"].cases
    low = [_band_mean(c, 0.5, 4.0) for c in cases]
    high = [_at(c, 12.0) for c in cases]
    spread = (max(high) - min(high)) / min(high)
    spoiled = low[-1] > 1.1 * low[0]
    held = cases[0].stats["stop_contacts"] == 0
    ok = spoiled and held and spread < 0.1
    return ok, (f"mean T over 0.5-4 Hz for {', '.join(c.label for c in cases)}: {_fmt(low)} "
                f"(highest gains must exceed the lowest by > 10 %); T(12 Hz): {_fmt(high)} "
                f"(spread {100 * spread:.1f} %, must stay < 10 %); lowest gains hold z: "
                f"{cases[0].stats['stop_contacts']} stop contacts, z in "
                f"[{cases[0].stats['z_min'] * 1e3:.1f}, {cases[0].stats['z_max'] * 1e3:.1f}] mm")


def _no_pi_stops(results):
    without, with_pi = results["no_pi"].cases
    ok = without.stats["stop_contacts"] > 0 and with_pi.stats["stop_contacts"] == 0
    return ok, (f"stop contacts without PI: {without.stats['stop_contacts']} (z reached "
                f"{without.stats['z_min'] * 1e3:.1f} mm); with PI: "
                f"{with_pi.stats['stop_contacts']} (z in [{with_pi.stats['z_min'] * 1e3:.1f}, "
                f"{with_pi.stats['z_max'] * 1e3:.1f}] mm)")


def _damping_small_effect(results):
    reference, *damped = results["damping"].cases
    changes = []
    for case in damped:
        keep = band_mask(case.frequency, 1.5, 20.0)
        ratio_db = 20 * np.log10(case.magnitude[keep] / reference.magnitude[keep])
        changes.append(float(-np.min(ratio_db)))
    ok = all(c < 3.0 for c in changes)
    return ok, (f"largest reduction of T over 1.5-20 Hz against Kd = 0 for "
                f"{', '.join(c.label for c in damped)}: {_fmt(changes)} dB "
                "(\"did not help much\" if < 3 dB)")


def _experiment_shape(results):
    case = results["processing"].cases[0]
    processed = case.extra
    f, t = processed["frequency"], processed["magnitude"]
    trusted = f >= 1.5 * processed["highpass"]
    peak_f = float(f[trusted][np.argmax(t[trusted])])
    rolloff = f >= 4.0
    slope = np.polyfit(np.log10(f[rolloff]), 20 * np.log10(t[rolloff]), 1)[0]
    t12 = float(np.interp(12.0, f, t))
    checks = [peak_f < 3.5, slope < 0, abs(t12 - 0.3) <= 0.1]
    ok = True if all(checks) else (False if not any(checks) else None)
    return ok, (f"processed like the experiment ({processed['n_averages']} averages, "
                f"{processed['highpass']:g} Hz high-pass): peak of T above 1.5 Hz at "
                f"{peak_f:.2f} Hz (paper: below 3.5 Hz); slope above 4 Hz {slope:.1f} dB/decade "
                f"(paper: rolls off); T(12 Hz) = {t12:.3f} (paper: 0.3, accepted 0.2-0.4)")


#: claim id -> (the paper's statement (docs/model.md §13), studies it needs, decision function)
CLAIMS = {
    "resonance_masked": ("Passive resonance about 0.08 Hz, masked by stiction.",
                         ("stiction",), _resonance_masked),
    "pi_resonance_range": ("PI moves the resonance within 0.08-0.45 Hz.",
                           ("pi_gains",), _pi_resonance_range),
    "stiction_low_frequency": ("More stiction: higher transmissibility at low frequency, "
                               "narrower isolation band.", ("stiction",),
                               _stiction_low_frequency),
    "viscous_high_frequency": ("Above about 3 Hz the viscous friction governs: more Cv, "
                               "higher transmissibility.", ("viscous",), _viscous_high_frequency),
    "pi_low_frequency": ("High PI gains spoil low-frequency isolation; gains should be just "
                         "high enough to hold z.", ("pi_gains",), _pi_low_frequency),
    "no_pi_stops": ("Without the PI loop the payload drifts to the hard stops "
                    "(Section 4.1).", ("no_pi",), _no_pi_stops),
    "damping_small_effect": ("Active damping did not help much.", ("damping",),
                             _damping_small_effect),
    "experiment_shape": ("Experiment: resonance peaks below 3.5 Hz, roll-off from 4 Hz, "
                         "transmissibility 0.3 at 12 Hz.", ("processing",), _experiment_shape),
}


def decide_claims(study_results):
    """Decide every claim whose studies were run; returns a list of :class:`Verdict`.

    Parameters
    ----------
    study_results : sequence of StudyResult
        The studies run; a claim is decided only if every study it needs is among them.

    Returns
    -------
    list of Verdict
        In the order of :data:`CLAIMS`.
    """
    by_name = {r.study.name: r for r in study_results}
    verdicts = []
    for claim, (statement, needs, decide) in CLAIMS.items():
        if all(n in by_name for n in needs):
            ok, evidence = decide(by_name)
            verdicts.append(Verdict(claim, statement, ok, evidence))
    return verdicts


def _figures(result, folder):
    """Draw a study's views; returns ``[(figure name, png path)]``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    drawn = []
    study = result.study
    if study.kind == "spring_characteristic":
        extra = result.cases[0].extra
        path = folder / "fig05_spring.png"
        fig = plot_spring_fit(extra["displacement"], extra["force"],
                              extra["fit"]["spring_force"], extra["fit"]["spring_shape"],
                              path=path, title=study.title)
        plt.close(fig)
        return [("fig05_spring", path)]
    for view in study.views:
        curves = [dict(label=c.label, frequency=c.frequency, magnitude=c.magnitude,
                       linear=c.linear.get("magnitude")) for c in result.cases]
        untrusted = None
        if study.kind == "processing":
            case = result.cases[0]
            curves = [dict(label=f"ideal: accelerations, {case.stats['n_averages']} averages",
                           frequency=case.frequency, magnitude=case.magnitude,
                           linear=case.linear.get("magnitude")),
                      dict(label=f"experiment-style: velocities through the "
                                 f"{case.extra['highpass']:g} Hz high-pass, "
                                 f"{case.extra['n_averages']} averages",
                           frequency=case.extra["frequency"], magnitude=case.extra["magnitude"])]
            untrusted = 1.5 * case.extra["highpass"]
        path = folder / f"{view['figure']}.png"
        fig = plot_transmissibility(curves, frequency_range=tuple(view["frequency_range"]),
                                    scale=view.get("frequency_scale", "linear"),
                                    title=study.title, path=path, untrusted_below=untrusted)
        plt.close(fig)
        drawn.append((view["figure"], path))
    return drawn


def _metric_rows(study_results):
    rows = []
    for result in study_results:
        for case in result.cases:
            row = {"study": result.study.name, "case": case.label}
            row.update({f"param.{k}": v for k, v in case.settings.items()})
            row.update(case.metrics)
            row.update({k: v for k, v in case.stats.items()})
            if case.linear:
                row["linear_undamped_natural_frequency"] = case.linear[
                    "undamped_natural_frequency"]
            row["seconds"] = case.seconds
            rows.append(row)
    return rows


def _json_ready(value):
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return None if not np.isfinite(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    return value


def write_paper_outputs(study_results, folder, *, quick=False, wall_seconds=None):
    """Write figures, ``metrics.json``, ``metrics.csv`` and ``report.html`` into ``folder``.

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

    Returns
    -------
    list of Verdict
        As :func:`decide_claims` gives them.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    figures = {r.study.name: _figures(r, folder) for r in study_results}
    verdicts = decide_claims(study_results)
    rows = _metric_rows(study_results)

    document = {"qzs_version": __version__, "quick": quick, "wall_seconds": wall_seconds,
                "studies": {r.study.name: {"title": r.study.title, "seconds": r.seconds,
                                           "cases": [row for row in rows
                                                     if row["study"] == r.study.name]}
                            for r in study_results},
                "claims": [{"claim": v.claim, "statement": v.statement, "verdict": v.label,
                            "evidence": v.evidence} for v in verdicts]}
    with atomic_path(folder / "metrics.json") as tmp:
        tmp.write_text(json.dumps(_json_ready(document), indent=2), encoding="utf-8")
    columns = list(dict.fromkeys(k for row in rows for k in row))
    buffer = _io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns)
    writer.writeheader()
    writer.writerows(rows)
    with atomic_path(folder / "metrics.csv") as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8")
    with atomic_path(folder / "report.html") as tmp:
        tmp.write_text(_html(study_results, figures, verdicts, quick, wall_seconds),
                       encoding="utf-8")
    return verdicts


_STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;color:#222}
section{border-top:1px solid #ccc;padding-top:1em;margin-top:2em}
.fig{display:flex;gap:1em;flex-wrap:wrap}.fig img{max-width:540px;width:100%}
.claim{padding:.6em 1em;margin:.6em 0;border-left:6px solid #999;background:#f7f7f7}
.reproduced{border-color:#2a8a2a}.not{border-color:#c0392b}.partly{border-color:#d4a017}
table{border-collapse:collapse;font-size:.85em}td,th{border:1px solid #ddd;padding:.2em .5em;
text-align:right}th{background:#eee}"""


def _html(study_results, figures, verdicts, quick, wall_seconds):
    by_claim = {v.claim: v for v in verdicts}
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>qzs paper report"
             f"</title><style>{_STYLE}</style></head><body>",
             "<h1>Semi-active QZS isolator: the paper's studies, reproduced</h1>",
             f"<p>qzs {html.escape(__version__)}; {'quick' if quick else 'full-length'} runs"
             + (f"; wall time {wall_seconds:.1f} s" if wall_seconds else "") +
             ". Transmissibility is the amplitude ratio sqrt(S_payload/S_base) of the "
             "accelerations (Hann window, Welch), shown in dB. Dashed: the linearised "
             "model (frictionless guide, viscous damping only).</p>",
             "<h2>Claims</h2><ul>"]
    for v in verdicts:
        parts.append(f"<li><b>{html.escape(v.label)}</b>: {html.escape(v.statement)}</li>")
    parts.append("</ul>")
    for result in study_results:
        study = result.study
        parts.append(f"<section><h2>{html.escape(study.title)}</h2>"
                     f"<p>{len(result.cases)} case(s), {result.seconds:.1f} s of simulation "
                     f"and analysis; definition <code>{html.escape(Path(study.source).name)}"
                     "</code></p><div class='fig'>")
        for name, path in figures.get(study.name, []):
            parts.append(f"<figure><img src='{html.escape(path.name)}' alt='{name}'>"
                         f"<figcaption>{html.escape(name)}</figcaption></figure>")
        parts.append("</div>")
        for claim in study.claims:
            verdict = by_claim.get(claim)
            if verdict is None:
                continue
            css = {True: "reproduced", False: "not", None: "partly"}[verdict.reproduced]
            parts.append(f"<div class='claim {css}'><b>Paper:</b> "
                         f"{html.escape(verdict.statement)}<br><b>Here: "
                         f"{html.escape(verdict.label)}</b>: {html.escape(verdict.evidence)}"
                         "</div>")
        parts.append(_case_table(result))
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _case_table(result):
    if result.study.kind == "spring_characteristic":
        fit = result.cases[0].extra["fit"]
        return (f"<p>Fit (model convention, F = -a tanh(b z)): a = {fit['spring_force']:.3f} N "
                f"[{fit['spring_force_interval'][0]:.3f}, {fit['spring_force_interval'][1]:.3f}],"
                f" b = {fit['spring_shape']:.2f} 1/m [{fit['spring_shape_interval'][0]:.2f}, "
                f"{fit['spring_shape_interval'][1]:.2f}] (95 %); Table 1: a = 60.84 N, "
                "b = 78.10 1/m. The paper's Fig. 5 prints a = -60.84 N in the test machine's "
                "displacement convention.</p>")
    head = ["case", "resonance [Hz]", "peak", "isolation onset [Hz]", "T(1 Hz)", "T(4 Hz)",
            "T(12 Hz)", "stop contacts", "locked [%]", "f_n linear [Hz]"]
    rows = ["<table><tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr>"]
    for case in result.cases:
        m, s = case.metrics, case.stats
        cells = [case.label, f"{m['resonance_frequency']:.3g}", f"{m['resonance_peak']:.3g}",
                 f"{m['isolation_onset']:.3g}", f"{m['transmissibility_at_1_hz']:.3g}",
                 f"{m['transmissibility_at_4_hz']:.3g}", f"{m['transmissibility_at_12_hz']:.3g}",
                 f"{s['stop_contacts']}", f"{100 * s['locked_fraction']:.1f}",
                 f"{case.linear['undamped_natural_frequency']:.3g}"]
        rows.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    rows.append("</table>")
    return "\n".join(rows)


def run_paper(definitions=None, folder="results/paper", *, quick=False, workers=None,
              progress=True):
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
        Worker processes; default all cores.
    progress : bool
        Show a progress bar over cases.

    Returns
    -------
    results : list of StudyResult
    verdicts : list of Verdict
    wall_seconds : float
        Wall time of the runs [s].
    """
    import time

    paths = shipped_studies() if definitions is None else definitions
    studies = [load_study(p) for p in paths]
    start = time.perf_counter()
    results = run_studies(studies, quick=quick, workers=workers, progress=progress)
    wall = time.perf_counter() - start
    verdicts = write_paper_outputs(results, folder, quick=quick, wall_seconds=wall)
    return results, verdicts, wall
