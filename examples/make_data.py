"""Regenerate the synthetic example data in examples/data/ (seeded: the same files every time).

    python examples/make_data.py [--out examples/data]

Every file is made by qzs's own model with added noise; none is a measurement. See
examples/README.md for what each file holds and the commands that use them.
"""
import argparse
from pathlib import Path

import numpy as np

import qzs
from qzs.analysis.spectral import highpass
from qzs.iotools.rig import write_dspace_mat

SEED = 20240605
RATE = 500.0  # [Hz] sample rate of the experiment log
CHIRP = qzs.Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=250.0)  # the paper's, shortened
HIGHPASS = 1.0  # [Hz] charge amplifiers' first-order high-pass
VELOCITY_NOISE = 0.2  # [mm/s] rms sensor noise on each velocity channel


def experiment_log(folder, rng):
    """Base and payload velocity [mm/s] through the 1 Hz high-pass, as CSV and dSPACE MAT."""
    run = qzs.simulate(CHIRP, dt=1e-4, sample_rate=RATE)
    time = run.time
    signals = {}
    for name, channel in (("shaker_vel", "base_velocity"), ("payload_vel", "payload_velocity")):
        measured = highpass(run[channel], HIGHPASS, RATE) * 1e3
        signals[name] = measured + rng.normal(0.0, VELOCITY_NOISE, time.size)
    table = np.column_stack([time, signals["shaker_vel"], signals["payload_vel"]])
    header = ("# synthetic experiment log made by examples/make_data.py (qzs model + noise)\n"
              "# base (shaker) and payload velocity [mm/s] after a 1 Hz first-order high-pass\n"
              "time,shaker_vel,payload_vel")
    np.savetxt(folder / "experiment.csv", table, delimiter=",", header=header, comments="",
               fmt=("%.4f", "%.5g", "%.5g"))
    names = {"Model Root/Sensors/shaker_vel": signals["shaker_vel"],
             "Model Root/Sensors/payload_vel": signals["payload_vel"]}
    write_dspace_mat(folder / "experiment_dspace.mat", time,
                     {k: v.astype(np.float32) for k, v in names.items()},
                     variable="experiment_dspace", units=dict.fromkeys(names, "mm/s"))


CSV_MAP = """\
# Channel map of experiment.csv (read by qzs.iotools.rig; `qzs docs identification`):
# which column is which, and its unit. Every key, commented: `qzs experiment --write-map F.toml`.
[time]
source = "time"
unit = "s"

[channels.base_velocity]
source = "shaker_vel"
unit = "mm/s"

[channels.payload_velocity]
source = "payload_vel"
unit = "mm/s"

[experiment]
highpass_corner = 1.0   # [Hz] charge amplifiers' first-order high-pass
"""

DSPACE_MAP = """\
# Channel map of experiment_dspace.mat, a dSPACE ControlDesk-style export:
# X(1).Data is the time, Y(k).Name / Y(k).Data the signals. "Y[1]/shaker_vel" takes Y(1)
# and checks that its name ends in shaker_vel; a bare name searches all Y(k).
[channels.base_velocity]
source = "Y[1]/shaker_vel"
unit = "mm/s"

[channels.payload_velocity]
source = "payload_vel"
unit = "mm/s"
scale = 1.0

[experiment]
highpass_corner = 1.0
"""


def channel_maps(folder):
    """The channel maps of the two experiment logs."""
    (folder / "experiment_map.toml").write_text(CSV_MAP, encoding="utf-8")
    (folder / "experiment_dspace_map.toml").write_text(DSPACE_MAP, encoding="utf-8")


def spring_test(folder, rng):
    """MagSpring static test: displacement [mm] and force [N] in the test machine's convention."""
    truth = qzs.IsolatorParameters()
    displacement = np.linspace(-100.0, 100.0, 41)  # [mm], counted downward: d = -z
    force = qzs.spring_force(-displacement * 1e-3, truth) + rng.normal(0.0, 0.5, displacement.size)
    header = ("# synthetic MagSpring static test made by examples/make_data.py (a = 60.84 N, "
              "b = 78.10 1/m, noise 0.5 N)\n# test machine convention: displacement counted "
              "downward (d = -z)\ndisplacement_mm,force_N")
    np.savetxt(folder / "spring_static.csv", np.column_stack([displacement, force]),
               delimiter=",", header=header, comments="", fmt=("%.2f", "%.4f"))


def friction_test(folder, rng):
    """Imposed sine about the operating point; the load cell's force (reaction sign)."""
    truth = qzs.IsolatorParameters()
    rate, frequency, amplitude, center = 1000.0, 0.5, 0.030, -0.060
    time = np.arange(0.0, 8.0, 1.0 / rate)
    omega = 2 * np.pi * frequency
    z = center + amplitude * np.sin(omega * time)
    v = amplitude * omega * np.cos(omega * time)
    a = -amplitude * omega ** 2 * np.sin(omega * time)
    friction = qzs.friction_force(v, truth)
    presliding = np.abs(v) < 5e-4  # [m/s] below this the carriage sticks: force ramps through 0
    friction[presliding] = -truth.stiction_force * v[presliding] / 5e-4
    applied = truth.mass * a - qzs.spring_force(z, truth) - friction + truth.mass * truth.gravity
    force = -applied + rng.normal(0.0, 0.2, time.size)  # the load cell reads the reaction
    displacement = z * 1e3 + rng.normal(0.0, 0.002, time.size)  # [mm], 2 um encoder noise
    header = ("# synthetic friction test made by examples/make_data.py: imposed 30 mm, 0.5 Hz "
              "sine about z = -60 mm; Fs = 10 N, Fc = 1 N, Cbc = 100 s/m, Cv = 100 N*s/m, "
              "spring and weight (6.4 kg) included\n# displacement z [mm] upward (model "
              "convention), force [N] as the load cell reads it (the carriage's reaction)\n"
              "time,displacement_mm,force_N")
    np.savetxt(folder / "friction_test.csv", np.column_stack([time, displacement, force]),
               delimiter=",", header=header, comments="", fmt=("%.3f", "%.4f", "%.4f"))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=Path(__file__).parent / "data", type=Path)
    folder = parser.parse_args(argv).out
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)
    experiment_log(folder, rng)
    channel_maps(folder)
    spring_test(folder, rng)
    friction_test(folder, rng)
    for path in sorted(folder.iterdir()):
        print(f"{path}  {path.stat().st_size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
