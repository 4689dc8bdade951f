"""Base excitations: displacement y(t) with consistent velocity and acceleration.

Every excitation packs into the same kernel form (pvlib ``loc_args`` style): an
integer kind, a float array of scalars and, for tabulated signals, a piecewise
cubic (breakpoints and coefficients, scipy ``PPoly`` layout). The kernel
:func:`base_motion` evaluates ``(y, yd, ydd)`` at any time, so integrator stages
between grid points see the exact same signal as the output samples.
"""
from dataclasses import dataclass

import numpy as np
from numba import njit

from qzs._validation import (as_float, choice, non_negative, positive, strictly_increasing,
                             validate_fields)
from qzs.errors import ExcitationError

__all__ = ["Chirp", "Sine", "RandomExcitation", "DisplacementRecord", "base_motion_series"]

KIND_CHIRP_LINEAR, KIND_CHIRP_LOG, KIND_SINE, KIND_TABLE = 0, 1, 2, 3
# Indices into the packed scalars; a table is a (5, n) array: breakpoints in row 0
# (one more than the pieces), the cubic's coefficients (highest power first) in rows 1-4.
E_KIND, E_AMPLITUDE, E_F0, E_F1, E_DURATION, E_PHASE, E_SPACING = range(7)
N_EXCITATION = 7
_TWO_PI = 2.0 * np.pi
_JIT = dict(cache=True, error_model="numpy")  # no fast-math: see qzs._kernels


@njit(**_JIT)
def excitation_tuple(ex):
    """The packed scalars as a tuple (cheaper than an array inside the kernels)."""
    return (ex[0], ex[1], ex[2], ex[3], ex[4], ex[5], ex[6])


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
def _harmonic(amplitude, s, c, omega, omega_dot):
    return amplitude * s, amplitude * c * omega, amplitude * (c * omega_dot - s * omega * omega)


@njit(**_JIT)
def base_motion(t, E, table):
    """Base displacement [m], velocity [m/s] and acceleration [m/s^2] at time ``t`` [s]."""
    if int(E[E_KIND]) == KIND_TABLE:
        return _table(t, E[E_SPACING], table)
    phase, omega, omega_dot = _phase(t, E)
    return _harmonic(E[E_AMPLITUDE], np.sin(phase), np.cos(phase), omega, omega_dot)


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
    """:func:`base_motion` at ``t``, given the phase and its sine/cosine at a nearby time."""
    if int(E[E_KIND]) == KIND_TABLE:
        return _table(t, E[E_SPACING], table)
    phase, omega, omega_dot = _phase(t, E)
    s, c = _rotate(phase, phase0, sin0, cos0)
    return _harmonic(E[E_AMPLITUDE], s, c, omega, omega_dot)


@njit(**_JIT)
def advance_phase(t, phase0, sin0, cos0, E, exact):
    """Phase [rad] and its sine and cosine at ``t``, rotated from a nearby time or ``exact``."""
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


_NO_TABLE = np.zeros((5, 2))


def _excitation_rule(rule):
    """A :mod:`qzs._validation` checker that raises :class:`ExcitationError`."""
    return lambda name, value: rule(name, value, ExcitationError)


def _pack(kind, amplitude=0.0, f0=0.0, f1=0.0, duration=0.0, phase=0.0, spacing=0.0):
    ex = np.zeros(N_EXCITATION)
    ex[[E_KIND, E_AMPLITUDE, E_F0, E_F1, E_DURATION, E_PHASE, E_SPACING]] = (
        kind, amplitude, f0, f1, duration, phase, spacing)
    return ex


@dataclass(frozen=True, kw_only=True)
class Chirp:
    """Constant-displacement-amplitude swept sine (the paper's: 10 mm, 0 -> 20 Hz).

    Parameters
    ----------
    amplitude : float
        Displacement amplitude [m]; default 0.010.
    f0, f1 : float
        Start and end frequency [Hz]; default 0 and 20.
    duration : float
        Sweep time [s]; default 2000 (enough for 122 Welch averages of 32768 at 1 kHz).
    method : {"linear", "logarithmic"}
        Instantaneous frequency linear or exponential in time (``f0 > 0`` for the latter).
    """

    amplitude: float = 0.010
    f0: float = 0.0
    f1: float = 20.0
    duration: float = 2000.0
    method: str = "linear"

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative),
            "f0": _excitation_rule(non_negative),
            "f1": _excitation_rule(non_negative),
            "duration": _excitation_rule(positive),
            "method": lambda n, v: choice(n, v, ("linear", "logarithmic"), ExcitationError),
        })
        if self.method == "logarithmic" and (self.f0 <= 0 or self.f1 <= 0):
            raise ExcitationError(
                f"a logarithmic chirp needs `f0` > 0 and `f1` > 0, got f0={self.f0!r} Hz, "
                f"f1={self.f1!r} Hz; start at e.g. 0.1 Hz or use method='linear'.")

    @property
    def max_frequency(self):
        """Highest frequency in the signal [Hz]."""
        return max(self.f0, self.f1)

    def frequency_at(self, time):
        """Instantaneous frequency [Hz] at ``time`` [s] (held at ``f1`` after the sweep)."""
        fraction = np.clip(np.asarray(time, dtype=float) / self.duration, 0.0, 1.0)
        if self.method == "linear":
            return self.f0 + (self.f1 - self.f0) * fraction
        return self.f0 * (self.f1 / self.f0) ** fraction

    def pack(self):
        """Kernel form: ``(scalars, table)``."""
        kind = KIND_CHIRP_LINEAR if self.method == "linear" else KIND_CHIRP_LOG
        return _pack(kind, self.amplitude, self.f0, self.f1, self.duration), _NO_TABLE


@dataclass(frozen=True, kw_only=True)
class Sine:
    """Harmonic base displacement ``amplitude*sin(2*pi*frequency*t + phase)``.

    Parameters
    ----------
    amplitude : float
        Displacement amplitude [m].
    frequency : float
        Frequency [Hz].
    phase : float
        Phase at t = 0 [rad].
    """

    amplitude: float = 0.010
    frequency: float = 1.0
    phase: float = 0.0
    duration = None  # unbounded: the run's duration is chosen by the caller

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative),
            "frequency": _excitation_rule(non_negative),
            "phase": _excitation_rule(as_float),
        })

    @property
    def max_frequency(self):
        """Highest frequency in the signal [Hz]."""
        return self.frequency

    def pack(self):
        """Kernel form: ``(scalars, table)``."""
        return _pack(KIND_SINE, self.amplitude, self.frequency, phase=self.phase), _NO_TABLE


class _Tabulated:
    """An excitation held as a C2 cubic spline of displacement (consistent derivatives)."""

    def _spline(self):  # pragma: no cover - defined by subclasses
        raise NotImplementedError

    def pack(self):
        """Kernel form: ``(scalars, table)`` of the cubic spline."""
        spline, spacing = self._spline()
        table = np.zeros((5, spline.x.size))
        table[0] = spline.x
        table[1:, :-1] = spline.c
        return _pack(KIND_TABLE, duration=self.duration, spacing=spacing), table


@dataclass(frozen=True, kw_only=True, eq=False)
class RandomExcitation(_Tabulated):
    """Band-limited random base displacement, reproducible from its seed.

    A flat displacement spectrum between ``f_low`` and ``f_high`` with random
    phases (a periodic multisine, period ``duration``), scaled to the RMS
    ``amplitude``, tabulated at 20 points per period of ``f_high`` and held as a
    C2 cubic spline so that velocity and acceleration are consistent.

    Parameters
    ----------
    amplitude : float
        RMS displacement [m].
    f_low, f_high : float
        Band edges [Hz], ``0 <= f_low < f_high``.
    duration : float
        Length of the record [s].
    seed : int
        Seed of ``numpy.random.default_rng``: the same seed gives the same signal.
    """

    amplitude: float = 0.001
    f_low: float = 0.5
    f_high: float = 20.0
    duration: float = 100.0
    seed: int = 0

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative),
            "f_low": _excitation_rule(non_negative),
            "f_high": _excitation_rule(positive),
            "duration": _excitation_rule(positive),
        })
        if self.f_low >= self.f_high:
            raise ExcitationError(
                f"`f_low` must be below `f_high`, got f_low={self.f_low!r} Hz, "
                f"f_high={self.f_high!r} Hz.")
        if not isinstance(self.seed, (int, np.integer)) or isinstance(self.seed, bool):
            raise ExcitationError(f"`seed` must be an integer, got {self.seed!r}.")

    @property
    def max_frequency(self):
        """Highest frequency in the signal [Hz]."""
        return self.f_high

    def _spline(self):
        from scipy.interpolate import CubicSpline

        rate = 20.0 * self.f_high
        n = int(np.ceil(self.duration * rate)) + 1
        n_fft = n if n % 2 == 0 else n + 1
        spacing = self.duration / (n - 1)
        freqs = np.fft.rfftfreq(n_fft, d=spacing)
        band = (freqs >= self.f_low) & (freqs <= self.f_high) & (freqs > 0)
        if not band.any():
            raise ExcitationError(
                f"no frequency line of a {self.duration!r} s record falls in "
                f"[{self.f_low!r}, {self.f_high!r}] Hz; lengthen `duration` or widen the band.")
        rng = np.random.default_rng(self.seed)
        spectrum = np.zeros(freqs.size, complex)
        spectrum[band] = np.exp(1j * rng.uniform(0, 2 * np.pi, band.sum()))
        signal = np.fft.irfft(spectrum, n_fft)[:n]
        rms = np.sqrt(np.mean(signal ** 2))
        signal *= self.amplitude / rms if rms > 0 else 0.0
        time = np.arange(n) * spacing
        return CubicSpline(time, signal, bc_type="not-a-knot"), spacing


@dataclass(frozen=True, kw_only=True, eq=False)
class DisplacementRecord(_Tabulated):
    """A user-given base displacement record, interpolated by a C2 cubic spline.

    Velocity and acceleration are the spline's derivatives, so all three are
    consistent. Measured records should be low-pass filtered first: the spline
    passes through every sample, noise included.

    Parameters
    ----------
    time : array_like
        Sample times [s], strictly increasing, at least 4 samples.
    displacement : array_like
        Base displacement [m] at those times.
    """

    time: np.ndarray
    displacement: np.ndarray

    def __post_init__(self):
        time = np.asarray(self.time, dtype=float)
        disp = np.asarray(self.displacement, dtype=float)
        if time.ndim != 1 or disp.shape != time.shape:
            raise ExcitationError(
                "`time` and `displacement` must be 1-D arrays of the same length, got shapes "
                f"{time.shape} and {disp.shape}.")
        if time.size < 4:
            raise ExcitationError(f"a displacement record needs at least 4 samples, got {time.size}.")
        for name, values in (("time", time), ("displacement", disp)):
            bad = np.count_nonzero(~np.isfinite(values))
            if bad:
                raise ExcitationError(f"`{name}` has {bad} non-finite samples (NaN or inf); "
                                      "remove or interpolate them first.")
        strictly_increasing("time", time, ExcitationError,
                            "sort the record and drop duplicates first")
        object.__setattr__(self, "time", time - time[0])
        object.__setattr__(self, "displacement", disp)

    @property
    def duration(self):
        """Length of the record [s]."""
        return float(self.time[-1])

    @property
    def max_frequency(self):
        """Nyquist frequency of the record [Hz] (an upper bound of its content)."""
        return 0.5 / float(np.median(np.diff(self.time)))

    def _spline(self):
        from scipy.interpolate import CubicSpline

        steps = np.diff(self.time)
        uniform = np.ptp(steps) <= 1e-9 * steps.mean()
        return CubicSpline(self.time, self.displacement), (steps.mean() if uniform else 0.0)

    @classmethod
    def from_file(cls, path, *, time_column="time", displacement_column="displacement"):
        """Read a record from a CSV file with a header (``time`` [s], ``displacement`` [m])."""
        from qzs.io import read_displacement_csv

        time, displacement = read_displacement_csv(path, time_column, displacement_column)
        return cls(time=time, displacement=displacement)


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
