"""Model identification from test-rig data (paper Section 2.1.2), one module per fit.

====================  =============================================================================
``spring``            :func:`fit_spring`: static force-displacement pairs -> a spring law: the
                      MagSpring's ``a``, ``b`` of ``F = -a*tanh(b*z)`` (the default), a
                      polynomial, the three-spring mechanism, a smoothed table, or the best of
                      them by BIC; either displacement convention
``spring_laws``       how the polynomial, the mechanism and the table are fitted
``friction``          :func:`fit_friction`: a dynamic test with imposed displacement and measured
                      force (the paper's Instron tests) -> stiction, Coulomb, Stribeck and viscous
                      friction (eq. 3)
``transmissibility``  :func:`fit_transmissibility`: chosen model parameters fitted to a measured
                      transmissibility curve through the simulator
``_statistics``       the fits' covariance, Student-t quantile and profile threshold
``_protocol``         what every fit shares: summary, plot, save by extension, to_xarray, intervals
====================  =============================================================================

All intervals are Student-t intervals on the covariance ``s^2 (J^T J)^-1`` of the
least-squares Jacobian ``J`` at the optimum (``s^2`` the residual variance): they assume
independent residuals of equal variance, and are local (linearised) intervals.
"""
from qzs.identify.friction import FrictionFit, fit_friction
from qzs.identify.spring import SpringFit, fit_spring
from qzs.identify.transmissibility import TransmissibilityFit, fit_transmissibility

__all__ = ["SpringFit", "fit_spring", "FrictionFit", "fit_friction", "TransmissibilityFit",
           "fit_transmissibility"]
