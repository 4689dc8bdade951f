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
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import csv_text, decibels, json_text
from qzs.analysis.hexapod_linear import entry_unit
from qzs.analysis.spectral import transmissibility_metrics
from qzs.defaults import AXES, AXIS_UNITS
from qzs.errors import ParameterError
from qzs.iotools.files import write_text
from qzs.iotools.result_files import save_by_extension, save_doc, suffixes_of
from qzs.viz.figures import check_frequency_scale
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod
from qzs.workflows.hexapod.transmissibility import hexapod_transmissibility
from qzs.workflows.findings.markdown import study_markdown, study_summary
from qzs.workflows.findings.tables import document_head, significant

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["CASES", "RUNS", "STUDY_AXES", "HexapodStudyResult", "run_hexapod_study",
           "study_result", "study_document", "comparison_figure", "study_steps",
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
        return study_summary(self)

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

    #: The extensions :meth:`save` accepts.
    save_suffixes = suffixes_of(dataset=True, record=True)

    def to_record(self) -> dict[str, Any]:
        """The study as its ``metrics.json`` holds it (:func:`study_document`), with the
        whole's wall time.

        Returns
        -------
        dict
        """
        return study_document(self.cases, self.rows, self.findings, self.quick,
                              self.wall_seconds)

    def to_xarray(self) -> "xr.Dataset":
        """The cases' matrices, as each ``hexapod_matrix_<case>.nc`` holds its own
        (:meth:`HexapodTransmissibility.to_xarray`), stacked on ``case``; the attributes
        every case shares kept.

        Returns
        -------
        xarray.Dataset
        """
        import xarray as xr

        return xr.concat([result.to_xarray() for result in self.cases.values()],
                         dim="case", data_vars="different", coords="minimal", compat="equals",
                         join="outer", combine_attrs="drop_conflicts").assign_coords(
            case=list(self.cases))

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray, record=self.to_record)

    save.__doc__ = save_doc("``.nc``, ``.csv``, ``.mat`` (:meth:`to_xarray`: every case's "
                            "matrix on ``case``) or ``.json`` (:meth:`to_record`: what "
                            "``metrics.json`` holds)")


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


def _findings(cases, rows):
    """Sentences derived from the numbers (nothing here is fixed text about the outcome)."""
    by = {(row["case"], row["axis"]): row for row in rows}
    out = []
    for axis, word in (("z", "vertical"), ("x", "lateral")):
        if ("PI", axis) not in by:
            continue
        row = by[("PI", axis)]
        spots = ", ".join(f"{significant(row[f'T_at_{f:g}_hz'])} at {f:g} Hz"
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
                       f"{significant(row['linear_coupling_peak'])} {row['linear_coupling_unit']} at "
                       f"{row['linear_coupling_frequency_hz']:.3g} Hz, where the linear model "
                       f"gives {significant(linear)} ({ratio_db:+.1f}"
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
            text = (f"{row['cross_entry']} in {label} ({significant(row['cross_peak'])} "
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
    return study_result(cases, folder, quick=quick, run_seconds=time.perf_counter() - start,
                        frequency_scale=frequency_scale, progress=progress)


def study_result(cases: Mapping[str, Any], folder: str | Path, *, quick: bool = False,
                 run_seconds: float | None = None, frequency_scale: str | None = None,
                 progress: bool = False) -> HexapodStudyResult:
    """The study from its cases' matrices: the metrics rows, the findings, the files written.

    Parameters
    ----------
    cases : mapping
        Case label (of :data:`CASES`) -> its :class:`~qzs.workflows.hexapod.
        transmissibility.HexapodTransmissibility` over :data:`STUDY_AXES`.
    folder : str or Path
        Output folder, created if missing.
    quick : bool
        Whether the runs were the quick ones.
    run_seconds : float, optional
        Wall time of the runs [s], recorded in the files.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figures; default ``qzs.defaults.FIGURES["frequency_scale"]``.
    progress : bool
        Show a progress bar over the figures and files.

    Returns
    -------
    HexapodStudyResult
    """
    start = time.perf_counter()
    rows = tuple(_metrics_row(label, result, axis) for label, result in cases.items()
                 for axis in STUDY_AXES)
    findings = _findings(cases, rows)
    files = write_study_outputs(cases, rows, findings, folder, quick=quick,
                                wall_seconds=run_seconds, frequency_scale=frequency_scale,
                                progress=progress)
    wall = (run_seconds or 0.0) + time.perf_counter() - start
    return HexapodStudyResult(cases=MappingProxyType(dict(cases)), rows=rows,
                              findings=findings, quick=quick, wall_seconds=wall,
                              folder=Path(folder), files=MappingProxyType(files))


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
def study_document(cases, rows, findings, quick, wall_seconds):
    """The study as ``metrics.json`` holds it: the head, each case's meaning, linear model,
    settings and steps, the metrics rows and the findings.

    Parameters
    ----------
    cases : mapping
        Case label -> HexapodTransmissibility.
    rows : sequence of dict
        The metrics rows.
    findings : sequence of str
        The findings' sentences.
    quick : bool
        Whether the runs were the quick ones.
    wall_seconds : float or None
        Wall time of the runs [s].

    Returns
    -------
    dict
    """
    from qzs.workflows.hexapod.transmissibility.result import run_steps

    return {**document_head(quick, wall_seconds), "setup": SHIPPED_DEFAULT,
            "axes": list(STUDY_AXES),
            "cases": {label: {"meaning": CASES[label][0], "overrides": CASES[label][1],
                              "linear_stable": result.linear_stable,
                              "linear_natural_frequencies_hz":
                                  result.linear_natural_frequencies,
                              "settings": dict(result.settings),
                              "steps": {a: {"dt_s": r["dt"], "step": r["step"],
                                            "error_db": r["error_db"],
                                            "tolerance_db": r["tolerance_db"],
                                            "reason": r["reason"]}
                                        for a, r in run_steps(result).items()}}
                      for label, result in cases.items()},
            "rows": list(rows), "findings": list(findings)}


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

    files["metrics.csv"] = write_text(folder / "metrics.csv", csv_text(rows))
    bar.update(1)
    files["metrics.json"] = write_text(folder / "metrics.json", json_text(
        study_document(cases, rows, findings, quick, wall_seconds)))
    bar.update(1)
    files["report.md"] = write_text(folder / "report.md", study_markdown(
        cases, rows, findings, files, quick, wall_seconds,
        meanings={label: meaning for label, (meaning, _) in CASES.items()}, axes=STUDY_AXES,
        setup_name=SHIPPED_DEFAULT, comparison=_FIGURE_COMPARISON,
        matrix_names={label: f"hexapod_matrix_{_slug(label)}" for label in cases}))
    bar.update(1)
    return files
