"""
A hexapod run
=============

:meth:`HexapodResult.plot <qzs.engine.hexapod.result.HexapodResult.plot>` (that is,
:func:`qzs.viz.plot_hexapod`) draws a run of the six-leg platform: the platform's pose
relative to the base, each leg's stroke between its stops, and the motor forces. The shipped
cubic platform of six paper legs (``paper_legs_cubic``), its base shaken sideways by a 3 mm,
4 Hz sine.
"""
import qzs
from qzs.workflows.hexapod.setups import load_hexapod

setup = load_hexapod("paper_legs_cubic")
result = qzs.simulate_hexapod(setup.geometry, setup.platform, setup.isolator, setup.controller,
                              excitation={"x": qzs.Sine(amplitude=0.003, frequency=4.0)},
                              duration=6.0, sample_rate=500.0)
print(result.summary())
fig = result.plot()
