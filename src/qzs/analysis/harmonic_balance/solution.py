"""One periodic response of the smooth model by Newton's method on the balance.

:func:`periodic_response` solves the residual of :mod:`.residual` at one frequency, from the
describing-function response or a given solution; :class:`HarmonicBalanceSolution` holds the
coefficients and derives the transmissibility, the harmonics and the time series.
"""
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from qzs._validation import positive_real
from qzs.analysis.harmonic_balance.blas import _single_threaded_blas
from qzs.analysis.harmonic_balance.fourier import (DEFAULT_HARMONICS, _basis, _check_settings,
                                                   _default_time_points)
from qzs.analysis.harmonic_balance.residual import (_force_scale, _linear_terms,
                                                    _relative_coefficients, _residual, _scales)
from qzs.analysis.harmonic_balance.smooth_model import SmoothModel
from qzs.errors import ParameterError
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc
from qzs.iotools.schema import Schema, Variable, time_coordinate, to_dataset
from qzs.model.isolator import friction_level, friction_slope

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["HarmonicBalanceSolution", "periodic_response", "PERIOD_CHANNELS"]

#: The time series of one period (:meth:`HarmonicBalanceSolution.time_series`): unit, meaning.
PERIOD_CHANNELS = {
    "relative_position": ("m", "relative position z"),
    "relative_velocity": ("m/s", "relative velocity"),
    "highpass_state": ("m/s", "state of the damping loop's high-pass"),
    "pi_integral": ("m*s", "integral of the position error (PI)"),
    "motor_force": ("N", "unsaturated motor command"),
    "payload_acceleration": ("m/s^2", "payload acceleration")}

#: Newton stops when the largest scaled update is below this [-].
NEWTON_TOLERANCE = 1e-10
#: Newton iterations at most per solve [-].
NEWTON_ITERATIONS = 40


def _newton(q, omega, model, basis, scale):
    """Damped Newton at fixed omega; returns ``(q, converged, iterations, residual norm)``."""
    force = _force_scale(model, omega, 1e-12)
    residual, d_q, _ = _residual(q, omega, model, basis)
    norm = np.max(np.abs(residual)) / force
    for iteration in range(1, NEWTON_ITERATIONS + 1):
        try:
            step = np.linalg.solve(d_q, -residual)
        except np.linalg.LinAlgError:
            return q, False, iteration, norm
        damping = 1.0
        while True:  # halve the step until the residual does not grow (globalisation)
            trial = q + damping * step
            trial_residual, trial_dq, _ = _residual(trial, omega, model, basis)
            trial_norm = np.max(np.abs(trial_residual)) / force
            if np.isfinite(trial_norm) and (trial_norm <= norm or damping < 1e-3):
                break
            damping *= 0.5
        q, residual, d_q, norm = trial, trial_residual, trial_dq, trial_norm
        if np.max(np.abs(damping * step) / scale) < NEWTON_TOLERANCE or norm < 1e-13:
            return q, bool(np.isfinite(norm)), iteration, norm
    return q, False, NEWTON_ITERATIONS, norm


@dataclass(frozen=True)
class HarmonicBalanceSolution:
    """A periodic response of the smooth model (:func:`periodic_response`).

    Attributes
    ----------
    frequency : float
        Excitation frequency [Hz].
    coefficients : ndarray, shape (2H+1,)
        Real Fourier coefficients of z [m]: ``[z0, a1, b1, ..., aH, bH]`` for
        ``z = z0 + sum a_k cos(k w t) + b_k sin(k w t)`` (base ``y = A cos(w t)``).
    integral_mean : float
        Mean of the PI integral [m*s] (0 without an integral gain).
    model : SmoothModel
        The model solved.
    converged : bool
        Newton met its tolerance.
    iterations : int
        Newton iterations taken [-].
    residual : float
        Largest residual force of the balance over a force scale [-].
    """

    frequency: float
    coefficients: np.ndarray
    integral_mean: float
    model: SmoothModel
    converged: bool
    iterations: int
    residual: float

    @property
    def harmonics(self):
        """Number of harmonics kept [-]."""
        return (self.coefficients.size - 1) // 2

    def relative_amplitudes(self):
        """Complex amplitudes ``Z_k`` [m] of z, k = 0..H (``z = Re sum Z_k e^{i k w t}``).

        Returns
        -------
        ndarray of complex, shape (H+1,)
        """
        q = self.coefficients
        out = np.empty(self.harmonics + 1, complex)
        out[0] = q[0]
        out[1:] = q[1::2] - 1j * q[2::2]
        return out

    @property
    def transmissibility(self):
        """Fundamental amplitude ratio of payload to base acceleration ``|X_1|/A`` [-]."""
        return float(abs(self.relative_amplitudes()[1] + self.model.amplitude)
                     / self.model.amplitude)

    @property
    def phase(self):
        """Phase of the payload's fundamental relative to the base's [rad]."""
        return float(np.angle(self.relative_amplitudes()[1] + self.model.amplitude))

    @property
    def relative_amplitude(self):
        """Fundamental amplitude of the relative position ``|Z_1|`` [m]."""
        return float(abs(self.relative_amplitudes()[1]))

    def harmonic_ratios(self, count=5):
        """Payload acceleration at harmonics 2..count over the base's fundamental [-].

        Parameters
        ----------
        count : int
            Highest harmonic [-].

        Returns
        -------
        ndarray, shape (count - 1,)
            ``k^2 |Z_k| / A`` for k = 2..count (NaN beyond the harmonics kept).
        """
        amplitudes = np.abs(self.relative_amplitudes())
        out = np.full(max(count - 1, 0), np.nan)
        for k in range(2, min(count, self.harmonics) + 1):
            out[k - 2] = k * k * amplitudes[k] / self.model.amplitude
        return out

    def time_series(self, points=None):
        """The response over one period, from phase 0 (base at its crest).

        Parameters
        ----------
        points : int, optional
            Samples per period [-]; default 8 per harmonic, at least 64.

        Returns
        -------
        dict of ndarray
            ``time`` [s], ``relative_position`` [m], ``relative_velocity`` [m/s],
            ``highpass_state`` [m/s], ``pi_integral`` [m*s], ``motor_force`` [N]
            (unsaturated command), ``payload_acceleration`` [m/s^2].
        """
        m = self.model
        points = _default_time_points(self.harmonics) if points is None else int(points)
        omega = 2 * np.pi * self.frequency
        k = np.arange(self.harmonics + 1)
        z_k = self.relative_amplitudes()
        y_k = np.zeros_like(z_k)
        y_k[1] = m.amplitude
        s = 1j * k * omega
        x_k = z_k + y_k
        xd_k = s * x_k
        with np.errstate(divide="ignore", invalid="ignore"):
            integral_k = np.where(k > 0, (-z_k) / np.where(k > 0, s, 1.0), self.integral_mean)
            w_k = (m.highpass_omega / (s + m.highpass_omega) * xd_k
                   if m.highpass_omega > 0 else np.zeros_like(xd_k))
        integral_k[0] = self.integral_mean
        w_k[0] = 0.0

        basis = _basis(self.harmonics, points)

        def synth(c):  # real samples of Re sum c_k e^{i k tau}
            real = np.empty(basis.size)
            real[0] = c[0].real
            real[1::2], real[2::2] = c[1:].real, -c[1:].imag
            return basis.synthesis @ real

        z, v, w, integral = synth(z_k), synth(s * z_k), synth(w_k), synth(integral_k)
        xd = synth(xd_k)
        motor = m.motor_force(z, integral, xd, w)
        return {"time": basis.tau / omega, "relative_position": z, "relative_velocity": v,
                "highpass_state": w, "pi_integral": integral, "motor_force": motor,
                "payload_acceleration": synth(s * xd_k)}

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def summary(self) -> str:
        """The solution as text: its fundamental, its harmonics kept, Newton's outcome.

        Returns
        -------
        str
        """
        state = (f"converged in {self.iterations} Newton iterations" if self.converged else
                 f"NOT converged after {self.iterations} Newton iterations")
        return (f"periodic response at {self.frequency:.6g} Hz, {self.harmonics} harmonics, "
                f"base amplitude {self.model.amplitude * 1e3:.4g} mm\n"
                f"  |X1/Y1| {self.transmissibility:.6g}, phase {self.phase:.4g} rad, "
                f"relative amplitude {self.relative_amplitude * 1e3:.4g} mm\n"
                f"  {state}, residual {self.residual:.3g} of the force scale")

    def to_xarray(self) -> "xr.Dataset":
        """One period of the response (:meth:`time_series`) on ``time`` [s], CF-1.10.

        The channels of :data:`PERIOD_CHANNELS` with their units; ``frequency`` [Hz],
        ``transmissibility`` [1], ``phase`` [rad], ``harmonics``, ``converged`` and
        ``residual`` as global attributes.

        Returns
        -------
        xarray.Dataset
        """
        schema = Schema(kind="a periodic response", dimensions={"time": None},
                        coordinates=(time_coordinate(),),
                        variables=tuple(Variable(name=name, dims=("time",), units=unit,
                                                 long_name=what)
                                        for name, (unit, what) in PERIOD_CHANNELS.items()))
        attrs = {"title": "one period of the smooth model's response (harmonic balance)",
                 "frequency": self.frequency, "frequency_units": "Hz",
                 "transmissibility": self.transmissibility, "transmissibility_units": "1",
                 "phase": self.phase, "phase_units": "rad", "harmonics": self.harmonics,
                 "converged": int(self.converged), "residual": self.residual}
        return to_dataset(schema, self.time_series(), attrs)

    def plot(self, path: str | Path | None = None, *, title: str | None = None) -> "Figure":
        """One period: relative position [mm], motor force [N] and payload acceleration
        [m/s^2] against time [s] (:func:`qzs.viz.response.plot_period`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (a .png also as .svg).
        title : str, optional
            Figure title; default one naming the frequency and the harmonics.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.response import plot_period

        return plot_period(self, path=path, title=title)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per sample) or "
                            "``.mat`` (MATLAB) of :meth:`to_xarray`: one period")

    def state_at_start(self):
        """State ``(z, v, w, I)`` at phase 0, for :func:`smooth_right_hand_side`.

        Returns
        -------
        ndarray, shape (4,)
            z [m], v [m/s], w [m/s], I [m*s].
        """
        series = self.time_series(points=8)
        return np.array([series[name][0] for name in ("relative_position",
                                                      "relative_velocity", "highpass_state",
                                                      "pi_integral")])


def _linear_guess(omega, model, basis):
    """Start of Newton: the response with the spring's tangent stiffness at the setpoint and
    friction replaced by its describing function, an equivalent viscous damping
    ``4 F(V)/(pi V) + Cv`` at the velocity amplitude ``V`` of the fundamental (at most the
    regularised law's slope at rest), found by a few fixed-point iterations."""
    q = np.zeros(basis.size)
    spring_at_setpoint, spring_slope = model.spring(model.position_setpoint)
    k_spring = -spring_slope
    rest_slope = -friction_slope(0.0, model)
    on_z, on_y, _, _ = _linear_terms(omega, model, 1)
    damping = rest_slope
    z1 = 0.0
    for _ in range(30):
        z1_new = -on_y[0] * model.amplitude / (on_z[0] + k_spring + 1j * omega * damping)
        z1 = z1_new if z1 == 0.0 else 0.5 * (z1 + z1_new)
        velocity = omega * abs(z1)
        level = float(friction_level(velocity, model))
        equivalent = 4 * level / (np.pi * velocity) if velocity > 0 else np.inf
        damping = min(equivalent, rest_slope - model.viscous_damping) + model.viscous_damping
    q[1], q[2] = z1.real, -z1.imag
    static = model.mass * model.gravity - spring_at_setpoint
    if model.pi_ki > 0:
        q[0] = float(static) / model.pi_ki
    else:
        q[0] = model.position_setpoint
    return q


def periodic_response(frequency, model, *, harmonics=DEFAULT_HARMONICS, time_points=None,
                     initial_guess=None):
    """The periodic response of the smooth model at one frequency, by harmonic balance.

    Parameters
    ----------
    frequency : float
        Excitation frequency [Hz].
    model : SmoothModel
        The smooth model (:meth:`SmoothModel.from_parameters`).
    harmonics : int
        Harmonics of z kept [-].
    time_points : int, optional
        Phases per period of the AFT [-] (at least ``4*harmonics + 2``); default a power
        of two of at least ``8*harmonics``.
    initial_guess : HarmonicBalanceSolution, optional
        Start of Newton (same harmonics); default the linearised response.

    Returns
    -------
    HarmonicBalanceSolution
        ``converged`` says whether Newton met its tolerance.
    """
    frequency = positive_real("frequency", frequency)
    if not isinstance(model, SmoothModel):
        raise ParameterError(f"`model` must be a SmoothModel, got {type(model).__name__}.")
    harmonics, time_points = _check_settings(harmonics, time_points)
    basis = _basis(harmonics, time_points)
    omega = 2 * np.pi * frequency
    if initial_guess is not None:
        q = _unknowns(initial_guess)
        if q.size != basis.size:
            raise ParameterError(f"`initial_guess` has {initial_guess.harmonics} harmonics, "
                                 f"not {harmonics}; solve with the same `harmonics`.")
    else:
        q = _linear_guess(omega, model, basis)
    scale = _scales(model, omega, basis.size)
    with _single_threaded_blas():
        q, converged, iterations, norm = _newton(q, omega, model, basis, scale)
    return _solution(q, frequency, model, converged, iterations, norm)


def _unknowns(solution):
    """The unknowns of a solution: its coefficients, the integral's mean in slot 0 when Ki > 0."""
    q = np.array(solution.coefficients, dtype=float)
    if solution.model.pi_ki > 0:
        q[0] = solution.integral_mean
    return q


def _solution(q, frequency, model, converged, iterations, norm):
    """The :class:`HarmonicBalanceSolution` of the unknowns ``q`` at ``frequency`` [Hz]."""
    coefficients = _relative_coefficients(q, model)
    integral = float(q[0]) if model.pi_ki > 0 else 0.0
    return HarmonicBalanceSolution(float(frequency), coefficients, integral, model,
                                   bool(converged), int(iterations), float(norm))
