"""
An experiment log beside its simulation
=======================================

:meth:`ExperimentResult.plot <qzs.workflows.experiment.process.ExperimentResult.plot>` (that is,
:func:`qzs.viz.experiment.plot_experiment`) draws the transmissibility measured from a rig's
log beside the simulation of the same chirp, processed the same way, with the coherence and
the band below 1.5 times the amplifiers' high-pass flagged. The "log" is made by qzs: base and
payload velocities through a 1 Hz high-pass, with sensor noise.
"""
import tempfile
from pathlib import Path

import numpy as np

import qzs
from qzs.analysis.spectral import highpass
from qzs.workflows.experiment.process import process_experiment

folder = Path(tempfile.mkdtemp())
run = qzs.simulate(qzs.Chirp(duration=120.0), sample_rate=500.0)
noise = np.random.default_rng(1)
columns = [run.time] + [1e3 * highpass(run[name], 1.0, 500.0) + noise.normal(0, 0.2, len(run))
                        for name in ("base_velocity", "payload_velocity")]
np.savetxt(folder / "log.csv", np.column_stack(columns), delimiter=",",
           header="time,shaker_vel,payload_vel", comments="")
(folder / "map.toml").write_text(
    '[time]\nsource = "time"\nunit = "s"\n'
    '[channels.base_velocity]\nsource = "shaker_vel"\nunit = "mm/s"\n'
    '[channels.payload_velocity]\nsource = "payload_vel"\nunit = "mm/s"\n')

recording = qzs.read_recording(folder / "log.csv", folder / "map.toml")
result = process_experiment(recording, highpass_corner=1.0, fft_length=4096, n_averages=28,
                            dt=2e-4)
fig = result.plot()
