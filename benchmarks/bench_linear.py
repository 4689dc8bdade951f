#!/usr/bin/env python
"""The analyses of a population vectorised (issue 34, targets 2 and 3), and the design question.

    .venv/bin/python benchmarks/bench_linear.py                # best of 3
    .venv/bin/python benchmarks/bench_linear.py --quick        # best of 2
    .venv/bin/python benchmarks/bench_linear.py --repeats 5 --idle-wait 60

1. **Hunting at rest of a population** (target 2): the shipped problem ``isolation_vs_effort``'s
   192 designs (a scrambled Sobol sample of its four variables, seed 34) under its three
   stictions (5, 10, 15 N): 576 cases, ``predict_hunting_population`` in one call. Baseline in
   the same run: the scalar path, ``predict_hunting(memoryless=False)`` (python-control's
   ``describing_function_response``), on the first 24 cases. Target: at most **1 ms per
   case** (a design under one stiction; per design of three cases the figure is 3x).
2. **Linear metrics of a Sobol run** (target 3): 512 Sobol designs x 3 stictions = 1536 cases
   of a problem whose goals are the linear transmissibility at 12 Hz and the gain and phase
   margins, through the design space's own path (``evaluation.evaluate_cases``: each case's
   model built, then one vectorised evaluation). Baseline: the scalar path
   (``linear_transmissibility`` and ``loop_margins``, python-control) on 96 of the cases,
   scaled to 1536. Target: the 1536 cases in at most **1 s**. An information row adds the
   hunting amplitude to the goals.
The design question as a whole process (issue 34, target 1), which took 32 s before this
work (86 % of it in the hunting prediction), is ``bench_optimize.py``'s.

Every timing is the best of N, each run started after waiting up to ``--idle-wait`` s for the
machine to go quiet (the helpers of ``bench_simulate.py``). Exits 0.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_simulate import (  # noqa: E402
    _busy_note, busy_runs, log_machine, repeats_of, report_only, timing_options, wait_for_idle)

TARGET_HUNTING = 1e-3     # [s] per case
TARGET_LINEAR = 1.0       # [s] for 1536 cases
STICTIONS = (5.0, 10.0, 15.0)

log = lambda msg="": print(msg, flush=True)  # noqa: E731


def sobol_designs(n, seed=34):
    """``n`` designs of isolation_vs_effort's variables: (spring_force, kp, ki, kd) rows."""
    from scipy.stats import qmc

    unit = qmc.Sobol(4, seed=seed).random_base2(int(np.ceil(np.log2(n))))[:n]
    low = np.array([58.0, np.log(10.0), np.log(0.1), 0.0])
    high = np.array([68.0, np.log(3000.0), np.log(100.0), 400.0])
    x = low + unit * (high - low)
    x[:, 1:3] = np.exp(x[:, 1:3])
    return x


def models(designs):
    """(isolators, controllers) of every design under every stiction, stictions fastest."""
    import qzs

    isolators, controllers = [], []
    for spring, kp, ki, kd in designs:
        for stiction in STICTIONS:
            isolators.append(qzs.IsolatorParameters(spring_force=float(spring),
                                                    stiction_force=stiction))
            controllers.append(qzs.ControllerParameters(pi_kp=float(kp), pi_ki=float(ki),
                                                        damping_gain=float(kd)))
    return isolators, controllers


def best(repeats, idle_wait, label, fn, runs):
    """Best of ``repeats`` timings of ``fn()`` [s], each after an idle wait."""
    times = []
    for k in range(repeats):
        busy = wait_for_idle(idle_wait)
        start = time.perf_counter()
        fn()
        seconds = time.perf_counter() - start
        times.append(seconds)
        runs.append(dict(seconds=seconds, busy=busy))
        log(f"  {label} {k + 1}/{repeats}: {seconds:.3f} s{_busy_note(busy)}")
    return min(times)


def measure_hunting(repeats, idle_wait, runs):
    from qzs.analysis.control_design.hunting import predict_hunting
    from qzs.analysis.control_design.hunting_population import predict_hunting_population

    isolators, controllers = models(sobol_designs(192))
    predict_hunting_population(isolators[:6], controllers[:6])  # imports, first calls
    population = best(repeats, idle_wait, "hunting, 576 cases, vectorised",
                      lambda: predict_hunting_population(isolators, controllers), runs)
    scalar = best(repeats, idle_wait, "hunting, 24 cases, python-control",
                  lambda: [predict_hunting(i, c, memoryless=False)
                           for i, c in zip(isolators[:24], controllers[:24])], runs)
    return dict(cases=len(isolators), population=population, scalar_per_case=scalar / 24)


def _linear_problem(goals):
    from qzs.workflows.design_space.problem import load_problem

    return load_problem({
        "problem": {"name": "linear_bench"},
        "variables": {"spring_force": {"low": 58.0, "high": 68.0},
                      "pi_kp": {"low": 10.0, "high": 3000.0, "scale": "log"},
                      "pi_ki": {"low": 0.1, "high": 100.0, "scale": "log"},
                      "damping_gain": {"low": 0.0, "high": 400.0}},
        "excitation": {"kind": "chirp", "amplitude": 0.01, "f0": 0.0, "f1": 20.0},
        "objectives": goals[:2], "constraints": goals[2:]})


def measure_linear(repeats, idle_wait, runs):
    from qzs.analysis.control_design.stability_margins import loop_margins
    from qzs.analysis.linear import linear_transmissibility
    from qzs.workflows.design_space.evaluation import evaluate_cases

    designs = sobol_designs(512)
    names = ("spring_force", "pi_kp", "pi_ki", "damping_gain")
    settings = [{**dict(zip(names, row.tolist())), "stiction_force": s}
                for row in designs for s in STICTIONS]
    goals = [{"metric": "linear_transmissibility_at", "frequency": 12.0},
             {"metric": "gain_margin", "sense": "maximize"},
             {"metric": "phase_margin", "min": 30.0}]
    problem = _linear_problem(goals)
    with_hunting = _linear_problem(goals + [{"metric": "hunting_amplitude", "max": 0.005}])
    evaluate_cases(problem, settings[:12])
    vector = best(repeats, idle_wait, "linear, 1536 cases, vectorised",
                  lambda: evaluate_cases(problem, settings), runs)
    hunting = best(repeats, idle_wait, "linear + hunting, 1536 cases, vectorised",
                   lambda: evaluate_cases(with_hunting, settings), runs)
    isolators, controllers = models(designs[:32])

    def scalar():
        for i, c in zip(isolators, controllers):
            abs(complex(linear_transmissibility(12.0, i, c)))
            loop_margins(i, c)
    scalar_96 = best(repeats, idle_wait, "linear, 96 cases, python-control", scalar, runs)
    return dict(cases=len(settings), vector=vector, hunting=hunting,
                scalar=scalar_96 * len(settings) / len(isolators))


def measure(repeats, idle_wait, runs):
    """Every figure of this benchmark (see the module's text)."""
    return dict(hunting=measure_hunting(repeats, idle_wait, runs),
                linear=measure_linear(repeats, idle_wait, runs))


def verdicts(results):
    """Rows ``(target, what, qzs, baseline, ratio, goal, verdict)`` of :func:`measure`."""
    h, lin = results["hunting"], results["linear"]
    per_case = h["population"] / h["cases"]
    rows = [(12, f"hunting at rest, {h['cases']} cases (192 designs x 3 stictions), per case",
             f"{per_case * 1e3:.3f} ms", f"{h['scalar_per_case'] * 1e3:.0f} ms",
             f"{h['scalar_per_case'] / per_case:.0f}x", f"<= {TARGET_HUNTING * 1e3:g} ms",
             "PASS" if per_case <= TARGET_HUNTING else "FAIL"),
            (13, f"linear transmissibility + margins, {lin['cases']} Sobol cases",
             f"{lin['vector']:.2f} s", f"{lin['scalar']:.1f} s",
             f"{lin['scalar'] / lin['vector']:.0f}x", f"<= {TARGET_LINEAR:g} s",
             "PASS" if lin["vector"] <= TARGET_LINEAR else "FAIL"),
            ("13i", "  the same with the hunting amplitude", f"{lin['hunting']:.2f} s", "-",
             "-", "-", "info")]
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    timing_options(parser)
    args = parser.parse_args(argv)
    repeats = repeats_of(args)
    log_machine(log, f"# bench_linear: best of {repeats}")
    runs = []
    results = measure(repeats, args.idle_wait, runs)
    noisy = busy_runs(runs)
    log("")
    if noisy:
        log(f"WARNING: {len(noisy)} of {len(runs)} timed runs started on a busy machine")
    for row in verdicts(results):
        log("  ".join(str(cell) for cell in row))
    return 0


if __name__ == "__main__":
    report_only(main)
