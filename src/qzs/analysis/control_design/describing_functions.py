"""Describing functions of the friction law as a memoryless function of slip velocity.

The friction law as a memoryless nonlinearity of the slip velocity, in the PI loop, has a
real describing function (``4*Fc/(pi*A)`` for Coulomb friction,
:func:`coulomb_describing_function`; the whole law numerically by python-control,
:func:`friction_describing_function`) whose ``-1/N`` lies on the negative real axis, which
a linearly stable loop's Nyquist curve reaches only as ``w -> 0``: it predicts no limit
cycle, ever. It cannot: the stuck phase, in which the integral winds up, has no place in a
velocity law (Olsson 1996; Armstrong-Hélouvry and Amin 1996). :mod:`.hunting` has the
stick-slip element that does predict the cycle.

References
----------
H. Olsson, "Describing function analysis of a system with friction", Proc. IEEE CCA 1995.
B. Armstrong-Hélouvry, B. Amin, "PID control in the presence of static friction: a
comparison of algebraic and describing function analysis", Automatica 32(5), 1996.
"""
import math

import numpy as np

from qzs.errors import ParameterError
from qzs.model.registry import model_inputs

__all__ = ["coulomb_describing_function", "FrictionNonlinearity",
           "friction_describing_function"]


def coulomb_describing_function(force, amplitude):
    """Describing function ``4*F/(pi*A)`` [N*s/m] of ideal Coulomb friction ``F*sign(v)``.

    Parameters
    ----------
    force : float
        Coulomb friction level F [N].
    amplitude : float or array_like
        Amplitude A of the sinusoidal slip velocity [m/s], > 0.

    Returns
    -------
    float or ndarray
        ``4*F/(pi*A)`` [N*s/m]: real (the force is in phase with the velocity).
    """
    return 4.0 * float(force) / (np.pi * np.asarray(amplitude, dtype=float))


class FrictionNonlinearity:
    """The friction law's rate-dependent part as a memoryless function of slip velocity.

    ``f(v) = [Fc + (Fs - Fc)*exp(-Cbc*|v|)]*sign(v)`` [N] (eq. 3 without the viscous term,
    which is linear and belongs to the plant). A static nonlinearity for
    :func:`control.describing_function` (``f(0) = 0``). It has no stuck state: the point of
    the first describing-function analysis of :func:`predict_hunting`.

    Parameters
    ----------
    stiction_force : float
        Breakaway friction Fs [N].
    coulomb_force : float
        Coulomb friction Fc [N].
    stribeck_decay : float
        Decay rate Cbc [s/m].
    """

    def __init__(self, stiction_force, coulomb_force, stribeck_decay):
        self.stiction_force = float(stiction_force)
        self.coulomb_force = float(coulomb_force)
        self.stribeck_decay = float(stribeck_decay)

    def __call__(self, velocity):
        v = float(np.squeeze(velocity))
        if v == 0.0:
            return 0.0
        level = self.coulomb_force + (self.stiction_force - self.coulomb_force) * math.exp(
            -self.stribeck_decay * abs(v))
        return math.copysign(level, v)

    def _isstatic(self):
        return True


def friction_describing_function(isolator=None, amplitude=None, *, points=4096):
    """Describing function [N*s/m] of the friction law in slip velocity (python-control).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Supplies ``stiction_force``, ``coulomb_force`` and ``stribeck_decay``.
    amplitude : float or array_like
        Slip-velocity amplitudes [m/s], > 0.
    points : int
        Samples per period of python-control's numerical integration [-].

    Returns
    -------
    ndarray of complex
        ``N(A)`` [N*s/m] (real up to round-off: a memoryless odd function).
    """
    import control

    isolator, _ = model_inputs(isolator, None)
    if amplitude is None:
        raise ParameterError("`amplitude` is required: the slip-velocity amplitudes in m/s.")
    law = FrictionNonlinearity(isolator.stiction_force, isolator.coulomb_force,
                               isolator.stribeck_decay)
    return np.asarray(control.describing_function(law, np.atleast_1d(amplitude),
                                                  num_points=int(points)))
