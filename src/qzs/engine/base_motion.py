"""Numba kernels of the base motion: ``(y, yd, ydd)`` of a packed excitation at any time.

The excitation objects of :mod:`qzs.model.excitation` pack themselves into an
integer kind, a float array of scalars and, for tabulated signals, a piecewise
cubic (``pack()``); these kernels evaluate that form (docs/model.md §6).
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT as _JIT
from qzs.model.excitation import (E_AMPLITUDE, E_DURATION, E_F0, E_F1, E_FADE, E_KIND,
                                  E_PHASE, E_SPACING, KIND_CHIRP_LINEAR, KIND_CHIRP_LOG,
                                  KIND_TABLE)

__all__ = ["base_motion", "base_motion_near", "advance_phase", "excitation_tuple",
           "base_motion_series"]

_TWO_PI = 2.0 * np.pi


@njit(**_JIT)
def excitation_tuple(ex):
    """The packed scalars as a tuple (cheaper than an array inside the kernels).

    Parameters
    ----------
    ex : ndarray, shape (8,)
        The packed scalars of an excitation (the first item of its ``pack()``).

    Returns
    -------
    tuple of float
        The same eight values (``E`` of the other kernels).
    """
    return (ex[0], ex[1], ex[2], ex[3], ex[4], ex[5], ex[6], ex[7])


@njit(**_JIT, inline="always")
def _phase(t, E):
    """Phase [rad], angular frequency [rad/s] and its rate [rad/s^2] of a harmonic kind."""
    kind = int(E[E_KIND])
    if kind == KIND_CHIRP_LINEAR:
        f0 = E[E_F0]
        rate = (E[E_F1] - f0) / E[E_DURATION]
        return (_TWO_PI * (f0 * t + 0.5 * rate * t * t), _TWO_PI * (f0 + rate * t),
                _TWO_PI * rate)
    if kind == KIND_CHIRP_LOG:
        f0 = E[E_F0]
        growth = np.log(E[E_F1] / f0) / E[E_DURATION]
        omega = _TWO_PI * f0 * np.exp(growth * t)
        return (omega - _TWO_PI * f0) / growth, omega, omega * growth
    omega = _TWO_PI * E[E_F0]
    return omega * t + E[E_PHASE], omega, 0.0


@njit(**_JIT, inline="always")
def _table(t, spacing, table):
    n = table.shape[1] - 1
    if spacing > 0.0:
        i = int((t - table[0, 0]) / spacing)
    else:
        lo, hi = 0, n  # bisection: table[0, lo] <= t < table[0, hi]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if table[0, mid] <= t:
                lo = mid
            else:
                hi = mid
        i = lo
    i = min(max(i, 0), n - 1)
    dx = t - table[0, i]
    c0, c1, c2, c3 = table[1, i], table[2, i], table[3, i], table[4, i]
    return (((c0 * dx + c1) * dx + c2) * dx + c3, (3.0 * c0 * dx + 2.0 * c1) * dx + c2,
            6.0 * c0 * dx + 2.0 * c1)


@njit(**_JIT, inline="always")
def _fade(t, fade, y, yd, ydd):
    """The motion times the fade-in window ``w(s) = s - sin(2*pi*s)/(2*pi)``, ``s = t/fade``.

    The window's slope ``(1 - cos(2*pi*s))/fade`` is a raised cosine, so ``w``, ``w'`` and
    ``w''`` are continuous at both ends: the faded motion has no step in displacement,
    velocity or acceleration. Product rule: ``(w*y)' = w'*y + w*y'`` and ``(w*y)'' =
    w''*y + 2*w'*y' + w*y''`` keep the three consistent (docs/model.md §6).
    """
    if t >= fade or fade <= 0.0:
        return y, yd, ydd
    if t <= 0.0:
        t = 0.0
    k = 2.0 * np.pi / fade
    s, c = np.sin(k * t), np.cos(k * t)
    w, w1, w2 = t / fade - s / (2.0 * np.pi), (1.0 - c) / fade, k * s / fade
    return w * y, w1 * y + w * yd, w2 * y + 2.0 * w1 * yd + w * ydd


@njit(**_JIT, inline="always")
def _harmonic(amplitude, s, c, omega, omega_dot):
    return amplitude * s, amplitude * c * omega, amplitude * (c * omega_dot - s * omega * omega)


@njit(**_JIT)
def base_motion(t, E, table):
    """Base displacement [m], velocity [m/s] and acceleration [m/s^2] at time ``t`` [s].

    Parameters
    ----------
    t : float
        Time [s].
    E : tuple of float
        The excitation's packed scalars (:func:`excitation_tuple`).
    table : ndarray, shape (5, n)
        The tabulated signal's piecewise cubic (unused by the harmonic kinds).

    Returns
    -------
    y, yd, ydd : float
        Base displacement [m], velocity [m/s] and acceleration [m/s^2].
    """
    if int(E[E_KIND]) == KIND_TABLE:
        y, yd, ydd = _table(t, E[E_SPACING], table)
    else:
        phase, omega, omega_dot = _phase(t, E)
        y, yd, ydd = _harmonic(E[E_AMPLITUDE], np.sin(phase), np.cos(phase), omega, omega_dot)
    return _fade(t, E[E_FADE], y, yd, ydd)


@njit(**_JIT, inline="always")
def _rotate(phase, phase0, sin0, cos0):
    """``sin`` and ``cos`` of ``phase`` from those of a nearby ``phase0``.

    By the Taylor series of the difference ``d`` (truncation below 1e-16 for
    ``|d| < 0.1``), else directly: one sine/cosine pair serves many nearby times.
    """
    d = phase - phase0
    if abs(d) < 0.1:
        d2 = d * d
        sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))))
        cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)))
        return sin0 * cd + cos0 * sd, cos0 * cd - sin0 * sd
    return np.sin(phase), np.cos(phase)


@njit(**_JIT, inline="always")
def base_motion_near(t, phase0, sin0, cos0, E, table):
    """:func:`base_motion` at ``t``, given the phase and its sine/cosine at a nearby time.

    Parameters
    ----------
    t : float
        Time [s].
    phase0 : float
        Phase at the nearby time [rad] (from :func:`advance_phase`).
    sin0, cos0 : float
        Its sine and cosine.
    E : tuple of float
        The excitation's packed scalars (:func:`excitation_tuple`).
    table : ndarray, shape (5, n)
        The tabulated signal's piecewise cubic (unused by the harmonic kinds).

    Returns
    -------
    y, yd, ydd : float
        Base displacement [m], velocity [m/s] and acceleration [m/s^2].
    """
    if int(E[E_KIND]) == KIND_TABLE:
        y, yd, ydd = _table(t, E[E_SPACING], table)
    else:
        phase, omega, omega_dot = _phase(t, E)
        s, c = _rotate(phase, phase0, sin0, cos0)
        y, yd, ydd = _harmonic(E[E_AMPLITUDE], s, c, omega, omega_dot)
    return _fade(t, E[E_FADE], y, yd, ydd)


@njit(**_JIT)
def advance_phase(t, phase0, sin0, cos0, E, exact):
    """Phase [rad] and its sine and cosine at ``t``, rotated from a nearby time or ``exact``.

    Parameters
    ----------
    t : float
        Time [s].
    phase0 : float
        Phase at the nearby time [rad].
    sin0, cos0 : float
        Its sine and cosine.
    E : tuple of float
        The excitation's packed scalars (:func:`excitation_tuple`).
    exact : bool
        Compute the sine and cosine directly instead of rotating them from ``phase0``.

    Returns
    -------
    phase, sine, cosine : float
        Phase [rad] at ``t`` and its sine and cosine; ``(0, 0, 1)`` for a tabulated signal.
    """
    if int(E[E_KIND]) == KIND_TABLE:
        return 0.0, 0.0, 1.0
    phase = _phase(t, E)[0]
    if exact:
        return phase, np.sin(phase), np.cos(phase)
    s, c = _rotate(phase, phase0, sin0, cos0)
    return phase, s, c


@njit(**_JIT)
def _series(times, ex, table, out):
    E = excitation_tuple(ex)
    for i in range(times.size):
        out[0, i], out[1, i], out[2, i] = base_motion(times[i], E, table)



def base_motion_series(excitation, time):
    """Evaluate an excitation at the given times.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base excitation.
    time : array_like
        Times [s].

    Returns
    -------
    displacement, velocity, acceleration : ndarray
        Base motion [m], [m/s], [m/s^2] at ``time``.
    """
    time = np.ascontiguousarray(time, dtype=float)
    out = np.empty((3, time.size))
    _series(time.ravel(), *excitation.pack(), out)
    return out[0], out[1], out[2]
