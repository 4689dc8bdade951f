"""A sweep's batch task, run in this process or on a Dask cluster.

:func:`run_batch` is the task every backend runs, unchanged (stumpy style: the
same kernel in-process and on a cluster): it builds the cases of one batch,
groups them by excitation, runs each group through
:func:`qzs.engine.batch.simulate_batch` (the groups side by side, one per core, when
the cases have excitations of their own) and reduces every case to the outputs
the sweep keeps (:func:`~qzs.workflows.sweeps.reduction.reduce_case`). A case with
invalid parameters, a diverged simulation or a failed analysis is recorded with its
status and message; the others go on. :func:`run_local` and :func:`run_on_dask` run a
list of batches and yield their results.
"""
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import nullcontext

import numpy as np

from qzs._optional import require
from qzs.engine.batch import simulate_batch
from qzs.errors import CaseError, DataError, ParameterError
from qzs.workflows.sweeps.cases import batch_channels, build_case, needs_estimates
from qzs.workflows.sweeps.reduction import estimate_cases, reduce_case
from qzs.workflows.sweeps.store import ANALYSIS_FAILED, COUNTS, FAILED, INVALID, OK, schema

__all__ = ["run_batch", "run_local", "run_on_dask"]

_LOCK = threading.Lock()  # one multi-threaded batch at a time per process



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



def run_batch(definition, start, settings, n_time, threads=None):
    """Simulate and reduce one batch of cases (the task of every backend).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    start : int
        Index of the batch's first case.
    settings : list of dict
        The varied parameters of each case (:func:`~qzs.workflows.sweeps.cases.case_settings`).
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
    else:  # one thread needs no turn: one-core batches of several tasks run side by side
        lock = nullcontext() if threads == 1 else _LOCK
        steps = sum(_run_group(definition, excitation, duration, members, arrays, n_time,
                               threads, lock=lock) for (excitation, duration), members in groups)
    return {"start": start, "arrays": arrays, "steps": steps,
            "elapsed": time.perf_counter() - began}



def _run_group(definition, excitation, duration, members, arrays, n_time, threads, lock=_LOCK):
    """Run cases sharing one excitation; cases the batch call rejects are recorded invalid.

    ``lock`` is held around the batch call (by default the process-wide one: one
    multi-threaded batch at a time).
    """
    out = definition.outputs
    spectral = needs_estimates(definition)
    channels = batch_channels(definition)
    sim = definition.simulation
    while members:
        try:
            with lock:
                result = simulate_batch(
                    [(iso, ctl) for _, iso, ctl in members], excitation, duration=duration,
                    dt=sim["dt"], sample_rate=definition.analysis["sample_rate"],
                    solver=sim["solver"], channels=channels, workers=threads)
        except CaseError as error:
            i = members.pop(error.index)[0]
            arrays["status"][i], arrays["message"][i] = INVALID, error.reason
            continue
        break
    else:
        return 0
    estimates = _estimates(definition, result) if spectral else {}
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
                if isinstance(estimates[j], Exception):
                    raise estimates[j]
                reduce_case(definition, None, None, arrays, i, estimate=estimates[j])
            except (DataError, ParameterError) as error:
                arrays["status"][i] = ANALYSIS_FAILED
                arrays["message"][i] = f"transmissibility analysis failed: {error}"
    return int(np.nansum(result.stats["steps"]))



def _estimates(definition, result):
    """The transmissibility estimate (or its error) of each case of ``result`` that ran to
    the end, by index, from one batched estimate (:func:`estimate_cases`)."""
    ran = np.flatnonzero(result.status == 0)
    base, payload = (result.channels[name] for name in ("base_acceleration",
                                                         "payload_acceleration"))
    if ran.size < base.shape[0]:  # a diverged case's signals stop short: left out
        base, payload = base[ran], payload[ran]
    return dict(zip(ran.tolist(), estimate_cases(definition, base, payload)))


def run_local(definition, batches, settings, n_time, threads):
    """Run batches in this process, one after the other.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    batches : list of (int, int)
        Each batch's first and past-the-last case index into ``settings``.
    settings : list of dict
        The varied parameters of each case (:func:`~qzs.workflows.sweeps.cases.case_settings`).
    n_time : int
        Samples kept per time series (0: none).
    threads : int or None
        Threads per batch (:func:`run_batch`); default all cores.

    Yields
    ------
    dict
        Each batch's :func:`run_batch` result, in the order of ``batches``.
    """
    for start, stop in batches:
        yield run_batch(definition, start, settings[start:stop], n_time, threads)



def run_on_dask(client, definition, batches, settings, n_time, threads, *, task=None):
    """Submit batches to a Dask cluster (at most two per worker thread in flight).

    A failed task is tried twice more (a lost worker, a full disk).

    Parameters
    ----------
    client : distributed.Client
        The cluster's client (:func:`~qzs.workflows.sweeps.cluster.dask_client`).
    definition : SweepDefinition
        The sweep.
    batches : list of (int, int)
        Each batch's first and past-the-last case index into ``settings``.
    settings : list of dict
        The varied parameters of each case (:func:`~qzs.workflows.sweeps.cases.case_settings`).
    n_time : int
        Samples kept per time series (0: none).
    threads : int or None
        Threads per batch on a worker (:func:`run_batch`).
    task : callable, optional
        What a worker runs, called as ``task(definition, start, settings[start:stop],
        n_time, threads)``; default :func:`run_batch` (the design space submits its own
        task, which calls it).

    Yields
    ------
    dict
        Each batch's :func:`run_batch` result, as it finishes (not in order). Closing
        the generator cancels the tasks still pending.
    """
    as_completed = require("distributed", "running a sweep on a Dask cluster").as_completed

    task = run_batch if task is None else task
    pending = iter(batches)
    window = max(2, 2 * sum(client.nthreads().values()))
    futures = as_completed()
    submitted = []

    def submit(batch):
        start, stop = batch
        submitted.append(client.submit(task, definition, start, settings[start:stop], n_time,
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

