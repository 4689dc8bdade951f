"""Running a sweep: one batch task, its reduction, and the local and Dask backends.

:func:`run_batch` is the task every backend runs, unchanged (stumpy style: the
same kernel in-process and on a cluster): it builds the cases of one batch,
groups them by excitation, runs each group through
:func:`qzs.engine.batch.simulate_batch` (the groups side by side, one per core, when
the cases have excitations of their own) and reduces every case to the outputs
the sweep keeps. A case with invalid parameters, a diverged simulation or a failed
analysis is recorded with its status and message; the others go on.
"""
import contextlib
import os
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext
from pathlib import Path
from typing import Any

import numpy as np

from qzs._optional import require
from qzs.analysis.spectral import band_mask, transmissibility, transmissibility_metrics
from qzs.engine.batch import simulate_batch
from qzs.engine.prepare import steps_per_sample
from qzs.defaults import SIMULATION
from qzs.errors import (CaseError, DataError, DataWarning, InvalidCasesError, OutputPathError,
                        ParameterError, SchedulerError)
from qzs.iotools.paths import check_output_path
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters
from qzs.workflows.sweeps.definition import SweepDefinition, case_excitation, sample_cases
from qzs.workflows.sweeps.store import (ANALYSIS_FAILED, COUNTS, FAILED, INVALID, OK,
                                        estimated_bytes, open_store, prepare_store, schema,
                                        write_batch)

__all__ = ["run_batch", "execute", "case_settings", "check_store_path", "build_case",
           "build_model",
           "check_cases", "check_resume", "choose_sweep_step", "dask_client", "STORE_SUFFIX"]

#: The extension of a sweep store: a Zarr folder, not a NetCDF file (``--out store.nc``
#: would make a folder named like a file of another format).
STORE_SUFFIX = ".zarr"

_LOCK = threading.Lock()  # one multi-threaded batch at a time per process


def case_settings(definition, columns):
    """One dict of plain Python values per case: the varied parameters.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    columns : dict of str to ndarray
        One array per varied parameter over the cases
        (:func:`~qzs.workflows.sweeps.definition.sample_cases`).

    Returns
    -------
    list of dict
        Per case, varied parameter name -> value (no ``sample`` index).
    """
    names = list(definition.varied)
    rows = zip(*(np.asarray(columns[n]).tolist() for n in names)) if names else []
    return [dict(zip(names, row)) for row in rows]


def case_duration(definition, settings):
    """Simulated time [s] of a case."""
    if "excitation.duration" in settings:
        return float(settings["excitation.duration"])
    return float(definition.excitation.get("duration", definition.analysis["duration"]))


def _empty(definition, n, n_time):
    """The batch's arrays, filled; counts as floats (NaN) until write_batch stores them."""
    arrays = {}
    for name, (dims, dtype, fill, _) in schema(definition, n_time).items():
        shape = tuple(n if d == "case" else (definition.frequency.size if d == "frequency"
                                             else n_time) for d in dims)
        if name in COUNTS:
            dtype, fill = np.float64, np.nan
        arrays[name] = np.full(shape, fill, dtype=object if name == "message" else dtype)
    return arrays


def build_model(definition, case):
    """A case's model parameters: the sweep's fixed ones with the case's varied ones.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    case : dict
        The case's varied parameters (``excitation.<name>`` entries are left out).

    Returns
    -------
    isolator : IsolatorParameters
    controller : ControllerParameters

    Raises
    ------
    ParameterError
        Invalid parameter values.
    """
    model = {k: v for k, v in case.items() if not k.startswith("excitation.")}
    return update_parameters(IsolatorParameters(), ControllerParameters(),
                             {**definition.parameters, **model})


def build_case(definition, case):
    """A case's parameters and excitation.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    case : dict
        The case's varied parameters (an entry of :func:`case_settings`).

    Returns
    -------
    isolator : IsolatorParameters
    controller : ControllerParameters
    excitation : tuple
        ``(excitation, duration [s])`` of
        :func:`~qzs.workflows.sweeps.definition.case_excitation`.
    key : tuple
        Equal for cases that share their excitation.

    Raises
    ------
    ParameterError
        Invalid parameter values.
    """
    excitation = {**definition.excitation,
                  **{k.split(".", 1)[1]: v for k, v in case.items()
                     if k.startswith("excitation.")}}
    isolator, controller = build_model(definition, case)
    built = case_excitation(definition.excitation_kind, excitation, definition.analysis)
    return isolator, controller, built, tuple(sorted(excitation.items()))


def check_cases(definition, settings):
    """Refuse a sweep with invalid cases before any runs, naming every one of them.

    Each case's parameters are built (:func:`qzs.model.registry.update_parameters`: a
    negative stiction, a NaN gain, a Coulomb force above the stiction), and each distinct
    excitation once. A step too coarse or a model too stiff for it is found per batch
    instead (the case is then recorded ``invalid`` with its reason).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        The varied parameters of each case (:func:`case_settings`).

    Raises
    ------
    InvalidCasesError
        Some cases are invalid (a :class:`~qzs.errors.CaseError`): their indices, values
        and reasons.
    """
    invalid, excitations = [], {}
    for i, case in enumerate(settings):
        varied = {k.split(".", 1)[1]: v for k, v in case.items() if k.startswith("excitation.")}
        try:
            build_model(definition, case)
            key = tuple(sorted(varied.items()))
            if key not in excitations:
                try:
                    case_excitation(definition.excitation_kind,
                                    {**definition.excitation, **varied}, definition.analysis)
                    excitations[key] = None
                except (ParameterError, TypeError) as error:
                    excitations[key] = error
            if excitations[key] is not None:
                raise excitations[key]
        except (ParameterError, TypeError) as error:
            invalid.append((i, case, str(error)))
    if invalid:
        raise InvalidCasesError(invalid, len(settings))


#: Cases of a sweep the accuracy-driven step is chosen on: the first, the middle and the
#: last (for a grid, its two extreme corners and its centre).
STEP_CASES = 3


def choose_sweep_step(definition, settings, *, progress=False):
    """Fix a sweep's step: the largest meeting its ``tolerance_db`` on every case probed.

    A sweep whose file gives no ``dt`` is integrated at the step chosen for
    ``[simulation] tolerance_db`` (default :data:`qzs.defaults.ACCURACY`) on
    :data:`STEP_CASES` cases spread over the sweep, probed at once
    (:func:`qzs.engine.accuracy_batch.choose_batch_step`, each group of them sharing an
    excitation in one batch); the smallest of their steps serves every case (all cases of
    a batch share their steps). Choosing is deterministic, so a resumed sweep gets the
    same step.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        The varied parameters of each case (:func:`case_settings`).
    progress : bool
        Show the probes' progress.

    Returns
    -------
    definition : SweepDefinition
        With ``simulation["dt"]`` set (the same object if the file gave ``dt``).
    choices : tuple of (int, BatchStepChoice)
        The probed cases' indices and their choices, each with the case's own ``dt`` and
        ``error`` (empty if the file gave ``dt``; a case no step meets is left out).

    Raises
    ------
    ParameterError
        No probed case is valid.

    Warns
    -----
    DataWarning
        A probed case for which no step meets the tolerance (its response depends on
        the step): the step comes from the others (the paper's dt = 1e-4 s if none), and
        the note says so.
    """
    import dataclasses

    from qzs.engine.accuracy_batch import choose_batch_step
    from qzs.engine.step_search import MAX_HALVINGS

    simulation = definition.simulation
    if simulation["dt"] is not None:
        return definition, ()
    picks = sorted({int(i) for i in np.linspace(0, len(settings) - 1, STEP_CASES).round()})
    groups, reasons = {}, []
    for i in picks:
        try:
            isolator, controller, (excitation, _), key = build_case(definition, settings[i])
        except (ParameterError, TypeError) as error:
            reasons.append(f"case {i}: {error}")
            continue
        groups.setdefault(key, (excitation, []))[1].append((i, (isolator, controller)))
    if not groups:
        raise ParameterError("no step could be chosen for `tolerance_db`: the cases probed "
                             f"are invalid ({'; '.join(reasons)}); fix them or give `dt`.")
    tolerance = simulation["tolerance_db"]
    choices, unmet = [], []
    for excitation, members in groups.values():  # the probed cases of one excitation at once
        labels = [f"case {i}" for i, _ in members]
        batch = choose_batch_step([pair for _, pair in members], excitation,
                                  tolerance_db=tolerance, solver=simulation["solver"],
                                  sample_rate=definition.analysis["sample_rate"],
                                  max_halvings=MAX_HALVINGS, fallback=True, progress=progress,
                                  labels=labels)
        if not batch.met:  # the one fallback: no case of this excitation sets the step
            unmet.append(f"{', '.join(labels)}: {batch.notes[-1]}")
            continue
        choices += [(i, dataclasses.replace(batch, dt=batch.case_steps[c],
                                            error=batch.case_errors[c]))
                    for c, (i, _) in enumerate(members) if c not in batch.unmet]
        unmet += [note for note in batch.notes if note.startswith(tuple(labels))]
    if choices:
        dt = min(choice.dt for _, choice in choices)
        note = (f"dt = {dt:g} s chosen for the transmissibility within {tolerance:g} dB on "
                "cases " + ", ".join(f"{i} (dt {c.dt:g} s, estimated error {c.error:.2g} dB)"
                                     for i, c in choices))
    else:
        dt = SIMULATION["dt"]
        note = f"dt = {dt:g} s, the paper's step: no case probed meets {tolerance:g} dB"
    if unmet:
        note += "; " + "; ".join(unmet) + "; their curves carry that uncertainty"
        warnings.warn(note, DataWarning, stacklevel=2)
    simulation = {**simulation, "dt": dt, "step_note": note}
    return dataclasses.replace(definition, simulation=simulation), tuple(choices)


def run_batch(definition, start, settings, n_time, threads=None):
    """Simulate and reduce one batch of cases (the task of every backend).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    start : int
        Index of the batch's first case.
    settings : list of dict
        The varied parameters of each case (:func:`case_settings`).
    n_time : int
        Samples kept per time series (0: none).
    threads : int, optional
        Cores to use: the threads of :func:`~qzs.engine.batch.simulate_batch`, or the
        groups run side by side when cases have their own excitation; default all.

    Returns
    -------
    dict
        ``start``, ``arrays`` (one per store variable, first axis the cases),
        ``steps`` and ``elapsed`` [s].
    """
    began = time.perf_counter()
    arrays = _empty(definition, len(settings), n_time)
    groups = {}
    for i, case in enumerate(settings):
        try:
            isolator, controller, built, key = build_case(definition, case)
        except (ParameterError, TypeError) as error:
            arrays["status"][i], arrays["message"][i] = INVALID, str(error)
            continue
        groups.setdefault(key, (built, []))[1].append((i, isolator, controller))
    groups = list(groups.values())
    cores = threads or os.cpu_count() or 1
    if len(groups) > 1 and cores > 1:  # cases with their own excitations: a group per core
        with _LOCK, ThreadPoolExecutor(min(cores, len(groups))) as pool:
            steps = sum(pool.map(lambda group: _run_group(
                definition, *group[0], group[1], arrays, n_time, 1, lock=nullcontext()), groups))
    else:
        steps = sum(_run_group(definition, excitation, duration, members, arrays, n_time,
                               threads) for (excitation, duration), members in groups)
    return {"start": start, "arrays": arrays, "steps": steps,
            "elapsed": time.perf_counter() - began}


def _run_group(definition, excitation, duration, members, arrays, n_time, threads, lock=_LOCK):
    """Run cases sharing one excitation; cases the batch call rejects are recorded invalid.

    ``lock`` is held around the batch call (by default the process-wide one: one
    multi-threaded batch at a time).
    """
    out = definition.outputs
    spectral = bool(out["transmissibility"] or out["coherence"] or out["metrics"]
                    or out["bands"] or out["rms_bands"])
    channels = (["base_acceleration", "payload_acceleration"] if spectral else []) + [
        c for c in out["time_series"] if not spectral or c not in (
            "base_acceleration", "payload_acceleration")]
    sim = definition.simulation
    while members:
        try:
            with lock:
                result = simulate_batch(
                    [(iso, ctl) for _, iso, ctl in members], excitation, duration=duration,
                    dt=sim["dt"], sample_rate=definition.analysis["sample_rate"],
                    solver=sim["solver"], channels=tuple(channels), workers=threads)
        except CaseError as error:
            i = members.pop(error.index)[0]
            arrays["status"][i], arrays["message"][i] = INVALID, error.reason
            continue
        break
    else:
        return 0
    for j, (i, _, _) in enumerate(members):
        for name in out["stats"]:
            arrays[name][i] = result.stats[name][j]
        for name in out["time_series"]:
            series = result.channels[name][j][:n_time]
            arrays[name][i, :series.size] = series
        if result.status[j]:
            arrays["status"][i], arrays["message"][i] = FAILED, result.messages[j]
            continue
        arrays["status"][i] = OK
        if spectral:
            try:
                _reduce(definition, result.channels["base_acceleration"][j],
                        result.channels["payload_acceleration"][j], arrays, i)
            except (DataError, ParameterError) as error:
                arrays["status"][i] = ANALYSIS_FAILED
                arrays["message"][i] = f"transmissibility analysis failed: {error}"
    return int(np.nansum(result.stats["steps"]))


def _reduce(definition, base, payload, arrays, i):
    """Transmissibility curve, metrics in the band and band means of one case."""
    a, out = definition.analysis, definition.outputs
    estimate = transmissibility(base, payload, a["sample_rate"], fft_length=a["fft_length"],
                                overlap=a["overlap"])
    f, magnitude = estimate.frequency, estimate.magnitude
    low, high = a["band"]
    keep = band_mask(f, low, high)
    arrays["n_averages"][i] = estimate.n_averages
    if out["transmissibility"]:
        arrays["transmissibility"][i] = magnitude[keep]
    if out["coherence"]:
        arrays["coherence"][i] = estimate.coherence[keep]
    for label, (lo, hi) in out["bands"].items():  # trusted bins only; NaN if none
        inside = band_mask(f, lo, hi, trusted=estimate.trusted)
        arrays[f"mean_transmissibility_{label}"][i] = (magnitude[inside].mean() if inside.any()
                                                       else np.nan)
    for label, (lo, hi) in out["rms_bands"].items():
        inside = band_mask(f, lo, hi, trusted=estimate.trusted)
        arrays[f"rms_transmissibility_{label}"][i] = (
            np.sqrt(np.mean(magnitude[inside] ** 2)) if inside.any() else np.nan)
    if out["metrics"]:
        metrics = transmissibility_metrics(f[keep], magnitude[keep],
                                           trusted=estimate.trusted[keep],
                                           at_frequencies=a["at_frequencies"]).to_dict()
        for name in out["metrics"]:
            arrays[name][i] = metrics[name]


# ---------------------------------------------------------------- backends
def _local(definition, batches, settings, n_time, threads):
    for start, stop in batches:
        yield run_batch(definition, start, settings[start:stop], n_time, threads)


def _dask(client, definition, batches, settings, n_time, threads):
    """Submit batches to a Dask cluster (at most two per worker thread in flight)."""
    as_completed = require("distributed", "running a sweep on a Dask cluster").as_completed

    pending = iter(batches)
    window = max(2, 2 * sum(client.nthreads().values()))
    futures = as_completed()
    submitted = []

    def submit(batch):
        start, stop = batch
        submitted.append(client.submit(run_batch, definition, start, settings[start:stop], n_time,
                                  threads, retries=2, pure=False))
        futures.add(submitted[-1])

    for batch in [b for _, b in zip(range(window), pending)]:
        submit(batch)
    try:
        for future in futures:
            result = future.result()
            future.release()
            following = next(pending, None)
            if following is not None:
                submit(following)
            yield result
    finally:
        futures.clear()
        client.cancel(submitted)


def _client(scheduler, workers):
    """A Dask client (and whether to close it): given, by address, or on a new LocalCluster."""
    distributed = require("distributed", "running a sweep on a Dask cluster")
    Client, LocalCluster = distributed.Client, distributed.LocalCluster

    if isinstance(scheduler, Client):
        return scheduler, None
    if scheduler is not None:
        return _connect(Client, scheduler), None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None,
                           processes=True)
    return Client(cluster), cluster


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """The Dask client a run uses, or None to run locally; what it starts, it closes.

    Parameters
    ----------
    scheduler : str or distributed.Client, optional
        A scheduler's address (connected to, and the connection closed on exit) or a
        client (used as it is, left open).
    workers : int, optional
        Start a local cluster of this many single-threaded worker processes (closed on
        exit).

    Yields
    ------
    distributed.Client or None
        None when neither is given.

    Raises
    ------
    SchedulerError
        Nothing answers at ``scheduler`` (at once, before any work).
    """
    if scheduler is None and workers is None:
        yield None
        return
    client, cluster = _client(scheduler, workers)
    try:
        yield client
    finally:
        if not _is_client(scheduler):
            client.close()
        if cluster is not None:
            cluster.close()


def _connect(client_class, address):
    """A client of the scheduler at ``address``, saying on stderr what it waits for."""
    import sys

    from dask import config

    _probe(address)
    timeout = config.get("distributed.comm.timeouts.connect")
    print(f"qzs: connecting to the Dask scheduler at {address} (giving up after {timeout}) ...",
          file=sys.stderr, flush=True)
    try:
        return client_class(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as error:
        raise SchedulerError(address, str(error) or type(error).__name__) from None


def _probe(address):
    """Fail at once where nothing can answer: an unknown host, or a refused connection (a
    slow or filtered one is left to the client's own timeout)."""
    import socket

    from distributed.comm import get_address_host_port

    try:
        host, port = get_address_host_port(address)
    except (ValueError, TypeError):  # not a TCP address the probe understands: let Dask try
        return
    try:
        socket.create_connection((host, port), timeout=1.0).close()
    except socket.gaierror as error:
        raise SchedulerError(address, f"the host {host!r} is unknown ({error.strerror})") \
            from None
    except ConnectionRefusedError:
        raise SchedulerError(address, f"nothing listens on port {port} of {host!r} (the "
                             "connection was refused)") from None
    except OSError:
        pass


def execute(definition: SweepDefinition, store: str | Path, *, resume: bool = False,
            overwrite: bool = False, scheduler: Any = None, workers: int | None = None,
            threads: int | None = None, progress: bool = True) -> dict[str, Any]:
    """Run the batches of `definition` not yet in `store`, storing each as it finishes.

    The engine of :func:`qzs.workflows.sweeps.run_sweep`, which says more.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    store : str or Path
        The Zarr store (a directory).
    resume : bool
        Keep the batches already in ``store`` and run the others.
    overwrite : bool
        Replace an existing ``store``.
    scheduler : str or distributed.Client, optional
        Run on this Dask cluster (scheduler address or client).
    workers : int, optional
        Start a local Dask cluster of this many single-threaded worker processes.
    threads : int, optional
        Threads per batch; default all cores locally, 1 on a Dask cluster.
    progress : bool
        Show a progress bar.

    Returns
    -------
    dict
        ``cases`` run now, ``failed`` among them, ``steps`` and ``wall`` [s].
    """
    from tqdm.auto import tqdm

    check_resume(store, "store", resume, overwrite)
    columns = sample_cases(definition)
    settings = case_settings(definition, columns)
    check_cases(definition, settings)
    if definition.simulation["dt"] is None:  # sized at the output period until dt is chosen
        _check_store(definition, store, _n_time(definition, settings), argument="store",
                     resume=resume, overwrite=overwrite)
    report = {"cases": 0, "failed": 0, "steps": 0, "wall": 0.0}
    began = time.perf_counter()
    bar = results = None
    with dask_client(scheduler, workers) as client:  # before any probe or store
        try:
            definition, _ = choose_sweep_step(definition, settings)
            n_time = _n_time(definition, settings)
            _check_store(definition, store, n_time, argument="store", resume=resume,
                         overwrite=overwrite)
            done = prepare_store(store, definition, columns, n_time, resume=resume,
                                 overwrite=overwrite)
            size = definition.batch_size
            batches = [(a, min(a + size, definition.n_cases))
                       for a in range(0, definition.n_cases, size)
                       if not done[a:a + size].all()]
            if client is not None:
                results = _dask(client, definition, batches, settings, n_time,
                                1 if threads is None else threads)
            else:
                results = _local(definition, batches, settings, n_time, threads)
            failed = _stored_failures(store) if done.any() else 0
            bar = tqdm(total=definition.n_cases, initial=int(done.sum()), unit="case",
                       desc=definition.name, disable=not progress, dynamic_ncols=True,
                       postfix={"failed": failed})
            for result in results:
                write_batch(store, definition, result["start"], result["arrays"], n_time)
                n = len(result["arrays"]["status"])
                new_failures = int(np.count_nonzero(result["arrays"]["status"] > OK))
                report["cases"] += n
                report["failed"] += new_failures
                report["steps"] += result["steps"]
                failed += new_failures
                bar.update(n)
                bar.set_postfix(failed=failed, refresh=False)
        finally:
            if bar is not None:
                bar.close()
            if results is not None:
                results.close()
            report["wall"] = time.perf_counter() - began
    return report


def _n_time(definition, settings):
    """Samples kept per time series (0 if none are kept).

    Before the step is chosen (``dt`` None), counted at the output period: the same
    count, give or take the last sample of a duration that is not a whole number of
    periods (enough for the size check made before any case runs).
    """
    if not definition.outputs["time_series"]:
        return 0
    longest = max(case_duration(definition, s) for s in settings)
    dt = definition.simulation["dt"] or 1.0 / definition.analysis["sample_rate"]
    decimation = steps_per_sample(definition.analysis["sample_rate"], dt)
    return int(round(longest / dt)) // decimation + 1


def check_store_path(definition: SweepDefinition, store: str | Path, *,
                     argument: str = "store", resume: bool = False,
                     overwrite: bool = False) -> None:
    """Check a sweep's store before any case runs: writable, room for it, not in the way.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    store : str or Path
        The Zarr store (a directory) to write.
    argument : str
        How the caller names the store, for the message (``"--out"``, ``"store"``).
    resume : bool
        The store will be continued: it may exist, and its size is not checked again.
    overwrite : bool
        The store will be replaced if it exists.

    Raises
    ------
    OutputPathError
        The store is not named ``*.zarr``, the folder cannot be written, the file system
        has less free space than the store's uncompressed size, the store exists without
        ``resume``/``overwrite``, or ``resume`` names no store.
    ParameterError
        Both ``resume`` and ``overwrite``.
    """
    check_resume(store, argument, resume, overwrite)
    settings = case_settings(definition, sample_cases(definition))
    _check_store(definition, store, _n_time(definition, settings), argument=argument,
                 resume=resume, overwrite=overwrite)


def check_resume(store, argument, resume, overwrite, work="the sweep"):
    """``resume`` and ``overwrite`` together, or ``resume`` of no store, are errors.

    Parameters
    ----------
    store : str or Path
        The store (a sweep's or a design search's).
    argument : str
        How the caller names it (``"--out"``, ``"store"``).
    resume, overwrite : bool
        What was asked for.
    work : str
        What leaving out ``resume`` starts, for the message.

    Raises
    ------
    ParameterError
        Both ``resume`` and ``overwrite``.
    OutputPathError
        ``resume`` of a store that does not exist.
    """
    if resume and overwrite:
        raise ParameterError("`resume` (--resume) continues the store and `overwrite` "
                             "(--overwrite) replaces it: give one of them, not both.")
    if resume and not Path(store).exists():
        raise OutputPathError(argument, store, "does not exist, so there is nothing to resume; "
                              f"check the name, or leave out `resume` (--resume) to start "
                              f"{work}")


def _check_store(definition, store, n_time, *, argument, resume, overwrite):
    size = None if resume else estimated_bytes(definition, n_time)
    check_output_path(store, argument=argument, suffixes=(STORE_SUFFIX,), directory=True,
                      estimated_bytes=size)
    if Path(store).exists() and not resume and not overwrite:
        raise OutputPathError(argument, store, "exists; pass `resume` (--resume) to continue "
                              "it, `overwrite` (--overwrite) to replace it, or choose another "
                              "store")


def _stored_failures(store):
    dataset = open_store(store)
    return int(np.count_nonzero(dataset["done"].values & (dataset["status"].values > OK)))


def _is_client(obj):
    try:
        from distributed import Client
    except ImportError:  # without Dask nothing is a client
        return False
    return isinstance(obj, Client)
