"""
The MagSpring's static characteristic and its fit
=================================================

:func:`qzs.viz.plot_spring_fit` draws a static force-displacement test of the MagSpring
beside the fitted law ``F = -a tanh(b z)`` (the paper's Fig. 5), with the residuals. The
"measurements" here are the paper's spring with 0.5 N of noise, fitted by
:func:`qzs.fit_spring`.
"""
import numpy as np

import qzs
from qzs.viz import plot_spring_fit

rng = np.random.default_rng(5)
z = np.linspace(-0.1, 0.1, 41)
force = qzs.spring_force(z, qzs.IsolatorParameters()) + rng.normal(0.0, 0.5, z.size)
fit = qzs.fit_spring(z, force)
print(f"a = {fit.spring_force:.2f} N, b = {fit.spring_shape:.2f} 1/m")
fig = plot_spring_fit(z, force, fit.spring_force, fit.spring_shape,
                      title="MagSpring static test")
