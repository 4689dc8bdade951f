"""The frequency-response curve: a branch of periodic responses with stability and folds."""
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs.analysis.harmonic_balance.smooth_model import SmoothModel
from qzs.analysis.harmonic_balance.solution import HarmonicBalanceSolution
from qzs.analysis.harmonic_balance.stability import _is_stable, floquet_exponents
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc
from qzs.iotools.schema import Schema, Variable, to_dataset

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["FrequencyResponseCurve"]


@dataclass(frozen=True)
class FrequencyResponseCurve:
    """A branch of periodic responses followed in frequency (:func:`frequency_response_curve`).

    Points are in the order of the arclength: where the curve folds, frequency goes back.

    Attributes
    ----------
    frequency : ndarray, shape (n,)
        Excitation frequency of each point [Hz].
    transmissibility : ndarray, shape (n,)
        Fundamental amplitude ratio of payload to base acceleration [-].
    phase : ndarray, shape (n,)
        Phase of the payload's fundamental relative to the base's [rad].
    relative_amplitude : ndarray, shape (n,)
        Fundamental amplitude of the relative position [m].
    harmonic_ratios : ndarray, shape (n, 4)
        Payload acceleration at harmonics 2..5 over the base's fundamental [-].
    relative_range : ndarray, shape (n, 2)
        Least and greatest relative position over the period [m].
    motor_force_peak : ndarray, shape (n,)
        Largest absolute unsaturated motor command over the period [N].
    stable : ndarray of bool, shape (n,)
        All Floquet exponents have negative real parts.
    largest_exponent : ndarray, shape (n,)
        Largest real part of the Floquet exponents [1/s].
    valid : ndarray of bool, shape (n,)
        The solution stays between the stops and below the motor's saturation, which the
        smooth model leaves out; an invalid point is no response of the simulator's model.
    folds : tuple of float
        Frequencies of the folds (turning points of the curve) [Hz]: where a stepped
        sweep jumps.
    coefficients : ndarray, shape (n, 2H+1)
        Each point's Fourier coefficients of z [m] (see :class:`HarmonicBalanceSolution`).
    integral_mean : ndarray, shape (n,)
        Each point's mean PI integral [m*s].
    model : SmoothModel
        The model.
    harmonics : int
        Harmonics kept [-].
    notes : tuple of str
        Where and why the continuation stopped early, if it did.
    """

    frequency: np.ndarray
    transmissibility: np.ndarray
    phase: np.ndarray
    relative_amplitude: np.ndarray
    harmonic_ratios: np.ndarray
    relative_range: np.ndarray
    motor_force_peak: np.ndarray
    stable: np.ndarray
    largest_exponent: np.ndarray
    valid: np.ndarray
    folds: tuple
    coefficients: np.ndarray
    integral_mean: np.ndarray
    model: SmoothModel
    harmonics: int
    notes: tuple = field(default=())

    def solution(self, index: int) -> HarmonicBalanceSolution:
        """The periodic solution of one point of the curve.

        Parameters
        ----------
        index : int
            Index of the point [-].

        Returns
        -------
        HarmonicBalanceSolution
        """
        return HarmonicBalanceSolution(float(self.frequency[index]),
                                       np.array(self.coefficients[index]),
                                       float(self.integral_mean[index]), self.model, True, 0,
                                       0.0)

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def summary(self) -> str:
        """The curve as text: its points, its stable peak, its folds and notes.

        Returns
        -------
        str
        """
        f = self.frequency
        lines = [f"harmonic balance, {self.harmonics} harmonics: {f.size} points "
                 f"{np.min(f):.4g}-{np.max(f):.4g} Hz, {int(np.sum(self.stable))} stable, "
                 f"{int(np.sum(~self.valid))} beyond the stops or saturation"]
        usable = np.flatnonzero(self.stable & self.valid)
        if usable.size:
            k = usable[np.argmax(self.transmissibility[usable])]
            lines.append(f"  stable peak |X1/Y1| {self.transmissibility[k]:.4g} at "
                         f"{f[k]:.4g} Hz, relative amplitude "
                         f"{self.relative_amplitude[k] * 1e3:.4g} mm")
        else:
            lines.append("  no stable point within the stops and the motor's limit")
        if self.folds:
            lines.append("  folds at " + ", ".join(f"{fold:.4g}" for fold in self.folds)
                         + " Hz")
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)

    def to_xarray(self) -> "xr.Dataset":
        """The curve as an ``xarray.Dataset`` on ``point`` (arclength order), CF-1.10.

        ``frequency`` [Hz], ``transmissibility`` [1], ``phase`` [rad],
        ``relative_amplitude``, ``relative_min``, ``relative_max`` [m],
        ``motor_force_peak`` [N], ``largest_exponent`` [1/s], the ``stable`` and ``valid``
        flags, ``harmonic_ratio`` [1] on ``(point, harmonic)``; ``folds`` [Hz] and
        ``harmonics`` as global attributes.

        Returns
        -------
        xarray.Dataset
        """
        def flag(name, meanings, what):
            return Variable(name=name, dims=("point",), units="1", dtype="int8",
                            flag_meanings=meanings, long_name=what,
                            order=("units", "flag_values", "flag_meanings", "long_name"))

        per_point = {"frequency": ("Hz", "excitation frequency"),
                     "transmissibility": ("1", "fundamental amplitude ratio of payload to "
                                               "base acceleration"),
                     "phase": ("rad", "phase of the payload's fundamental"),
                     "relative_amplitude": ("m", "fundamental amplitude of the relative "
                                                 "position"),
                     "relative_min": ("m", "least relative position over the period"),
                     "relative_max": ("m", "greatest relative position over the period"),
                     "motor_force_peak": ("N", "largest unsaturated motor command"),
                     "largest_exponent": ("1/s", "largest real part of the Floquet "
                                                 "exponents")}
        schema = Schema(
            kind="a harmonic balance curve", dimensions={"point": None, "harmonic": 4},
            coordinates=(Variable(name="harmonic", dims=("harmonic",), units="1",
                                  dtype="int64", long_name="harmonic order"),),
            variables=(*(Variable(name=name, dims=("point",), units=unit, long_name=what)
                         for name, (unit, what) in per_point.items()),
                       Variable(name="harmonic_ratio", dims=("point", "harmonic"), units="1",
                                long_name="payload acceleration at the harmonic over the "
                                          "base's fundamental"),
                       flag("stable", "unstable stable", "1 where every Floquet exponent "
                                                         "decays"),
                       flag("valid", "beyond within", "1 within the stops and the motor's "
                                                      "limit")))
        values = {"harmonic": np.arange(2, 6), "frequency": self.frequency,
                  "transmissibility": self.transmissibility, "phase": self.phase,
                  "relative_amplitude": self.relative_amplitude,
                  "relative_min": self.relative_range[:, 0],
                  "relative_max": self.relative_range[:, 1],
                  "motor_force_peak": self.motor_force_peak,
                  "largest_exponent": self.largest_exponent,
                  "harmonic_ratio": self.harmonic_ratios, "stable": self.stable,
                  "valid": self.valid}
        attrs = {"title": "frequency-response curve of the smooth model (harmonic balance)",
                 "harmonics": self.harmonics, "folds": np.asarray(self.folds, float),
                 "folds_units": "Hz", "friction_velocity": self.model.friction_velocity,
                 "friction_velocity_units": "m/s"}
        return to_dataset(schema, values, attrs)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """The transmissibility [dB] and relative amplitude [mm] over frequency, stable
        solid, unstable dashed, folds marked (:func:`qzs.viz.response.plot_balance`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (a .png also as .svg).
        title : str, optional
            Figure title; default one naming the harmonics.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.response import plot_balance

        return plot_balance(self, path=path, title=title, frequency_scale=frequency_scale)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per point and "
                            "harmonic) or ``.mat`` (MATLAB) of :meth:`to_xarray`")

    def to_dict(self) -> dict[str, Any]:
        """The curve as plain lists (NaN kept), for JSON.

        Returns
        -------
        dict
        """
        return {"frequency": self.frequency.tolist(),
                "transmissibility": self.transmissibility.tolist(),
                "relative_amplitude": self.relative_amplitude.tolist(),
                "stable": self.stable.tolist(), "valid": self.valid.tolist(),
                "folds": list(self.folds), "harmonics": self.harmonics,
                "friction_velocity": self.model.friction_velocity, "notes": list(self.notes)}


def _curve(points, tangents, model, harmonics, notes):
    """The :class:`FrequencyResponseCurve` of ``points`` (solutions in arclength order) and
    the frequency components of their ``tangents``: ranges, motor peaks, stability,
    validity and folds."""
    n = len(points)
    frequency = np.array([p.frequency for p in points])
    ratios = np.array([p.harmonic_ratios(5) for p in points]).reshape(n, 4)
    ranges = np.empty((n, 2))
    peaks = np.empty(n)
    stable = np.zeros(n, bool)
    largest = np.empty(n)
    for i, p in enumerate(points):
        series = p.time_series()
        ranges[i] = series["relative_position"].min(), series["relative_position"].max()
        peaks[i] = np.max(np.abs(series["motor_force"]))
        exponents = floquet_exponents(p)
        largest[i] = exponents.real.max()
        stable[i] = _is_stable(exponents, 2 * np.pi * p.frequency)
    valid = ((ranges[:, 0] >= model.stop_low) & (ranges[:, 1] <= model.stop_high)
             & (peaks <= model.motor_force_max))
    folds = []
    t = np.asarray(tangents)
    for i in range(1, t.size):
        if t[i - 1] * t[i] < 0:  # the frequency component of the tangent changes sign
            w = t[i - 1] / (t[i - 1] - t[i])
            folds.append(float(frequency[i - 1] + w * (frequency[i] - frequency[i - 1])))
    return FrequencyResponseCurve(
        frequency=frequency, transmissibility=np.array([p.transmissibility for p in points]),
        phase=np.array([p.phase for p in points]),
        relative_amplitude=np.array([p.relative_amplitude for p in points]),
        harmonic_ratios=ratios, relative_range=ranges, motor_force_peak=peaks, stable=stable,
        largest_exponent=largest, valid=valid, folds=tuple(folds),
        coefficients=np.array([p.coefficients for p in points]).reshape(n, 2 * harmonics + 1),
        integral_mean=np.array([p.integral_mean for p in points]), model=model,
        harmonics=harmonics, notes=tuple(notes))
