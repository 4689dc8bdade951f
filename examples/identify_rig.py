"""Identify the MagSpring and the friction from the example test-rig files.

    python examples/identify_rig.py [--data examples/data] [--out results/identify]

Reads spring_static.csv (a static test in the test machine's convention) and
friction_test.csv (imposed sine, load-cell force), prints the fitted parameters with
their 95 % confidence intervals, and writes the figures spring_fit.png (paper Fig. 5)
and friction_fit.png (friction against velocity, residuals).
"""
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from qzs.identify import fit_friction, fit_spring  # noqa: E402
from qzs.model import IsolatorParameters  # noqa: E402
from qzs.viz import plot_spring_fit  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=Path(__file__).parent / "data")
    parser.add_argument("--out", type=Path, default=Path("results/identify"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    static = np.loadtxt(args.data / "spring_static.csv", delimiter=",", skiprows=3)
    displacement, force = static[:, 0] * 1e-3, static[:, 1]  # [mm] -> [m]
    spring = fit_spring(displacement, force, convention="test_machine")
    print(f"MagSpring ({spring.convention} convention in, model convention out):")
    print(f"  a = {spring.spring_force:.2f} N   95 % CI {spring.intervals['plateau'][0]:.2f} .. "
          f"{spring.intervals['plateau'][1]:.2f}   (the paper's Fig. 5 prints "
          f"a = {spring.as_paper_reports()[0]:.2f} N)")
    print(f"  b = {spring.spring_shape:.2f} 1/m 95 % CI {spring.intervals['shape'][0]:.2f} .. "
          f"{spring.intervals['shape'][1]:.2f}   residual rms {spring.residual_rms:.2f} N")
    plt.close(plot_spring_fit(-displacement, force, spring.spring_force, spring.spring_shape,
                              path=args.out / "spring_fit.png", title="MagSpring static test"))

    test = np.loadtxt(args.data / "friction_test.csv", delimiter=",", skiprows=3)
    isolator = IsolatorParameters(spring_force=spring.spring_force,
                                  spring_shape=spring.spring_shape)
    friction = fit_friction(test[:, 0], test[:, 1] * 1e-3, test[:, 2], spring=isolator,
                            mass=isolator.mass)
    print(f"Friction (force read as the {friction.force_sign}; {friction.n_used} samples used, "
          f"{friction.n_excluded} near-zero-velocity samples excluded):")
    units = {"stiction_force": "N", "coulomb_force": "N", "stribeck_decay": "s/m",
             "viscous_damping": "N*s/m", "offset": "N"}
    for name, unit in units.items():
        low, high = friction.intervals[name]
        print(f"  {name:<16} {getattr(friction, name):9.3f} {unit:<6} "
              f"95 % CI {low:.3f} .. {high:.3f}")
    print(f"  residual rms {friction.residual_rms:.3f} N")
    plt.close(friction.plot(path=args.out / "friction_fit.png", title="friction test"))
    print(f"wrote {args.out / 'spring_fit.png'} and {args.out / 'friction_fit.png'} (+ .svg)")


if __name__ == "__main__":
    main()
