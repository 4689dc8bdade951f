"""What a controller's blocks cost per step, against PI + damping measured in the same run.

    python benchmarks/bench_controller.py [--quick] [--repeats N]

Issue 40's speed targets: a 4-state continuous ``LinearController`` (a lead-lag on the measured
payload velocity with two first-order low-passes, beside the PI + damping) costs at most 25 %
more per step than ``PIDamping`` alone, in the single run and in the lanes. Each figure is the
best of ``--repeats`` runs of a 3 Hz, 10 mm sine (stick-slip at every reversal), ode3 at
dt = 1e-4 s: simulated steps per second of the kernel (``steps_per_second`` /
``BatchResult.elapsed``, compilation excluded: every kernel is compiled or loaded first). Rows:
the default controller (the baseline), the 4-state linear controller, friction compensation
with an observer, a dither, and all of them; for the lanes, 64 cases of each. The ratio is the
time per step against the baseline's (1.25 at most for the 4-state row). Exits 0: a benchmark
reports.
"""
import argparse
import platform
import time

import numpy as np

import qzs
from qzs.engine.batch import simulate_batch

TARGET_LTI4 = 1.25  # time per step of the 4-state linear controller / PI + damping's


def lead_lag_4():
    """A 4-state damping filter: a lead-lag on the measured payload velocity and two
    first-order low-passes (1 and 2 ms) [N per m/s]."""
    import control

    system = (control.tf([-800.0, -8000.0], [1.0, 40.0]) * control.tf([1.0, 5.0], [1.0, 50.0])
              * control.tf([1.0], [1e-3, 1.0]) * control.tf([1.0], [2e-3, 1.0]))
    return qzs.LinearController.from_system(control.ss(system),
                                            inputs=("measured_payload_velocity",))


def controllers():
    """Name -> controller of each row (the first is the baseline)."""
    base = qzs.PIDamping()
    compensation = qzs.FrictionCompensation(fraction=0.8, observer_bandwidth=5.0)
    dither = qzs.Dither(amplitude=1.0, frequency=40.0)
    linear = lead_lag_4()
    return {"PI + damping (baseline)": base,
            "+ 4-state linear controller": base + linear,
            "+ compensation with observer": base + compensation,
            "+ dither": base + dither,
            "+ all three": base + compensation + dither + linear}


def single_rate(isolator, controller, duration, repeats):
    """Best steps per second of one run [1/s]."""
    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    return max(qzs.simulate(excitation, isolator, controller, duration=duration, dt=1e-4,
                            sample_rate=1000.0).steps_per_second for _ in range(repeats))


def lanes_rate(isolator, controller, cases, duration, repeats):
    """Best steps per second of ``cases`` lanes (stiction 8-12 N), summed over the cases
    [1/s]."""
    import dataclasses

    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    pairs = [(dataclasses.replace(isolator, stiction_force=float(fs)), controller)
             for fs in np.linspace(8.0, 12.0, cases)]
    best = 0.0
    for _ in range(repeats):
        batch = simulate_batch(pairs, excitation, duration=duration, dt=1e-4, sample_rate=100.0,
                               channels=(), workers=1)
        best = max(best, cases * duration / 1e-4 / batch.elapsed)
    return best


def compare(name, heading, rows, quick, repeats, target_row, target, sentence):
    """Measure every row against the first, print the table and the target's verdicts.

    ``heading``: what a row is; ``rows``: label -> ``(isolator, controller)``, the baseline
    first; ``target_row``: the
    label's start of the row the target is on; ``sentence``: the target, as printed.
    """
    duration, lanes_duration, cases = (5.0, 0.5, 16) if quick else (20.0, 2.0, 64)
    print(f"# {name}  {time.strftime('%Y-%m-%d %H:%M')}  python {platform.python_version()}")
    for isolator, controller in rows.values():  # compile or load every kernel first
        single_rate(isolator, controller, 0.1, 1)
        lanes_rate(isolator, controller, 2, 0.05, 1)
    print(f"{heading:32s} {'single [M steps/s]':>19s} {'ratio':>6s} "
          f"{'lanes, 1 thread [M steps/s]':>28s} {'ratio':>6s}")
    base_single = base_lanes = None
    verdicts = []
    for label, (isolator, controller) in rows.items():
        single = single_rate(isolator, controller, duration, repeats)
        lanes = lanes_rate(isolator, controller, cases, lanes_duration, repeats)
        base_single = base_single or single
        base_lanes = base_lanes or lanes
        ratio_single, ratio_lanes = base_single / single, base_lanes / lanes
        print(f"{label:32s} {single / 1e6:19.2f} {ratio_single:6.2f} {lanes / 1e6:28.2f} "
              f"{ratio_lanes:6.2f}")
        if label.startswith(target_row):
            verdicts = [("single", ratio_single), ("lanes", ratio_lanes)]
    for where, ratio in verdicts:
        verdict = "met" if ratio <= target else "NOT met"
        print(f"target: {sentence} ({where}): {ratio:.2f} x, {verdict}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--repeats", type=int, default=5, help="best of this many runs")
    args = parser.parse_args()
    rows = {name: (qzs.IsolatorParameters(), controller)
            for name, controller in controllers().items()}
    compare("bench_controller", "controller", rows, args.quick, args.repeats, "+ 4-state", TARGET_LTI4,
            f"4-state linear controller per step <= {TARGET_LTI4:.2f} x PI + damping")


if __name__ == "__main__":
    main()
