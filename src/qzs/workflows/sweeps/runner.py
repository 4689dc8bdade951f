"""A sweep run end to end: checks, step, store, the batches locally or on Dask, progress.

:func:`execute` is the engine of :func:`qzs.workflows.sweeps.run_sweep`: it checks the
cases and the store before any run, chooses the step, runs the batches not yet stored
(:mod:`qzs.workflows.sweeps.batch`) and stores each as it finishes, so that an
interrupted run resumes.
"""
import time
from pathlib import Path
from typing import Any

import numpy as np

from qzs.iotools.paths import removed_on_error
from qzs.workflows.sweeps.batch import run_local, run_on_dask
from qzs.workflows.sweeps.cases import case_settings, check_cases
from qzs.workflows.sweeps.cluster import dask_client
from qzs.workflows.sweeps.definition import SweepDefinition, sample_cases
from qzs.workflows.sweeps.step import choose_sweep_step
from qzs.workflows.sweeps.store import OK, open_store, prepare_store, write_batch
from qzs.workflows.sweeps.store_checks import (check_resume, check_run_length, check_store,
                                             time_samples)

__all__ = ["execute"]


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
    from qzs.engine.progress import progress_bar

    check_resume(store, "store", resume, overwrite)
    columns = sample_cases(definition)
    settings = case_settings(definition, columns)
    check_cases(definition, settings)
    batch = min(definition.batch_size, len(settings))
    check_run_length(definition, settings, cases=batch, threads=threads)  # before any probe
    if definition.simulation["dt"] is None:  # sized at the output period until dt is chosen
        check_store(definition, store, time_samples(definition, settings), argument="store",
                     resume=resume, overwrite=overwrite)
    report = {"cases": 0, "failed": 0, "steps": 0, "wall": 0.0}
    began = time.perf_counter()
    bar = results = None
    with dask_client(scheduler, workers) as client, removed_on_error(store) as made:
        try:
            if definition.simulation["dt"] is None:
                definition, _ = choose_sweep_step(definition, settings)
                check_run_length(definition, settings, cases=batch, threads=threads)
            n_time = time_samples(definition, settings)
            check_store(definition, store, n_time, argument="store", resume=resume,
                         overwrite=overwrite)
            done = prepare_store(store, definition, columns, n_time, resume=resume,
                                 overwrite=overwrite)
            if done.any():
                made.keep()
            size = definition.batch_size
            batches = [(a, min(a + size, definition.n_cases))
                       for a in range(0, definition.n_cases, size)
                       if not done[a:a + size].all()]
            if client is not None:
                results = run_on_dask(client, definition, batches, settings, n_time,
                                1 if threads is None else threads)
            else:
                results = run_local(definition, batches, settings, n_time, threads)
            failed = _stored_failures(store) if done.any() else 0
            bar = progress_bar(total=definition.n_cases, initial=int(done.sum()), unit="case",
                               desc=definition.name, disable=not progress, dynamic_ncols=True,
                               postfix={"failed": failed})
            for result in results:
                write_batch(store, definition, result["start"], result["arrays"], n_time)
                made.keep()
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



def _stored_failures(store):
    dataset = open_store(store)
    return int(np.count_nonzero(dataset["done"].values & (dataset["status"].values > OK)))

