"""
The FMU in FMPy beside qzs simulate
===================================

:func:`qzs.export_fmu` writes the isolator as an FMI 3.0 co-simulation FMU: qzs's C model,
no Python inside (``qzs docs fmu``). Here FMPy, the tool many FMI users have, steps it through
20 s of the paper's chirp (swept in 20 s) with a 1 ms communication step, beside
:func:`qzs.simulate` at the same internal step and solver. The two runs are the same to the
last bit: the upper panels show the first 6 s (the payload sticks and slips), the lower one
their difference over the whole run, zero throughout.
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from fmpy import simulate_fmu

import qzs

chirp = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0)
with tempfile.TemporaryDirectory() as folder:
    fmu = qzs.export_fmu(Path(folder) / "isolator.fmu", chirp, duration=20.0)
    fmpy_run = simulate_fmu(str(fmu), stop_time=20.0, output_interval=1e-3)
qzs_run = qzs.simulate(chirp, duration=20.0, dt=1e-4, sample_rate=1000.0)

time = np.asarray(qzs_run.time)
fig, axes = plt.subplots(3, 1, figsize=(8, 7), layout="constrained")
axes[0].plot(time, 1e3 * np.asarray(qzs_run.relative_position), label="qzs simulate", lw=2.5)
axes[0].plot(fmpy_run["time"], 1e3 * fmpy_run["relative_position"], "--", label="FMU in FMPy")
axes[0].set_ylabel("relative position z [mm]")
axes[0].legend(loc="lower left")
axes[1].plot(time, np.asarray(qzs_run.friction_force), lw=2.5)
axes[1].plot(fmpy_run["time"], fmpy_run["friction_force"], "--")
axes[1].set_ylabel("friction force [N]")
for axis in axes[:2]:  # the first seconds, where the payload sticks and slips
    axis.set_xlim(0.0, 6.0)
    axis.set_xlabel("time [s] (the first 6 s)")
for name in ("relative_position", "friction_force", "payload_acceleration"):
    ours = np.asarray(qzs_run[name])
    axes[2].plot(time, (fmpy_run[name] - ours) / np.ptp(ours), label=name)
axes[2].set_ylabel("difference / range [-]")
axes[2].set_xlabel("time [s] (the whole 20 s run)")
axes[2].set_xlim(0.0, time[-1])
axes[2].legend(loc="upper left", title="FMPy minus qzs simulate: zero to the bit")
fig.suptitle("The isolator FMU (FMI 3.0) in FMPy and qzs simulate: the same run")
