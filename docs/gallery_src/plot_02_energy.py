"""
The energy ledger
=================

Every run books the work of the base and of the motor, the heat of friction and of the
stops, and the payload's kinetic, spring and gravity energy (docs/model.md §8).
:func:`qzs.viz.plot_energy` draws the ledger and its residual, which closes to the
integrator's truncation error. Here the passive isolator (no PI loop) on a short chirp: it
sinks onto its lower stop, so the stop's dissipation shows too.
"""
import qzs
from qzs.viz import plot_energy

passive = qzs.ControllerParameters(pi_kp=0.0, pi_ki=0.0)
result = qzs.simulate(qzs.Chirp(duration=20.0), controller=passive, duration=20.0,
                      sample_rate=1000.0)
print(result.summary())
fig = plot_energy(result)
