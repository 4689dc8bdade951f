"""The result: the 6x6 matrix with its trusted entries, and its views (summary, record, file)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import number
from qzs.analysis.hexapod_linear import entry_unit
from qzs.defaults import AXES, AXIS_UNITS
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc
from qzs.iotools.schema import Schema, Variable, to_dataset

if TYPE_CHECKING:
    from collections.abc import Mapping

    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.workflows.hexapod.setups import HexapodSetup


@dataclass(frozen=True, kw_only=True, eq=False)
class HexapodTransmissibility:
    """The simulated 6x6 transmissibility of a hexapod (:func:`hexapod_transmissibility`).

    Entry ``[:, i, j]`` is platform axis ``i`` per base axis ``j`` (``x, y, z`` [m], ``rx,
    ry, rz`` [rad]) at the top frame origin: [-] on the diagonal blocks, [m/rad] for a
    translation per rotation, [rad/m] for a rotation per translation. Columns of base axes
    that were not excited are NaN (``trusted`` False). The object holds data; its methods
    delegate to this module's functions, :mod:`qzs.viz.hexapod_matrix` and
    :mod:`qzs.iotools.files`.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Welch bin frequencies [Hz], from 0 to the chirp's end ``f1`` (above it the base
        put no power).
    response : ndarray of complex, shape (n, 6, 6)
        The estimate (``H1`` or ``H2``) [1, m/rad, rad/m]; NaN in columns not excited.
    coherence : ndarray, shape (n, 6, 6)
        Magnitude-squared coherence of base axis ``j`` and platform axis ``i`` [-].
    trusted : ndarray of bool, shape (n, 6, 6)
        Bins that may be read: the single axis's trusted bins (docs/model.md §10), not
        ``below_floor``, and at or above ``settings["trusted_from"]`` (the sweep's start).
    below_floor : ndarray of bool, shape (n, 6, 6)
        Bins whose dimensionless response is below ``settings["floor_db"]`` of the base
        motion: rounding, not a response, whatever their coherence.
    linear_response : ndarray of complex, shape (n, 6, 6)
        :meth:`HexapodLinearModel.transmissibility` at ``frequency`` (NaN at 0 Hz), the
        linear model at the top frame origin, every column.
    linear_stable : bool
        Whether the linear model's closed loop is asymptotically stable; if not, its
        frequency response is not a steady state anything reaches.
    linear_natural_frequencies : ndarray, shape (6,)
        Its undamped natural frequencies [Hz]; NaN for a statically unstable direction.
    linear_notes : tuple of str
        What the linearisation says about unstable directions.
    excited_axes : tuple of str
        The base axes excited, in the order of :data:`AXES`.
    amplitude : mapping
        Chirp amplitude per excited axis [m, rad] (translations, rotations).
    energy_residual : mapping
        Per excited axis, the run's largest energy-ledger imbalance divided by its largest
        ``|base work|`` [-] (docs/hexapod.md §9.6).
    runs : mapping
        Per excited axis, the run's record: ``dt`` [s] and ``step`` (how it was chosen:
        ``"accuracy-driven"``, ``"set-up"`` or ``"given"``), ``step_error_db`` (the
        estimated error [dB], NaN if none), ``step_reference_dt`` [s], ``step_history``,
        ``step_reason``, ``steps``, ``events``,
        ``elapsed`` [s], ``locked_fraction`` [-] per leg, ``stop_contacts`` and
        ``stick_events`` per leg, ``stroke_used`` [m] per leg, ``energy_residual`` [J],
        ``base_work_max`` [J], ``n_averages``, ``seconds`` (wall time of the run and its
        reduction) [s].
    settings : mapping
        ``f0``, ``f1`` [Hz], ``duration`` [s], ``sample_rate`` [Hz], ``solver``,
        ``fft_length`` [samples], ``overlap`` [-], ``estimator``, ``coherence_min``,
        ``base_share_min`` [-], ``floor_db`` [dB], ``platform_size`` [m],
        ``trusted_from`` [Hz] (:func:`sweep_trusted_from`), ``tolerance_db`` [dB],
        ``setup_dt`` [s], ``dt`` [s] (None: chosen per run for ``tolerance_db``, which is
        None with a given ``dt``) and ``frame`` (where the
        axes are).
    setup : HexapodSetup
        The platform simulated.
    """

    frequency: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    trusted: np.ndarray
    below_floor: np.ndarray
    linear_response: np.ndarray
    linear_stable: bool
    linear_natural_frequencies: np.ndarray
    linear_notes: tuple
    excited_axes: tuple
    amplitude: MappingProxyType
    energy_residual: MappingProxyType
    runs: MappingProxyType
    settings: MappingProxyType
    setup: HexapodSetup = field(repr=False)

    @property
    def magnitude(self) -> np.ndarray:
        """``|response|`` [1, m/rad, rad/m], shape (n, 6, 6); NaN in columns not excited."""
        return np.abs(self.response)

    @property
    def excited(self) -> np.ndarray:
        """Which base axes were excited, one flag per axis of :data:`AXES` [-]."""
        return np.array([axis in self.excited_axes for axis in AXES])

    def to_xarray(self) -> xr.Dataset:
        """Repackage as an ``xarray.Dataset`` (:func:`transmissibility_dataset`).

        Dimensions ``frequency`` [Hz], ``output_dof`` and ``input_dof`` (``x … rz``);
        units in the attributes.

        Returns
        -------
        xarray.Dataset
        """
        return transmissibility_dataset(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> Figure:
        """The 6x6 grid with the linear model dashed (:func:`qzs.viz.hexapod_matrix.
        plot_transmissibility_matrix`); columns not excited are left empty.

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there (atomically; format from the suffix).
        title : str, optional
            Figure title; default one naming the platform and the run settings.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.hexapod_matrix import plot_transmissibility_matrix

        return plot_transmissibility_matrix(
            self.frequency, linear=np.abs(self.linear_response), simulated=self.magnitude,
            trusted=self.trusted, excited=self.excited, frequency_range=_plot_range(self),
            title=title or default_title(self), out=path,
            linear_label=None if self.linear_stable else "linear model (UNSTABLE loop)",
            untrusted_below=self.settings["trusted_from"], frequency_scale=frequency_scale)

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per frequency and "
                            "entry) or ``.mat`` (MATLAB) of :meth:`to_xarray`")

    def summary(self) -> str:
        """One-screen text (:func:`transmissibility_summary`).

        Returns
        -------
        str
        """
        return transmissibility_summary(self)


# ---------------------------------------------------------------- views
def _plot_range(result):
    low = max(result.settings["f0"], 0.05, float(result.frequency[1]))
    return (low, result.settings["f1"])


def default_title(result):
    """The grid's default title: platform, chirps, where the step came from.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    str
    """
    setup, s = result.setup, result.settings
    steps = sorted({f"{r['dt']:g} s ({r['step']})" for r in result.runs.values()})
    loop = ("centralised loops" if getattr(setup, "cartesian", None) is not None else
            "each leg's own loop" if getattr(setup, "leg_controllers", None) is not None else
            f"Kp {setup.controller.pi_kp:g} N/m, Ki {setup.controller.pi_ki:g} N/(m s)")
    return (f"Simulated transmissibility of the {setup.kind} hexapod, platform "
            f"{setup.platform.mass:.3g} kg, {loop}: chirps {s['f0']:g}-{s['f1']:g} Hz over "
            f"{s['duration']:g} s in {', '.join(result.excited_axes)}; dt {', '.join(steps)}\n"
            "platform axis per base axis at the top frame origin, |T| in dB of its unit; "
            "solid: trusted bins, faint: untrusted, dashed: linear model; grey band: the "
            "sweep's start, untrusted")


def transmissibility_summary(result):
    """The text of :meth:`HexapodTransmissibility.summary`.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    str
    """
    s = result.settings
    lines = [f"Hexapod transmissibility: {result.setup.kind} platform "
             f"{result.setup.platform.mass:.4g} kg; chirps {s['f0']:g}-{s['f1']:g} Hz, "
             f"{s['duration']:g} s, in {', '.join(result.excited_axes)}; {s['estimator'].upper()} "
             f"Welch estimate, {s['fft_length']} samples per segment at {s['sample_rate']:g} Hz",
             "  linear model: natural frequencies "
             + ", ".join(number(f, undefined="unstable")
                         for f in result.linear_natural_frequencies)
             + " Hz" + ("" if result.linear_stable else "; the loop is UNSTABLE"),
             "",
             "run  amplitude      dt [s]   step             locked [%]  stop contacts  "
             "stroke used [mm]  ledger closure [-]"]
    for axis in result.excited_axes:
        r = result.runs[axis]
        unit = AXIS_UNITS[AXES.index(axis)]
        lines.append(f"{axis:<4} {result.amplitude[axis]:8.3g} {unit:<4} {r['dt']:9.3g}   "
                     f"{r['step']:<16} {100 * float(np.mean(r['locked_fraction'])):10.1f}  "
                     f"{int(np.sum(r['stop_contacts'])):13d}  "
                     f"{1e3 * float(np.max(r['stroke_used'])):16.2f}  "
                     f"{result.energy_residual[axis]:18.2g}")
    lines += ["", "entry (platform/base)  trusted bins  coherence median  peak |T| (trusted) "
                  "at [Hz]   linear there"]
    magnitude = result.magnitude
    for axis in result.excited_axes:
        j = AXES.index(axis)
        for i in range(6):
            ok = result.trusted[:, i, j]
            head = f"  {AXES[i]:>2} / {axis:<2} [{entry_unit(i, j)}]"
            median = float(np.nanmedian(result.coherence[1:, i, j]))
            if not ok.any():
                lines.append(f"{head:<24}{0:>10}  {median:16.3g}  untrusted everywhere")
                continue
            k = int(np.flatnonzero(ok)[np.argmax(magnitude[ok, i, j])])
            lines.append(f"{head:<24}{int(ok.sum()):>10}  {median:16.3g}  "
                         f"{magnitude[k, i, j]:10.3g} at {result.frequency[k]:6.3g}   "
                         f"{abs(result.linear_response[k, i, j]):10.3g}")
    for note in result.linear_notes:
        lines.append(f"  note: {note}")
    for axis in result.excited_axes:
        lines.append(f"  step of the {axis} run: {step_text(result.runs[axis], s)}")
    return "\n".join(lines)


def step_text(run: Mapping[str, Any], settings: Mapping[str, Any]) -> str:
    """One run's step in words: the step, how it was chosen, its estimated error.

    Parameters
    ----------
    run : mapping
        The run's record (:attr:`HexapodTransmissibility.runs`).
    settings : mapping
        The matrix's settings (``tolerance_db`` [dB]).

    Returns
    -------
    str
    """
    from qzs.engine.step_search import record_line

    return record_line(run)


def run_steps(result: HexapodTransmissibility) -> dict[str, dict[str, Any]]:
    """Each run's step as data (the ``steps`` of :func:`transmissibility_record`).

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    dict
        Per excited axis: ``dt`` [s], ``step`` (how chosen), ``error_db`` (the estimated
        error [dB], NaN if none), ``tolerance_db`` [dB] (None with a given ``dt``),
        ``reference_dt`` [s], ``reason``.
    """
    return {axis: {"dt": run["dt"], "step": run["step"],
                   "error_db": run.get("step_error_db", math.nan),
                   "tolerance_db": result.settings["tolerance_db"],
                   "reference_dt": run.get("step_reference_dt", math.nan),
                   "reason": run.get("step_reason", "given by the caller")}
            for axis, run in result.runs.items()}


def transmissibility_record(result: HexapodTransmissibility) -> dict[str, Any]:
    """The matrix's summary as data (``qzs hexapod transmissibility --json``).

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    dict
        ``summary`` (text), ``excited_axes``, ``amplitude`` [m or rad], ``settings``,
        ``runs`` (per axis: ``dt`` [s], ``step``, ledger, legs), ``steps`` (per axis: ``dt``
        [s], ``step`` (how chosen), ``error_db`` (estimated error [dB], NaN if none),
        ``tolerance_db`` [dB], ``reference_dt`` [s], ``reason``), ``energy_residual`` [-],
        ``linear_stable``, ``linear_natural_frequencies`` [Hz], ``trusted_bins`` (count
        per entry ``"output/input"`` of the excited columns), ``source`` (the set-up's
        file).
    """
    return {"summary": transmissibility_summary(result),
            "excited_axes": list(result.excited_axes), "amplitude": dict(result.amplitude),
            "settings": dict(result.settings),
            "runs": {axis: dict(run) for axis, run in result.runs.items()},
            "steps": run_steps(result),
            "energy_residual": dict(result.energy_residual),
            "linear_stable": result.linear_stable,
            "linear_natural_frequencies": result.linear_natural_frequencies,
            "trusted_bins": {f"{AXES[i]}/{axis}": int(result.trusted[:, i, AXES.index(axis)]
                                                      .sum())
                             for axis in result.excited_axes for i in range(6)},
            "source": result.setup.source}


def transmissibility_schema(estimator="h1"):
    """The CF-1.10 layout (a ``Schema``) of :func:`transmissibility_dataset`.

    Parameters
    ----------
    estimator : str
        The estimator, named in the magnitude's ``long_name``.
    """
    mixed = ("1 on the diagonal blocks, m/rad for a translation per rotation, rad/m for a "
             "rotation per translation (see entry_units)")
    on = ("frequency", "output_dof", "input_dof")
    flag = ("units", "long_name", "flag_meanings", "flag_values")
    dof_doc = "degree of freedom: translations x, y, z [m], rotations rx, ry, rz [rad]"
    variables = (
        Variable(name="magnitude", dims=on, units=mixed,
                 long_name=f"|{estimator.upper()}| platform motion per base motion",
                 attributes={"units_by_entry": "entry_units"}),
        Variable(name="phase", dims=on, units="rad",
                 long_name="phase of the platform motion relative to the base's"),
        Variable(name="coherence", dims=on, units="1",
                 long_name="magnitude-squared coherence of base and platform axis"),
        Variable(name="trusted", dims=on, units="1", dtype="int8", order=flag,
                 long_name="1 where the bin may be read (docs/model.md section 10 and the "
                           "numerical floor)", flag_meanings="untrusted trusted"),
        Variable(name="below_floor", dims=on, units="1", dtype="int8", order=flag,
                 long_name="1 where the dimensionless response is below the numerical floor "
                           "(rounding, not response)", flag_meanings="above below"),
        Variable(name="linear_magnitude", dims=on, units=mixed,
                 long_name="|T| of the linear model at the top frame origin",
                 attributes={"units_by_entry": "entry_units"}),
        Variable(name="linear_phase", dims=on, units="rad", long_name="phase of the linear model"),
        Variable(name="entry_units", dims=on[1:], dtype="str",
                 long_name="unit of each matrix entry"),
        Variable(name="excited", dims=on[2:], units="1", dtype="int8", order=flag, long_name=(
            "1 where the base axis was excited"), flag_meanings="not_excited excited"),
        Variable(name="amplitude", dims=on[2:], units=", ".join(AXIS_UNITS),
                 long_name="chirp displacement amplitude",
                 attributes={"units_by_dof": "; ".join(
                     f"{a}: {u}" for a, u in zip(AXES, AXIS_UNITS))}),
        Variable(name="energy_residual", dims=on[2:], units="1",
                 long_name="largest energy-ledger imbalance over the largest |base work| of the "
                           "run"))
    coordinates = (
        Variable(name="frequency", dims=on[:1], units="Hz", long_name="frequency"),
        *(Variable(name=name, dims=(name,), units="1", long_name=f"{side} {dof_doc}",
                   dtype="str", order=("long_name", "units"))
          for name, side in (("output_dof", "platform"), ("input_dof", "base"))))
    return Schema(kind="a 6x6 transmissibility", coordinates=coordinates, variables=variables,
                  dimensions={"frequency": None, "output_dof": 6, "input_dof": 6})


def transmissibility_dataset(result):
    """:meth:`HexapodTransmissibility.to_xarray`: the matrix as an ``xarray.Dataset``.

    Dimensions ``frequency`` [Hz], ``output_dof`` (platform axis) and ``input_dof`` (base
    axis). A matrix entry's unit depends on both axes, so each matrix variable's
    ``units`` attribute says so in words and the string variable ``entry_units`` gives
    it per entry; ``magnitude`` and ``phase`` [rad] carry the complex estimate (NetCDF has
    no complex type), likewise ``linear_magnitude`` and ``linear_phase``. Flags are int8
    with ``flag_values``/``flag_meanings``; settings, the runs' records and the set-up's
    parameters are global attributes with their units in ``<key>_units``.

    Parameters
    ----------
    result : HexapodTransmissibility
        The matrix.

    Returns
    -------
    xarray.Dataset
    """
    import datetime

    from qzs._version import __version__
    from qzs.model.registry import parameter_fields, unit_of

    values = {
        "magnitude": result.magnitude, "phase": np.angle(result.response),
        "coherence": result.coherence, "trusted": result.trusted,
        "below_floor": result.below_floor, "linear_magnitude": np.abs(result.linear_response),
        "linear_phase": np.angle(result.linear_response), "excited": result.excited,
        "entry_units": [[entry_unit(i, j) for j in range(6)] for i in range(6)],
        "amplitude": [result.amplitude.get(a, np.nan) for a in AXES],
        "energy_residual": [result.energy_residual.get(a, np.nan) for a in AXES],
        "frequency": result.frequency, "output_dof": list(AXES), "input_dof": list(AXES)}
    now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    attrs = {"title": "qzs simulated 6x6 transmissibility of a six-leg platform",
             "source": f"qzs {__version__}: one chirp per base axis through "
                       "simulate_hexapod, single-axis Welch estimates (docs/hexapod.md)",
             "history": f"{now} qzs {__version__}: qzs.hexapod_transmissibility (Python)",
             "qzs_version": __version__, "excited_axes": ", ".join(result.excited_axes),
             "linear_stable": int(result.linear_stable),
             "linear_natural_frequencies": result.linear_natural_frequencies,
             "linear_natural_frequencies_units": "Hz",
             "linear_notes": "; ".join(result.linear_notes) or "none"}
    units = {"f0": "Hz", "f1": "Hz", "duration": "s", "sample_rate": "Hz",
             "fft_length": "samples", "overlap": "1", "coherence_min": "1",
             "base_share_min": "1", "floor_db": "dB", "platform_size": "m",
             "tolerance_db": "dB", "setup_dt": "s", "dt": "s"}
    for key, value in result.settings.items():
        attrs[f"settings.{key}"] = _attribute(value)
        if key in units:
            attrs[f"settings.{key}_units"] = units[key]
    from qzs.engine.step_search import RECORD_UNITS

    run_units = {"dt": "s", "elapsed": "s", "seconds": "s", "energy_residual": "J",
                 "base_work_max": "J", "stroke_used": "m", "stroke_half": "m",
                 "locked_fraction": "1",
                 **{key: unit for key, unit in RECORD_UNITS.items() if unit}}
    for axis, record in result.runs.items():
        for key, value in record.items():
            if key == "step_history":
                value = np.array([v for pair in value for v in pair], dtype=float)
            attrs[f"run.{axis}.{key}"] = _attribute(value)
            if key in run_units:
                attrs[f"run.{axis}.{key}_units"] = run_units[key]
    import dataclasses

    setup = result.setup
    for section, obj in (("isolator", setup.isolator), ("controller", setup.controller)):
        for item in parameter_fields(obj):
            attrs[f"{section}.{item.name}"] = _attribute(getattr(obj, item.name))
            unit = unit_of(item.name)
            if unit:
                attrs[f"{section}.{item.name}_units"] = unit
    platform = setup.platform
    attrs.update({"platform.mass": platform.mass, "platform.mass_units": "kg",
                  "platform.inertia": np.asarray(platform.inertia, dtype=float).ravel(),
                  "platform.inertia_units": "kg*m^2",
                  "platform.center_of_mass": np.asarray(platform.center_of_mass, dtype=float),
                  "platform.center_of_mass_units": "m",
                  "platform.gravity": platform.gravity, "platform.gravity_units": "m/s^2",
                  "geometry.kind": setup.kind,
                  "geometry.base_joints": np.asarray(setup.geometry.base_joints).ravel(),
                  "geometry.top_joints": np.asarray(setup.geometry.top_joints).ravel(),
                  "geometry.home_position": np.asarray(setup.geometry.home_position),
                  "geometry.stroke_half": setup.geometry.stroke_half,
                  "geometry.base_joints_units": "m", "geometry.top_joints_units": "m",
                  "geometry.home_position_units": "m", "geometry.stroke_half_units": "m",
                  "source_file": setup.source or "none"})
    return to_dataset(transmissibility_schema(result.settings["estimator"]), values, attrs)


def _attribute(value):
    """A value as a NetCDF attribute (None -> "none", booleans -> 0/1, sequences -> arrays)."""
    if value is None:
        return "none"
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        array = np.asarray(value)
        if array.dtype.kind in "iub":
            return array.astype(np.int64).ravel()
        if array.dtype.kind == "f":
            return array.astype(float).ravel()
        return ", ".join(str(v) for v in np.ravel(array))
    if isinstance(value, float) and not math.isfinite(value):
        return "nan"
    return value
