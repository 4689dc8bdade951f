#!/usr/bin/env python
"""The stepped-sine steady-state response: speed, and how far the paper's chirp is from it.

Run from the repository root with the project's interpreter::

    .venv/bin/python benchmarks/bench_response.py            # the speed target
    .venv/bin/python benchmarks/bench_response.py --study    # chirp vs steady state, paper cases
    .venv/bin/python benchmarks/bench_response.py --study --cases stiction viscous

**Speed** (target: 40 frequencies of the paper's isolator in under 30 s on 2 cores). The
paper's default case (Table 1, Kp = 50 N/m, Ki = 20 N/(m s), 10 mm), 40 log-spaced
frequencies from 0.5 to 20 Hz, swept up and down (two processes), the step chosen for
0.01 dB, with the harmonic balance beside it: the wall time of the whole call (the step's
choice, process start-up and loading numba's cached kernels included), the share of each
part, the time per frequency and the periods each frequency needed to become periodic.
One warm-up call first fills numba's on-disk cache so that compile time is left out.

**Study** (``--study``): for each transmissibility case of the paper's shipped studies
(``src/qzs/workflows/paper/study_files``), the steady state beside the chirp-and-Welch estimate
(:func:`qzs.workflows.response.chirp_transmissibility`: 0 -> 20 Hz at 0.01 Hz/s, 1 kHz,
32768-point Hann segments), compared by frequency band of the up sweep: *locked* (the
payload held all period), *stick-slip* (part of it) and *sliding* (never held). Printed: the
median and largest |chirp - steady| [dB] over the chirp's trusted bins in each band, the
frequencies where the down sweep settles elsewhere (hysteresis) or nowhere (NaN). The
script always exits 0.
"""
import argparse
import math
import os
import sys
import time

import numpy as np

from qzs import ControllerParameters, IsolatorParameters
from qzs.model.registry import update_parameters
from qzs.workflows.response import steady_state_response

TARGET_SECONDS = 30.0
FREQUENCIES = np.geomspace(0.5, 20.0, 40)


def _load():
    """Load average of the last minute over the cores [-] (None where unknown)."""
    try:
        return os.getloadavg()[0] / (os.cpu_count() or 1)
    except OSError:
        return None


def speed(workers):
    steady_state_response([2.0, 5.0], direction="both", dt=1e-3, workers=workers,
                          balance_harmonics=5)  # warm numba's cache in the workers too
    print(f"machine: {os.cpu_count()} cores, load {_load():.2f} per core before the run")
    rows = []
    for label, options in (
            ("both sweeps + harmonic balance (the CLI's default)", {}),
            ("both sweeps, no harmonic balance", {"harmonic_balance": False}),
            ("sweep up only, no harmonic balance, 1 process",
             {"harmonic_balance": False, "direction": "up", "workers": 1})):
        options = {"workers": workers, **options}
        start = time.perf_counter()
        response = steady_state_response(FREQUENCIES, 0.010, **options)
        wall = time.perf_counter() - start
        rows.append((label, wall, response))
    print(f"\n{len(FREQUENCIES)} frequencies {FREQUENCIES[0]:g}-{FREQUENCIES[-1]:g} Hz (log), "
          f"10 mm, the paper's default isolator; step chosen for 0.01 dB: "
          f"dt <= {rows[0][2].dt:.3g} s")
    print(f"{'run':<52} {'wall [s]':>9} {'target':>7}")
    for label, wall, _ in rows:
        verdict = "PASS" if wall < TARGET_SECONDS else "FAIL"
        print(f"{label:<52} {wall:9.2f} {verdict:>7}")
    response = rows[0][2]
    print("\nper frequency (the first run):")
    print(f"{'sweep':<6} {'frequencies':>11} {'time/freq [s] median':>21} {'max':>6} "
          f"{'periods median':>15} {'max':>5} {'settle [s] median':>18} {'NaN':>4}")
    for direction in response.directions:
        b = response.branch(direction)
        ok = b["converged"] == 1
        print(f"{direction:<6} {b['frequency'].size:11d} {np.median(b['seconds']):21.4f} "
              f"{b['seconds'].max():6.3f} {np.median(b['periods'][ok]):15.0f} "
              f"{b['periods'][ok].max():5.0f} {np.median(b['settle_time'][ok]):18.2f} "
              f"{int((~ok).sum()):4d}")
    step = response.step
    if step is not None:
        print(f"\nstep choice: dt = {step.dt:.3g} s, estimated error {step.error:.2g} dB")
    if response.balance is not None:
        print(f"harmonic balance: {response.balance.frequency.size} points, folds "
              f"{[round(f, 3) for f in response.balance.folds]}")
    for note in response.notes:
        print(f"note: {note}")
    print("\nper frequency, sweep up: f [Hz], periods, settle [s], time [ms], T [dB], locked")
    b = response.branch("up")
    for i, f in enumerate(b["frequency"]):
        t = b["transmissibility"][i]
        print(f"  {f:7.3f} {int(b['periods'][i]):5d} {b['settle_time'][i]:8.2f} "
              f"{1e3 * b['seconds'][i]:7.1f} "
              f"{(20 * math.log10(t) if t > 0 else float('nan')):+8.3f} "
              f"{b['locked_fraction'][i]:5.2f}")


def _study_cases(names):
    from qzs.workflows.paper.studies import load_study, shipped_studies

    for path in shipped_studies():
        study = load_study(path)
        if study.kind != "transmissibility" or (names and study.name not in names):
            continue
        for case in study.cases:
            settings = {**study.defaults, **{k: v for k, v in case.items() if k != "label"}}
            isolator, controller = update_parameters(IsolatorParameters(),
                                                     ControllerParameters(), settings)
            yield study.name, case.get("label", ""), isolator, controller


def study(names, workers):
    print("chirp (0.01 Hz/s, Welch 32768) against the stepped-sine steady state, sweep up; "
          "|difference| [dB] over the chirp's trusted bins, median / max")
    print(f"{'study':<10} {'case':<28} {'locked':>11} {'stick-slip':>11} {'sliding':>11} "
          f"{'up NaN':>11} {'down differs':>13} {'down NaN':>11} {'s':>4}")
    for name, label, isolator, controller in _study_cases(names):
        start = time.perf_counter()
        response = steady_state_response(FREQUENCIES, 0.010, isolator, controller,
                                         compare_chirp=True, harmonic_balance=False,
                                         workers=workers)
        up = response.branch("up")
        chirp = response.chirp_at()
        with np.errstate(divide="ignore", invalid="ignore"):
            gap = np.abs(20 * np.log10(chirp / up["transmissibility"]))
        locked = up["locked_fraction"]
        cells = []
        for band in (locked >= 1.0, (locked > 0) & (locked < 1.0), locked == 0.0):
            values = gap[band & np.isfinite(gap)]
            cells.append(f"{np.median(values):4.2f}/{values.max():4.2f}" if values.size
                         else "-")
        down = response.branch("down")
        differs = response.hysteresis()
        up_nan = up["frequency"][up["converged"] == 0]
        nan = down["frequency"][down["converged"] == 0]
        print(f"{name:<10} {label[:28]:<28} {cells[0]:>11} {cells[1]:>11} {cells[2]:>11} "
              f"{_span(up_nan):>11} {_span(differs):>13} {_span(nan):>11} "
              f"{time.perf_counter() - start:4.0f}")
        sys.stdout.flush()


def _span(frequencies):
    if len(frequencies) == 0:
        return "-"
    return f"{len(frequencies)}: {min(frequencies):.2g}-{max(frequencies):.2g}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", action="store_true",
                        help="compare the chirp with the steady state for the paper's cases")
    parser.add_argument("--cases", nargs="*", default=None,
                        help="studies to compare (default: every transmissibility study)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    args = parser.parse_args(argv)
    if args.study:
        study(args.cases, args.workers)
    else:
        speed(args.workers)
    return 0


if __name__ == "__main__":
    sys.exit(main())
