"""Throughput of the batch engine against single runs measured in the same process.

    python benchmarks/bench_batch.py [--quick]

For 1, 64 and 1024 cases (stiction 5-15 N and PI gains 5-50 N/m drawn at random; a
10 mm, 0-20 Hz chirp over the run, so the payload sticks and slips; ode3 at
dt = 1e-4 s; 2e6 steps for one case and 1e5 per case for the batches; stats only, no
time series kept) prints simulated steps per second of the kernel (integration only,
``BatchResult.elapsed``) on 1 and on all worker threads, per core, the speed-up from 1
to 2 cores, the same end to end (validating and setting up each case, about 0.25 ms,
included), and the baseline measured in the same run: ``qzs.simulate`` one case after
another. Targets (issue 4): >= 10e6 steps/s per core at 1024 cases, >= 1.8x on 2 cores.
Exits 0: a benchmark reports.
"""
import argparse
import os
import platform
import sys
import time

import numpy as np

import qzs
from qzs.engine.batch import simulate_batch

TARGET_PER_CORE = 10e6
TARGET_SPEEDUP = 1.8


def cases(n):
    rng = np.random.default_rng(0)
    return [(qzs.IsolatorParameters(stiction_force=float(fs)),
             qzs.ControllerParameters(pi_kp=float(kp), pi_ki=0.4 * float(kp)))
            for fs, kp in zip(rng.uniform(5, 15, n), rng.uniform(5, 50, n))]


def best(function, repeats):
    """Shortest wall time [s] of ``repeats`` calls, and the result of that call."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append((time.perf_counter() - start, result))
    return min(times, key=lambda pair: pair[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    print(f"# bench_batch  {time.strftime('%Y-%m-%d %H:%M')}  python "
          f"{platform.python_version()}  cores {cores}")
    steps_per_case = {1: 2e5 if args.quick else 2e6, 64: 2e4 if args.quick else 1e5,
                      1024: 2e4 if args.quick else 1e5}
    warm = qzs.Chirp(duration=0.5)
    simulate_batch(cases(2), warm, sample_rate=100.0, channels=(), workers=2)  # load the cache
    qzs.simulate(warm, sample_rate=100.0)
    print("kernel: integration only (BatchResult.elapsed); end to end: the whole call, "
          "validating and setting up every case included")
    print(f"{'cases':>6} {'steps/case':>11} {'single runs':>12} {'kernel 1 core':>14} "
          f"{'kernel ' + str(cores) + ' cores':>15} {'per core':>10} {'speed-up':>9} "
          f"{'end to end':>11} {'per core':>10}")
    for n in (1, 64, 1024):
        duration = steps_per_case[n] * 1e-4
        excitation = qzs.Chirp(duration=duration)
        pairs = cases(n)
        steps = n * int(round(duration / 1e-4))
        singles = pairs[:min(n, 8)]  # baseline on up to 8 cases, scaled per step
        t_single = best(lambda: [qzs.simulate(excitation, i, c, sample_rate=100.0)
                                 for i, c in singles], 1)[0] / (len(singles) * steps / n)
        repeats = 1 if n > 1 else 3
        one = best(lambda: simulate_batch(pairs, excitation, sample_rate=100.0, channels=(),
                                          workers=1), repeats)[1]
        wall, every = best(lambda: simulate_batch(pairs, excitation, sample_rate=100.0,
                                                  channels=(), workers=cores), repeats)
        single_rate, one_rate, all_rate = 1 / t_single, steps / one.elapsed, steps / every.elapsed
        print(f"{n:>6} {steps // n:>11,} {single_rate / 1e6:>8.2f} M/s {one_rate / 1e6:>10.2f} M/s"
              f" {all_rate / 1e6:>11.2f} M/s {all_rate / cores / 1e6:>6.2f} M/s "
              f"{all_rate / one_rate:>8.2f}x {steps / wall / 1e6:>7.2f} M/s "
              f"{steps / wall / cores / 1e6:>6.2f} M/s")
        if n == 1024:
            per_core = all_rate / cores
            print(f"\nkernel per-core throughput at 1024 cases: {per_core / 1e6:.2f} M steps/s, "
                  f"target {TARGET_PER_CORE / 1e6:.0f} M: "
                  f"{'PASS' if per_core >= TARGET_PER_CORE else 'FAIL'} "
                  f"({per_core / TARGET_PER_CORE:.2f} of the target; end to end "
                  f"{steps / wall / cores / 1e6:.2f} M)")
            speedup = all_rate / one_rate
            print(f"speed-up 1 -> {cores} cores at 1024 cases: {speedup:.2f}x, target "
                  f"{TARGET_SPEEDUP}x: {'PASS' if speedup >= TARGET_SPEEDUP else 'FAIL'}")
            print(f"batch on {cores} cores / single runs one after another: "
                  f"{all_rate / single_rate:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
