"""Wall time of `qzs paper`: each study and the whole, full-length (target < 180 s on 2 cores).

    python benchmarks/bench_paper.py [--quick] [--workers N]

Also measures the quick paper on one worker and on all workers in the same run, and
prints the parallel speed-up (the baseline is measured here, not remembered).
Compile time is excluded: one warm-up case runs first so the numba cache is loaded.
"""
import argparse
import os
import platform
import sys
import tempfile
import time

from qzs.workflows.paper.report import write_paper_outputs
from qzs.workflows.paper.studies import load_study, run_studies, shipped_studies

TARGET_SECONDS = 180.0


def timed(studies, quick, workers):
    start = time.perf_counter()
    results = run_studies(studies, quick=quick, workers=workers, progress=False)
    with tempfile.TemporaryDirectory() as folder:
        write_paper_outputs(results, folder, quick=quick)
    return results, time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="only the quick comparison")
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    args = parser.parse_args()
    print(f"# bench_paper  {time.strftime('%Y-%m-%d %H:%M')}  python {platform.python_version()}"
          f"  cores {os.cpu_count()}  workers {args.workers}")
    studies = [load_study(p) for p in shipped_studies()]
    run_studies([studies[1]], quick=True, workers=1, progress=False)  # warm the numba cache

    _, serial = timed(studies, True, 1)
    _, parallel = timed(studies, True, args.workers)
    print(f"quick paper, 1 worker        {serial:8.1f} s")
    print(f"quick paper, {args.workers} workers      {parallel:8.1f} s   "
          f"speed-up {serial / parallel:.2f}x")
    if args.quick:
        return 0
    results, wall = timed(studies, False, args.workers)
    print(f"\n{'study':<12}{'cases':>6}{'case-seconds':>14}")
    for result in results:
        print(f"{result.study.name:<12}{len(result.cases):>6}{result.seconds:>14.1f}")
    verdict = "PASS" if wall < TARGET_SECONDS else "FAIL"
    print(f"{'whole':<12}{'':>6}{wall:>14.1f}   wall time, target < {TARGET_SECONDS:.0f} s: "
          f"{verdict} ({wall / TARGET_SECONDS:.2f} of the target)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
