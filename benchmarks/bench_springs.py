"""What a spring law costs per step, against the MagSpring's tanh measured in the same run.

    python benchmarks/bench_springs.py [--quick] [--repeats N]

Issue 41's speed target: a ``TabulatedSpring`` of 200 points costs at most 15 % more per step
than the tanh, in the single run and in the lanes. Each figure is the best of ``--repeats``
runs of a 3 Hz, 10 mm sine (stick-slip at every reversal) with the default PI + damping, ode3
at dt = 1e-4 s: simulated steps per second of the kernel (``steps_per_second`` /
``BatchResult.elapsed``, compilation excluded: every kernel is compiled or loaded first).
Rows: the default isolator (the MagSpring's tanh on the default path: the baseline), a
200-point table sampled from that tanh over the stroke (PCHIP, ``outside="extend"``), the
same law as a ``TanhSpring`` value (the default path too: the check that a value costs
nothing), a cubic ``PolynomialSpring`` and the ``ObliqueSpringQZS`` at its quasi-zero
condition; for the lanes, 64 cases of each (stiction 8-12 N). The ratio is the time per step
against the baseline's. Exits 0: a benchmark reports.
"""
import argparse
import platform
import time

import numpy as np

import qzs
from qzs.engine.batch import simulate_batch

TARGET_TABLE = 1.15  # time per step of a 200-point table / the tanh's
TABLE_POINTS = 200


def laws():
    """Name -> spring law of each row (None: the default isolator, the baseline)."""
    iso = qzs.IsolatorParameters()
    center = qzs.ControllerParameters().position_setpoint
    positions = np.linspace(center - 1.5 * iso.stroke_half, center + 1.5 * iso.stroke_half,
                            TABLE_POINTS)
    tanh = qzs.TanhSpring(plateau=iso.spring_force, shape=iso.spring_shape)
    return {"tanh, default path (baseline)": None,
            f"table of {TABLE_POINTS} points": qzs.TabulatedSpring.from_law(
                tanh, positions, outside="extend"),
            "TanhSpring value": tanh,
            "cubic polynomial": qzs.PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4),
                                                     center=center),
            "oblique, quasi-zero": qzs.ObliqueSpringQZS.quasi_zero()}


def single_rate(law, duration, repeats):
    """Best steps per second of one run [1/s]."""
    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    iso = qzs.IsolatorParameters(spring=law)
    return max(qzs.simulate(excitation, iso, duration=duration, dt=1e-4,
                            sample_rate=1000.0).steps_per_second for _ in range(repeats))


def lanes_rate(law, cases, duration, repeats):
    """Best steps per second of ``cases`` lanes, summed over the cases [1/s]."""
    excitation = qzs.Sine(amplitude=0.01, frequency=3.0)
    pairs = [(qzs.IsolatorParameters(stiction_force=float(fs), spring=law),
              qzs.ControllerParameters()) for fs in np.linspace(8.0, 12.0, cases)]
    best = 0.0
    for _ in range(repeats):
        batch = simulate_batch(pairs, excitation, duration=duration, dt=1e-4, sample_rate=100.0,
                               channels=(), workers=1)
        best = max(best, cases * duration / 1e-4 / batch.elapsed)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--repeats", type=int, default=5, help="best of this many runs")
    args = parser.parse_args()
    duration, lanes_duration, cases = (5.0, 0.5, 16) if args.quick else (20.0, 2.0, 64)
    print(f"# bench_springs  {time.strftime('%Y-%m-%d %H:%M')}  python "
          f"{platform.python_version()}")
    rows = laws()
    for law in rows.values():  # compile or load every kernel first
        single_rate(law, 0.1, 1)
        lanes_rate(law, 2, 0.05, 1)
    print(f"{'spring law':32s} {'single [M steps/s]':>19s} {'ratio':>6s} "
          f"{'lanes, 1 thread [M steps/s]':>28s} {'ratio':>6s}")
    base_single = base_lanes = None
    verdicts = []
    for name, law in rows.items():
        single = single_rate(law, duration, args.repeats)
        lanes = lanes_rate(law, cases, lanes_duration, args.repeats)
        base_single = base_single or single
        base_lanes = base_lanes or lanes
        ratio_single, ratio_lanes = base_single / single, base_lanes / lanes
        print(f"{name:32s} {single / 1e6:19.2f} {ratio_single:6.2f} {lanes / 1e6:28.2f} "
              f"{ratio_lanes:6.2f}")
        if name.startswith("table"):
            verdicts = [("single", ratio_single), ("lanes", ratio_lanes)]
    for where, ratio in verdicts:
        verdict = "met" if ratio <= TARGET_TABLE else "NOT met"
        print(f"target: {TABLE_POINTS}-point table per step <= {TARGET_TABLE:.2f} x the tanh "
              f"({where}): {ratio:.2f} x, {verdict}")


if __name__ == "__main__":
    main()
