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
import sys
from pathlib import Path

import numpy as np

import qzs

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_controller import compare  # noqa: E402  the same measurement and table

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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs")
    parser.add_argument("--repeats", type=int, default=5, help="best of this many runs")
    args = parser.parse_args()
    rows = {name: (qzs.IsolatorParameters(spring=law), qzs.ControllerParameters())
            for name, law in laws().items()}
    compare("bench_springs", "spring law", rows, args.quick, args.repeats, "table", TARGET_TABLE,
            f"{TABLE_POINTS}-point table per step <= {TARGET_TABLE:.2f} x the tanh")


if __name__ == "__main__":
    main()
