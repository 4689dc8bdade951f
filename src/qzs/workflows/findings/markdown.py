"""The six-axis study's ``report.md`` and its console summary, from its rows and findings."""
import math

import numpy as np

from qzs._format import markdown_table, number
from qzs._version import __version__
from qzs.workflows.findings.tables import metric_cell, significant
from qzs.workflows.hexapod.transmissibility.result import step_text

__all__ = ["study_markdown", "study_summary"]


_TABLE = (("T_at_1_hz", "T(1 Hz) [-]"), ("T_at_2_hz", "T(2 Hz) [-]"),
          ("T_at_4_hz", "T(4 Hz) [-]"), ("T_at_8_hz", "T(8 Hz) [-]"),
          ("T_at_16_hz", "T(16 Hz) [-]"), ("resonance_frequency_hz", "peak at [Hz]"),
          ("resonance_peak", "peak T [-]"), ("isolation_onset_hz", "isolation from [Hz]"))


def study_markdown(cases, rows, findings, files, quick, wall_seconds, *, meanings, axes,
                   setup_name, comparison, matrix_names):
    """The six-axis study's ``report.md`` (:mod:`qzs.workflows.hexapod.study`).

    Parameters
    ----------
    cases : mapping
        Case label -> HexapodTransmissibility.
    rows : sequence of dict
        The metrics rows, one per case and excited axis.
    findings : sequence of str
        The findings' sentences.
    files : mapping
        Name -> path of every file written.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float or None
        Wall time of the runs [s].
    meanings : mapping
        Case label -> what the case's loop is.
    axes : tuple of str
        The base axes excited.
    setup_name : str
        The shipped set-up's file stem.
    comparison : str
        The comparison figure's file stem.
    matrix_names : mapping
        Case label -> its matrix figure's file stem.

    Returns
    -------
    str
    """
    first = next(iter(cases.values()))
    setup, s = first.setup, first.settings
    notes = {}

    def cell(row, key):
        return metric_cell(row.get(key, math.nan),
                           row.get(f"{key}_reason", "not defined on the trusted bins"), notes)

    lines = [
        "# Six paper legs in a Stewart platform: simulated 6x6 transmissibility",
        "",
        f"qzs {__version__}, `qzs hexapod study{' --quick' if quick else ''}`; "
        f"{'quick' if quick else 'full-length'} runs"
        + (f", wall time {wall_seconds:.1f} s" if wall_seconds else "") + ". "
        "Model and method: docs/hexapod.md (§9 dynamics, \"Simulated transmissibility and the "
        "shipped study\").",
        "",
        "## The platform",
        "",
        f"The shipped file `{setup_name}.toml`: six Table 1 legs (MagSpring, Stribeck "
        f"friction with stiction {setup.isolator.stiction_force:g} N, viscous "
        f"{setup.isolator.viscous_damping:g} N·s/m, stops at ±"
        f"{1e3 * setup.geometry.stroke_half:g} mm, motor limit "
        f"{setup.isolator.motor_force_max:g} N) in the cubic configuration of edge "
        f"{np.mean(setup.geometry.home_lengths):.3g} m, carrying the "
        f"{setup.platform.mass:.4g} kg their MagSprings hold at the operating point "
        "(the legs' moving parts lumped into the platform).",
        "",
        "## What \"without PI\" means here",
        "",
        "In the paper, \"without PI\" is the passive leg, whose payload drifts onto its stops. "
        "Six such legs cannot hold a platform at all: each pushes with about 61 N along a "
        "line that turns with the platform on spherical joints, a negative stiffness of "
        "about -4f/a in each translation that beats the springs' 1.6 N/m a thousandfold "
        "(docs/hexapod.md §6). Only a stiff position loop holds the platform up, which is "
        "why the shipped file runs Kp = 2000 N/m. So the study runs three loops:",
        "",
    ]
    for label, meaning in meanings.items():
        if label in cases:
            result = cases[label]
            frequencies = ", ".join(number(f, undefined="unstable")
                                    for f in result.linear_natural_frequencies)
            lines.append(f"- **{label}**: {meaning}. Linear model: "
                         f"{'stable' if result.linear_stable else 'UNSTABLE'}, natural "
                         f"frequencies {frequencies} Hz.")
    lines += ["",
              "\"P only\" answers what the integral does; \"no position loop\" is the paper's "
              "\"without PI\", reported for what it does to the platform rather than as an "
              "isolator's curve.", "",
              "## Runs and analysis", ""]
    steps = []
    for label, result in cases.items():
        for axis in result.excited_axes:
            r = result.runs[axis]
            steps.append(f"{label}/{axis}: {r['dt']:g} s ({r['step']})")
    lines += markdown_table(["setting", "value"], [
        ["base axes excited", f"{', '.join(axes)} (one run each, the others at rest)"],
        ["chirp", f"linear, {s['f0']:g} → {s['f1']:g} Hz, constant displacement amplitude "
                  f"{first.amplitude['z'] * 1e3:g} mm, {s['duration']:g} s"],
        ["solver, output rate", f"{s['solver']}, {s['sample_rate']:g} Hz"],
        ["integration step [s]", "; ".join(steps)],
        ["estimate", f"{s['estimator'].upper()} Welch, Hann segments of {s['fft_length']} "
                     f"samples ({s['fft_length'] / s['sample_rate']:g} s), "
                     f"{100 * s['overlap']:g} % overlap, from the base point's velocity to the "
                     "platform's twist at the cube's centre"],
        ["trusted bins", f"coherence ≥ {s['coherence_min']:g}, base power share ≥ "
                         f"{s['base_share_min']:g}, at or above {s['trusted_from']:.3g} Hz (the "
                         f"sweep's start), response above {s['floor_db']:g} dB of the base "
                         "motion (dimensionless, rotations times the platform size "
                         f"{s['platform_size'] * 1e3:.0f} mm)"]])
    lines.append("")
    if quick:
        lines.append(f"Quick runs: {s['duration']:g} s chirps instead of 400 s (trusted from "
                     f"{s['trusted_from']:.2g} Hz instead of 0.2 Hz); the full study is "
                     "`qzs hexapod study`.")
    if s["dt"] is not None:
        lines.append(f"Steps: {s['dt']:g} s, given (no error estimate).")
    else:
        lines.append("Steps: accuracy-driven where the probe's differences shrink with the "
                     "step as the scheme's order predicts (tolerance "
                     f"{s['tolerance_db']:g} dB on each run's column of the matrix); elsewhere the "
                     "file's "
                     f"{s['setup_dt']:g} s. Per run:")
        for label, result in cases.items():
            for axis in result.excited_axes:
                lines.append(f"- {label}, {axis}: {step_text(result.runs[axis], s)}")
    lines += ["", "## Metrics", "",
              "Diagonal entries (platform axis per the same base axis, amplitude ratio), "
              "read on trusted bins only; a dash with a note where they do not define it.", ""]
    lines += markdown_table(["case", "chirp", *(title for _, title in _TABLE)],
                            [[row["case"], f"{row['axis']} ({row['axis']}/{row['axis']})",
                              *(cell(row, key) for key, _ in _TABLE)] for row in rows])
    lines += ["", "Cross-axis entries: the coupling the linear model has (its largest "
                  "off-diagonal entry of the column, dimensionless; none for z, which the "
                  "symmetric platform keeps to itself) and the strongest trusted off-diagonal "
                  "entry of the simulation; peaks over trusted bins, with the linear model at "
                  "the same frequency:", ""]
    def peak(row, prefix):
        unit = row[f"{prefix}_unit"]
        return cell(row, f"{prefix}_peak") + (f" {unit}" if unit not in ("", "-") else "")

    def entries(row, prefix):
        return [row[f"{prefix}_entry"], peak(row, prefix), cell(row, f"{prefix}_frequency_hz"),
                cell(row, f"{prefix}_linear")]

    lines += markdown_table(["case", "chirp", "linear coupling", "peak", "at [Hz]",
                             "linear there", "strongest cross-axis entry", "peak", "at [Hz]",
                             "linear there"],
                            [[row["case"], row["axis"], *entries(row, "linear_coupling"),
                              *entries(row, "cross")] for row in rows])
    lines += ["", "The legs and the energy ledger:", ""]
    lines += markdown_table(
        ["case", "chirp", "locked [%]", "stop contacts", "stroke used [mm]",
         "platform − base, max [mm; mrad]", "ledger closure [-]", "run [s]"],
        [[row["case"], row["axis"], f"{row['locked_percent']:.1f}", f"{row['stop_contacts']}",
          f"{row['stroke_used_mm']:.2f}",
          f"{row['relative_translation_mm']:.3g}; {row['relative_rotation_mrad']:.3g}",
          f"{row['ledger_closure']:.2g}", f"{row['run_seconds']:.1f}"] for row in rows])
    if notes:
        lines.append("")
        for reason, note in notes.items():
            lines.append(f"<sup>{note}</sup> {reason}  ")
    lines += ["", "## Findings", ""]
    lines += [f"- {finding}" for finding in findings]
    lines += ["", "## Figures", "",
              f"![Cases compared]({comparison}.png)", "",
              "**Cases compared.** Top: the vertical (z/z, left) and lateral (x/x, right) "
              "transmissibility; below them the coupling the linear model has (ry/x) and the "
              "strongest cross-axis response the PI run trusts; bottom: the diagonal's "
              "coherence with the trusted threshold. Solid: trusted bins; faint: untrusted; "
              "dashed: the linear model of each stable loop; grey band: the sweep's start, "
              f"untrusted in every entry (SVG: `{comparison}.svg`).", ""]
    for label in cases:
        name = matrix_names[label]
        lines += [f"![{label}: 6x6 matrix]({name}.png)", "",
                  f"**{label}: the 6x6 matrix.** Row: platform axis; column: base axis "
                  "(y, rx, ry, rz not excited, left empty); dB of the entry's unit [1, m/rad "
                  f"or rad/m]. Data: `{name}.nc`.", ""]
    lines += ["## Notes", "",
              "- Trusted bins (docs/model.md §10, docs/hexapod.md): a single sweep gives each "
              "bin's power to one or two Welch segments, so the coherence of a chirp is near 1 "
              "wherever nothing but the base moved the platform; it drops where stick-slip "
              "spreads the platform's motion over other segments. The numerical floor removes "
              "entries that are rounding (zero by symmetry in exact arithmetic, yet "
              "deterministic, hence coherent); the sweep's start removes the bins crossed under "
              "the first segment's rising taper.",
              "- Not modelled (docs/hexapod.md §7, §9.9): the legs' own inertia and "
              "transverse dynamics, joint friction and compliance, sampled or centralised "
              "control, the base's reaction.",
              f"- Files: {', '.join(f'`{name}`' for name in sorted(files))}, `report.md`.",
              ""]
    return "\n".join(lines)


def study_summary(study):
    """The six-axis study's console summary (:meth:`HexapodStudyResult.summary
    <qzs.workflows.hexapod.study.HexapodStudyResult.summary>`).

    Parameters
    ----------
    study : HexapodStudyResult
        The study.

    Returns
    -------
    str
    """
    lines = [f"qzs hexapod study: {'quick' if study.quick else 'full'} runs, wall "
             f"{study.wall_seconds:.1f} s",
             "case               chirp  T(4 Hz)  T(8 Hz)  T(16 Hz)  locked [%]  contacts  "
             "ledger"]
    for row in study.rows:
        a = row["axis"]
        lines.append(f"{row['case']:<18} {a:>5}  {significant(row['T_at_4_hz']):>7}  "
                     f"{significant(row['T_at_8_hz']):>7}  {significant(row['T_at_16_hz']):>8}  "
                     f"{row['locked_percent']:10.1f}  {row['stop_contacts']:8d}  "
                     f"{row['ledger_closure']:.1g}")
    lines += [f"  - {finding}" for finding in study.findings]
    for label, result in study.cases.items():
        for axis in result.excited_axes:
            lines.append(f"  step {label}/{axis}: "
                         f"{step_text(result.runs[axis], result.settings)}")
    lines.append(f"wrote {study.folder / 'report.md'}, metrics.csv, metrics.json, figures and "
                 "matrices")
    return "\n".join(lines)
