"""Harmonic balance of the smooth isolator model: periodic responses, stability, continuation.

The *smooth model* (:class:`SmoothModel`) is the simulator's model with every non-smooth
part made smooth or left out (friction regularised, no saturation, no stops), so that a
periodic response is a zero of a smooth function of its Fourier coefficients
(docs/response.md §5). Unknowns are the real Fourier coefficients of the relative position
up to ``H`` harmonics; the linear parts are exact per harmonic, the spring and friction
forces are evaluated on a time grid and transformed back (alternating frequency-time, AFT).
Newton's method solves the balance at one frequency (:func:`periodic_response`);
pseudo-arclength continuation follows it in frequency around folds
(:func:`frequency_response_curve`); Hill's method gives each solution's Floquet exponents
(:func:`floquet_exponents`): a point is stable when they all have negative real parts.
Pure numpy.

================  ==============================================================================
``smooth_model``  the smooth model (the model's spring and regularised friction laws), as an ODE
``fourier``       the real Fourier basis: synthesis, analysis, d/dtau; default harmonics, phases
``residual``      the balance's residual and its Jacobian (AFT), the scales of the unknowns
``solution``      one periodic response by damped Newton, and what it derives (transmissibility)
``stability``     Floquet exponents by Hill's method, and the stability they decide
``curve``         the frequency-response curve: a branch with stability, validity and folds
``continuation``  pseudo-arclength continuation in frequency around folds
``blas``          one BLAS thread for the small dense linear algebra
================  ==============================================================================

References
----------
Cameron, T. M., Griffin, J. H. (1989). An alternating frequency/time domain method for
calculating the steady-state response of nonlinear dynamic systems. J. Appl. Mech. 56, 149-154.
Keller, H. B. (1977). Numerical solution of bifurcation and nonlinear eigenvalue problems. In
*Applications of Bifurcation Theory*, Academic Press, 359-384 (pseudo-arclength continuation).
Lazarus, A., Thomas, O. (2010). A harmonic-based method for computing the stability of periodic
solutions of dynamical systems. C. R. Mécanique 338, 510-517 (Hill's method, eigenvalue choice).
"""
from qzs.analysis.harmonic_balance.continuation import (MAX_POINTS_PER_RANGE,
                                                        MIN_TANGENT_COSINE, START_ATTEMPTS,
                                                        frequency_response_curve)
from qzs.analysis.harmonic_balance.curve import FrequencyResponseCurve
from qzs.analysis.harmonic_balance.fourier import DEFAULT_HARMONICS
from qzs.analysis.harmonic_balance.smooth_model import (FRICTION_VELOCITY, SmoothModel,
                                                        smooth_right_hand_side)
from qzs.analysis.harmonic_balance.solution import (NEWTON_ITERATIONS, NEWTON_TOLERANCE,
                                                    HarmonicBalanceSolution, periodic_response)
from qzs.analysis.harmonic_balance.stability import STABILITY_MARGIN, floquet_exponents

__all__ = ["SmoothModel", "HarmonicBalanceSolution", "FrequencyResponseCurve",
           "periodic_response", "frequency_response_curve", "floquet_exponents",
           "smooth_right_hand_side", "DEFAULT_HARMONICS", "FRICTION_VELOCITY",
           # the solvers' settings, importable from here as from the single module before
           "NEWTON_TOLERANCE", "NEWTON_ITERATIONS", "START_ATTEMPTS", "MAX_POINTS_PER_RANGE",
           "MIN_TANGENT_COSINE", "STABILITY_MARGIN"]
