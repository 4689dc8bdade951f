"""
Sweep figures: a metric against the parameters, and the spread of the curves
============================================================================

:func:`qzs.viz.sweeps.plot_metric` draws one output of a sweep against one varied parameter
(a line through the median, with the spread over the other parameters) or two (a heat map),
and :func:`qzs.viz.sweeps.plot_transmissibility_band` the median transmissibility with its
5-95 % band, one per level of a parameter. ``qzs sweep-plot`` draws the same. The sweep: the
PI proportional gain against the stiction, a 4 x 3 grid, each case a 41 s chirp.
"""
import tempfile
from pathlib import Path

from qzs.viz.sweeps import plot_metric, plot_transmissibility_band
from qzs.workflows.sweeps import run_sweep

folder = Path(tempfile.mkdtemp())
(folder / "gains.toml").write_text('''
[sweep]
name = "gains"
batch_size = 12

[grid]
pi_kp = [2.0, 20.0, 200.0, 1000.0]                     # [N/m]
stiction_force = { start = 5.0, stop = 15.0, num = 3 }  # [N]

[parameters]
pi_ki = 2.0                                             # [N/(m*s)]

[excitation]
kind = "chirp"
amplitude = 0.010
f0 = 0.0
f1 = 20.0

[analysis]
sample_rate = 200.0
fft_length = 1024
n_averages = 15
band = [0.0, 20.0]

[outputs]
stats = ["peak_stroke", "motor_force_rms"]
metrics = ["isolation_onset"]
bands = { low = [1.0, 3.0] }
''')
data = run_sweep(folder / "gains.toml", folder / "gains.zarr", progress=False)
# sphinx_gallery_thumbnail_number = 2

# %%
# The low-frequency cost of the gains: the mean transmissibility over 1-3 Hz, worst case
# over the stictions.
fig = plot_metric(data, "mean_transmissibility_low", "pi_kp", reduce="max")

# %%
# The same output over both parameters.
fig = plot_metric(data, "mean_transmissibility_low", "pi_kp", "stiction_force")

# %%
# The transmissibility's median and 5-95 % band over the gains, one per stiction.
fig = plot_transmissibility_band(data, by="stiction_force", frequency_scale="linear")
