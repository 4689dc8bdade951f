"""
A transmissibility fit
======================

:meth:`TransmissibilityFit.plot <qzs.identify.transmissibility.TransmissibilityFit.plot>`
(that is, :func:`qzs.viz.plot_transmissibility_fit`) draws a measured transmissibility beside
the model fitted to it through the simulator, and the residuals in dB. The "measurement" is
the model itself with a viscous friction of 60 N s/m and 3 % noise; the fit recovers it.
"""
import numpy as np

import qzs

chirp = qzs.Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=60.0)
truth = qzs.IsolatorParameters(viscous_damping=60.0, stiction_force=6.0)
run = qzs.simulate(chirp, truth, dt=5e-4, sample_rate=100.0)
estimate = qzs.transmissibility(run.base_acceleration, run.payload_acceleration, 100.0,
                                fft_length=1024)
noisy = estimate.magnitude * np.exp(np.random.default_rng(0).normal(0.0, 0.03,
                                                                    estimate.frequency.size))

fit = qzs.fit_transmissibility(estimate.frequency, noisy, ("viscous_damping",),
                               isolator=qzs.IsolatorParameters(stiction_force=6.0),
                               excitation=chirp)
print(fit.parameters, fit.intervals)
fig = fit.plot(title="viscous friction fitted to a transmissibility")
