"""The sweeps run: each a chain of frequencies, every one starting from the last one's final
state, in this process or in a pool of processes beside the extra tasks (the harmonic
balance, the chirp), stopped at once on an error or an interruption.
"""
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

from qzs.workflows.response.frequency import _run_frequency


def _run_chains(chains, base, extra, workers, progress):
    """Run the sweeps (each a chain of frequencies of the :class:`~qzs.workflows.response.
    frequency.SweepPlan` ``base``) and the extra tasks; returns ``(points in sweep order,
    {name: outcome})``."""
    from qzs.engine.progress import progress_bar

    total = sum(len(c) for c in chains.values())
    bar = progress_bar(total=total, unit="frequency", desc="steady state", disable=not progress,
                       leave=False)
    points = {d: [] for d in chains}
    outcomes = {}
    try:
        if workers == 1:
            for name, (function, task) in extra.items():
                outcomes[name] = function(task)
            for d, chain in chains.items():
                carried = None
                for frequency in chain:
                    point, carried = _run_frequency(base.at(d, frequency, carried))
                    points[d].append(point)
                    bar.update()
        else:
            _run_pool(chains, base, extra, workers, points, outcomes, bar)
    finally:
        bar.close()
    return [p for d in chains for p in points[d]], outcomes


def _run_pool(chains, base, extra, workers, points, outcomes, bar):
    pool = ProcessPoolExecutor(max_workers=workers)
    finished = False
    try:
        pending = {}
        for name, (function, task) in extra.items():
            pending[pool.submit(function, task)] = ("extra", name, None)
        for d, chain in chains.items():
            pending[pool.submit(_run_frequency, base.at(d, chain[0]))] = ("chain", d, 0)
        while pending:
            done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
            for future in done:
                kind, name, index = pending.pop(future)
                if kind == "extra":
                    outcomes[name] = future.result()
                    continue
                point, carried = future.result()
                points[name].append(point)
                bar.update()
                if index + 1 < len(chains[name]):
                    task = base.at(name, chains[name][index + 1], carried)
                    pending[pool.submit(_run_frequency, task)] = ("chain", name, index + 1)
        finished = True
    finally:
        if not finished:  # Ctrl-C, SIGTERM, an error: stop the workers now, not after their task
            processes = getattr(pool, "_processes", None) or {}
            for process in list(processes.values()):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)

