"""``qzs hexapod study``: six paper legs in a Stewart platform, with and without PI.

The issue's shipped study, in the paper report's style: the platform of the shipped file
``paper_legs_cubic.toml`` (six Table 1 legs in the cubic configuration of edge 0.15 m,
carrying the 21.48 kg their MagSprings hold at the operating point), its 6x6
transmissibility from a chirp in z and one in x (:func:`qzs.workflows.
hexapod.transmissibility.hexapod_transmissibility`), for three position loops:

``PI``
    The shipped loop: ``Kp`` = 2000 N/m, ``Ki`` = 800 N/(m*s) per leg.
``P only``
    The integral off, the proportional stiffening kept (``Ki`` = 0, ``Kp`` = 2000 N/m).
``no position loop``
    ``Kp`` = ``Ki`` = 0, the paper's "without PI". With the legs' preload turning on their
    spherical joints the platform is then statically unstable (docs/hexapod.md §6): it
    rests on its stops or drifts while friction lets it, as the linear model predicts.

Why three: "without PI" in the paper is the passive leg, whose payload drifts onto the
stops. Six such legs cannot even hold a platform: the preload's negative stiffness,
``-4 f/a``, beats the springs' 1.6 N/m a thousandfold, so only a stiff position loop keeps
it up (the shipped file's ``Kp``). So the integral's share is shown by switching it off
alone (``P only``), and the passive legs by switching the whole loop off, with what
that does to the platform reported, not hidden.

Writes into a folder, each file atomically: ``report.md`` (settings, metrics table with
units, figures, findings derived from the numbers), ``metrics.csv`` and ``metrics.json``
(one row per case and excited axis, NaN as empty/null with ``<metric>_reason`` beside it),
the figures (PNG and SVG) and each case's matrix as NetCDF.
"""
import functools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import (csv_text, decibels, footnoted, json_text, markdown_table,
                         number)
from qzs._version import __version__
from qzs.analysis.hexapod_linear import entry_unit
from qzs.analysis.spectral import transmissibility_metrics
from qzs.defaults import AXES, AXIS_UNITS
from qzs.errors import ParameterError
from qzs.iotools.files import atomic_path
from qzs.viz.figures import check_frequency_scale
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod
from qzs.workflows.hexapod.transmissibility import hexapod_transmissibility
from qzs.workflows.hexapod.transmissibility.result import step_text

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["CASES", "RUNS", "STUDY_AXES", "HexapodStudyResult", "run_hexapod_study",
           "comparison_figure", "study_steps",
           "write_study_outputs"]

#: The study's cases: label -> (what it means, registry overrides of every leg's loop).
CASES = MappingProxyType({
    "PI": ("the shipped loop: Kp = 2000 N/m, Ki = 800 N/(m*s) on every leg", {}),
    "P only": ("the integral off, the proportional stiffening kept: Kp = 2000 N/m, Ki = 0",
               {"pi_ki": 0.0}),
    "no position loop": ("Kp = Ki = 0, the paper's passive leg: statically unstable here "
                         "(docs/hexapod.md §6)", {"pi_kp": 0.0, "pi_ki": 0.0}),
})
#: Base axes excited, one chirp each.
STUDY_AXES = ("z", "x")
#: Chirp length [s] of the full and the quick study; both take the accuracy-driven step of
#: :mod:`qzs.workflows.hexapod.transmissibility` unless a ``dt`` is given (falling back to
#: the file's 1e-4 s where the probe's differences do not shrink).
RUNS: Mapping[str, Mapping[str, Any]] = MappingProxyType({
    "full": MappingProxyType({"duration": 400.0}),
    "quick": MappingProxyType({"duration": 60.0}),
})
#: Frequencies [Hz] the report quotes the diagonal at.
SPOT_FREQUENCIES = (1.0, 2.0, 4.0, 8.0, 16.0)
_FIGURE_COMPARISON = "hexapod_study_comparison"
#: Axes that change sign under the mirror in the xz plane, which maps the shipped cubic
#: platform onto itself: y, and the rotations about x and z (an angular velocity is a
#: pseudovector: its components in the mirror plane change sign, the normal one does not).
_MIRROR_ODD = ("y", "rx", "rz")


@dataclass(frozen=True, kw_only=True, eq=False)
class HexapodStudyResult:
    """The study's matrices, metrics and where they were written.

    Attributes
    ----------
    cases : mapping
        Case label -> :class:`~qzs.workflows.hexapod.transmissibility.
        HexapodTransmissibility`.
    rows : tuple of dict
        One metrics row per case and excited axis (the rows of ``metrics.csv``).
    findings : tuple of str
        What the numbers say, as the report states it.
    quick : bool
        Whether the quick runs were made.
    wall_seconds : float
        Wall time of the whole [s]: the runs, the figures and the report (the files record
        the runs' alone).
    folder : Path
        The output folder.
    files : mapping
        Name -> path of every file written.
    """

    cases: MappingProxyType
    rows: tuple
    findings: tuple
    quick: bool
    wall_seconds: float
    folder: Path
    files: MappingProxyType

    def summary(self) -> str:
        """Short text: the metrics of each case and axis, and the findings.

        Returns
        -------
        str
        """
        return _summary_text(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """The comparison figure of the cases (:func:`comparison_figure`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there.
        title : str, optional
            Figure title; default one naming the platform, the chirps and the line styles.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        return comparison_figure(self.cases, out=path, frequency_scale=frequency_scale,
                                 title=title)


# ---------------------------------------------------------------- metrics
def _dimensionless(result, i, j):
    size = result.settings["platform_size"]
    scale = (size if i >= 3 else 1.0) / (size if j >= 3 else 1.0)
    return result.magnitude[:, i, j] * scale


def _linear_coupling(result, j):
    """The column's largest off-diagonal entry of the linear model (dimensionless), or None."""
    if not result.linear_stable:
        return None
    size = result.settings["platform_size"]
    best, level = None, 1e-6
    for i in range(6):
        if i == j:
            continue
        scale = (size if i >= 3 else 1.0) / (size if j >= 3 else 1.0)
        value = float(np.nanmax(np.abs(result.linear_response[:, i, j])) * scale)
        if value > level:
            best, level = i, value
    return best


def _coupling(result, j, only=None):
    """The strongest trusted cross-axis entry of column ``j`` (or entry ``only``):
    (i, |T|, f, linear |T|), None if it has no trusted bin."""
    best = None
    for i in range(6):
        if i == j or (only is not None and i != only):
            continue
        ok = result.trusted[:, i, j]
        if not ok.any():
            continue
        values = _dimensionless(result, i, j)
        k = int(np.flatnonzero(ok)[np.argmax(values[ok])])
        if best is None or values[k] > best[1]:
            best = (i, float(values[k]), k)
    if best is None:
        return None
    i, _, k = best
    return (i, float(result.magnitude[k, i, j]), float(result.frequency[k]),
            float(abs(result.linear_response[k, i, j])))


def _metrics_row(label, result, axis):
    """One row of metrics for a case's run along ``axis`` (units in the key names)."""
    j = AXES.index(axis)
    run = result.runs[axis]
    f = result.frequency
    diagonal = result.magnitude[:, j, j]
    ok = result.trusted[:, j, j]
    row = {"case": label, "axis": axis, "diagonal_entry": f"{axis}/{axis}",
           "amplitude": result.amplitude[axis],
           "amplitude_unit": AXIS_UNITS[j],
           "dt_s": run["dt"], "step": run["step"],
           "chirp_duration_s": result.settings["duration"],
           "trusted_from_hz": result.settings["trusted_from"],
           "trusted_bins": int(ok.sum())}
    reasons = {}
    import warnings

    from qzs.errors import DataWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        metrics = transmissibility_metrics(f, diagonal, trusted=ok,
                                           at_frequencies=SPOT_FREQUENCIES)
    for frequency in SPOT_FREQUENCIES:
        key = f"T_at_{frequency:g}_hz"
        row[key] = metrics.at[float(frequency)]
        reason = metrics.reasons.get(f"transmissibility_at_{frequency:g}_hz", "")
        if reason:
            reasons[key] = reason
    for name, key in (("resonance_frequency", "resonance_frequency_hz"),
                      ("resonance_peak", "resonance_peak"),
                      ("isolation_onset", "isolation_onset_hz")):
        row[key] = getattr(metrics, name)
        if metrics.reasons.get(name):
            reasons[key] = metrics.reasons[name]
    linear_entry = _linear_coupling(result, j)
    for prefix, entry, why in (
            ("linear_coupling", linear_entry,
             "the linear model couples no other axis to this one (or its loop is unstable)"),
            ("cross", None, "no cross-axis entry of this column has a trusted bin")):
        if prefix == "linear_coupling" and entry is None:
            coupling = None
        else:
            coupling = _coupling(result, j, only=entry)
        if coupling is None:
            name = "none" if entry is None else f"{AXES[entry]}/{axis}"
            row.update({f"{prefix}_entry": name, f"{prefix}_peak": math.nan,
                        f"{prefix}_unit": "", f"{prefix}_frequency_hz": math.nan,
                        f"{prefix}_linear": math.nan})
            for key in ("peak", "frequency_hz", "linear"):
                reasons[f"{prefix}_{key}"] = (why if entry is None else
                                              f"{name} has no trusted bin")
            continue
        i, peak, frequency, linear = coupling
        row.update({f"{prefix}_entry": f"{AXES[i]}/{axis}", f"{prefix}_peak": peak,
                    f"{prefix}_unit": entry_unit(i, j, dimensionless="-"),
                    f"{prefix}_frequency_hz": frequency,
                    f"{prefix}_linear": linear if result.linear_stable else math.nan})
        if not result.linear_stable:
            reasons[f"{prefix}_linear"] = "the linear model's loop is unstable"
    pose = np.asarray(run["relative_pose_max"])
    row.update(locked_percent=100 * float(np.mean(run["locked_fraction"])),
               stop_contacts=int(np.sum(run["stop_contacts"])),
               stroke_used_mm=1e3 * float(np.max(run["stroke_used"])),
               relative_translation_mm=1e3 * float(np.max(pose[:3])),
               relative_rotation_mrad=1e3 * float(np.max(pose[3:])),
               ledger_closure=result.energy_residual[axis],
               linear_stable=bool(result.linear_stable),
               run_seconds=run["seconds"])
    for key, reason in reasons.items():
        row[f"{key}_reason"] = reason
    return row


#: A number in the study's text and tables: three significant digits, a dash if undefined.
_fmt = functools.partial(number, undefined="—")


def _findings(cases, rows):
    """Sentences derived from the numbers (nothing here is fixed text about the outcome)."""
    by = {(row["case"], row["axis"]): row for row in rows}
    out = []
    for axis, word in (("z", "vertical"), ("x", "lateral")):
        if ("PI", axis) not in by:
            continue
        row = by[("PI", axis)]
        spots = ", ".join(f"{_fmt(row[f'T_at_{f:g}_hz'])} at {f:g} Hz"
                          for f in SPOT_FREQUENCIES)
        out.append(f"With PI, the {word} transmissibility {axis}/{axis} is {spots} "
                   f"(amplitude ratio; a dash where the bin is untrusted). The legs are locked "
                   f"{row['locked_percent']:.0f} % of the time: below the break-away the "
                   "platform moves with the base (T = 1).")
    if "PI" in cases and "P only" in cases:
        for axis in STUDY_AXES:
            j = AXES.index(axis)
            a, b = cases["PI"], cases["P only"]
            if axis not in a.excited_axes or axis not in b.excited_axes:
                continue
            both = a.trusted[:, j, j] & b.trusted[:, j, j]
            if both.any():
                difference = np.abs(decibels(a.magnitude[both, j, j] / b.magnitude[both, j, j]))
                k = int(np.argmax(difference))
                largest = float(difference[k])
                text = (f"Switching the integral off (P only) changes {axis}/{axis} by at "
                        f"most {largest:.2g} dB (at {float(a.frequency[both][k]):.3g} Hz) "
                        f"over the {int(both.sum())} bins trusted in both.")
                steps = [d for r in (a.runs[axis], b.runs[axis])
                         for _, d in r["step_history"] if np.isfinite(d)]
                if steps:
                    text += (f" Halving the step changed this entry by up to {max(steps):.2g} "
                             "dB on the step probes" + (
                                 ", so the difference is within the stick-slip pattern's "
                                 "sensitivity." if max(steps) >= largest else "."))
                out.append(text + " The payload is what the springs hold, so the integral "
                                  "carries no static load here.")
    if "no position loop" in cases:
        rows_none = [by[("no position loop", axis)] for axis in STUDY_AXES
                     if ("no position loop", axis) in by]
        result = cases["no position loop"]
        stable = "stable" if result.linear_stable else "unstable"
        unstable = int(np.sum(~np.isfinite(result.linear_natural_frequencies)))
        parts = [f"{row['axis']} chirp: {row['stop_contacts']} stop contacts, legs up to "
                 f"{row['stroke_used_mm']:.1f} mm from their setpoint (stroke "
                 f"{1e3 * result.setup.geometry.stroke_half:.0f} mm), the platform up to "
                 f"{row['relative_translation_mm']:.3g} mm and {row['relative_rotation_mrad']:.3g}"
                 " mrad away from the base's pose" for row in rows_none]
        out.append(f"Without a position loop the linear model is {stable} ({unstable} "
                   "statically unstable directions, docs/hexapod.md §6), and the simulation "
                   "shows it: " + "; ".join(parts) + ". Its curves describe a platform "
                   "sagging or resting on its stops, not an isolator.")
    for label, result in cases.items():
        for axis in result.excited_axes:
            row = by[(label, axis)]
            if row["linear_coupling_entry"] == "none" or not math.isfinite(
                    row["linear_coupling_peak"]):
                continue
            linear = row["linear_coupling_linear"]
            ratio = row["linear_coupling_peak"] / linear
            ratio_db = decibels(ratio) if 0 < ratio < math.inf else math.nan
            out.append(f"{label}, {axis} chirp: {row['linear_coupling_entry']}, the coupling "
                       "the linear model has (the legs' preload and the weight couple "
                       "translation and tilt, docs/hexapod.md §6), peaks at "
                       f"{_fmt(row['linear_coupling_peak'])} {row['linear_coupling_unit']} at "
                       f"{row['linear_coupling_frequency_hz']:.3g} Hz, where the linear model "
                       f"gives {_fmt(linear)} ({ratio_db:+.1f}"
                       " dB): stick-slip moves the response to the break-away.")
    odd, even = [], []
    for label, result in cases.items():
        if not result.linear_stable:
            continue  # far from home: the linear model says nothing there
        for axis in result.excited_axes:
            row = by[(label, axis)]
            if row["cross_entry"] == "none":
                continue
            output = row["cross_entry"].split("/")[0]
            i, j = AXES.index(output), AXES.index(axis)
            scale = result.settings["platform_size"]
            exact = np.nanmax(np.abs(result.linear_response[:, i, j])
                              * (scale if i >= 3 else 1.0) / (scale if j >= 3 else 1.0))
            if exact >= 1e-9:
                continue
            text = (f"{row['cross_entry']} in {label} ({_fmt(row['cross_peak'])} "
                    f"{row['cross_unit']} at {row['cross_frequency_hz']:.3g} Hz)")
            (odd if output in _MIRROR_ODD and axis not in _MIRROR_ODD else even).append(text)
    if odd:
        out.append("Cross-axis responses that the platform's mirror symmetry (its xz plane: "
                   "y, rx and rz change sign, x, z and ry do not) forbids are trusted above "
                   "the numerical floor in: " + "; ".join(odd) + ". The symmetric motion "
                   "loses its symmetry once the legs break away: the Stribeck friction's "
                   "falling branch is a negative damping under which the legs split into "
                   "groups (with Coulomb friction, Fs = Fc, the same platform stays symmetric "
                   "to rounding, docs/hexapod.md §9.8).")
    if even:
        out.append("Cross-axis responses the linear model has none of but the symmetry "
                   "allows, from the legs' stick-slip (legs on either side lock and slip at "
                   "different times): " + "; ".join(even) + ".")
    closures = [row["ledger_closure"] for row in rows]
    out.append(f"The energy ledger closes in every run: largest imbalance "
               f"{max(closures):.2g} of the run's largest |base work|.")
    return tuple(out)


# ---------------------------------------------------------------- the run
def run_hexapod_study(folder: str | Path = "results/hexapod_study", *, quick: bool = False,
                      dt: float | None = None, tolerance: float | None = None,
                      workers: int | None = None, progress: bool = True,
                      frequency_scale: str | None = None,
                      tolerance_db: float | None = None) -> HexapodStudyResult:
    """Run the shipped hexapod study and write its report (``qzs hexapod study``).

    Parameters
    ----------
    folder : str or Path
        Output folder, created if missing.
    quick : bool
        60 s chirps instead of 400 s.
    dt : float, optional
        A literal step [s] for every run; default the accuracy-driven step of each run
        (:mod:`qzs.workflows.hexapod.transmissibility`).
    tolerance : float, optional
        Tolerance [dB] of the accuracy-driven step on each run's column; default
        ``qzs.defaults.ACCURACY["tolerance_db"]`` (0.01). Not with ``dt``.
    workers : int, optional
        Processes per case (one per excited axis); default the machine's cores.
    progress : bool
        Show progress bars over each case's runs.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figures; default ``qzs.defaults.FIGURES["frequency_scale"]``
        (log).
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    HexapodStudyResult
    """
    from qzs._validation import integer, renamed_keyword

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)

    if workers is not None:
        workers = integer("workers", workers, 1)
    if not isinstance(quick, (bool, np.bool_)):
        raise ParameterError(f"`quick` must be True or False, got {quick!r}.")
    from qzs.iotools.paths import check_output_path

    check_output_path(folder, argument="folder", suffixes=None, directory=True)
    if frequency_scale is not None:
        check_frequency_scale(frequency_scale)
    settings = RUNS["quick" if quick else "full"]
    setups = {label: load_hexapod(SHIPPED_DEFAULT, overrides)
              for label, (_, overrides) in CASES.items()}
    start = time.perf_counter()
    cases = {}
    for label, setup in setups.items():
        cases[label] = hexapod_transmissibility(setup, axes=STUDY_AXES,
                                                duration=settings["duration"],
                                                dt=dt, tolerance=tolerance,
                                                workers=workers,
                                                progress=progress)
    wall = time.perf_counter() - start
    rows = tuple(_metrics_row(label, result, axis) for label, result in cases.items()
                 for axis in STUDY_AXES)
    findings = _findings(cases, rows)
    files = write_study_outputs(cases, rows, findings, folder, quick=quick, wall_seconds=wall,
                                frequency_scale=frequency_scale, progress=progress)
    return HexapodStudyResult(cases=MappingProxyType(cases), rows=rows, findings=findings,
                              quick=quick, wall_seconds=time.perf_counter() - start,
                              folder=Path(folder),
                              files=MappingProxyType(files))


def study_steps(study: HexapodStudyResult) -> dict[str, dict[str, dict[str, Any]]]:
    """Each run's step as data: ``{case: {axis: {dt, step, error_db, tolerance_db,
    reference_dt, reason}}}`` (``qzs hexapod study --json``).

    Parameters
    ----------
    study : HexapodStudyResult
        The study.

    Returns
    -------
    dict
        ``dt`` [s], ``step`` (how chosen), ``error_db`` (estimated error [dB], NaN if
        none), ``tolerance_db`` [dB] (None with a given ``dt``), ``reference_dt`` [s],
        ``reason``.
    """
    from qzs.workflows.hexapod.transmissibility.result import run_steps

    return {label: run_steps(result) for label, result in study.cases.items()}


# ---------------------------------------------------------------- outputs
def _slug(label):
    return label.lower().replace(" ", "_")


def comparison_figure(cases, out=None, frequency_scale=None, title=None):
    """The study's comparison figure: the direct and coupled entries of every case.

    Parameters
    ----------
    cases : mapping
        Case label -> :class:`~qzs.workflows.hexapod.transmissibility.HexapodTransmissibility`
        (:attr:`HexapodStudyResult.cases`), the first the reference (PI).
    out : str or Path, optional
        Write the figure there (PNG and SVG beside it).
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figures; default ``qzs.defaults.FIGURES["frequency_scale"]``
        (log).
    title : str, optional
        Figure title; default one naming the platform, the chirps and the line styles.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from qzs.viz.hexapod_study import plot_study_comparison

    first = next(iter(cases.values()))
    entries = []
    for axis in STUDY_AXES:
        j = AXES.index(axis)
        column = [(j, j)]
        # the coupling the linear model has, then the strongest cross-axis entry the first
        # case (PI) trusts, if another
        coupled = _linear_coupling(first, j)
        if coupled is not None:
            column.append((coupled, j))
        for result in cases.values():
            coupling = _coupling(result, j)
            if coupling is not None:
                if coupling[0] != coupled:
                    column.append((coupling[0], j))
                break
        entries.append(column)
    settings = first.settings
    figure = plot_study_comparison(
        list(cases.items()), entries=entries, coherence_min=settings["coherence_min"],
        frequency_range=(max(0.1, float(first.frequency[1])), settings["f1"]),
        untrusted_below=settings["trusted_from"],
        title=title or (f"Six paper legs, cubic platform {first.setup.platform.mass:.4g} kg: "
               f"chirps of {first.amplitude['z'] * 1e3:g} mm in z and x, "
               f"{settings['duration']:g} s each\n"
               "solid: trusted bins; faint: untrusted; dashed: linear model (stable loops "
               "only); grey: the sweep's start, untrusted"),
        out=out, frequency_scale=frequency_scale)
    return figure


def write_study_outputs(cases, rows, findings, folder, *, quick=False, wall_seconds=None,
                        frequency_scale=None, progress=False):
    """Write the figures, matrices, ``metrics.csv``, ``metrics.json`` and ``report.md``.

    Parameters
    ----------
    cases : mapping
        Case label -> HexapodTransmissibility.
    rows : sequence of dict
        The metrics rows.
    findings : sequence of str
        The findings' sentences.
    folder : str or Path
        Output folder, created if missing.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float, optional
        Wall time of the runs [s].
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figures; default ``qzs.defaults.FIGURES["frequency_scale"]``
        (log).
    progress : bool
        Show a progress bar: one step per figure and per file.

    Returns
    -------
    dict
        Name -> path of every file written.
    """
    from qzs.engine.progress import progress_bar

    with progress_bar(total=2 * len(cases) + 4, unit="part", desc="figures and report",
                      disable=not progress, leave=False) as bar:
        return _write_outputs(cases, rows, findings, Path(folder), quick, wall_seconds,
                              frequency_scale, bar)


def _write_outputs(cases, rows, findings, folder, quick, wall_seconds, frequency_scale, bar):
    """:func:`write_study_outputs`, advancing ``bar`` after each figure and file."""
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    files = {}
    for label, result in cases.items():
        name = f"hexapod_matrix_{_slug(label)}"
        figure = result.plot(path=folder / f"{name}.png", frequency_scale=frequency_scale)
        plt.close(figure)
        files[f"{name}.png"] = folder / f"{name}.png"
        bar.update(1)
        files[f"{name}.nc"] = result.save(folder / f"{name}.nc")
        bar.update(1)
    plt.close(comparison_figure(cases, out=folder / f"{_FIGURE_COMPARISON}.png",
                                frequency_scale=frequency_scale))
    bar.update(1)
    files[f"{_FIGURE_COMPARISON}.png"] = folder / f"{_FIGURE_COMPARISON}.png"
    files[f"{_FIGURE_COMPARISON}.svg"] = folder / f"{_FIGURE_COMPARISON}.svg"

    with atomic_path(folder / "metrics.csv") as tmp:
        tmp.write_text(csv_text(rows), encoding="utf-8")
    files["metrics.csv"] = folder / "metrics.csv"
    bar.update(1)
    document = {"qzs_version": __version__, "quick": quick, "wall_seconds": wall_seconds,
                "setup": SHIPPED_DEFAULT, "axes": list(STUDY_AXES),
                "cases": {label: {"meaning": CASES[label][0], "overrides": CASES[label][1],
                                  "linear_stable": result.linear_stable,
                                  "linear_natural_frequencies_hz":
                                      result.linear_natural_frequencies,
                                  "settings": dict(result.settings),
                                  "steps": {a: {"dt_s": r["dt"], "step": r["step"],
                                                "error_db": r["step_error_db"],
                                                "tolerance_db":
                                                    result.settings["tolerance_db"],
                                                "reason": r["step_reason"]}
                                            for a, r in result.runs.items()}}
                          for label, result in cases.items()},
                "rows": list(rows), "findings": list(findings)}
    with atomic_path(folder / "metrics.json") as tmp:
        tmp.write_text(json_text(document), encoding="utf-8")
    files["metrics.json"] = folder / "metrics.json"
    bar.update(1)
    with atomic_path(folder / "report.md") as tmp:
        tmp.write_text(_markdown(cases, rows, findings, files, quick, wall_seconds),
                       encoding="utf-8")
    files["report.md"] = folder / "report.md"
    bar.update(1)
    return files


_TABLE = (("T_at_1_hz", "T(1 Hz) [-]"), ("T_at_2_hz", "T(2 Hz) [-]"),
          ("T_at_4_hz", "T(4 Hz) [-]"), ("T_at_8_hz", "T(8 Hz) [-]"),
          ("T_at_16_hz", "T(16 Hz) [-]"), ("resonance_frequency_hz", "peak at [Hz]"),
          ("resonance_peak", "peak T [-]"), ("isolation_onset_hz", "isolation from [Hz]"))


def _markdown(cases, rows, findings, files, quick, wall_seconds):
    first = next(iter(cases.values()))
    setup, s = first.setup, first.settings
    notes = {}

    def cell(row, key):
        value = row.get(key, math.nan)
        if isinstance(value, float) and not math.isfinite(value):
            return footnoted("—", row.get(f"{key}_reason", "not defined on the trusted bins"),
                             notes)
        return _fmt(value)

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
        f"The shipped file `{SHIPPED_DEFAULT}.toml`: six Table 1 legs (MagSpring, Stribeck "
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
    for label, (meaning, _) in CASES.items():
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
        ["base axes excited", f"{', '.join(STUDY_AXES)} (one run each, the others at rest)"],
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
              f"![Cases compared]({_FIGURE_COMPARISON}.png)", "",
              "**Cases compared.** Top: the vertical (z/z, left) and lateral (x/x, right) "
              "transmissibility; below them the coupling the linear model has (ry/x) and the "
              "strongest cross-axis response the PI run trusts; bottom: the diagonal's "
              "coherence with the trusted threshold. Solid: trusted bins; faint: untrusted; "
              "dashed: the linear model of each stable loop; grey band: the sweep's start, "
              f"untrusted in every entry (SVG: `{_FIGURE_COMPARISON}.svg`).", ""]
    for label in cases:
        name = f"hexapod_matrix_{_slug(label)}"
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


def _summary_text(study):
    lines = [f"qzs hexapod study: {'quick' if study.quick else 'full'} runs, wall "
             f"{study.wall_seconds:.1f} s",
             "case               chirp  T(4 Hz)  T(8 Hz)  T(16 Hz)  locked [%]  contacts  "
             "ledger"]
    for row in study.rows:
        a = row["axis"]
        lines.append(f"{row['case']:<18} {a:>5}  {_fmt(row['T_at_4_hz']):>7}  "
                     f"{_fmt(row['T_at_8_hz']):>7}  {_fmt(row['T_at_16_hz']):>8}  "
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

