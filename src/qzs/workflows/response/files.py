"""The steady-state response's files: the dataset, CSV and JSON of a
:class:`~qzs.workflows.response.result.SteadyStateResponse`, written atomically.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

from qzs.iotools.schema import Schema, Variable, to_dataset

__all__ = ["RESPONSE_SUFFIXES", "POINT_FIELDS", "response_schema", "response_dataset",
           "write_response"]

#: File formats :meth:`~qzs.workflows.response.result.SteadyStateResponse.save` writes, by
#: extension.
RESPONSE_SUFFIXES = (".nc", ".csv", ".json", ".mat")
#: Numeric fields of :class:`~qzs.workflows.response.result.ResponsePoint` with their units
#: and descriptions.
POINT_FIELDS = {
    "transmissibility": ("1", "fundamental amplitude ratio of payload to base acceleration"),
    "phase": ("rad", "phase of the payload's fundamental relative to the base's"),
    "subharmonic": ("1", "largest sub-harmonic payload acceleration over the base's fundamental"),
    "period_multiple": ("1", "periods of the excitation per period of the response (0: none)"),
    "relative_amplitude": ("m", "fundamental amplitude of the relative position"),
    "relative_peak": ("m", "half the peak-to-peak relative position"),
    "mean_relative_position": ("m", "mean relative position"),
    "locked_fraction": ("1", "share of the period the payload is locked"),
    "stop_contacts": ("1", "hard-stop contacts per period"),
    "saturated_fraction": ("1", "share of the period the motor command is at its limit"),
    "periods": ("1", "periods simulated at this frequency"),
    "settle_time": ("s", "simulated time at this frequency"),
    "residual": ("1", "scaled state change over the last period(s)"),
    "converged": ("1", "1 if the response became periodic"),
    "dt": ("s", "integration step at this frequency"),
    "seconds": ("s", "wall time of this frequency"),
}


#: Stored types of the fields of :data:`POINT_FIELDS` that are not float64.
_POINT_TYPES = {"period_multiple": "int64", "periods": "int64", "converged": "int8"}


def response_schema(response):
    """The CF-1.10 layout of a response's dataset (:func:`response_dataset`).

    Dimensions ``direction``, ``frequency``, ``harmonic`` and ``linear_frequency``, and
    ``balance_point`` and ``chirp_frequency`` where the response has a harmonic balance
    or a chirp estimate; the fields of :data:`POINT_FIELDS` on ``(direction, frequency)``
    (counts int64, ``converged`` int8), ``harmonics``, ``reason`` and ``start`` (strings),
    the linear model, the harmonic balance and the chirp estimate.

    Parameters
    ----------
    response : SteadyStateResponse
        The response (its sizes, and whether it has a balance and a chirp estimate).

    Returns
    -------
    Schema
    """
    points = ("direction", "frequency")
    dimensions = {"direction": len(response.directions),
                  "frequency": response.frequencies.size,
                  "harmonic": len(response.points[0].harmonics) if response.points else 0,
                  "linear_frequency": np.asarray(response.linear.get("frequency", [])).size}
    variables = [Variable(name=name, dims=points, units=unit, long_name=doc,
                          dtype=_POINT_TYPES.get(name, "float64"))
                 for name, (unit, doc) in POINT_FIELDS.items()]
    variables += [
        Variable(name="harmonics", dims=(*points, "harmonic"), units="1",
                 long_name="payload acceleration at the harmonic over the base's fundamental"),
        Variable(name="reason", dims=points, dtype="str",
                 long_name="why the point did not converge (empty if it did)"),
        Variable(name="start", dims=points, dtype="str",
                 long_name="the state the point's periodic run started from"),
        Variable(name="linear_transmissibility", dims=("linear_frequency",), units="1",
                 long_name="linearised closed loop |X/Y|")]
    coordinates = [Variable(name="direction", dims=("direction",), dtype="str",
                            long_name="direction of the frequency sweep"),
                   Variable(name="frequency", dims=("frequency",), units="Hz",
                            long_name="excitation frequency"),
                   Variable(name="harmonic", dims=("harmonic",), units="1", dtype="int64",
                            long_name="harmonic number (multiple of the fundamental)"),
                   Variable(name="linear_frequency", dims=("linear_frequency",), units="Hz",
                            long_name="frequency of the linearised model's curve")]
    if response.balance is not None:
        dimensions["balance_point"] = response.balance.frequency.size
        coordinates.append(Variable(name="balance_point", dims=("balance_point",),
                                    dtype="int64", units="1",
                                    long_name="index of the point along the harmonic balance "
                                              "curve"))
        variables += [
            Variable(name="balance_frequency", dims=("balance_point",), units="Hz",
                     long_name="harmonic balance, excitation frequency"),
            Variable(name="balance_transmissibility", dims=("balance_point",), units="1",
                     long_name="harmonic balance, fundamental amplitude ratio"),
            Variable(name="balance_relative_amplitude", dims=("balance_point",), units="m",
                     long_name="harmonic balance, fundamental amplitude of the relative "
                               "position"),
            Variable(name="balance_stable", dims=("balance_point",), units="1", dtype="int8",
                     long_name="1 where stable (Hill)"),
            Variable(name="balance_valid", dims=("balance_point",), units="1", dtype="int8",
                     long_name="1 within stops and saturation")]
    if response.chirp is not None:
        dimensions["chirp_frequency"] = response.chirp.frequency.size
        coordinates.append(Variable(name="chirp_frequency", dims=("chirp_frequency",),
                                    units="Hz", long_name="frequency of the chirp estimate"))
        variables += [
            Variable(name="chirp_transmissibility", dims=("chirp_frequency",), units="1",
                     long_name="chirp and Welch amplitude ratio (PSD ratio)"),
            Variable(name="chirp_trusted", dims=("chirp_frequency",), units="1", dtype="int8",
                     long_name="1 where the chirp estimate is trusted")]
    return Schema(kind="a steady-state response", dimensions=dimensions,
                  coordinates=coordinates, variables=variables)


def response_dataset(response):
    """The response as an ``xarray.Dataset``: sweeps on ``(direction, frequency)``.

    Variables of :class:`~qzs.workflows.response.result.ResponsePoint` on
    ``(direction, frequency)`` (``harmonics`` on ``(direction, frequency, harmonic)``,
    ``reason`` and ``start`` as strings), the linear model on ``linear_frequency``, the
    harmonic balance on ``balance_point``, the chirp estimate on ``chirp_frequency``
    (:func:`response_schema`); every parameter as a global attribute ``isolator.<name>`` /
    ``controller.<name>`` with its unit.

    Parameters
    ----------
    response : SteadyStateResponse
        The response.

    Returns
    -------
    xarray.Dataset
    """
    from qzs._version import __version__

    schema = response_schema(response)
    sizes = schema.dimensions
    branches = [response.branch(d) for d in response.directions]
    values = {name: [b[name] for b in branches] for name in POINT_FIELDS}
    values.update({
        "harmonics": np.array([b["harmonics"] for b in branches]).reshape(
            sizes["direction"], sizes["frequency"], sizes["harmonic"]),
        "reason": [b["reason"] for b in branches], "start": [b["start"] for b in branches],
        "linear_transmissibility": response.linear.get("transmissibility", []),
        "direction": list(response.directions), "frequency": response.frequencies,
        "harmonic": np.arange(2, 2 + sizes["harmonic"]),
        "linear_frequency": response.linear.get("frequency", [])})
    if response.balance is not None:
        b = response.balance
        values.update({"balance_point": np.arange(b.frequency.size),
                       "balance_frequency": b.frequency,
                       "balance_transmissibility": b.transmissibility,
                       "balance_relative_amplitude": b.relative_amplitude,
                       "balance_stable": b.stable, "balance_valid": b.valid})
    if response.chirp is not None:
        values.update({"chirp_frequency": response.chirp.frequency,
                       "chirp_transmissibility": response.chirp.magnitude,
                       "chirp_trusted": response.chirp.trusted})
    attrs = {"title": "qzs steady-state frequency response of the semi-active QZS isolator",
             "source": f"qzs {__version__}: stepped-sine simulation (docs/response.md)",
             "qzs_version": __version__, "amplitude": response.amplitude,
             "amplitude_units": "m", "dt": response.dt, "dt_units": "s",
             "solver": response.solver, "elapsed": response.elapsed, "elapsed_units": "s",
             "notes": " | ".join(response.notes)}
    for key, value in response.settings.items():
        attrs[f"settings.{key}"] = value
    attrs.update(_parameter_attributes(response.isolator, response.controller))
    return to_dataset(schema, values, attrs)


def write_response(response, path):
    """Write ``response`` atomically: ``.nc`` (NetCDF), ``.csv`` (one row per point),
    ``.json`` (its ``to_record()``) or ``.mat`` (MATLAB: its dataset, the variables and
    names of the NetCDF file, :func:`qzs.iotools.matfile.write_mat`).

    Parameters
    ----------
    response : SteadyStateResponse
        The response.
    path : str or Path
        The file; its extension chooses the format (:data:`RESPONSE_SUFFIXES`).

    Returns
    -------
    Path
    """
    from qzs.iotools.files import atomic_path
    from qzs.iotools.writer import write_netcdf
    from qzs.iotools.paths import check_output_path

    path = check_output_path(path, argument="path", suffixes=RESPONSE_SUFFIXES)
    suffix = path.suffix.lower()
    if suffix == ".mat":
        from qzs.iotools.matfile import write_mat

        return write_mat(response.to_xarray(), path)
    with atomic_path(path) as tmp:
        if suffix == ".nc":
            write_netcdf(response.to_xarray(), tmp)
        elif suffix == ".json":
            import json

            Path(tmp).write_text(json.dumps(_json_safe(response.to_record()),
                                            allow_nan=False, indent=1), encoding="utf-8")
        else:
            Path(tmp).write_text(_csv(response), encoding="utf-8")
    return path


def _json_safe(value):
    """Plain JSON types: NaN and inf -> None, numpy -> Python."""
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return _json_safe(value.tolist())
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def _csv(response):
    """The points as CSV: ``# key = value [unit]`` lines, a row of names, a row of their
    units (:data:`qzs.iotools.writer.CSV_LAYOUT`, the units of the NetCDF's variables), one
    row per point."""
    from qzs.iotools.writer import CSV_LAYOUT

    attrs = _parameter_attributes(response.isolator, response.controller)
    lines = [f"# amplitude = {response.amplitude!r} [m]", f"# dt = {response.dt!r} [s]",
             f"# solver = {response.solver}"]
    lines += [f"# {key} = {value}" for key, value in attrs.items() if not key.endswith("_units")]
    records = response.to_records()
    n_harm = len(records[0]["harmonics"]) if records else 0
    names = (["direction", "frequency", "transmissibility", "phase"]
             + [f"harmonic_{k}" for k in range(2, 2 + n_harm)]
             + [n for n in records[0] if n not in ("direction", "frequency", "transmissibility",
                                                  "phase", "harmonics")] if records else [])
    dataset = response.to_xarray()
    units = [dataset[name.split("_")[0] + "s" if name.startswith("harmonic_") else name]
             .attrs.get("units", "") if (name.startswith("harmonic_") or name in dataset)
             else "" for name in names]
    header = len(lines) + 2  # the names' line, after the layout line
    lines.append(f"# {CSV_LAYOUT.format(names=header, units=header + 1, data=header + 2)}")
    lines.append(",".join(names))
    lines.append(",".join(units))
    for record in records:
        row = []
        for name in names:
            value = (record["harmonics"][int(name.split("_")[1]) - 2]
                     if name.startswith("harmonic_") else record[name])
            if isinstance(value, str):
                row.append('"' + value.replace('"', "'") + '"' if "," in value else value)
            elif isinstance(value, bool):
                row.append(str(int(value)))
            else:
                row.append(f"{value:.10g}")
        lines.append(",".join(row))
    return "\n".join(lines) + "\n"


def _parameter_attributes(isolator, controller):
    from qzs.model.controller import block_parameters
    from qzs.model.registry import parameter_fields, unit_of

    attrs = {}
    for section, params in (("isolator", isolator), ("controller", controller)):
        for item in parameter_fields(params):
            value = getattr(params, item.name)
            if value is None:
                value = "none"
            elif isinstance(value, bool):
                value = int(value)
            attrs[f"{section}.{item.name}"] = value
            attrs[f"{section}.{item.name}_units"] = unit_of(item.name)
    if isolator.spring is not None:  # the spring law, as a run's records write it
        for name, (value, unit) in isolator.spring.parameters().items():
            attrs[f"isolator.spring.{name}"] = value
            attrs[f"isolator.spring.{name}_units"] = unit
    for name, (value, unit) in block_parameters(controller).items():
        attrs[f"controller.{name}"] = "none" if value is None else value
        attrs[f"controller.{name}_units"] = unit
    return attrs

