#!/usr/bin/env python
"""The engine before and after a change: cold compile time and warm speed of every driver.

Run from the repository root with the project's interpreter::

    .venv/bin/python benchmarks/bench_engine.py                     # against 026d44b
    .venv/bin/python benchmarks/bench_engine.py --baseline HEAD~5 --repeats 5
    .venv/bin/python benchmarks/bench_engine.py --skip-cold         # warm speed only

The baseline is another revision of this repository, checked out into a temporary git
worktree and measured in the same run, the two trees taking turns (these 2-core machines are
shared and their speed varies over minutes: turns expose both to the same conditions). By
default the revision before the one-engine refactor of issue 22 (026d44b).

What is measured, each in a fresh interpreter with ``PYTHONPATH`` on the tree's ``src``:

- **cold**: the whole process of ``qzs simulate --duration 5``, ``qzs hexapod simulate
  --duration 0.1`` and ``qzs response --frequencies 2 --dt 1e-3 --direction up
  --no-harmonic-balance``, each with an empty ``NUMBA_CACHE_DIR`` (every kernel compiled);
  the smallest of ``--cold-repeats`` runs;
- **warm**: the integration speed of each driver with its kernels loaded from the cache,
  best of ``--repeats``: ``qzs.simulate`` (200 s of the paper's chirp at dt = 1e-4 s, steps
  per second), ``qzs.simulate_batch`` (16 cases, 100 s, steps x cases per second),
  ``qzs.simulate_hexapod`` (the cubic platform of bench_hexapod.py, 10 s) and
  ``steady_state_response`` (8 frequencies, both sweeps in one process, wall time).

Each line prints both figures and the ratio after/before; PASS when the change is no worse
than 3 % (speed) or 10 % (a cold compile, whose spread is larger), else FAIL. The script
always exits 0: a benchmark reports, it does not fail CI.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASELINE = "026d44b"

COLD = {
    "qzs simulate": ["simulate", "--duration", "5", "--plot", "none", "--quiet"],
    "qzs hexapod simulate": ["hexapod", "simulate", "--duration", "0.1", "--quiet"],
    "qzs response": ["response", "--frequencies", "2", "--dt", "1e-3", "--direction", "up",
                     "--no-harmonic-balance", "--workers", "1", "--plot", "none", "--quiet"],
}

WARM = r"""
import json, sys, time
import numpy as np
import qzs
from qzs.model.hexapod import PlatformParameters, cubic_geometry
which = sys.argv[1]
chirp = qzs.Chirp(duration=200.0)
def single():
    return qzs.simulate(chirp, dt=1e-4).run["elapsed"], 2e6
def batch():
    cases = [(qzs.IsolatorParameters(stiction_force=fs), qzs.ControllerParameters(pi_kp=kp))
             for fs in (5.0, 8.0, 10.0, 12.0) for kp in (5.0, 20.0, 50.0, 100.0)]
    r = qzs.simulate_batch(cases, qzs.Chirp(duration=100.0), dt=1e-4, workers=2)
    return r.elapsed, 16 * 1e6
def hexapod():
    r = qzs.simulate_hexapod(cubic_geometry(cube_edge=0.3, cube_center_height=0.3),
                             PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5])),
                             controller=qzs.ControllerParameters(pi_kp=2000.0, pi_ki=800.0),
                             excitation={"z": qzs.Chirp(duration=10.0)}, duration=10.0)
    return r.run["elapsed"], 1e5
def response():
    from qzs.workflows.response import steady_state_response
    start = time.perf_counter()
    steady_state_response([0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 8.0, 12.0], direction="both",
                          dt=1e-3, workers=1, harmonic_balance=False)
    return time.perf_counter() - start, 1.0
run = dict(single=single, batch=batch, hexapod=hexapod, response=response)[which]
run()  # load (or compile) the kernels
seconds, work = min(run() for _ in range(int(sys.argv[2])))
print(json.dumps({"seconds": seconds, "work": work}))
"""


def _environment(tree, cache):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(tree, "src")
    env["NUMBA_CACHE_DIR"] = cache
    return env


def cold(tree, arguments, repeats):
    best = float("inf")
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            subprocess.run([sys.executable, "-m", "qzs", *arguments], cwd=folder, check=True,
                           env=_environment(tree, cache), stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            best = min(best, time.perf_counter() - start)
    return best


def warm(tree, which, repeats, cache):
    out = subprocess.run([sys.executable, "-c", WARM, which, str(repeats)], check=True,
                         env=_environment(tree, cache), capture_output=True, text=True)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    return result["work"] / result["seconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=BASELINE, help="revision to compare with")
    parser.add_argument("--baseline-tree", help="an existing checkout to use instead")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--cold-repeats", type=int, default=2)
    parser.add_argument("--turns", type=int, default=2,
                        help="times each tree is measured, taking turns")
    parser.add_argument("--skip-cold", action="store_true")
    args = parser.parse_args()
    made = None
    if args.baseline_tree:
        base = args.baseline_tree
    else:
        made = base = tempfile.mkdtemp(prefix="qzs-baseline-")
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", base, args.baseline],
                       check=True, capture_output=True)
    trees = {"before": base, "after": ROOT}
    caches = {name: tempfile.mkdtemp(prefix=f"qzs-cache-{name}-") for name in trees}
    print(f"baseline {args.baseline_tree or args.baseline} ({base}); load "
          f"{os.getloadavg()[0]:.2f} at the start", flush=True)
    rows = []
    try:
        if not args.skip_cold:
            for label, arguments in COLD.items():
                best = {name: float("inf") for name in trees}
                for _ in range(args.turns):
                    for name, tree in trees.items():
                        best[name] = min(best[name], cold(tree, arguments, args.cold_repeats))
                rows.append((f"cold {label} [s]", best["before"], best["after"],
                             best["after"] / best["before"], best["after"] <= 1.10 *
                             best["before"]))
                print(rows[-1], flush=True)
        for which, unit in (("single", "steps/s"), ("batch", "case-steps/s"),
                            ("hexapod", "steps/s"), ("response", "sweeps/s")):
            best = {name: 0.0 for name in trees}
            for _ in range(args.turns):
                for name, tree in trees.items():
                    best[name] = max(best[name], warm(tree, which, args.repeats, caches[name]))
            rows.append((f"warm {which} [{unit}]", best["before"], best["after"],
                         best["after"] / best["before"], best["after"] >= 0.97 *
                         best["before"]))
            print(rows[-1], flush=True)
    finally:
        for cache in caches.values():
            shutil.rmtree(cache, ignore_errors=True)
        if made:
            subprocess.run(["git", "-C", ROOT, "worktree", "remove", "--force", made],
                           capture_output=True)
    print(f"\n{'measure':38s} {'before':>12s} {'after':>12s} {'ratio':>7s}")
    for name, before, after, ratio, passed in rows:
        print(f"{name:38s} {before:12.4g} {after:12.4g} {ratio:7.3f}  "
              f"{'PASS' if passed else 'FAIL'}")
    print(f"load {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
