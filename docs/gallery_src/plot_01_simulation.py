"""
A run's time series
===================

:meth:`SimulationResult.plot <qzs.engine.result.SimulationResult.plot>` (that is,
:func:`qzs.viz.plot_simulation`) draws what happened during a run: base and payload motion,
the stroke used between the guide's stops, the forces, the accelerations, and when the payload
was locked by friction. Here the paper's default isolator under its 0-20 Hz chirp, swept in
60 s instead of 2000 s.
"""
import qzs

result = qzs.simulate(qzs.Chirp(duration=60.0), duration=60.0, sample_rate=500.0)
fig = result.plot()
