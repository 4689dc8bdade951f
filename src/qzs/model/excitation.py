"""Base excitations: displacement y(t) with consistent velocity and acceleration.

Every excitation packs into the same kernel form (pvlib ``loc_args`` style): an
integer kind, a float array of scalars and, for tabulated signals, a piecewise
cubic (breakpoints and coefficients, scipy ``PPoly`` layout). The engine's kernel
(:func:`qzs.engine.base_motion.base_motion`) evaluates ``(y, yd, ydd)`` at any
time from that form, so integrator stages between grid points see the exact same
signal as the output samples (docs/model.md §6).

:func:`build_excitation` is the one factory that turns a kind name and options
(as configs, the command line and sweeps spell them) into an excitation object.
"""
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs._validation import (choice, known_keys, non_negative_real, parameter, positive_real,
                             read_csv_table, real, strictly_increasing, validate_fields)
from qzs._validation import seed as checked_seed
from qzs.defaults import EXCITATION
from qzs.errors import DataError, ExcitationError

__all__ = ["Chirp", "Sine", "RandomExcitation", "DisplacementRecord", "Excitation",
           "EXCITATION_KINDS", "EXCITATION_OPTIONS", "DEFAULT_FADE_IN", "build_excitation",
           "read_displacement_csv", "highest_frequency"]

KIND_CHIRP_LINEAR, KIND_CHIRP_LOG, KIND_SINE, KIND_TABLE = 0, 1, 2, 3
# Indices into the packed scalars; a table is a (5, n) array: breakpoints in row 0
# (one more than the pieces), the cubic's coefficients (highest power first) in rows 1-4.
E_KIND, E_AMPLITUDE, E_F0, E_F1, E_DURATION, E_PHASE, E_SPACING, E_FADE = range(8)
N_EXCITATION = 8
#: Default fade-in [s] of the excitations that start at full amplitude (sine, random,
#: record): a smooth ramp (its slope a raised cosine) of a few of the closed loop's
#: time constants (docs/model.md §6). A chirp from 0 Hz starts gently and needs none.
DEFAULT_FADE_IN = 2.0

_NO_TABLE = np.zeros((5, 2))


def _excitation_rule(rule):
    """A :mod:`qzs._validation` checker that raises :class:`ExcitationError` naming the field."""
    return lambda name, value: rule(name, value,
                                    lambda message: ExcitationError(message, (name,)))


def _pack(kind, amplitude=0.0, f0=0.0, f1=0.0, duration=0.0, phase=0.0, spacing=0.0,
          fade=0.0):
    ex = np.zeros(N_EXCITATION)
    ex[[E_KIND, E_AMPLITUDE, E_F0, E_F1, E_DURATION, E_PHASE, E_SPACING, E_FADE]] = (
        kind, amplitude, f0, f1, duration, phase, spacing, fade)
    return ex


def _fade_rule(name, value):
    return _excitation_rule(non_negative_real)(name, value)


def _resolve_fade(excitation):
    """``fade_in=None`` (the default) becomes :data:`DEFAULT_FADE_IN`, or a quarter of the
    excitation's length if that is shorter; then the value is checked."""
    duration = excitation.duration
    if excitation.fade_in is None:
        fade = DEFAULT_FADE_IN if duration is None else min(DEFAULT_FADE_IN, 0.25 * duration)
        object.__setattr__(excitation, "fade_in", fade)
    object.__setattr__(excitation, "fade_in", _fade_rule("fade_in", excitation.fade_in))
    if duration is not None and excitation.fade_in > duration:
        raise ExcitationError(
            f"`fade_in` ({excitation.fade_in!r} s) must not exceed the excitation's length "
            f"`duration` ({duration!r} s); shorten it, or set fade_in=0 to start at full "
            "amplitude.", ("fade_in", "duration"))


def _check_peak(amplitude, frequency, names, crest=1.0):
    """Refuse an amplitude whose peak base acceleration ``(2 pi f)^2 A`` (times the crest
    factor of a random signal) is not a finite float64 number, with room for the forces
    (a factor 1e3): the run would overflow at its first step, which is bad input (exit 2),
    not a diverging model (exit 1)."""
    with np.errstate(over="ignore"):
        peak = (2.0 * np.pi * frequency) ** 2 * amplitude * crest * 1e3
    if not np.isfinite(peak):
        raise ExcitationError(
            f"`amplitude` = {amplitude!r} m at {frequency!r} Hz gives a peak base acceleration "
            f"(2 pi f)^2 A beyond float64's range (about 1.8e308): the run would overflow at "
            f"its first step; use a physical amplitude (the paper's is 0.01 m).", names)


_FADE_DOC = ("fade-in [s]: smooth ramp (slope a raised cosine) of the amplitude from 0 at "
             "t = 0 to full at t = fade_in; 0 starts at full amplitude; default 2 s (a "
             "quarter of the excitation if shorter; none for a chirp)")


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
        Sweep time [s]; default 2000, the paper's (121 half-overlapping Welch segments of 32768
        samples at 1 kHz; the paper's 122 need 2015.2 s, which the studies run).
    method : {"linear", "logarithmic"}
        Instantaneous frequency linear or exponential in time (``f0 > 0`` for the latter).
    fade_in : float
        Smooth ramp (slope a raised cosine) of the amplitude over the first ``fade_in`` [s];
        default 0 (a chirp from 0 Hz starts gently; give one for ``f0 > 0``).
    """

    amplitude: float = parameter(EXCITATION["amplitude"], "m", "chirp displacement amplitude")
    f0: float = parameter(0.0, "Hz", "chirp start frequency")
    f1: float = parameter(20.0, "Hz", "chirp end frequency")
    duration: float = parameter(2000.0, "s", "sweep time")
    method: str = parameter("linear", "-", "sweep law: linear or logarithmic")
    fade_in: float = parameter(0.0, "s", _FADE_DOC)

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative_real),
            "f0": _excitation_rule(non_negative_real),
            "f1": _excitation_rule(non_negative_real),
            "duration": _excitation_rule(positive_real),
            "method": lambda n, v: choice(n, v, ("linear", "logarithmic"),
                                          lambda message: ExcitationError(message, (n,))),
        })
        _resolve_fade(self)
        _check_peak(self.amplitude, max(self.f0, self.f1), ("amplitude", "f1"))
        if self.method == "logarithmic" and (self.f0 <= 0 or self.f1 <= 0):
            raise ExcitationError(
                f"a logarithmic chirp needs `f0` > 0 and `f1` > 0, got `f0` = {self.f0!r} Hz, "
                f"`f1` = {self.f1!r} Hz; start at e.g. 0.1 Hz or use `method` = 'linear'.",
                ("f0", "f1", "method"))

    @property
    def max_frequency(self) -> float:
        """Highest frequency in the signal [Hz]."""
        return max(self.f0, self.f1)

    @overload
    def frequency_at(self, time: float) -> float: ...
    @overload
    def frequency_at(self, time: ArrayLike) -> float | NDArray[np.float64]: ...

    def frequency_at(self, time: ArrayLike) -> float | NDArray[np.float64]:
        """Instantaneous frequency [Hz] at ``time`` [s] (held at ``f1`` after the sweep).

        Parameters
        ----------
        time : float or array_like
            Time since the start of the sweep [s] (held at ``f0`` before it).

        Returns
        -------
        float or ndarray
            Instantaneous frequency [Hz].
        """
        fraction = np.clip(np.asarray(time, dtype=float) / self.duration, 0.0, 1.0)
        if self.method == "linear":
            return self.f0 + (self.f1 - self.f0) * fraction
        return self.f0 * (self.f1 / self.f0) ** fraction

    def pack(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kernel form: ``(scalars, table)``."""
        kind = KIND_CHIRP_LINEAR if self.method == "linear" else KIND_CHIRP_LOG
        return (_pack(kind, self.amplitude, self.f0, self.f1, self.duration, fade=self.fade_in),
                _NO_TABLE)


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
    fade_in : float
        Smooth ramp (slope a raised cosine) of the amplitude over the first ``fade_in`` [s];
        default (None) 2 s (:data:`DEFAULT_FADE_IN`); 0 starts at full amplitude, which
        kicks the payload off its setpoint (docs/model.md §6).
    """

    amplitude: float = parameter(EXCITATION["amplitude"], "m", "sine displacement amplitude")
    frequency: float = parameter(1.0, "Hz", "sine frequency")
    phase: float = parameter(0.0, "rad", "phase at t = 0")
    fade_in: float | None = parameter(None, "s", _FADE_DOC)
    duration = None  # unbounded: the run's duration is chosen by the caller

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative_real),
            "frequency": _excitation_rule(non_negative_real),
            "phase": _excitation_rule(real),
        })
        _resolve_fade(self)
        _check_peak(self.amplitude, self.frequency, ("amplitude", "frequency"))

    @property
    def max_frequency(self) -> float:
        """Highest frequency in the signal [Hz]."""
        return self.frequency

    def pack(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kernel form: ``(scalars, table)``."""
        return (_pack(KIND_SINE, self.amplitude, self.frequency, phase=self.phase,
                      fade=self.fade_in), _NO_TABLE)


class _Tabulated:
    """An excitation held as a C2 cubic spline of displacement (consistent derivatives)."""

    if TYPE_CHECKING:  # defined by the subclasses: a field or a property
        @property
        def duration(self) -> float: ...
        fade_in: float | None

    def _spline(self):  # pragma: no cover - defined by subclasses
        raise NotImplementedError

    def pack(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kernel form: ``(scalars, table)`` of the cubic spline."""
        spline, spacing = self._spline()
        table = np.zeros((5, spline.x.size))
        table[0] = spline.x
        table[1:, :-1] = spline.c
        return _pack(KIND_TABLE, duration=self.duration, spacing=spacing, fade=self.fade_in), table


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
        Seed of ``numpy.random.default_rng`` (>= 0): the same seed gives the same signal.
    fade_in : float
        Smooth ramp (slope a raised cosine) of the amplitude over the first ``fade_in`` [s];
        default (None) 2 s (:data:`DEFAULT_FADE_IN`), or a quarter of ``duration`` if
        that is shorter; 0 starts at full amplitude.
    """

    amplitude: float = parameter(0.001, "m", "RMS displacement")
    f_low: float = parameter(0.5, "Hz", "lower band edge")
    f_high: float = parameter(20.0, "Hz", "upper band edge")
    duration: float = parameter(100.0, "s", "record length")
    seed: int = parameter(0, "1", "random seed")
    fade_in: float | None = parameter(None, "s", _FADE_DOC)

    def __post_init__(self):
        validate_fields(self, {
            "amplitude": _excitation_rule(non_negative_real),
            "f_low": _excitation_rule(non_negative_real),
            "f_high": _excitation_rule(positive_real),
            "duration": _excitation_rule(positive_real),
        })
        if self.f_low >= self.f_high:
            raise ExcitationError(
                f"`f_low` ({self.f_low!r} Hz) must be below `f_high` ({self.f_high!r} Hz), the "
                "band's upper edge; swap them or widen the band.", ("f_low", "f_high"))
        object.__setattr__(self, "seed", checked_seed("seed", self.seed, ExcitationError))
        _resolve_fade(self)
        _check_peak(self.amplitude, self.f_high, ("amplitude", "f_high"), crest=4.0)

    @property
    def max_frequency(self) -> float:
        """Highest frequency in the signal [Hz]."""
        return self.f_high

    @property
    def record_points(self) -> float:
        """Points of the tabulated record [-]: 20 per period of ``f_high`` over ``duration``,
        both ends included (a float: beyond any integer's use for a record of 1e300 s)."""
        return float(np.ceil(self.duration * 20.0 * self.f_high)) + 1.0

    def _spline(self):
        from scipy.interpolate import CubicSpline

        n = int(self.record_points)
        n_fft = n if n % 2 == 0 else n + 1
        spacing = self.duration / (n - 1)
        freqs = np.fft.rfftfreq(n_fft, d=spacing)
        band = (freqs >= self.f_low) & (freqs <= self.f_high) & (freqs > 0)
        if not band.any():
            raise ExcitationError(
                f"no frequency line of a {self.duration!r} s record falls in "
                f"[{self.f_low!r}, {self.f_high!r}] Hz; lengthen `duration` or widen the band.",
                ("duration",))
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
    fade_in : float
        Smooth ramp (slope a raised cosine) of the amplitude over the first ``fade_in`` [s];
        default (None) 2 s (:data:`DEFAULT_FADE_IN`), or a quarter of the record if that
        is shorter; 0 replays the record as it is.
    """

    time: np.ndarray = parameter(unit="s", doc="sample times")
    displacement: np.ndarray = parameter(unit="m", doc="base displacement")
    fade_in: float | None = parameter(None, "s", _FADE_DOC)

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
        _resolve_fade(self)

    @property
    def duration(self) -> float:
        """Length of the record [s]."""
        return float(self.time[-1])

    @property
    def max_frequency(self) -> float:
        """Nyquist frequency of the record [Hz] (an upper bound of its content)."""
        return 0.5 / float(np.median(np.diff(self.time)))

    def _spline(self):
        from scipy.interpolate import CubicSpline

        steps = np.diff(self.time)
        uniform = np.ptp(steps) <= 1e-9 * steps.mean()
        return CubicSpline(self.time, self.displacement), (steps.mean() if uniform else 0.0)

    @classmethod
    def from_file(cls, path: str | Path, *, time_column: str = "time",
                  displacement_column: str = "displacement",
                  fade_in: float | None = None) -> "DisplacementRecord":
        """Read a record from a CSV file with a header (see :func:`read_displacement_csv`).

        Parameters
        ----------
        path : str or Path
            The CSV file.
        time_column, displacement_column : str
            Names of the columns holding time [s] and displacement [m].
        fade_in : float
            Smooth ramp (slope a raised cosine) of the amplitude [s]; 0 for none; default
            (None) as :class:`DisplacementRecord`'s.
        """
        time, displacement = read_displacement_csv(path, time_column, displacement_column)
        return cls(time=time, displacement=displacement, fade_in=fade_in)


#: Excitation kinds by the names configs, the command line and sweeps use.
#: Any base excitation (a type for hints: ``excitation: Excitation``).
Excitation = Chirp | Sine | RandomExcitation | DisplacementRecord

EXCITATION_KINDS = {"chirp": Chirp, "sine": Sine, "random": RandomExcitation,
                    "file": DisplacementRecord}
#: Options of each kind, as configs, the command line and sweeps spell them.
EXCITATION_OPTIONS = {
    "chirp": ("amplitude", "f0", "f1", "duration", "method", "fade_in"),
    "sine": ("amplitude", "frequency", "phase", "fade_in"),
    "random": ("amplitude", "f0", "f1", "duration", "seed", "fade_in"),
    "file": ("record", "fade_in"),
}
# Option name -> field name where they differ (a random band is f0..f1 in files).
_FIELD_NAMES = {"random": {"f0": "f_low", "f1": "f_high"}}


def highest_frequency(excitation, duration=None):
    """The highest frequency [Hz] an excitation reaches within its first ``duration`` seconds.

    A chirp cut short reaches only the frequency of its end; a sine its frequency; a random
    excitation its band's upper edge; a record the Nyquist frequency of its samples (an
    upper bound of its content).

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord
        The base motion.
    duration : float, optional
        Simulated time [s]; default the whole excitation.

    Returns
    -------
    float
        The frequency [Hz].
    """
    if isinstance(excitation, Chirp):
        end = excitation.duration if duration is None else duration
        return float(max(excitation.frequency_at(0.0), excitation.frequency_at(end)))
    return float(excitation.max_frequency)


def option_field(kind, option):
    """The field of ``kind``'s class that the option ``option`` sets (its name, usually)."""
    return _FIELD_NAMES.get(kind, {}).get(option, option)


def build_excitation(kind, options=None, *, names=None):
    """The excitation of kind ``kind`` built from ``options`` (the one factory).

    Parameters
    ----------
    kind : {"chirp", "sine", "random", "file"}
        Excitation kind.
    options : dict, optional
        Option name -> value, names as in :data:`EXCITATION_OPTIONS`: ``amplitude`` [m]
        (RMS for random), ``f0``/``f1`` [Hz] (chirp start/end, random band),
        ``frequency`` [Hz] and ``phase`` [rad] (sine), ``duration`` [s], ``method``
        (chirp), ``seed`` (random), ``record`` (file: a CSV path), ``fade_in`` [s]
        (every kind). Missing options take the class defaults.
    names : dict, optional
        Option -> how the caller names it, for the messages (the command line's
        ``{"duration": "--excitation-duration", "f0": "--f0"}``); default the option's name.

    Returns
    -------
    Chirp, Sine, RandomExcitation or DisplacementRecord

    Raises
    ------
    ExcitationError
        Unknown kind, an option the kind does not take, or an invalid value (its
        :attr:`~qzs.errors.ExcitationError.options` named as ``names`` says).
    DataError
        The record of a ``file`` excitation cannot be read (prefixed with its ``names``
        spelling, if any).
    """
    names = dict(names or {})
    try:
        return _build(kind, dict(options or {}))
    except ExcitationError as error:
        fields = {option_field(kind, option): option for option in EXCITATION_OPTIONS.get(kind, ())}
        raise error.renamed(fields).renamed(names) from None
    except DataError as error:
        if "record" not in names:
            raise
        raise DataError(f"{names['record']}: {error}") from None


def _build(kind, options):
    if kind not in EXCITATION_KINDS:
        raise ExcitationError(f"excitation `kind` must be one of {tuple(EXCITATION_KINDS)}, "
                              f"got {kind!r}.")
    known_keys(options, EXCITATION_OPTIONS[kind], f"a {kind} excitation", noun="option",
               error=ExcitationError)
    if kind == "file":
        if "record" not in options:
            raise ExcitationError("a `file` excitation needs `record`, the path of a CSV file "
                                  "with columns time [s] and displacement [m].")
        return DisplacementRecord.from_file(
            options["record"], **({"fade_in": options["fade_in"]} if "fade_in" in options else {}))
    if kind == "random" and "seed" in options:
        seed = options["seed"]
        if isinstance(seed, float) and seed.is_integer():
            options["seed"] = int(seed)
    cls = EXCITATION_KINDS[kind]
    return cls(**{option_field(kind, name): value for name, value in options.items()})


def read_displacement_csv(path, time_column="time", displacement_column="displacement"):
    """Read ``time`` [s] and ``displacement`` [m] columns from a CSV file with a header.

    Parameters
    ----------
    path : str or Path
        The CSV file: a header line of column names, then rows of numbers; lines
        starting with ``#`` are comments.
    time_column, displacement_column : str
        Names of the columns holding time [s] and displacement [m].

    Returns
    -------
    time, displacement : ndarray
        The two columns [s], [m].

    Raises
    ------
    DataError
        Missing file, a folder, a file that is not UTF-8 text, missing columns (the
        message lists the columns found), non-numeric or non-finite samples.
    """
    names, data = read_csv_table(
        path, "displacement record",
        f"a header with {time_column!r} and {displacement_column!r}, then rows of numbers")
    missing = [c for c in (time_column, displacement_column) if c not in names]
    if missing:
        raise DataError(f"{str(path)!r} has no column(s) {missing}; columns found: {names}.")
    time = data[:, names.index(time_column)]
    displacement = data[:, names.index(displacement_column)]
    bad = int(np.count_nonzero(~np.isfinite(time)) + np.count_nonzero(~np.isfinite(displacement)))
    if bad:
        raise DataError(f"{str(path)!r}: {bad} non-finite samples (NaN or inf) in "
                        f"{time_column!r}/{displacement_column!r}; clean the record first.")
    return time, displacement
