"""The result of a six-axis run: :class:`HexapodResult`, its channels and flags, its file.

:data:`HEXAPOD_CHANNELS` and :data:`HEXAPOD_FLAGS` name the columns of the output samples
(:mod:`qzs.engine.hexapod.layout`); :func:`hexapod_schema` is the CF-1.10 layout that
:meth:`HexapodResult.to_xarray` builds and :class:`HexapodWriter` (a configuration of
:class:`qzs.iotools.writer.StreamWriter`) streams.
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from qzs.defaults import AXIS_RATE_UNITS, AXIS_UNITS
from qzs.engine.channels import BLOCK_CHANNELS
from qzs.engine.hexapod.layout import (AXES, C_ACC, C_BASE_ACC, C_BASE_POSE, C_BASE_VEL,
                                       C_DF, C_DS, C_EG, C_EK, C_ESP, C_EST, C_FCO, C_FDA,
                                       C_FDI, C_FFR, C_FLI, C_FMO, C_FOB, C_FPI, C_FSP, C_FST,
                                       C_POSE, C_TIME, C_TWIST, C_V, C_VME, C_WB, C_WM, C_Z,
                                       LEG_COUNT, N_BASE_CHANNELS, N_CHANNELS, N_FLAGS,
                                       O_CONTACT, O_LOCKED)
from qzs.engine.hexapod.statistics import _Statistics, _summary_text
from qzs.errors import ParameterError
from qzs.iotools.paths import check_output_path
from qzs.iotools.schema import CONVENTIONS, Schema, Variable, time_coordinate, to_dataset
from qzs.iotools.writer import StreamWriter, estimated_file_size
from qzs.model.registry import parameter_fields, unit_of

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.hexapod import HexapodGeometry, PlatformParameters
    from qzs.model.isolator import IsolatorParameters

__all__ = ["HexapodResult", "HEXAPOD_CHANNELS", "HEXAPOD_BLOCK_CHANNELS", "HEXAPOD_FLAGS",
           "hexapod_schema",
           "hexapod_file_layout", "HexapodWriter", "estimated_hexapod_size", "HEXAPOD_SUFFIXES",
           "save_hexapod_result"]

_ACCELERATION = ("m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2")
#: Output channels: name -> (first column, dimension (None: time only, "dof" or "leg"),
#: unit (per dof for "dof" variables), description).
HEXAPOD_CHANNELS = {
    "time": (C_TIME, None, "s", "time since the start of the run"),
    "platform_pose": (C_POSE, "dof", AXIS_UNITS,
                      "platform pose relative to home: displacement of the top frame origin "
                      "and rotation angles (R = Rz Ry Rx), world frame"),
    "platform_twist": (C_TWIST, "dof", AXIS_RATE_UNITS,
                       "velocity of the top frame origin and angular velocity, world frame"),
    "platform_acceleration": (C_ACC, "dof", _ACCELERATION,
                              "acceleration of the top frame origin and angular acceleration, "
                              "world frame"),
    "base_pose": (C_BASE_POSE, "dof", AXIS_UNITS,
                  "base pose: displacement of the base point under the top frame origin at "
                  "home and rotation angles (R = Rz Ry Rx)"),
    "base_velocity": (C_BASE_VEL, "dof", AXIS_RATE_UNITS,
                      "velocity of that base point and the base's angular velocity, world frame"),
    "base_acceleration": (C_BASE_ACC, "dof", _ACCELERATION,
                          "acceleration of that base point and the base's angular "
                          "acceleration, world frame"),
    "relative_position": (C_Z, "leg", "m",
                          "leg relative position z_i = L_i - L_i,home + z_ref (its encoder)"),
    "relative_velocity": (C_V, "leg", "m/s", "leg slip velocity v_i = dL_i/dt (0 when locked)"),
    "spring_force": (C_FSP, "leg", "N", "spring force along the leg, on the platform"),
    "friction_force": (C_FFR, "leg", "N",
                       "friction force along the leg (the holding force when locked)"),
    "stop_force": (C_FST, "leg", "N", "hard-stop force along the leg"),
    "motor_force": (C_FMO, "leg", "N", "motor force along the leg (saturated)"),
    "pi_force": (C_FPI, "leg", "N", "PI position-loop command (before saturation)"),
    "damping_force": (C_FDA, "leg", "N", "active damping command (before saturation)"),
    "measured_velocity": (C_VME, "leg", "m/s",
                          "top joint's absolute velocity along the leg seen by the controller "
                          "(high-passed)"),
    "base_work": (C_WB, None, "J", "work done by the base through the legs"),
    "friction_dissipation": (C_DF, None, "J", "energy dissipated by the legs' friction"),
    "motor_work": (C_WM, None, "J", "work done by the motors"),
    "stop_dissipation": (C_DS, None, "J", "energy dissipated in the hard stops"),
    "kinetic_energy": (C_EK, None, "J", "kinetic energy of the platform (translation + rotation)"),
    "spring_energy": (C_ESP, None, "J", "energy stored in the six legs' springs"),
    "gravity_energy": (C_EG, None, "J", "gravitational potential energy m*g*z of the centre of "
                                        "mass (world frame)"),
    "stop_energy": (C_EST, None, "J", "elastic energy stored in the compliant stops"),
}
#: Each leg's block forces beyond PI + damping (docs/model.md §5.1), recorded only when a
#: leg's controller has blocks (0 on a leg without that block): name -> as HEXAPOD_CHANNELS.
HEXAPOD_BLOCK_CHANNELS = {
    name: (column, "leg", BLOCK_CHANNELS[name][1], f"{BLOCK_CHANNELS[name][2]}, per leg")
    for name, column in (("compensation_force", C_FCO), ("friction_estimate", C_FOB),
                         ("dither_force", C_FDI), ("linear_force", C_FLI))}
#: Boolean outputs per leg: name -> (first column, description).
HEXAPOD_FLAGS = {
    "locked": (O_LOCKED, "leg held at zero slip by friction"),
    "stop_contact": (O_CONTACT, "leg beyond one of its stops (in contact)"),
}
_FLAG_MEANINGS = {"locked": "slipping locked", "stop_contact": "free contact"}


def _per_leg(meta, section, part, legs):
    """Add each leg's ``{name: (value, unit)}`` (its blocks', its spring law's) to ``meta``:
    ``<section>.<part><name>`` once when the six agree, else ``<section>.legN.<part><name>``."""
    same = all(b.keys() == legs[0].keys() and all(
        np.array_equal(np.asarray(b[k][0]), np.asarray(legs[0][k][0])) for k in b)
        for b in legs)
    for leg, parameters in enumerate(legs[:1] if same else legs):
        prefix = f"{section}." if same else f"{section}.leg{leg + 1}."
        for name, (value, unit) in parameters.items():
            meta[f"{prefix}{part}{name}"] = (value, unit)


def _attribute(value):
    """A value as a NetCDF-storable attribute (None -> "none", booleans -> 0/1)."""
    if value is None:
        return "none"
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, np.ndarray):
        return value.astype(float).ravel()
    if isinstance(value, (list, tuple)):
        array = np.asarray(value)
        return array.astype(np.int64 if array.dtype.kind in "iub" else float).ravel()
    return value


#: Where a run's output rows go in its file: variable -> (block, column or the six columns).
_BLOCK_COLUMNS = {name: ("data", slice(column, column + 6))
                  for name, (column, _, _, _) in HEXAPOD_BLOCK_CHANNELS.items()}
_COLUMNS = {**{name: ("data", column if dim is None else slice(column, column + 6))
               for name, (column, dim, _, _) in HEXAPOD_CHANNELS.items()},
            **{name: ("flags", slice(column, column + 6))
               for name, (column, _) in HEXAPOD_FLAGS.items()}}
#: The values of the coordinates that are labels: the degrees of freedom and the legs.
_LABELS = {"dof": list(AXES), "leg": np.arange(1, LEG_COUNT + 1)}


def _channels(blocks):
    """The channels of a run: with ``blocks``, each leg's block forces too."""
    return {**HEXAPOD_CHANNELS, **HEXAPOD_BLOCK_CHANNELS} if blocks else HEXAPOD_CHANNELS


def hexapod_schema(blocks=False):
    """The CF-1.10 layout of a hexapod run's dataset and file (docs/model.md §7).

    What :meth:`HexapodResult.to_xarray` builds and :class:`HexapodWriter` streams:
    dimensions ``time`` (unlimited), ``dof`` and ``leg``; every variable has ``units`` and
    ``long_name``; a ``dof`` variable mixes translations and rotations, so its ``units``
    lists one unit per dof (``units_by_dof`` names them); flags are int8 0/1 with
    ``flag_values`` and ``flag_meanings``; time in plain seconds.

    Parameters
    ----------
    blocks : bool
        A run whose controller has blocks beyond PI + damping: its legs' block forces too
        (:data:`HEXAPOD_BLOCK_CHANNELS`).

    Returns
    -------
    Schema
    """
    variables = []
    for name, (_, dim, unit, doc) in _channels(blocks).items():
        if name == "time":
            continue
        dims = ("time",) if dim is None else ("time", dim)
        if dim == "dof":
            variables.append(Variable(
                name=name, dims=dims, units=", ".join(unit), long_name=doc,
                attributes={"units_by_dof": "; ".join(f"{a}: {u}" for a, u in zip(AXES, unit))},
                order=("long_name", "units", "units_by_dof")))
        else:
            variables.append(Variable(name=name, dims=dims, units=unit, long_name=doc,
                                      order=("long_name", "units")))
    variables += [Variable(name=name, dims=("time", "leg"), units="1", long_name=doc,
                           dtype="int8", flag_meanings=_FLAG_MEANINGS[name])
                  for name, (_, doc) in HEXAPOD_FLAGS.items()]
    coordinates = (
        time_coordinate(),
        Variable(name="dof", dims=("dof",), units="1", dtype="str",
                 long_name="degree of freedom: translations x, y, z [m], rotations rx, ry, rz "
                           "[rad]", order=("long_name", "units")),
        Variable(name="leg", dims=("leg",), units="1", long_name="leg number", dtype="int64",
                 order=("long_name", "units")))
    return Schema(kind="a hexapod run", dimensions={"time": None, "dof": 6, "leg": LEG_COUNT},
                  coordinates=coordinates, variables=variables, header_bytes=256 << 10)


def hexapod_file_layout():
    """:func:`hexapod_schema` as plain dicts (the form this layout had before the schema).

    Returns
    -------
    dict
        ``{"variables": {name: (dims, attrs)}, "coordinates": {name: (dims, values,
        attrs)}}`` (the ``time`` coordinate's values are None: the run's own).
    """
    schema = hexapod_schema()
    return {"variables": {v.name: (v.dims, v.attrs()) for v in schema.variables},
            "coordinates": {c.name: (c.dims, _LABELS.get(c.name), c.attrs())
                            for c in schema.coordinates}}


def estimated_hexapod_size(n_samples, suffix=".nc", blocks=False):
    """Size of a hexapod result file of ``n_samples`` samples [bytes], an upper estimate.

    Parameters
    ----------
    n_samples : int
        Output samples [samples] (``duration * sample_rate + 1``).
    suffix : {".nc", ".mat"}
        The file format (a path's suffix; a path is accepted too); a ``.mat`` file needs
        twice the space while it is written (:func:`~qzs.iotools.writer.estimated_file_size`).
    blocks : bool
        The legs' block forces too (:func:`hexapod_schema`).

    Returns
    -------
    int
        Estimated size [bytes]: 8 bytes per channel value, 1 per flag, in whole chunks of
        4096 samples, plus the chunk index and about 256 KiB of header
        (:func:`qzs.iotools.writer.estimated_file_size` of :func:`hexapod_schema`).
    """
    return estimated_file_size(hexapod_schema(blocks), n_samples, suffix)


#: File formats of a hexapod run, by extension (its variables are not columns: no CSV).
HEXAPOD_SUFFIXES = (".nc", ".mat")


class HexapodWriter(StreamWriter):
    """Stream a hexapod run (:func:`qzs.simulate_hexapod`'s ``sink``) to NetCDF or MATLAB.

    :class:`~qzs.iotools.writer.StreamWriter` configured with :func:`hexapod_schema`: a
    hidden temporary file beside the target, disk space reserved before each chunk,
    renamed onto the target only when the run has ended (:meth:`finish`); on any error or
    interruption nothing is left behind. Flags are stored as int8 (0/1) with
    ``flag_values`` and ``flag_meanings``. :meth:`append` takes ``data, flags``: output rows
    of shape (n, N_CHANNELS), the columns of :data:`HEXAPOD_CHANNELS`, and the flags of
    :data:`HEXAPOD_FLAGS`, shape (n, 12).

    Parameters
    ----------
    path : str or Path
        Target file, ending in ``.nc`` or ``.mat`` (:mod:`qzs.iotools.matfile`); its folder
        is created if missing.
    blocks : bool
        The run's controller has blocks beyond PI + damping: its rows hold the legs' block
        forces too (:data:`HEXAPOD_BLOCK_CHANNELS`, N_CHANNELS columns).

    Raises
    ------
    ParameterError
        A suffix other than ``.nc`` or ``.mat``.
    WriteError
        The temporary file cannot be created (attributes ``path`` and ``reason``).

    Examples
    --------
    >>> with HexapodWriter("platform.nc") as writer:  # doctest: +SKIP
    ...     result = simulate_hexapod(geometry, platform, sink=writer.append)
    ...     writer.finish(result)
    """

    def __init__(self, path, blocks=False):
        super().__init__(path, hexapod_schema(blocks),
                         blocks={"data": N_CHANNELS if blocks else N_BASE_CHANNELS,
                                 "flags": N_FLAGS},
                         columns={**_COLUMNS, **_BLOCK_COLUMNS} if blocks else _COLUMNS,
                         values=_LABELS, suffixes=HEXAPOD_SUFFIXES)

    def finish(self, result):
        """Write the run's settings and outcome, flush, and rename the file onto ``path``.

        Parameters
        ----------
        result : HexapodResult
            The run (its parameters and ``run`` dict become global attributes).

        Returns
        -------
        Path
            The path written.

        Raises
        ------
        WriteError
            Writing failed: the temporary file is removed (attributes ``path`` and
            ``reason``).
        """
        return super().finish(result.global_attributes())


def _format(path):
    """The suffix of ``path`` if it is a hexapod run's format, else ``.nc`` (for estimates)."""
    suffix = str(path).lower().rsplit(".", 1)[-1]
    return f".{suffix}" if f".{suffix}" in HEXAPOD_SUFFIXES else ".nc"


def save_hexapod_result(result, path):
    """Write a hexapod run held in memory to NetCDF or MATLAB (``.mat``), atomically.

    Parameters
    ----------
    result : HexapodResult
        A run holding every sample (not the preview of a run streamed to a file).
    path : str or Path
        Target ``.nc`` or ``.mat`` file; checked (folder, permissions, free space) before
        writing.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        ``result`` holds a preview only (``run["preview_every"]`` > 1).
    OutputPathError
        ``path`` cannot be written.
    """
    every = result.run.get("preview_every", 1)
    if every > 1:
        raise ParameterError(
            f"this result holds every {every}th sample only (a preview of a run streamed to a "
            "file); the whole run is in the file it was streamed to.")
    check_output_path(path, argument="path", suffixes=HEXAPOD_SUFFIXES,
                      estimated_bytes=estimated_hexapod_size(len(result), _format(path),
                                                             result.has_blocks))
    with HexapodWriter(path, blocks=result.has_blocks) as writer:
        for start in range(0, len(result), 100_000):
            writer.append(result._data[start:start + 100_000],
                          result._flags[start:start + 100_000])
        return writer.finish(result)


class HexapodResult:
    """Time series and metadata of one hexapod run
    (:func:`~qzs.engine.hexapod.simulate.simulate_hexapod`).

    Channels are attributes and items (``result.platform_pose``, ``result["locked"]``):
    arrays of shape (n,) for ``time`` and the energy ledger, (n, 6) per degree of freedom
    (``x, y, z, rx, ry, rz``) or per leg (legs 1 to 6); see :data:`HEXAPOD_CHANNELS` and
    :data:`HEXAPOD_FLAGS` for names and units. The object only holds and delegates.

    Parameters
    ----------
    data : ndarray, shape (n_samples, N_CHANNELS)
        The output samples.
    flags : ndarray of bool, shape (n_samples, 12)
        Locked and contact flags of the six legs.
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass, inertia, centre of mass and gravity.
    isolators : tuple of IsolatorParameters
        The six legs' plants.
    controllers : tuple of ControllerParameters
        The six legs' loops.
    excitation : dict
        Axis name -> excitation of the axes that moved.
    run : dict
        Solver, ``dt`` [s], ``sample_rate`` [Hz], ``duration`` [s], ``steps``, ``elapsed`` [s]
        (integration only), ``samples``, ``events`` (located transitions), per leg
        ``stick_events`` and ``stop_contacts``, ``stops`` (per leg, [m]), ``control``,
        ``controller_rate`` [Hz], ``completed`` (False if interrupted) and
        ``preview_every`` (1, or k if the result of a run streamed to a file keeps the min/max
        envelope of groups of k samples).
    statistics : dict, optional
        The summary's statistics over every sample (see
        :mod:`qzs.engine.hexapod.statistics`); computed from ``data`` if omitted.
    """

    def __init__(self, data: NDArray[np.float64], flags: NDArray[np.bool_], *,
                 geometry: HexapodGeometry, platform: PlatformParameters,
                 isolators: Iterable[IsolatorParameters],
                 controllers: Iterable[ControllerParameters],
                 excitation: Mapping[str, Excitation], run: dict[str, Any],
                 statistics: dict[str, Any] | None = None) -> None:
        self._data = data
        self._flags = flags
        self.geometry = geometry
        self.platform = platform
        self.isolators = tuple(isolators)
        self.controllers = tuple(controllers)
        self.excitation = dict(excitation)
        self.run = run
        if statistics is None:  # from the samples held
            running = _Statistics([0.5 * (low + high) for low, high in run["stops"]],
                                  self.controllers if self.has_blocks else None)
            running.add(data, flags)
            statistics = running.result()
        self.statistics = statistics

    @property
    def has_blocks(self) -> bool:
        """Whether the run's rows hold the legs' block forces (a controller with blocks)."""
        return self._data.shape[1] > N_BASE_CHANNELS

    def __getitem__(self, name: str) -> NDArray[Any]:
        channels = _channels(self.has_blocks)
        if name in channels:
            column, dim = channels[name][:2]
            return self._data[:, column] if dim is None else self._data[:, column:column + 6]
        if name in HEXAPOD_FLAGS:
            column = HEXAPOD_FLAGS[name][0]
            return self._flags[:, column:column + 6]
        absent = (f" ({name!r} is recorded only when a leg's controller has blocks beyond PI + "
                  "damping)" if name in HEXAPOD_BLOCK_CHANNELS else "")
        raise KeyError(f"no channel {name!r}{absent}; channels are "
                       f"{', '.join([*channels, *HEXAPOD_FLAGS])}.")

    def __getattr__(self, name: str) -> NDArray[Any]:
        if name.startswith("_") or name not in {**HEXAPOD_CHANNELS, **HEXAPOD_BLOCK_CHANNELS,
                                                **HEXAPOD_FLAGS}:
            raise AttributeError(name)
        return self[name]

    def __len__(self) -> int:
        return self._data.shape[0]

    def __repr__(self):
        return (f"<HexapodResult {len(self)} samples, {self['time'][-1]:.6g} s, "
                f"{self.run['solver']} dt={self.run['dt']:g} s>")

    @property
    def steps_per_second(self) -> float:
        """Integration throughput of the run [steps/s]."""
        return self.run["steps"] / max(self.run["elapsed"], 1e-12)

    def mechanical_energy(self) -> NDArray[np.float64]:
        """Kinetic + spring + gravity + stop elastic energy [J] at each sample."""
        return (self["kinetic_energy"] + self["spring_energy"] + self["gravity_energy"]
                + self["stop_energy"])

    def energy_residual(self) -> NDArray[np.float64]:
        """Energy-ledger imbalance [J]: change of mechanical energy minus the net work.

        ``dE - (W_base + W_motor - D_friction - D_stop)``; zero up to the integrator's
        truncation error.
        """
        energy = self.mechanical_energy()
        net = (self["base_work"] + self["motor_work"] - self["friction_dissipation"]
               - self["stop_dissipation"])
        return energy - energy[0] - net

    def metadata(self) -> dict[str, tuple[Any, str]]:
        """Every parameter and run setting with its unit: ``{key: (value, unit)}``.

        Keys ``platform.<name>``, ``geometry.<name>``, ``isolator.<name>`` and
        ``controller.<name>`` (one value, or six per leg where the legs differ),
        ``excitation.<axis>`` (the class) and ``excitation.<axis>.<field>``, ``run.<key>``.
        """
        import dataclasses

        from qzs.model.controller import block_parameters

        meta = {}
        for name in ("base_joints", "top_joints", "home_position", "stroke_half"):
            meta[f"geometry.{name}"] = (getattr(self.geometry, name), "m")
        for field in dataclasses.fields(self.platform):
            meta[f"platform.{field.name}"] = (getattr(self.platform, field.name),
                                              field.metadata.get("unit", ""))
        for section, objects in (("isolator", self.isolators), ("controller", self.controllers)):
            for field in parameter_fields(objects[0]):
                values = [getattr(o, field.name) for o in objects]
                value = values[0] if all(v == values[0] for v in values) else values
                meta[f"{section}.{field.name}"] = (value, unit_of(field.name))
        _per_leg(meta, "controller", "", [block_parameters(c) for c in self.controllers])
        _per_leg(meta, "isolator", "spring.", [{} if i.spring is None else i.spring.parameters()
                                               for i in self.isolators])
        for axis, value in self.excitation.items():
            meta[f"excitation.{axis}"] = (type(value).__name__, "")
            for field in dataclasses.fields(value):
                item = getattr(value, field.name)
                if not isinstance(item, np.ndarray):
                    unit = field.metadata.get("unit", "")
                    if axis in AXES[3:]:
                        unit = unit.replace("m", "rad") if unit in ("m", "m/s", "m/s^2") else unit
                    meta[f"excitation.{axis}.{field.name}"] = (item, unit)
        from qzs.engine.step_search import RECORD_UNITS

        units = {"dt": "s", "sample_rate": "Hz", "duration": "s", "elapsed": "s", "stops": "m",
                 **{key: unit or "-" for key, unit in RECORD_UNITS.items()}}
        for key, value in self.run.items():
            meta[f"run.{key}"] = (value, units.get(key, "1" if key != "solver" else "-"))
        return meta

    def to_xarray(self) -> xr.Dataset:
        """The run as an ``xarray.Dataset`` with dimensions ``time``, ``dof`` and ``leg``.

        CF-1.10 as :meth:`qzs.engine.result.SimulationResult.to_xarray` (time in plain
        seconds, docs/model.md §7; :func:`hexapod_schema`): every variable has ``units`` and
        ``long_name``; a ``dof`` variable mixes translations and rotations, so its ``units``
        lists one unit per dof in the order of the ``dof`` coordinate (``units_by_dof`` says
        so by name); flags are booleans with ``flag_values`` and ``flag_meanings``.
        Parameters and run settings are global attributes with their units in
        ``<key>_units``.
        """
        schema = hexapod_schema(self.has_blocks)
        values = {name: _LABELS[name] if name in _LABELS else self[name]
                  for name in schema.names}
        return to_dataset(schema, values, self.global_attributes(), boolean_flags=True)

    def global_attributes(self) -> dict[str, Any]:
        """The file's global attributes: CF conventions, provenance, every parameter and run
        setting (``<key>`` with its unit in ``<key>_units``)."""
        import datetime

        from qzs._version import __version__

        now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
        attrs = {"Conventions": CONVENTIONS,
                 "title": "qzs simulation of a six-leg platform of semi-active QZS isolator legs",
                 "source": f"qzs {__version__}: fixed-step hexapod dynamics with exact stick-slip "
                           "per leg (model: docs/hexapod.md, docs/model.md)",
                 "history": f"{now} qzs {__version__}: qzs.simulate_hexapod (Python), solver "
                            f"{self.run['solver']}, dt {self.run['dt']} s, "
                            f"{self.run['steps']} steps",
                 "qzs_version": __version__}
        for key, (value, unit) in self.metadata().items():
            attrs[key] = _attribute(value)
            if unit:
                attrs[f"{key}_units"] = unit
        return attrs

    def summary(self) -> str:
        """One-screen text summary: per leg stroke used, contacts, time locked, motor RMS."""
        return _summary_text(self)

    #: The extensions :meth:`save` accepts.
    save_suffixes = HEXAPOD_SUFFIXES

    def save(self, path: str | Path) -> Path:
        """Write the run to NetCDF or MATLAB (:func:`save_hexapod_result`).

        Parameters
        ----------
        path : str or Path
            Target ``.nc`` or ``.mat`` file.

        Returns
        -------
        Path
        """
        return save_hexapod_result(self, path)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> Figure:
        """Plot the run (:func:`qzs.viz.hexapod.plot_hexapod`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there too (format from the suffix).
        title : str, optional
            Figure title; default one naming the run.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.hexapod import plot_hexapod

        return plot_hexapod(self, path=path, title=title)
