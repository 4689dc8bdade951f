"""Linear metrics of a whole population at once: transmissibility, stability, margins.

The scalar path builds a python-control transfer function per design
(:func:`qzs.analysis.linear.linear_transmissibility`,
:func:`~qzs.analysis.control_design.stability_margins.loop_margins`), about 3 ms each. Here
every design's closed forms are evaluated in one numpy expression:

- the transmissibility ``|T(j 2 pi f)|`` of :func:`qzs.analysis.linear.linearize`;
- stability by Routh-Hurwitz on the characteristic polynomial
  (:func:`~qzs.analysis.control_design.linear_stability.characteristic_polynomial`), where
  the scalar path asks python-control for the closed loop's poles;
- the margins of the continuous loop ``L = (Kp + Ki/s + Kd s HP(s))/(m s^2 + Cv s + k)``
  (:func:`~qzs.analysis.control_design.loop_transfers.loop_transfer`) read from its
  response on the scalar path's grid with its rules (every crossover counted, the worst of
  each kind, :class:`~qzs.analysis.control_design.stability_margins.LoopMargins`), each
  design a row of one array.

A sampled controller (``controller_rate > 0``) has no such closed form here: those designs go
through the scalar path. Tests hold every number to python-control's within 1e-10 relative,
with the same verdicts.
"""
import math
from dataclasses import dataclass

import numpy as np

from qzs.analysis.control_design.hunting_population import population_constants
from qzs.analysis.control_design.stability_margins import _margin_grid, loop_margins

#: Designs whose responses are evaluated together [-] (their arrays stay in the cache).
_CHUNK = 64

__all__ = ["PopulationMargins", "population_transmissibility", "population_stable",
           "population_margins"]


def _constants(isolators, controllers, constants):
    return population_constants(isolators, controllers) if constants is None else constants


def population_transmissibility(frequency, isolators=None, controllers=None, *,
                                constants=None):
    """``|X/Y|`` [-] of the linearised isolator of every design at ``frequency`` [Hz].

    ``T(s) = (Cv s + K + Ki/s)/(m s^2 + Cv s + K + Ki/s + Kd s HP(s))`` at the setpoint
    (:func:`qzs.analysis.linear.linearize`), ``K = k + Kp``.

    Parameters
    ----------
    frequency : float or array_like
        Frequencies [Hz].
    isolators, controllers : sequence of IsolatorParameters, ControllerParameters
        The designs (unused when ``constants`` is given).
    constants : dict, optional
        :func:`~qzs.analysis.control_design.hunting_population.population_constants`.

    Returns
    -------
    ndarray, shape (n_designs,) + shape of ``frequency``
        Amplitude ratio [-].
    """
    c = _constants(isolators, controllers, constants)
    f = np.asarray(frequency, dtype=float)
    shape = (-1,) + (1,) * f.ndim
    m, cv, kd, w = (c[name].reshape(shape) for name in ("mass", "viscous_damping",
                                                          "damping_gain", "highpass"))
    k_total = (c["spring_stiffness"] + c["pi_kp"]).reshape(shape)
    ki = c["pi_ki"].reshape(shape)
    s = 2j * np.pi * f
    with np.errstate(divide="ignore", invalid="ignore"):
        integral = np.where(ki > 0, ki / s, 0.0)
        highpass = np.where(w > 0, s / (s + w), 1.0)
    coupling = cv * s + k_total + integral
    return np.abs(coupling / (m * s ** 2 + coupling + kd * s * highpass))


def _hurwitz(a):
    """Every Routh-Hurwitz condition holds, per row of ``a`` (highest power first)."""
    ok = np.all(a > 0, axis=1)
    if a.shape[1] == 4:
        a3, a2, a1, a0 = a.T
        ok &= a2 * a1 - a3 * a0 > 0
    elif a.shape[1] == 5:
        a4, a3, a2, a1, a0 = a.T
        ok &= (a3 * a2 - a4 * a1 > 0) & (a3 * a2 * a1 - a4 * a1 ** 2 - a3 ** 2 * a0 > 0)
    return ok


def population_stable(isolators=None, controllers=None, *, constants=None):
    """The linearised closed loop of every design is stable (Routh-Hurwitz).

    The characteristic polynomial of
    :func:`~qzs.analysis.control_design.linear_stability.characteristic_polynomial` (degree
    2 to 4 as the integral and the high-passed damping are on), every condition at once.

    Parameters
    ----------
    isolators, controllers : sequence of IsolatorParameters, ControllerParameters
        The designs (unused when ``constants`` is given).
    constants : dict, optional
        :func:`~qzs.analysis.control_design.hunting_population.population_constants`.

    Returns
    -------
    ndarray of bool, shape (n_designs,)
    """
    c = _constants(isolators, controllers, constants)
    m, cv, kd, w, ki = (c[n] for n in ("mass", "viscous_damping", "damping_gain",
                                       "highpass", "pi_ki"))
    big_k = c["spring_stiffness"] + c["pi_kp"]
    stable = np.zeros(m.size, dtype=bool)
    passband = (w > 0) & (kd > 0)
    integral = ki > 0
    forms = {
        (True, True): lambda: [m, m * w + cv + kd, cv * w + big_k, big_k * w + ki, ki * w],
        (True, False): lambda: [m, m * w + cv + kd, cv * w + big_k, big_k * w],
        (False, True): lambda: [m, cv + kd, big_k, ki],
        (False, False): lambda: [m, cv + kd, big_k]}
    for (high, with_integral), form in forms.items():
        rows = (passband == high) & (integral == with_integral)
        if rows.any():
            stable[rows] = _hurwitz(np.column_stack(form())[rows])
    return stable


@dataclass(frozen=True, kw_only=True)
class PopulationMargins:
    """Stability margins of the continuous loop of every design, as
    :class:`~qzs.analysis.control_design.stability_margins.LoopMargins` gives them.

    Attributes
    ----------
    stable : ndarray of bool
        The closed loop is stable; where it is not, the margins and crossovers are NaN (an
        unstable loop has none).
    gain_margin : ndarray
        [dB]; ``inf`` where the phase never reaches -180 deg.
    phase_margin : ndarray
        [deg]; NaN where ``|L|`` never crosses 1.
    gain_crossover_frequency : ndarray
        [Hz] (NaN if none).
    phase_crossover_frequency : ndarray
        [Hz] (NaN if none).
    """

    stable: np.ndarray
    gain_margin: np.ndarray
    phase_margin: np.ndarray
    gain_crossover_frequency: np.ndarray
    phase_crossover_frequency: np.ndarray


def _numerator(c):
    """Numerator of ``L`` over ``s^i (s + w)^p (m s^2 + Cv s + k)``, lowest power first.

    ``(Kp s + Ki)(s + w_hp) + Kd s^3`` with the integral (``i = 1``) and the high-passed
    damping (``p = 1``), and its forms without them (without a high-pass the damping is
    ``Kd s``; with ``Kd = 0`` python-control's ``minreal`` drops the high-pass). Returns
    the coefficients, shape (n, 4), and the masks ``integral`` and ``passband``.
    """
    kp, ki, kd, w = (c[n] for n in ("pi_kp", "pi_ki", "damping_gain", "highpass"))
    integral = ki > 0
    passband = (w > 0) & (kd > 0)
    direct = np.where(w > 0, 0.0, kd)  # the damping without a high-pass: Kd s
    both, high = integral & passband, passband & ~integral
    a = np.zeros((kp.size, 4))
    a[:, 0] = np.where(both, ki * w, np.where(high, kp * w, np.where(integral, ki, kp)))
    a[:, 1] = np.where(both, kp * w + ki, np.where(high, kp, np.where(integral, kp, direct)))
    a[:, 2] = np.where(both, kp, np.where(high, kd, np.where(integral, direct, 0.0)))
    a[:, 3] = np.where(both, kd, 0.0)
    return a, integral, passband


def _denominator(c, integral, passband):
    """Coefficients of ``s^i (s + w)^p (m s^2 + Cv s + k)``, lowest power first, shape (n, 5)."""
    n = c["mass"].size
    d = np.zeros((n, 5))
    d[:, 0], d[:, 1], d[:, 2] = c["spring_stiffness"], c["viscous_damping"], c["mass"]
    w = np.where(passband, c["highpass"], 0.0)[:, None]
    shifted = np.zeros_like(d)
    shifted[:, 1:] = d[:, :-1]
    d = np.where(passband[:, None], w * d + shifted, d)
    shifted = np.zeros_like(d)
    shifted[:, 1:] = d[:, :-1]
    return np.where(integral[:, None], shifted, d)


def _largest_root(coefficients):
    """Largest ``|root|`` of each row's polynomial (lowest power first; 0 if constant)."""
    out = np.zeros(coefficients.shape[0])
    nonzero = coefficients != 0
    degree = np.where(nonzero.any(axis=1),
                      coefficients.shape[1] - 1 - np.argmax(nonzero[:, ::-1], axis=1), 0)
    for d in np.unique(degree[degree > 0]):
        rows = np.flatnonzero(degree == d)
        lead = coefficients[rows, d]
        companion = np.zeros((rows.size, d, d))
        companion[:, 0, :] = -coefficients[rows, d - 1::-1] / lead[:, None]
        companion[:, np.arange(1, d), np.arange(d - 1)] = 1.0
        out[rows] = np.max(np.abs(np.linalg.eigvals(companion)), axis=1)
    return out


def _grid_top(c):
    """Top of the margin grid per design: ``max(1e4, 10 * largest |pole| or |zero|)``.

    The loop's poles and zeros (:func:`_numerator`, :func:`_denominator`) as python-control's
    ``minreal`` leaves them (a cancelled pair aside).
    """
    a, integral, passband = _numerator(c)
    largest = np.maximum(_largest_root(a), _largest_root(_denominator(c, integral, passband)))
    return np.maximum(1e4, 10 * largest)


def _response(c, omega, rows):
    """``L(j omega)`` of the designs ``rows`` of ``c`` (one frequency each), nested form."""
    s = 1j * omega
    kp, ki, kd, w = (c[n][rows] for n in ("pi_kp", "pi_ki", "damping_gain", "highpass"))
    with np.errstate(divide="ignore", invalid="ignore"):
        pi = kp + np.where(ki > 0, ki / s, 0.0)
        highpass = np.where(w > 0, s / (s + w), 1.0)
    return ((pi + kd * s * highpass) / (c["mass"][rows] * s ** 2
                                        + c["viscous_damping"][rows] * s
                                        + c["spring_stiffness"][rows]))


def _worst(n, row, distance, where):
    """Per row, the least ``distance`` and the ``where`` of its first occurrence."""
    best, at = np.full(n, math.inf), np.full(n, math.nan)
    if row.size:
        order = np.lexsort((np.arange(row.size), distance, row))
        first = np.ones(order.size, dtype=bool)
        first[1:] = row[order][1:] != row[order][:-1]
        pick = order[first]
        best[row[pick]], at[row[pick]] = distance[pick], where[pick]
    return best, at


def _margins_on_grid(c, omega):
    """Margins of the designs of ``c`` from their loops' responses on one grid.

    The scalar path's rules (``stability_margins._margins``) on the whole grid, found
    cheaply: the sign of ``|N|^2 - |D|^2`` and of ``Im(N conj D)`` (polynomials in ``w``,
    one matrix product per part) marks the intervals where ``|L|`` may cross 1 or the phase
    a multiple of 180 deg; the magnitude in dB and the phase are computed at those
    intervals' ends only, and the crossings interpolated there as the scalar path does.
    """
    n = c["mass"].size
    a, integral, passband = _numerator(c)
    d = _denominator(c, integral, passband)
    w2 = omega ** 2
    numerator_re = a[:, [0, 2]] @ np.vstack((np.ones_like(omega), -w2))
    numerator_im = a[:, [1, 3]] @ np.vstack((omega, -omega * w2))
    denominator_re = d[:, [0, 2, 4]] @ np.vstack((np.ones_like(omega), -w2, w2 ** 2))
    denominator_im = d[:, [1, 3]] @ np.vstack((omega, -omega * w2))
    gain_sign = np.sign(numerator_re ** 2 + numerator_im ** 2
                        - denominator_re ** 2 - denominator_im ** 2)
    phase_sign = np.sign(numerator_im * denominator_re - numerator_re * denominator_im)
    log_w = np.log(omega)

    def ends(row, i):
        both = np.concatenate((i, i + 1))
        rows = np.concatenate((row, row))
        values = _response(c, omega[both], rows)
        magnitude = 20 * np.log10(np.maximum(np.abs(values), 1e-300))
        phase = np.angle(values)
        half = row.size
        # unwrapped across the interval as np.unwrap does it; a whole number of turns
        # apart from the scalar path's phase, which changes no margin
        step = np.mod(phase[half:] - phase[:half] + np.pi, 2 * np.pi) - np.pi
        step = np.where((step == -np.pi) & (phase[half:] - phase[:half] > 0), np.pi, step)
        return magnitude[:half], magnitude[half:], phase[:half], phase[:half] + step

    def interpolate(lw, i, left, right):  # np.interp between the interval's ends
        slope = (right - left) / (log_w[i + 1] - log_w[i])
        return np.where(lw == log_w[i], left, slope * (lw - log_w[i]) + left)

    row, i = np.nonzero(gain_sign[:, :-1] * gain_sign[:, 1:] <= 0)
    db0, db1, p0, p1 = ends(row, i)
    cross = np.sign(db0) * np.sign(db1) < 0
    row, i, db0, db1, p0, p1 = (x[cross] for x in (row, i, db0, db1, p0, p1))
    lw = log_w[i] + (log_w[i + 1] - log_w[i]) * db0 / (db0 - db1)
    angle = interpolate(lw, i, p0, p1)
    remainder = np.fmod(angle, 2 * np.pi)  # the IEEE remainder: into [-pi, pi]
    remainder = np.where(remainder > np.pi, remainder - 2 * np.pi,
                         np.where(remainder < -np.pi, remainder + 2 * np.pi, remainder))
    pm, f_gc = _worst(n, row, 180.0 - np.abs(np.degrees(remainder)), np.exp(lw) / (2 * np.pi))

    row, i = np.nonzero(phase_sign[:, :-1] * phase_sign[:, 1:] <= 0)
    db0, db1, p0, p1 = ends(row, i)
    t0, t1 = (p0 + np.pi) / (2 * np.pi), (p1 + np.pi) / (2 * np.pi)
    level = np.floor(np.maximum(t0, t1))
    below, above = t0 - level, t1 - level
    cross = np.sign(below) * np.sign(above) < 0
    row, i, db0, db1, below, above = (x[cross] for x in (row, i, db0, db1, below, above))
    lw = log_w[i] + (log_w[i + 1] - log_w[i]) * below / (below - above)
    gm, f_pc = _worst(n, row, np.abs(interpolate(lw, i, db0, db1)), np.exp(lw) / (2 * np.pi))
    return gm, np.where(np.isfinite(pm), pm, np.nan), f_gc, f_pc


def population_margins(isolators=None, controllers=None, *, constants=None):
    """Gain and phase margins and stability of every design's loop, vectorised.

    The numbers of :func:`~qzs.analysis.control_design.stability_margins.loop_margins` at
    the controller's rate and no delay: the continuous loop in closed form; a design with a
    sampled controller (``controller_rate > 0``) through ``loop_margins`` itself.

    Parameters
    ----------
    isolators, controllers : sequence of IsolatorParameters, ControllerParameters
        The designs (needed for sampled controllers; else unused when ``constants`` is
        given).
    constants : dict, optional
        :func:`~qzs.analysis.control_design.hunting_population.population_constants`.

    Returns
    -------
    PopulationMargins
    """
    c = _constants(isolators, controllers, constants)
    n = c["mass"].size
    stable = population_stable(constants=c)
    gm, pm, f_gc, f_pc = (np.full(n, np.nan) for _ in range(4))
    continuous = c["controller_rate"] <= 0
    tops = _grid_top(c)
    for top in np.unique(tops[continuous]):
        omega = _margin_grid(float(top))  # the scalar path's grid
        group = np.flatnonzero(continuous & (tops == top))
        for start in range(0, group.size, _CHUNK):  # rows a few at a time: in the cache
            rows = group[start:start + _CHUNK]
            sub = {name: value[rows] for name, value in c.items()}
            gm[rows], pm[rows], f_gc[rows], f_pc[rows] = _margins_on_grid(sub, omega)
    for k in np.flatnonzero(~continuous):  # sampled: the scalar path
        margins = loop_margins(isolators[k], controllers[k])
        stable[k], gm[k], pm[k] = margins.stable, margins.gain_margin, margins.phase_margin
        f_gc[k] = margins.gain_crossover_frequency
        f_pc[k] = margins.phase_crossover_frequency
    for values in (gm, pm, f_gc, f_pc):  # an unstable loop has no margins (as loop_margins)
        values[~stable] = np.nan
    return PopulationMargins(stable=stable, gain_margin=gm, phase_margin=pm,
                             gain_crossover_frequency=f_gc, phase_crossover_frequency=f_pc)
