"""Result objects: they hold arrays and metadata, and delegate (pvlib style).

``SimulationResult.plot()`` calls :mod:`qzs.viz`, ``.summary()`` calls
:mod:`qzs.analysis.summary`, and ``.to_xarray()`` only repackages. A run's file layout is
:func:`simulation_schema` (:mod:`qzs.iotools.schema`): ``to_xarray()`` builds its dataset
and :class:`ResultWriter`, a configuration of :class:`qzs.iotools.writer.StreamWriter`,
streams it to NetCDF, CSV or MATLAB (``.save()``, :func:`save_result`, :func:`read_result`).
"""
from __future__ import annotations

import dataclasses
import datetime
import os
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from qzs.engine import kernels as K
from qzs.errors import ParameterError
from qzs.iotools import files
from qzs.iotools.schema import (CONVENTIONS, NONE_VALUE, Schema, Variable, time_coordinate,
                                to_dataset)
from qzs.iotools.writer import StreamWriter, estimated_file_size
from qzs.model.registry import unit_of

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from qzs.model.controller import ControllerParameters
    from qzs.model.excitation import Excitation
    from qzs.model.isolator import IsolatorParameters

__all__ = ["SimulationResult", "CHANNELS", "FLAGS", "FLAG_MEANINGS", "RUN_UNITS", "CONVENTIONS",
           "NONE_VALUE", "simulation_schema", "variable_attributes", "parameter_metadata",
           "run_metadata", "history_line", "file_attributes", "named_block", "ResultWriter",
           "estimated_size", "save_result", "read_result"]

#: Output channels: descriptive name -> (kernel column, unit, description).
CHANNELS = {
    "time": (K.C_TIME, "s", "time"),
    "base_displacement": (K.C_BASE_Y, "m", "base displacement y"),
    "base_velocity": (K.C_BASE_YD, "m/s", "base velocity"),
    "base_acceleration": (K.C_BASE_YDD, "m/s^2", "base acceleration"),
    "payload_displacement": (K.C_X, "m", "payload displacement x = y + z"),
    "payload_velocity": (K.C_XD, "m/s", "payload velocity"),
    "payload_acceleration": (K.C_XDD, "m/s^2", "payload acceleration"),
    "relative_position": (K.C_Z, "m", "relative position z = x - y (encoder)"),
    "relative_velocity": (K.C_V, "m/s", "relative (slip) velocity v"),
    "spring_force": (K.C_F_SPRING, "N", "MagSpring force on the payload"),
    "friction_force": (K.C_F_FRICTION, "N", "friction force on the payload"),
    "stop_force": (K.C_F_STOP, "N", "hard-stop force on the payload"),
    "motor_force": (K.C_F_MOTOR, "N", "motor force on the payload (saturated)"),
    "pi_force": (K.C_F_PI, "N", "PI position-loop command (before saturation)"),
    "damping_force": (K.C_F_DAMP, "N", "active damping command (before saturation)"),
    "measured_payload_velocity": (K.C_V_MEASURED, "m/s",
                                  "payload velocity seen by the controller (high-passed)"),
    "base_work": (K.C_W_BASE, "J", "work done by the base on the payload"),
    "friction_dissipation": (K.C_D_FRICTION, "J", "energy dissipated by friction"),
    "motor_work": (K.C_W_MOTOR, "J", "work done by the motor on the payload"),
    "stop_dissipation": (K.C_D_STOP, "J", "energy dissipated in the hard stops"),
    "kinetic_energy": (K.C_E_KINETIC, "J", "kinetic energy of the payload"),
    "spring_energy": (K.C_E_SPRING, "J", "energy stored in the MagSpring"),
    "gravity_energy": (K.C_E_GRAVITY, "J", "gravitational potential energy m*g*x"),
    "stop_energy": (K.C_E_STOP, "J", "elastic energy stored in a compliant stop"),
}
#: Boolean output channels: name -> (column, description).
FLAGS = {
    "locked": (K.O_LOCKED, "payload held at zero slip (stuck by friction or on a plastic stop)"),
    "stop_contact": (K.O_CONTACT, "payload in contact with a hard stop"),
}
#: CF ``flag_meanings`` of the flags: the words for the values 0 and 1.
FLAG_MEANINGS = {"locked": "slipping locked", "stop_contact": "free contact"}
#: Units of the entries of :attr:`SimulationResult.run` ("1" for counts and 0/1 booleans,
#: "-" for a choice).
RUN_UNITS = {"solver": "-", "dt": "s", "sample_rate": "Hz", "duration": "s", "steps": "1",
             "elapsed": "s", "completed": "1", "stop_contacts": "1", "stick_events": "1",
             "stop_low": "m", "stop_high": "m", "samples": "1", "preview_every": "1",
             "step_tolerance_db": "dB", "step_error_db": "dB", "step_tolerance_m": "m",
             "step_error_m": "m"}
#: File formats of a run's result: suffix -> name.
RESULT_SUFFIXES = files.RESULT_SUFFIXES
#: Where a run's output rows go in its file: variable -> (block, column) of ``(data, flags)``.
_COLUMNS = {**{name: ("data", column) for name, (column, _, _) in CHANNELS.items()},
            **{name: ("flags", column) for name, (column, _) in FLAGS.items()}}


def simulation_schema():
    """The CF-1.10 layout of a run's dataset and file (docs/model.md §7).

    Dimension ``time`` (unlimited: a run is streamed along it); coordinate ``time`` [s]; a
    float64 variable per channel of :data:`CHANNELS` and an int8 flag per flag of
    :data:`FLAGS` (``flag_values`` 0 and 1, ``flag_meanings``), each with ``units`` and
    ``long_name``.

    Returns
    -------
    Schema
    """
    channels = [Variable(name=name, dims=("time",), units=unit, long_name=doc)
                for name, (_, unit, doc) in CHANNELS.items() if name != "time"]
    flags = [Variable(name=name, dims=("time",), units="1", long_name=doc, dtype="int8",
                      flag_meanings=FLAG_MEANINGS[name]) for name, (_, doc) in FLAGS.items()]
    return Schema(kind="a run", dimensions={"time": None}, coordinates=(time_coordinate(),),
                  variables=(*channels, *flags))


def variable_attributes():
    """CF attributes of every variable of a result, ``time`` first, then channels and flags.

    Every variable has ``units`` and ``long_name``; ``time`` also ``standard_name`` and
    ``axis``; the flags (stored as int8 0/1) ``flag_values`` and ``flag_meanings``
    (:func:`simulation_schema`).

    Returns
    -------
    dict of str to dict
        Variable name -> attributes.
    """
    return simulation_schema().attributes()


def _plain(value):
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def parameter_metadata(isolator, controller, excitation):
    """Every parameter of a run with its unit: ``{key: (value, unit)}``.

    Keys are ``isolator.<name>``, ``controller.<name>``, ``excitation`` (the class
    name, no unit) and ``excitation.<field>``; units come from the parameter
    registry and the excitation's field metadata. ``None`` values are kept,
    booleans become 0/1; a displacement record's arrays are data, not metadata.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Controller parameters.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation.

    Returns
    -------
    dict of str to (object, str)
    """
    meta = {}
    for section, params in (("isolator", isolator), ("controller", controller)):
        for field in dataclasses.fields(params):
            meta[f"{section}.{field.name}"] = (_plain(getattr(params, field.name)),
                                               unit_of(field.name))
    meta["excitation"] = (type(excitation).__name__, "")
    for field in dataclasses.fields(excitation):
        value = getattr(excitation, field.name)
        if not isinstance(value, np.ndarray):
            meta[f"excitation.{field.name}"] = (_plain(value), field.metadata.get("unit", ""))
    if "excitation.duration" not in meta and getattr(excitation, "duration", None) is not None:
        meta["excitation.duration"] = (float(excitation.duration), "s")
    return meta


def run_metadata(run):
    """The run's settings and outcome with units: ``{"run.<key>": (value, unit)}``.

    Parameters
    ----------
    run : dict
        :attr:`SimulationResult.run`; counts stay integers, booleans become 0/1.

    Returns
    -------
    dict of str to (object, str)
    """
    return {f"run.{k}": (_plain(v), RUN_UNITS.get(k, "")) for k, v in run.items()}


def _now():
    return datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()


def history_line(excitation, run):
    """One CF ``history`` line: ISO time, qzs version, command and what was run.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.
    run : dict
        :attr:`SimulationResult.run`.

    Returns
    -------
    str
    """
    from qzs._version import __version__

    program = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    if program == "qzs" or sys.argv[0].endswith(os.path.join("qzs", "__main__.py")):
        command = shlex.join(["qzs", *sys.argv[1:]])
    else:
        command = "qzs.simulate (Python)"
    state = "" if run.get("completed", True) else ", interrupted"
    return (f"{_now()} qzs {__version__}: {command}; {type(excitation).__name__} base "
            f"excitation, solver {run.get('solver')}, dt {run.get('dt')} s, "
            f"{run.get('steps')} steps{state}")


def _storable(meta):
    """NetCDF global attributes from ``{key: (value, unit)}``: values, ``<key>_units``,
    ``None`` as :data:`NONE_VALUE` listed in ``none_parameters``."""
    attrs, none = {}, []
    for key, (value, unit) in meta.items():
        if value is None:
            value = NONE_VALUE
            none.append(key)
        attrs[key] = value
        if unit:
            attrs[f"{key}_units"] = unit
    return attrs, none


def file_attributes(isolator, controller, excitation, run, history=None):
    """The global attributes of a result file (CF-1.10 and every parameter with its unit).

    Split in two: ``(head, tail)``, the part known before the run (conventions,
    title, source, parameters) and the part known after it (``run.*``, ``history``).

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Controller parameters.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation.
    run : dict or None
        :attr:`SimulationResult.run`; None for the head only (``tail`` is then empty).
    history : str, optional
        The ``history`` line; default :func:`history_line`.

    Returns
    -------
    (dict, dict)
    """
    from qzs._version import __version__

    params, none = _storable(parameter_metadata(isolator, controller, excitation))
    head = {"Conventions": CONVENTIONS,
            "title": f"qzs simulation of the semi-active QZS isolator under a "
                     f"{type(excitation).__name__} base excitation",
            "source": f"qzs {__version__}: fixed-step simulation of the semi-active "
                      "quasi-zero-stiffness isolator (model: docs/model.md)",
            "references": "Leav, Eriksson, Cazzolato, Robertson, Ding: A novel semi-active "
                          "quasi-zero stiffness vibration isolation system using a "
                          "constant-force magnetic spring and an electromagnetic linear motor",
            "comment": "parameters are global attributes '<section>.<name>' in SI units, "
                       "each with its unit in '<section>.<name>_units'",
            "qzs_version": __version__}
    head.update(params)
    if none:
        head["none_parameters"] = " ".join(none)
    if run is None:
        return head, {}
    tail, _ = _storable(run_metadata(run))
    tail["history"] = history if history is not None else history_line(excitation, run)
    return head, tail


def named_block(data, flags):
    """Output rows as the named arrays :class:`~qzs.analysis.statistics.SummaryStatistics` takes.

    Parameters
    ----------
    data : ndarray, shape (n, N_CHANNELS)
        Output rows, one column per channel of :data:`CHANNELS`.
    flags : ndarray of bool, shape (n, 2)
        The flags of :data:`FLAGS`.

    Returns
    -------
    dict of str to ndarray
        Every channel and flag by name (views), plus ``mechanical_energy`` [J].
    """
    block = {name: data[:, column] for name, (column, _, _) in CHANNELS.items()}
    block.update({name: flags[:, column] for name, (column, _) in FLAGS.items()})
    block["mechanical_energy"] = (block["kinetic_energy"] + block["spring_energy"]
                                  + block["gravity_energy"] + block["stop_energy"])
    return block


class SimulationResult:
    """Time series and metadata of one simulation.

    Channels are attributes (``result.payload_acceleration``) and items
    (``result["locked"]``); see :data:`CHANNELS` and :data:`FLAGS`.

    Parameters
    ----------
    data : ndarray, shape (n_samples, N_CHANNELS)
        The output samples, one column per channel of :data:`CHANNELS` (in their units).
    flags : ndarray of bool, shape (n_samples, 2)
        The boolean outputs, one column per flag of :data:`FLAGS`.
    statistics : dict, optional
        The summary's statistics of every sample, when ``data`` is only a preview of a run
        streamed to a file (see :attr:`statistics`); computed from ``data`` if omitted.

    Attributes
    ----------
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        PI and damping loops of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.
    run : dict
        Solver, ``dt`` [s], ``sample_rate`` [Hz], ``steps``, ``elapsed`` [s] (integration
        only: compiling the kernels is not counted), ``completed``, ``stop_contacts``,
        ``stick_events``, stop positions [m], ``samples`` (output samples of the run) and
        ``preview_every`` (1, or k if the result of a streamed run keeps the min/max
        envelope of groups of k samples, for figures).
    """

    def __init__(self, data: NDArray[np.float64], flags: NDArray[np.bool_], *,
                 isolator: IsolatorParameters, controller: ControllerParameters,
                 excitation: Excitation, run: dict[str, Any],
                 statistics: dict[str, Any] | None = None) -> None:
        self._data = data
        self._flags = flags
        self.isolator = isolator
        self.controller = controller
        self.excitation = excitation
        self.run = run
        self._statistics = statistics

    @property
    def statistics(self) -> dict[str, Any]:
        """What the summary reports, from every sample of the run (also of a streamed one).

        A dict, see :data:`qzs.analysis.statistics.SUMMARY_STATISTICS` for names and units.
        """
        if self._statistics is None:  # a result built from arrays: summarise them
            from qzs.analysis.statistics import SummaryStatistics

            center = 0.5 * (self.run["stop_low"] + self.run["stop_high"])
            statistics = SummaryStatistics(center, self.isolator.motor_force_max)
            statistics.add(named_block(self._data, self._flags))
            self._statistics = statistics.result()
        return self._statistics

    def __getitem__(self, name: str) -> NDArray[Any]:
        if name in CHANNELS:
            return self._data[:, CHANNELS[name][0]]
        if name in FLAGS:
            return self._flags[:, FLAGS[name][0]]
        raise KeyError(f"no channel {name!r}; channels are {', '.join([*CHANNELS, *FLAGS])}.")

    def __getattr__(self, name: str) -> NDArray[Any]:
        if name.startswith("_") or (name not in CHANNELS and name not in FLAGS):
            raise AttributeError(name)
        return self[name]

    def __len__(self) -> int:
        return self._data.shape[0]

    @property
    def completed(self) -> bool:
        """False if the run was interrupted before its end."""
        return self.run["completed"]

    @property
    def steps_per_second(self) -> float:
        """Integration throughput of the run [steps/s]."""
        return self.run["steps"] / max(self.run["elapsed"], 1e-12)

    def mechanical_energy(self) -> NDArray[np.float64]:
        """Kinetic + spring + gravity + stop elastic energy [J] at each sample."""
        return cast("NDArray[np.float64]",  # a sum of four arrays, never the start value 0
                    sum(self[n] for n in ("kinetic_energy", "spring_energy", "gravity_energy",
                                          "stop_energy")))

    def energy_residual(self) -> NDArray[np.float64]:
        """Energy-ledger imbalance [J]: change of mechanical energy minus net work.

        ``dE - (W_base + W_motor - D_friction - D_stop)``; zero up to the
        integrator's truncation error.
        """
        energy = self.mechanical_energy()
        net = self.base_work + self.motor_work - self.friction_dissipation - self.stop_dissipation
        return energy - energy[0] - net

    def metadata(self) -> dict[str, Any]:
        """Flat ``dict`` of every parameter, the excitation, the run settings and the version.

        ``None`` values are kept, booleans are 0/1; the units are in
        :func:`parameter_metadata` and :func:`run_metadata`.
        """
        from qzs._version import __version__

        meta: dict[str, Any] = {"qzs_version": __version__}
        meta.update({k: v for k, (v, _) in parameter_metadata(
            self.isolator, self.controller, self.excitation).items()})
        meta.update({k: v for k, (v, _) in run_metadata(self.run).items()})
        return meta

    def to_xarray(self) -> xr.Dataset:
        """The run as an ``xarray.Dataset`` on dimension ``time``, with CF-1.10 metadata.

        The same variables and attributes as a saved NetCDF file (:func:`simulation_schema`,
        docs/model.md §7), except that the flags stay boolean and ``None`` parameters are
        ``"none"`` (listed in ``none_parameters``).
        """
        schema = simulation_schema()
        head, tail = file_attributes(self.isolator, self.controller, self.excitation, self.run)
        return to_dataset(schema, {name: self[name] for name in schema.names},
                          {**head, **tail}, boolean_flags=True)

    def summary(self) -> str:
        """One-screen text summary of the run."""
        from qzs.analysis.summary import summary_text

        return summary_text(self)

    def plot(self, **kwargs: Any) -> Figure:
        """Plot the time series (see :func:`qzs.viz.plot_simulation`)."""
        from qzs.viz.simulation import plot_simulation

        return plot_simulation(self, **kwargs)

    def save(self, path: str | Path) -> Path:
        """Write the run atomically to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

        Parameters
        ----------
        path : str or Path
            Target file; its suffix (``.nc``, ``.csv`` or ``.mat``) chooses the format.

        Returns
        -------
        Path
            The path written (see :func:`save_result`).
        """
        return save_result(self, path)

    def __repr__(self):
        return (f"<SimulationResult {len(self)} samples, {self['time'][-1]:.6g} s, "
                f"{self.run['solver']} dt={self.run['dt']:g} s, "
                f"{'complete' if self.completed else 'interrupted'}>")



class ResultWriter(StreamWriter):
    """Stream a run's result to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

    :class:`~qzs.iotools.writer.StreamWriter` configured with :func:`simulation_schema`:
    memory grows with the chunk appended, not with the run; the file is written to a
    hidden temporary file beside ``path`` and renamed onto ``path`` by :meth:`finish`;
    :meth:`abort` (also called on any exception, ``KeyboardInterrupt`` included, when
    used as a context manager) removes it. NetCDF files follow CF-1.10 (docs/model.md §7):
    ``time`` is an unlimited dimension, the flags are int8 with
    ``flag_values``/``flag_meanings``, the parameters global attributes with their units.
    CSV files have the parameters as ``# key = value [unit]`` header lines, the rows, and
    the run's outcome as trailing ``# run.key = value`` lines (known only at the end).
    MATLAB files (:mod:`qzs.iotools.matfile`) hold the same variables, with the units and
    parameters in structs.
    :func:`save_result` writes through this class; so does :func:`qzs.simulate`'s
    ``sink`` when a run is streamed to a file. :meth:`append` takes ``data, flags``: output
    rows of shape (n, N_CHANNELS), one column per channel of :data:`CHANNELS`, and the flags
    of :data:`FLAGS`, shape (n, 2).

    Parameters
    ----------
    path : str or Path
        Target file, ending in ``.nc``, ``.csv`` or ``.mat``; its folder is created if
        missing.
    isolator : IsolatorParameters
        Plant parameters of the run.
    controller : ControllerParameters
        Controller parameters of the run.
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        Base excitation of the run.

    Raises
    ------
    ParameterError
        A suffix other than ``.nc``, ``.csv`` or ``.mat``.
    WriteError
        The temporary file cannot be created (attributes ``path`` and ``reason``).

    Examples
    --------
    >>> with ResultWriter("run.nc", isolator=iso, controller=ctrl,
    ...                   excitation=ex) as writer:  # doctest: +SKIP
    ...     for data, flags in chunks:
    ...         writer.append(data, flags)
    ...     writer.finish(run)
    """

    def __init__(self, path, *, isolator, controller, excitation):
        self._parameters = (isolator, controller, excitation)
        head, _ = file_attributes(isolator, controller, excitation, None)
        super().__init__(path, simulation_schema(), blocks={"data": K.N_CHANNELS, "flags": 2},
                         columns=_COLUMNS, attributes=head, suffixes=tuple(RESULT_SUFFIXES))

    def finish(self, run):
        """Write the run's settings and outcome, flush, and rename the file onto ``path``.

        Parameters
        ----------
        run : dict
            :attr:`SimulationResult.run` (its entries become ``run.*`` global attributes,
            with the ``history`` line).

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
        _, tail = file_attributes(*self._parameters, run)
        return super().finish(tail)


def estimated_size(n_samples, suffix):
    """Size of a run's result file of ``n_samples`` samples [bytes], an upper estimate.

    NetCDF: 8 bytes per channel value and 1 per flag, in whole chunks of 4096
    samples, plus about 128 KiB of header and the chunk index; CSV: about 17 bytes
    per value (the ``%.10g`` format and a comma) plus the header lines
    (:func:`qzs.iotools.writer.estimated_file_size` of :func:`simulation_schema`).

    Parameters
    ----------
    n_samples : int
        Output samples of the run [samples] (``duration * sample_rate + 1``).
    suffix : {".nc", ".csv"}
        The file format (a path's suffix; a path is accepted too).

    Returns
    -------
    int
        Estimated size [bytes].
    """
    return estimated_file_size(simulation_schema(), n_samples, suffix)


def save_result(result, path):
    """Write a :class:`SimulationResult` to NetCDF (``.nc``), CSV (``.csv``) or MATLAB (``.mat``).

    Each carries every parameter with its unit, the excitation, the run settings and
    the qzs version as metadata (NetCDF: CF-1.10 global attributes; CSV:
    ``# key = value [unit]`` lines; MATLAB: structs, :mod:`qzs.iotools.matfile`), see
    docs/model.md §7. Written through :class:`ResultWriter` in chunks, atomically.

    Parameters
    ----------
    result : SimulationResult
        The run.
    path : str or Path
        Target file, ending in ``.nc``, ``.csv`` or ``.mat``.

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    ParameterError
        Any other suffix, or a preview of a streamed run (``run["preview_every"] > 1``).
    WriteError
        Writing failed (disk full, permissions; attributes ``path`` and ``reason``);
        nothing is left behind.
    """
    every = result.run.get("preview_every", 1)
    if every != 1:
        raise ParameterError(f"this result keeps only every {every}th sample of a run streamed "
                             "to a file (a preview); its full samples are in that file.")
    data, flags = result._data, result._flags
    with ResultWriter(path, isolator=result.isolator, controller=result.controller,
                      excitation=result.excitation) as writer:
        step = 1 << 17
        for start in range(0, max(len(result), 1), step):
            writer.append(data[start:start + step], flags[start:start + step])
        return writer.finish(result.run)


def read_result(path: str | Path) -> xr.Dataset:
    """Read a saved run (``.nc`` or ``.csv``) back as an ``xarray.Dataset``.

    The flags come back boolean and ``None`` parameters as ``None``, so that a
    NetCDF file reads back as the run's :meth:`SimulationResult.to_xarray` (a CSV one
    too, to its 10 significant digits): :func:`qzs.iotools.files.read_result` with
    :func:`simulation_schema`.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`save_result` or :class:`ResultWriter` (any suffix other
        than ``.nc`` is read as CSV).

    Returns
    -------
    xarray.Dataset
        The channels on coordinate ``time`` [s], units and metadata in attributes.

    Raises
    ------
    DataError
        Missing or unreadable file, or a CSV without a header line or with mismatched
        columns.
    """
    return files.read_result(path, simulation_schema())
