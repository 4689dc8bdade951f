#!/usr/bin/env python
"""The shipped design question as a whole process (issue 34, targets 1 and 5).

    .venv/bin/python benchmarks/bench_optimize.py                  # best of 3
    .venv/bin/python benchmarks/bench_optimize.py --quick          # best of 2
    .venv/bin/python benchmarks/bench_optimize.py --repeats 5 --idle-wait 60

1. **Target 1**: ``qzs optimize isolation_vs_effort --quiet`` (192 designs x 3 stictions
   over 8 generations, a 41 s chirp at dt 1 ms: 576 runs), the whole process from the
   shell, warm (numba's cache filled by an untimed run first), against **5 s** on the
   machine's cores. Before issue 34 the same command took 32 s (7.9 s once the hunting
   prediction and linear metrics were vectorised, targets 2 and 3).
2. **Target 5**: the same with ``--workers 1`` and ``--workers 2`` (a local Dask cluster of
   single-threaded worker processes, each batch's runs, estimates and linear metrics in
   one task on a worker), and with ``--threads 1`` (this process, one core).
3. **The same answer**: every configuration's Pareto set (``pareto.nc``: the designs'
   variables, goal values and flags) and every evaluated design (``designs.nc``) equal,
   bit for bit, to the one-worker result.
4. **Where the time goes** (information): one run of the default configuration in a child
   process, timed stage by stage, wall and CPU time (start-up and imports, the evaluation,
   the rest of the search, the files and figure); on a busy machine the CPU times say more.

Every timing is the best of N, each run started after waiting up to ``--idle-wait`` s for the
machine to go quiet (the helpers of ``bench_simulate.py``); the other load before each run is
printed. Exits 0.
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_simulate import (  # noqa: E402
    _busy_note, busy_runs, _load, log_machine, repeats_of, report_only, timing_options,
    wait_for_idle)

TARGET_OPTIMIZE = 5.0     # [s] the whole design question (issue 34, target 1)
PROBLEM = "isolation_vs_effort"
#: (label, extra command-line arguments); the first is target 1's, the second the reference.
CONFIGURATIONS = (("default (this process, all cores)", []),
                  ("--workers 1", ["--workers", "1"]),
                  ("--workers 2", ["--workers", "2"]),
                  ("--threads 1", ["--threads", "1"]))

log = lambda msg="": print(msg, flush=True)  # noqa: E731

#: A child process's stages, printed as JSON (what --breakdown times).
_STAGES = r"""
import json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
t0 = clock()
marks = {}
import qzs, qzs.cli
marks["start-up: python, import qzs and its command line"] = clock()
from qzs.workflows.design_space import load_problem, optimize
from qzs.workflows.design_space import optimizer
from qzs.workflows.design_space.result import file_writer
marks["import the design space (pymoo, ...; scipy.signal loads with the first estimate)"] = clock()
evaluation = [0.0, 0.0]
evaluate = optimizer.evaluate
def timed(*args, **kwargs):
    began = clock()
    try:
        return evaluate(*args, **kwargs)
    finally:
        now = clock()
        evaluation[0] += now[0] - began[0]
        evaluation[1] += now[1] - began[1]
optimizer.evaluate = timed
problem = load_problem(sys.argv[1])
with file_writer(sys.argv[2]) as writer:  # as the command line: forked before the search
    result = optimize(problem, sys.argv[2] + "/s.zarr", overwrite=True, progress=False)
    marks["search: store, NSGA-II, store writes (evaluation apart)"] = clock()
    writer.write(result)
marks["files and figure (7 files, by the forked writer; its CPU not counted)"] = clock()
out, last = {}, t0
for name, t in marks.items():
    out[name] = [t[0] - last[0], t[1] - last[1]]
    last = t
search = "search: store, NSGA-II, store writes (evaluation apart)"
out[search] = [out[search][0] - evaluation[0], out[search][1] - evaluation[1]]
out["evaluation: 576 runs, estimates, linear metrics (8 generations)"] = evaluation
out["total (in the process)"] = [last[0] - t0[0], last[1] - t0[1]]
print(json.dumps(out))
"""


def qzs_command():
    exe = Path(sys.executable).with_name("qzs")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "qzs"]


def _run(extra, out):
    start = time.perf_counter()
    subprocess.run(qzs_command() + ["optimize", PROBLEM, "--quiet", "--overwrite", "--out",
                                    str(out)] + extra, check=True, capture_output=True)
    return time.perf_counter() - start


def measure(repeats, idle_wait, runs, folder, configurations=CONFIGURATIONS):
    """Best wall time [s] of each configuration; its output folder is ``folder/<k>``."""
    _run([], folder / "warm")  # numba's cache, the first imports
    best = {}
    for k, (label, extra) in enumerate(configurations):
        times = []
        for r in range(repeats):
            busy = wait_for_idle(idle_wait)
            seconds = _run(extra, folder / str(k))
            times.append(seconds)
            runs.append(dict(seconds=seconds, busy=busy))
            log(f"  {label} {r + 1}/{repeats}: {seconds:.2f} s{_busy_note(busy)}")
        best[label] = min(times)
    return best


def same_answer(folder, k, reference):
    """Whether output ``folder/k`` holds the Pareto set and designs of ``folder/reference``,
    bit for bit (every variable of ``pareto.nc`` and ``designs.nc``)."""
    import numpy as np
    import xarray as xr

    for name in ("pareto.nc", "designs.nc"):
        with xr.open_dataset(folder / str(k) / name) as a, \
                xr.open_dataset(folder / str(reference) / name) as b:
            if set(a.variables) != set(b.variables):
                return False
            for v in a.variables:
                x, y = a[v].values, b[v].values
                if x.shape != y.shape or not np.array_equal(
                        x, y, equal_nan=x.dtype.kind == "f"):
                    return False
    return True


def breakdown(folder):
    """``{stage: [wall, cpu]}`` [s] of one default run (see :data:`_STAGES`; cpu: this
    process's threads together)."""
    proc = subprocess.run([sys.executable, "-c", _STAGES, PROBLEM, str(folder)], check=True,
                          capture_output=True, text=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def verdicts(best, equal):
    """Rows ``(target, what, qzs, baseline, ratio, goal, verdict)``."""
    labels = [label for label, _ in CONFIGURATIONS]
    default, one, two = best[labels[0]], best[labels[1]], best[labels[2]]
    rows = [(14, f"`qzs optimize {PROBLEM}` whole process, warm (issue 34 target 1)",
             f"{default:.2f} s", "32 s (7.9 s)", f"{32.0 / default:.1f}x",
             f"<= {TARGET_OPTIMIZE:g} s",
             "PASS" if default <= TARGET_OPTIMIZE and equal[labels[0]] else "FAIL")]
    rows.append(("14w", "  --workers 2 against --workers 1 (target 5)", f"{two:.2f} s",
                 f"{one:.2f} s", f"{one / two:.2f}x", "faster", "PASS" if two < one else "FAIL"))
    for label in labels[1:]:
        rows.append(("14i", f"  {label}", f"{best[label]:.2f} s", "-", "-", "-", "info"))
    rows.append(("14=", "  the same Pareto set and designs as --workers 1, bit for bit",
                 f"{sum(equal.values())}/{len(equal)}", "-", "-", "all",
                 "PASS" if all(equal.values()) else "FAIL"))
    return rows


def run(repeats, idle_wait, runs):
    """Everything this benchmark measures: ``(rows, stages)``."""
    with tempfile.TemporaryDirectory(prefix="qzs-bench-optimize-") as tmp:
        folder = Path(tmp)
        best = measure(repeats, idle_wait, runs, folder)
        equal = {label: same_answer(folder, k, 1) for k, (label, _) in enumerate(CONFIGURATIONS)}
        wait_for_idle(idle_wait)
        stages = breakdown(folder / "stages")
    return verdicts(best, equal), stages


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    timing_options(parser)
    args = parser.parse_args(argv)
    repeats = repeats_of(args)
    log_machine(log, f"# bench_optimize: best of {repeats}")
    runs = []
    rows, stages = run(repeats, args.idle_wait, runs)
    noisy = busy_runs(runs)
    log("")
    if noisy:
        log(f"WARNING: {len(noisy)} of {len(runs)} timed runs started on a busy machine")
    log("where one default run's time goes (in the process, after the interpreter starts):")
    for name, (wall, cpu) in stages.items():
        log(f"  {wall:6.2f} s wall {cpu:6.2f} s CPU  {name}")
    for row in rows:
        log("  ".join(str(cell) for cell in row))
    log(f"load average at end: {_load()}")
    return 0


if __name__ == "__main__":
    report_only(main)
