"""The frequency-response curve: a branch of periodic responses with stability and folds."""
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qzs.analysis.harmonic_balance.smooth_model import SmoothModel
from qzs.analysis.harmonic_balance.solution import HarmonicBalanceSolution
from qzs.analysis.harmonic_balance.stability import _is_stable, floquet_exponents

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
