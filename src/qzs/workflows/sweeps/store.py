"""The Zarr store of a sweep: layout, creation, batch writes, resume checks.

Layout (an ``xarray.Dataset``): dimension ``case`` (chunked by the sweep's
``batch_size``), ``frequency`` if a spectral curve is kept, ``time`` if time series
are kept. The varied parameters are coordinates on ``case``. Every case has
``done`` (bool), ``status`` (:data:`STATUS`) and ``message`` ('' or why it failed).
Counts (:data:`COUNTS`, ``n_averages``) are integers; a count of a case that has
none (not run, or invalid) is :data:`COUNT_FILL` (-1), never NaN.

The store has consolidated metadata (``zarr.consolidate_metadata``: one read opens
it); :func:`open_store` uses it where it exists and falls back to reading every
array's metadata for stores written without it.

Writes are atomic per batch: the template (metadata only) is written to a
temporary directory and renamed into place; a batch covers whole chunks, each
chunk file is replaced atomically by zarr, and the batch's ``done`` flags are
written last. A process killed mid-batch leaves that batch not done, and
``--resume`` recomputes exactly the batches that are not done.
"""
from __future__ import annotations

import json
import os
import shutil
import warnings
from collections.abc import Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._optional import require
from qzs._version import __version__
from qzs.engine.batch import STATS
from qzs.engine.channels import run_channels
from qzs.errors import ParameterError
from qzs.model.registry import unit_of

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["STATUS", "PENDING", "OK", "INVALID", "FAILED", "ANALYSIS_FAILED", "COUNTS",
           "COUNT_FILL", "schema", "prepare_store", "write_batch", "open_store",
           "estimated_bytes", "store_exists", "summary_text"]

#: Case status codes stored in ``status``.
STATUS = {0: "pending", 1: "ok", 2: "invalid", 3: "failed", 4: "analysis_failed"}
PENDING, OK, INVALID, FAILED, ANALYSIS_FAILED = range(5)
_STATUS_DOC = ("0 pending (not run), 1 ok, 2 invalid parameters, 3 simulation failed "
               "(diverged), 4 analysis failed")
_METRIC_UNITS = {"resonance_frequency": "Hz", "resonance_peak": "1", "isolation_onset": "Hz",
                 "minus_3db_frequency": "Hz", "rolloff_db_per_decade": "dB/decade"}
_STRING = (np.dtypes.StringDType() if hasattr(np.dtypes, "StringDType")  # numpy >= 2
           else np.dtype(object))
#: Per-case statistics that count something: stored as integers.
COUNTS = ("stop_contacts", "stick_events", "steps")
#: The stored count of a case that has none (not run, invalid parameters).
COUNT_FILL = -1
_REGION = dict(consolidated=False)  # batch writes change no metadata: keep the consolidated one


@contextmanager
def _v3_consolidated():
    """Consolidated metadata in Zarr format 3 is zarr-python's extension: it says so."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata is currently not part")
        yield


def schema(definition, n_time):
    """Variables of the store: name -> (dims, dtype, fill, attrs).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    n_time : int
        Samples kept per time series (0 if none are kept).
    """
    out = definition.outputs
    rate = definition.analysis["sample_rate"]
    variables = {
        "status": (("case",), np.int8, PENDING, {"long_name": "case status",
                                                 "flag_values": list(STATUS),
                                                 "flag_meanings": " ".join(STATUS.values()),
                                                 "description": _STATUS_DOC}),
        "message": (("case",), _STRING, "", {"long_name": "failure message ('' if ok)"}),
    }
    for name in out["stats"]:
        unit, doc = STATS[name]
        if name in COUNTS:
            variables[name] = (("case",), np.int64, COUNT_FILL,
                               {"units": unit, "long_name": doc, "valid_min": 0,
                                "comment": f"{COUNT_FILL} where the case has no count "
                                           "(not run or invalid, see status)"})
        else:
            variables[name] = (("case",), np.float64, np.nan, {"units": unit, "long_name": doc})
    spectral = (out["transmissibility"] or out["coherence"] or out["metrics"] or out["bands"]
                or out["rms_bands"])
    if spectral:
        variables["n_averages"] = (("case",), np.int32, 0,
                                   {"long_name": "Welch segments averaged"})
    for name in out["metrics"]:
        unit = _METRIC_UNITS.get(name, "1")
        variables[name] = (("case",), np.float64, np.nan,
                           {"units": unit, "long_name": name.replace("_", " ")})
    for label, (low, high) in out["bands"].items():
        variables[f"mean_transmissibility_{label}"] = (
            ("case",), np.float64, np.nan,
            {"units": "1", "band": [low, high],
             "long_name": f"mean transmissibility {low:g}-{high:g} Hz, amplitude ratio "
                          "sqrt(S_payload/S_base)"})
    for label, (low, high) in out["rms_bands"].items():
        variables[f"rms_transmissibility_{label}"] = (
            ("case",), np.float64, np.nan,
            {"units": "1", "band": [low, high],
             "long_name": f"RMS transmissibility {low:g}-{high:g} Hz, amplitude ratio "
                          "sqrt(S_payload/S_base)"})
    if out["transmissibility"]:
        variables["transmissibility"] = (("case", "frequency"), np.float64, np.nan,
                                         {"units": "1", "long_name": "transmissibility, "
                                          "amplitude ratio sqrt(S_payload / S_base)"})
    if out["coherence"]:
        variables["coherence"] = (("case", "frequency"), np.float64, np.nan,
                                  {"units": "1", "long_name": "magnitude-squared coherence"})
    recordable = run_channels(every_block=True)
    for name in out["time_series"]:
        _, unit, doc = recordable[name]
        variables[name] = (("case", "time"), np.float64, np.nan,
                           {"units": unit, "long_name": doc, "sample_rate": rate})
    return variables


def _coords(definition, columns, n_time):
    coords = {"case": ("case", np.arange(definition.n_cases), {"long_name": "case index"})}
    for name, values in columns.items():
        values = np.asarray(values)
        if values.dtype.kind in "UO":
            values = values.astype(_STRING)
        units = unit_of(name, definition.excitation_kind) if name != "sample" else "1"
        coords[name] = ("case", values, {"units": units, "long_name": f"varied: {name}"}
                        if name != "sample" else {"long_name": "index of the random draw"})
    if definition.outputs["transmissibility"] or definition.outputs["coherence"]:
        coords["frequency"] = ("frequency", definition.frequency,
                               {"units": "Hz", "long_name": "frequency"})
    if n_time:
        rate = definition.analysis["sample_rate"]
        coords["time"] = ("time", np.arange(n_time) / rate,
                          {"units": "s", "long_name": "time since the start of the run"})
    return coords


def _attrs(definition):
    a, s = definition.analysis, definition.simulation
    return {"sweep_name": definition.name, "sweep_title": definition.title,
            "sweep_method": definition.method, "sweep_hash": definition.hash,
            "sweep_definition": json.dumps(definition.document, sort_keys=True, default=str),
            "sweep_source": definition.source, "batch_size": definition.batch_size,
            "excitation_kind": definition.excitation_kind, "dt": s["dt"], "solver": s["solver"],
            "tolerance_db": s.get("tolerance_db"),
            "dt_note": s.get("step_note", "dt fixed by the sweep file"),
            "sample_rate": a["sample_rate"], "fft_length": a["fft_length"],
            "n_averages": a["n_averages"], "overlap": a["overlap"], "band": a["band"],
            "duration": a["duration"], "qzs_version": __version__}


def _create(path, definition, columns, n_time):
    """Write the template (metadata only) beside `path`, then rename it into place."""
    require("zarr", "writing a sweep store")
    da = require("dask.array", "writing a sweep store")
    import xarray as xr

    chunk = definition.batch_size
    sizes = {"case": definition.n_cases, "frequency": definition.frequency.size,
             "time": n_time}
    data = {}
    for name, (dims, dtype, fill, attrs) in schema(definition, n_time).items():
        shape = tuple(sizes[d] for d in dims)
        chunks = tuple(chunk if d == "case" else sizes[d] for d in dims)
        data[name] = (dims, da.full(shape, fill, dtype=dtype, chunks=chunks), attrs)
    data["done"] = (("case",), da.zeros(definition.n_cases, dtype=bool, chunks=chunk),
                    {"long_name": "case finished and stored"})
    dataset = xr.Dataset(data, coords=_coords(definition, columns, n_time),
                         attrs=_attrs(definition))
    tmp = path.with_name(f".{path.name}.creating-{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        with _v3_consolidated():
            dataset.to_zarr(tmp, mode="w-", compute=False, zarr_format=3, consolidated=True)
        os.rename(tmp, path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def prepare_store(path, definition, columns, n_time, *, resume=False, overwrite=False):
    """Create the store, or open it to resume; returns the ``done`` flags (n_cases,).

    Parameters
    ----------
    path : str or Path
        The Zarr store (a directory).
    definition : SweepDefinition
        The sweep.
    columns : dict of str to ndarray
        The varied parameters of every case (:func:`~qzs.workflows.sweeps.sample_cases`),
        stored as coordinates of a new store.
    n_time : int
        Samples kept per time series (0 if none are kept).
    resume : bool
        Open an existing store written by the same definition, keeping its cases.
    overwrite : bool
        Replace an existing store (unless ``resume``).

    Returns
    -------
    ndarray of bool, shape (n_cases,)
        Which cases are already stored (all False for a new store).

    Raises
    ------
    ParameterError
        `path` exists and neither `resume` nor `overwrite` is set, or it was written
        by a different sweep definition (its hash differs).
    """
    path = Path(path)
    if path.exists() and overwrite and not resume:
        shutil.rmtree(path)
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        _create(path, definition, columns, n_time)
        return np.zeros(definition.n_cases, dtype=bool)
    if not resume:
        raise ParameterError(f"the store {str(path)!r} {store_exists('store')}.")
    try:
        dataset = open_store(path)
    except Exception as error:  # noqa: BLE001 - anything that is not a readable store
        raise ParameterError(f"{str(path)!r} is not a readable sweep store ({error}); "
                             "remove it or choose another store.") from None
    stored = dataset.attrs.get("sweep_hash")
    if stored != definition.hash:
        raise ParameterError(
            f"cannot resume {str(path)!r}: it was written by a different sweep definition "
            f"(stored hash {str(stored)[:12]}, this definition {definition.hash[:12]}). "
            "Resume with the same sweep file, or use --overwrite or another --out.")
    if dataset.sizes.get("case") != definition.n_cases or dataset.sizes.get("time", 0) != n_time:
        raise ParameterError(f"cannot resume {str(path)!r}: its shape does not match the "
                             "definition; use --overwrite or another --out.")
    return dataset["done"].values.astype(bool)


def write_batch(path, definition, start, arrays, n_time):
    """Store one finished batch (cases ``start:start + n``), its ``done`` flags last.

    Parameters
    ----------
    path : str or Path
        The Zarr store, created by :func:`prepare_store`.
    definition : SweepDefinition
        The sweep.
    start : int
        Index of the batch's first case.
    arrays : dict of str to ndarray
        Every variable of :func:`schema`, first axis the batch's cases.
    n_time : int
        Samples kept per time series (0 if none are kept).
    """
    import xarray as xr

    variables = schema(definition, n_time)
    n = len(arrays["status"])
    region = {"case": slice(start, start + n)}
    data = {name: (dims, _stored(arrays[name], dtype, fill))
            for name, (dims, dtype, fill, _) in variables.items()}
    xr.Dataset(data).to_zarr(path, region=region, mode="r+", **_REGION)
    xr.Dataset({"done": ("case", np.ones(n, dtype=bool))}).to_zarr(
        path, region=region, mode="r+", **_REGION)


def _stored(values, dtype, fill):
    """``values`` in the store's dtype: a float count's NaN becomes ``fill``, not garbage."""
    values = np.asarray(values)
    if np.dtype(dtype).kind in "iu" and values.dtype.kind == "f":
        values = np.rint(np.where(np.isfinite(values), values, fill))
    return values.astype(dtype, copy=False)


def store_exists(argument):
    """Why an existing store stops a run that neither resumes nor replaces it, with the
    switches spelt as the caller of ``argument`` spells them
    (:func:`qzs.iotools.paths.switch`): ``resume=True`` in Python, ``--resume`` on the
    command line.

    Parameters
    ----------
    argument : str
        How the caller names the store (``"--out"``, ``"store"``).

    Returns
    -------
    str
    """
    from qzs.iotools.paths import switch

    return (f"exists; pass {switch(argument, 'resume')} to continue it, "
            f"{switch(argument, 'overwrite')} to replace it, or choose another store")


def estimated_bytes(definition, n_time):
    """Uncompressed size of a sweep store [bytes]: an upper bound for the free-space check.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    n_time : int
        Samples kept per time series (0 if none are kept).

    Returns
    -------
    int
    """
    sizes = {"case": definition.n_cases, "frequency": definition.frequency.size,
             "time": n_time}
    total = definition.n_cases * (1 + 64)  # done flags, coordinates
    for dims, dtype, _, _ in schema(definition, n_time).values():
        itemsize = 64 if dtype is _STRING else np.dtype(dtype).itemsize
        total += itemsize * int(np.prod([sizes[d] for d in dims]))
    return total


def open_store(path):
    """Open a sweep store lazily as an ``xarray.Dataset`` (strings as Python objects).

    Parameters
    ----------
    path : str or Path
        The Zarr store (a directory).

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ParameterError
        There is no store at ``path``, or what is there is not a sweep store (a file, a
        folder that is no Zarr store, a Zarr store that ``qzs sweep`` did not write).
    """
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"no sweep store at {str(path)!r}; give the folder that "
                             "`qzs sweep` wrote (its --out, default <name>.zarr).")
    if not path.is_dir():
        raise ParameterError(f"{str(path)!r} is a file, not a sweep store (a Zarr folder "
                             "written by `qzs sweep`); give the store's folder.")
    dataset = _open_zarr(path)
    missing = sorted({"done", "status"} - set(dataset.variables)) + (
        [] if "sweep_hash" in dataset.attrs else ["attribute sweep_hash"])
    if missing:
        raise ParameterError(f"{str(path)!r} is a Zarr store but not a sweep store: it has "
                             f"no {', '.join(missing)}; give a store written by `qzs sweep`.")
    strings = [n for n, v in dataset.variables.items() if v.dtype == _STRING]
    return dataset.assign({n: dataset[n].astype(object) for n in strings if n in
                           dataset.data_vars}).assign_coords(
        {n: dataset[n].astype(object) for n in strings if n in dataset.coords})


def _open_zarr(path):
    """Open lazily, without dask: consolidated metadata where it exists, else per array."""
    import xarray as xr

    try:
        with _v3_consolidated():
            return xr.open_zarr(path, chunks=None, consolidated=True)
    except Exception:  # noqa: BLE001 - no consolidated metadata (older stores), or no store
        pass
    try:
        return xr.open_zarr(path, chunks=None, consolidated=False)
    except Exception as error:  # noqa: BLE001 - zarr's errors for "not a store" vary
        raise ParameterError(f"{str(path)!r} is not a sweep store (no readable Zarr group: "
                             f"{error}); give a store written by `qzs sweep`.") from None


def summary_text(dataset: xr.Dataset, report: Mapping[str, Any] | None = None) -> str:
    """A few lines: cases by status, the commonest failures, this run's throughput.

    Parameters
    ----------
    dataset : xarray.Dataset
        An opened store.
    report : dict, optional
        What :func:`qzs.workflows.sweeps.runner.execute` returned (cases, steps, wall [s]).
    """
    status = dataset["status"].values
    done = dataset["done"].values
    lines = [f"sweep {dataset.attrs.get('sweep_name', '?')!r}: {int(done.sum())} of "
             f"{done.size} cases stored"]
    counts = {STATUS[k]: int(np.count_nonzero(status[done] == k)) for k in STATUS if k}
    lines.append("  " + ", ".join(f"{name} {n}" for name, n in counts.items()))
    if "dt_note" in dataset.attrs:
        lines.append(f"  {dataset.attrs['dt_note']}")
    failed = done & (status > OK)
    if failed.any():
        messages = dataset["message"].values[failed]
        kinds: dict[str, int] = {}
        first: dict[str, tuple[np.integer[Any], str]] = {}
        for index, message in zip(np.flatnonzero(failed), messages):
            key = str(message).split(" at t = ")[0][:80]
            kinds[key] = kinds.get(key, 0) + 1
            first.setdefault(key, (index, str(message)))
        for key, count in sorted(kinds.items(), key=lambda kv: -kv[1])[:3]:
            index, message = first[key]
            lines.append(f"  {count} x (e.g. case {index}): {message[:160]}")
    if report and report["cases"]:
        wall = max(report["wall"], 1e-9)
        lines.append(f"  this run: {report['cases']} cases in {wall:.1f} s wall, "
                     f"{report['steps']:.3g} steps, {report['steps'] / wall:.3g} steps/s")
    return "\n".join(lines)
