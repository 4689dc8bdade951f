"""
The 6x6 transmissibility of a hexapod
=====================================

:func:`qzs.viz.hexapod_matrix.plot_transmissibility_matrix` draws the platform's
transmissibility as a 6x6 grid: each panel one platform axis (row) per base axis (column), in
dB of its unit, the linear model dashed and simulated curves solid on their trusted bins.
First the linear model of the shipped cubic platform (``qzs hexapod linear --plot``), then
:meth:`HexapodTransmissibility.plot
<qzs.workflows.hexapod.transmissibility.HexapodTransmissibility.plot>` with simulated chirps
in ``x`` and ``z`` (``qzs hexapod transmissibility``), short ones here.
"""
import numpy as np

import qzs
from qzs.analysis.hexapod_linear import hexapod_linearize
from qzs.viz.hexapod_matrix import plot_transmissibility_matrix
from qzs.workflows.hexapod.setups import load_hexapod

setup = load_hexapod("paper_legs_cubic")
model = hexapod_linearize(setup.geometry, setup.platform, setup.isolator, setup.controller)
frequency = np.logspace(-1, np.log10(50.0), 300)
fig = plot_transmissibility_matrix(frequency, linear=model, title="paper_legs_cubic: linear model")

# %%
# Simulated, one 30 s chirp per excited axis, with the linear model beside it.
simulated = qzs.hexapod_transmissibility(setup, axes=("x", "z"), duration=30.0, workers=2,
                                         progress=False)
fig = simulated.plot()
