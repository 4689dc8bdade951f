"""The steady-state response's files: the dataset, CSV and JSON of a
:class:`~qzs.workflows.response.result.SteadyStateResponse`, written atomically.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

__all__ = ["RESPONSE_SUFFIXES", "POINT_FIELDS", "response_dataset", "write_response"]

#: File formats :meth:`~qzs.workflows.response.result.SteadyStateResponse.save` writes, by
#: extension.
RESPONSE_SUFFIXES = (".nc", ".csv", ".json")
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


def response_dataset(response):
    """The response as an ``xarray.Dataset``: sweeps on ``(direction, frequency)``.

    Variables of :class:`~qzs.workflows.response.result.ResponsePoint` on
    ``(direction, frequency)`` (``harmonics`` on ``(direction, frequency, harmonic)``,
    ``reason`` and ``start`` as strings), the linear model on ``linear_frequency``, the
    harmonic balance on ``balance_point``, the chirp estimate on ``chirp_frequency``; every
    parameter as a global attribute ``isolator.<name>`` / ``controller.<name>`` with its
    unit.

    Parameters
    ----------
    response : SteadyStateResponse
        The response.

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    from qzs._version import __version__

    directions = list(response.directions)
    n_harm = len(response.points[0].harmonics) if response.points else 0
    variables = {}
    branches = [response.branch(d) for d in directions]
    for name, (unit, doc) in POINT_FIELDS.items():
        values = np.array([b[name] for b in branches])
        if name in ("period_multiple", "periods"):
            values = values.astype(np.int64)
        elif name == "converged":
            values = values.astype(np.int8)
        variables[name] = (("direction", "frequency"), values,
                           {"units": unit, "long_name": doc})
    variables["harmonics"] = (("direction", "frequency", "harmonic"),
                              np.array([b["harmonics"] for b in branches]).reshape(
                                  len(directions), response.frequencies.size, n_harm),
                              {"units": "1", "long_name": "payload acceleration at the "
                               "harmonic over the base's fundamental"})
    for name in ("reason", "start"):
        variables[name] = (("direction", "frequency"),
                           np.array([b[name] for b in branches], dtype=str), {})
    variables["linear_transmissibility"] = (
        ("linear_frequency",), np.asarray(response.linear.get("transmissibility", [])),
        {"units": "1", "long_name": "linearised closed loop |X/Y|"})
    coords = {"direction": ("direction", np.array(directions, dtype=str)),
              "frequency": ("frequency", response.frequencies, {"units": "Hz"}),
              "harmonic": ("harmonic", np.arange(2, 2 + n_harm), {"units": "1"}),
              "linear_frequency": ("linear_frequency",
                                   np.asarray(response.linear.get("frequency", [])),
                                   {"units": "Hz"})}
    if response.balance is not None:
        b = response.balance
        coords["balance_point"] = ("balance_point", np.arange(b.frequency.size))
        variables.update({
            "balance_frequency": ("balance_point", b.frequency, {"units": "Hz"}),
            "balance_transmissibility": ("balance_point", b.transmissibility,
                                         {"units": "1", "long_name": "harmonic balance, "
                                          "fundamental amplitude ratio"}),
            "balance_relative_amplitude": ("balance_point", b.relative_amplitude,
                                           {"units": "m"}),
            "balance_stable": ("balance_point", b.stable.astype(np.int8),
                               {"units": "1", "long_name": "1 where stable (Hill)"}),
            "balance_valid": ("balance_point", b.valid.astype(np.int8),
                              {"units": "1", "long_name": "1 within stops and saturation"})})
    if response.chirp is not None:
        coords["chirp_frequency"] = ("chirp_frequency", response.chirp.frequency,
                                     {"units": "Hz"})
        variables["chirp_transmissibility"] = (
            "chirp_frequency", response.chirp.magnitude,
            {"units": "1", "long_name": "chirp and Welch amplitude ratio (PSD ratio)"})
        variables["chirp_trusted"] = ("chirp_frequency", response.chirp.trusted.astype(np.int8),
                                      {"units": "1"})
    attrs = {"Conventions": "CF-1.10",
             "title": "qzs steady-state frequency response of the semi-active QZS isolator",
             "source": f"qzs {__version__}: stepped-sine simulation (docs/response.md)",
             "qzs_version": __version__, "amplitude": response.amplitude,
             "amplitude_units": "m", "dt": response.dt, "dt_units": "s",
             "solver": response.solver, "elapsed": response.elapsed, "elapsed_units": "s",
             "notes": " | ".join(response.notes)}
    for key, value in response.settings.items():
        attrs[f"settings.{key}"] = value
    attrs.update(_parameter_attributes(response.isolator, response.controller))
    return xr.Dataset(variables, coords=coords, attrs=attrs)


def write_response(response, path):
    """Write ``response`` atomically: ``.nc`` (NetCDF), ``.csv`` (one row per point) or
    ``.json`` (its ``to_record()``).

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
    from qzs.iotools.paths import check_output_path

    path = check_output_path(path, argument="path", suffixes=RESPONSE_SUFFIXES)
    suffix = path.suffix.lower()
    with atomic_path(path) as tmp:
        if suffix == ".nc":
            response.to_xarray().to_netcdf(tmp, engine="h5netcdf")
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
    """The points as CSV: ``# key = value [unit]`` lines, a header, one row per point."""
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
    lines.append(",".join(names))
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
    from qzs.model.registry import unit_of

    attrs = {}
    for section, params in (("isolator", isolator), ("controller", controller)):
        for item in dataclasses.fields(params):
            value = getattr(params, item.name)
            if value is None:
                value = "none"
            elif isinstance(value, bool):
                value = int(value)
            attrs[f"{section}.{item.name}"] = value
            attrs[f"{section}.{item.name}_units"] = unit_of(item.name)
    return attrs

