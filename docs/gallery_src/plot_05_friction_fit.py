"""
A friction fit
==============

:meth:`FrictionFit.plot <qzs.identify.friction.FrictionFit.plot>` (that is,
:func:`qzs.viz.plot_friction_fit`) draws the friction force recovered from a test with imposed
motion against the slip velocity, with the fitted law (paper eq. 3), and the residuals against
time. The test: the paper's carriage driven through a 30 mm, 0.5 Hz sine about the setpoint,
the force the machine applies with 0.2 N of noise.
"""
import numpy as np

import qzs

truth = qzs.IsolatorParameters()
rng = np.random.default_rng(0)
time = np.arange(0.0, 8.0, 1e-3)
omega = 2 * np.pi * 0.5
z = -0.060 + 0.030 * np.sin(omega * time)
v = 0.030 * omega * np.cos(omega * time)
a = -0.030 * omega**2 * np.sin(omega * time)
force = (truth.mass * a - qzs.spring_force(z, truth) - qzs.friction_force(v, truth)
         + truth.mass * truth.gravity + rng.normal(0.0, 0.2, time.size))

fit = qzs.fit_friction(time, z, force, spring=truth, mass=truth.mass)
fig = fit.plot(title="friction test")
