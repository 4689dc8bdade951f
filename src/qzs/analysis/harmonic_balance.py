"""Harmonic balance of the smooth isolator model: periodic responses, stability, continuation.

The *smooth model* is the simulator's model (docs/model.md §2-5) with every non-smooth part
made smooth or left out, so that a periodic response is a zero of a smooth function of its
Fourier coefficients (docs/response.md §5):

* one degree of freedom, relative coordinates ``z = x - y``, ``v = dz/dt``, base
  ``y = A cos(w t)``;
* the MagSpring ``-a tanh(b z)`` as it is;
* friction regularised: ``-[Fc + (Fs - Fc) exp(-Cbc |v|)] tanh(v/v_reg) - Cv v``, the sign
  function replaced by ``tanh(v/v_reg)`` (``friction_velocity`` = ``v_reg`` [m/s]); there
  is no sticking, a held payload creeps at a velocity of the order of ``v_reg``;
* the PI loop and the active damping through the amplifier's high-pass as in docs/model.md
  §5, without saturation and anti-windup; no hard stops; gravity as it is (the integral's
  mean carries what the spring does not).

Unknowns are the real Fourier coefficients of ``z`` up to ``H`` harmonics; with ``pi_ki > 0``
the mean of ``z`` is the setpoint (the integral of a periodic error is periodic only if the
error has zero mean) and the mean of the PI integral takes the mean's slot. The linear parts
(mass, PI, damping through the high-pass) are exact per harmonic; the spring and friction
forces are evaluated on a time grid and transformed back (alternating frequency-time, AFT).
Newton's method solves the balance at one frequency (:func:`periodic_response`);
pseudo-arclength continuation follows it in frequency around folds
(:func:`frequency_response_curve`); Hill's method gives each solution's Floquet exponents
(:func:`floquet_exponents`): a point is stable when they all have negative real parts.

Pure numpy; :func:`smooth_right_hand_side` is the same model as an ordinary differential
equation, for time-domain checks.

References
----------
Cameron, T. M., Griffin, J. H. (1989). An alternating frequency/time domain method for
calculating the steady-state response of nonlinear dynamic systems. J. Appl. Mech. 56, 149-154.
Keller, H. B. (1977). Numerical solution of bifurcation and nonlinear eigenvalue problems. In
*Applications of Bifurcation Theory*, Academic Press, 359-384 (pseudo-arclength continuation).
Lazarus, A., Thomas, O. (2010). A harmonic-based method for computing the stability of periodic
solutions of dynamical systems. C. R. Mécanique 338, 510-517 (Hill's method, eigenvalue choice).
"""
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from qzs._validation import integer, non_negative, positive
from qzs.errors import ParameterError
from qzs.model.registry import model_inputs

__all__ = ["SmoothModel", "HarmonicBalanceSolution", "FrequencyResponseCurve",
           "periodic_response", "frequency_response_curve", "floquet_exponents",
           "smooth_right_hand_side", "DEFAULT_HARMONICS", "FRICTION_VELOCITY"]

#: Harmonics of the relative position kept by default [-]: enough for the default
#: regularisation at the paper's 10 mm (the reversal of the friction force then takes about
#: 1/300 of a period at 5 Hz).
DEFAULT_HARMONICS = 40
#: Default regularisation velocity of the friction's sign function [m/s]. It must be small
#: beside the Stribeck velocity ``1/stribeck_decay`` (10 mm/s by default), or the regularised
#: law never reaches the stiction level: with Table 1 it peaks at 8.1 N of Fs = 10 N at
#: 1 mm/s (6.9 N at 2 mm/s, 9.4 N at 0.2 mm/s, which would need hundreds of harmonics).
FRICTION_VELOCITY = 1e-3
#: Newton stops when the largest scaled update is below this [-].
NEWTON_TOLERANCE = 1e-10
#: Newton iterations at most per solve [-].
NEWTON_ITERATIONS = 40
#: Frequencies (geometric, over the range) where Newton tries to start the continuation [-].
START_ATTEMPTS = 12
#: Fewest continuation steps over the frequency range (the largest frequency step) [-].
MAX_POINTS_PER_RANGE = 150
#: Successive tangents of the continuation must make an angle with at least this cosine [-].
MIN_TANGENT_COSINE = 0.95
#: Real parts of Floquet exponents below ``-STABILITY_MARGIN * omega`` count as negative [-].
STABILITY_MARGIN = 1e-7


# ---------------------------------------------------------------- the smooth model
@dataclass(frozen=True, kw_only=True)
class SmoothModel:
    """The smooth isolator model of harmonic balance (see the module's docstring).

    Build it from the simulator's parameters with :meth:`from_parameters`.

    Parameters
    ----------
    mass : float
        Moving mass [kg].
    gravity : float
        Gravitational acceleration [m/s^2].
    spring_force : float
        MagSpring plateau force a [N].
    spring_shape : float
        MagSpring transition coefficient b [1/m].
    stiction_force : float
        Breakaway friction level Fs [N] (the regularised law's level at small velocity).
    coulomb_force : float
        Sliding friction level Fc [N].
    stribeck_decay : float
        Decay rate Cbc from stiction to Coulomb level [s/m].
    viscous_damping : float
        Viscous friction coefficient Cv [N*s/m].
    position_setpoint : float
        PI setpoint z_ref [m].
    pi_kp : float
        Proportional gain [N/m].
    pi_ki : float
        Integral gain [N/(m*s)].
    damping_gain : float
        Active damping gain on the measured payload velocity [N*s/m].
    velocity_highpass : float
        Corner of the charge amplifier's high-pass [Hz]; 0: none.
    friction_velocity : float
        Regularisation velocity v_reg of the friction's sign [m/s].
    amplitude : float
        Base displacement amplitude A [m].
    motor_force_max : float
        Motor saturation [N]: not modelled, only checked (:attr:`FrequencyResponseCurve.valid`).
    stop_low, stop_high : float
        Hard stops in z [m]: not modelled, only checked.
    """

    mass: float
    gravity: float
    spring_force: float
    spring_shape: float
    stiction_force: float
    coulomb_force: float
    stribeck_decay: float
    viscous_damping: float
    position_setpoint: float
    pi_kp: float
    pi_ki: float
    damping_gain: float
    velocity_highpass: float
    friction_velocity: float
    amplitude: float
    motor_force_max: float = np.inf
    stop_low: float = -np.inf
    stop_high: float = np.inf

    def __post_init__(self):
        for name in ("mass", "spring_shape", "friction_velocity", "amplitude"):
            positive(name, getattr(self, name))
        for name in ("gravity", "spring_force", "stiction_force", "coulomb_force",
                     "stribeck_decay", "viscous_damping", "pi_kp", "pi_ki", "damping_gain",
                     "velocity_highpass"):
            non_negative(name, getattr(self, name))

    @classmethod
    def from_parameters(cls, isolator=None, controller=None, *, amplitude,
                        friction_velocity=FRICTION_VELOCITY):
        """The smooth model of a simulator case.

        Parameters
        ----------
        isolator : IsolatorParameters, optional
            Plant parameters; Table 1 defaults if omitted. Stops and saturation are kept
            for the validity check only.
        controller : ControllerParameters, optional
            PI and damping loops; defaults if omitted. A sampled controller
            (``controller_rate > 0``) is treated as continuous.
        amplitude : float
            Base displacement amplitude [m].
        friction_velocity : float
            Regularisation velocity of the friction's sign [m/s].

        Returns
        -------
        SmoothModel
        """
        isolator, controller = model_inputs(isolator, controller)
        center = (controller.position_setpoint if isolator.stop_center is None
                  else isolator.stop_center)
        return cls(mass=isolator.mass, gravity=isolator.gravity,
                   spring_force=isolator.spring_force, spring_shape=isolator.spring_shape,
                   stiction_force=isolator.stiction_force, coulomb_force=isolator.coulomb_force,
                   stribeck_decay=isolator.stribeck_decay,
                   viscous_damping=isolator.viscous_damping,
                   position_setpoint=controller.position_setpoint, pi_kp=controller.pi_kp,
                   pi_ki=controller.pi_ki, damping_gain=controller.damping_gain,
                   velocity_highpass=controller.velocity_highpass,
                   friction_velocity=friction_velocity, amplitude=amplitude,
                   motor_force_max=isolator.motor_force_max,
                   stop_low=center - isolator.stroke_half, stop_high=center + isolator.stroke_half)

    @property
    def highpass_omega(self):
        """Corner of the high-pass as an angular frequency [rad/s]."""
        return 2 * np.pi * self.velocity_highpass

    @property
    def states(self):
        """Names of the first-order states whose exponents Hill's method computes.

        ``z`` and ``v`` always; the high-pass state ``w`` when it feeds back (damping gain
        and corner both positive; with no gain it is a stable filter of exponent
        ``-2*pi*velocity_highpass`` that does not couple); the integral ``I`` when
        ``pi_ki > 0``.
        """
        names = ["z", "v"]
        if self.damping_gain > 0 and self.velocity_highpass > 0:
            names.append("w")
        if self.pi_ki > 0:
            names.append("I")
        return tuple(names)

    @property
    def peak_friction(self):
        """Largest dry-friction force the regularised law reaches [N] (viscous part left
        out): below ``stiction_force`` when ``friction_velocity`` is not small beside the
        Stribeck velocity ``1/stribeck_decay``."""
        if self.stiction_force == 0.0 and self.coulomb_force == 0.0:
            return 0.0
        top = 10 * self.friction_velocity + (10.0 / self.stribeck_decay
                                             if self.stribeck_decay > 0 else 0.0)
        v = np.linspace(0.0, top, 20001)
        return float(np.max(-(self.friction(v)[0] + self.viscous_damping * v)))

    def spring(self, relative_position):
        """Spring force [N] and its slope dF/dz [N/m] at ``relative_position`` [m].

        Parameters
        ----------
        relative_position : float or ndarray
            Relative position z [m].

        Returns
        -------
        force, slope : ndarray
            ``-a tanh(b z)`` [N] and ``-a b / cosh(b z)^2`` [N/m].
        """
        t = np.tanh(self.spring_shape * np.asarray(relative_position, dtype=float))
        return -self.spring_force * t, -self.spring_force * self.spring_shape * (1 - t * t)

    def friction(self, relative_velocity):
        """Regularised friction force [N] and its slope dF/dv [N*s/m] at ``relative_velocity``.

        Parameters
        ----------
        relative_velocity : float or ndarray
            Relative velocity v [m/s].

        Returns
        -------
        force, slope : ndarray
            ``-[Fc + (Fs - Fc) exp(-Cbc |v|)] tanh(v/v_reg) - Cv v`` [N] and its derivative
            [N*s/m] (continuous: the kink of ``|v|`` is multiplied by ``tanh(0) = 0``).
        """
        v = np.asarray(relative_velocity, dtype=float)
        th = np.tanh(v / self.friction_velocity)
        decay = np.exp(-self.stribeck_decay * np.abs(v))
        excess = self.stiction_force - self.coulomb_force
        level = self.coulomb_force + excess * decay
        force = -level * th - self.viscous_damping * v
        slope = (excess * self.stribeck_decay * decay * np.abs(th)
                 - level * (1 - th * th) / self.friction_velocity - self.viscous_damping)
        return force, slope


def smooth_right_hand_side(time, state, frequency, model):
    """The smooth model as a first-order ODE: ``d(z, v, w, I)/dt`` at ``time``.

    Base motion ``y = A cos(2 pi f t)``; the same equations as the simulator's
    (docs/model.md §2-5) with the regularised friction, without saturation, anti-windup
    and stops. ``w`` and ``I`` are integrated even where they do not feed back.

    Parameters
    ----------
    time : float
        Time [s].
    state : array_like, shape (4,) or (4, k)
        Relative position z [m], relative velocity v [m/s], high-pass state w [m/s],
        PI integral I [m*s] (columns: several states at once).
    frequency : float
        Excitation frequency [Hz].
    model : SmoothModel
        The model.

    Returns
    -------
    ndarray, shape of ``state``
        The derivatives [m/s, m/s^2, m/s^2, m].
    """
    z, v, w, integral = np.asarray(state, dtype=float)
    omega = 2 * np.pi * frequency
    a = model.amplitude
    yd = -a * omega * np.sin(omega * time)
    ydd = -a * omega ** 2 * np.cos(omega * time)
    xd = yd + v
    measured = xd - w if model.velocity_highpass > 0 else xd
    error = model.position_setpoint - z
    motor = model.pi_kp * error + model.pi_ki * integral - model.damping_gain * measured
    force = model.spring(z)[0] + model.friction(v)[0] + motor - model.mass * model.gravity
    return np.array([v, force / model.mass - ydd, model.highpass_omega * (xd - w), error])


# ---------------------------------------------------------------- Fourier bases
class _Basis:
    """Real Fourier basis of ``H`` harmonics on ``N`` equidistant phases of one period.

    Coefficient layout ``[c0, a1, b1, ..., aH, bH]`` for ``c0 + sum a_k cos(k tau) + b_k
    sin(k tau)``, ``tau = w t``; ``synthesis`` maps coefficients to samples, ``analysis``
    back (exact for ``N > 2H``), ``derivative`` is d/dtau on coefficients.
    """

    def __init__(self, harmonics, time_points):
        self.harmonics = harmonics
        self.time_points = time_points
        self.size = 2 * harmonics + 1
        tau = 2 * np.pi * np.arange(time_points) / time_points
        k = np.arange(1, harmonics + 1)
        self.tau = tau
        self.synthesis = np.ones((time_points, self.size))
        self.synthesis[:, 1::2] = np.cos(np.outer(tau, k))
        self.synthesis[:, 2::2] = np.sin(np.outer(tau, k))
        self.analysis = self.synthesis.T * (2.0 / time_points)
        self.analysis[0] = 1.0 / time_points
        self.derivative = np.zeros((self.size, self.size))
        for h in k:
            self.derivative[2 * h - 1, 2 * h] = h
            self.derivative[2 * h, 2 * h - 1] = -h
        self.synthesis_derivative = self.synthesis @ self.derivative

    def complex_coefficients(self, q):
        """Complex amplitudes ``X_k`` (``x = Re sum X_k e^{i k tau}``), k = 0..H."""
        out = np.empty(self.harmonics + 1, complex)
        out[0] = q[0]
        out[1:] = q[1::2] - 1j * q[2::2]
        return out


@lru_cache(maxsize=16)
def _basis(harmonics, time_points):
    """The cached :class:`_Basis` of ``harmonics`` on ``time_points`` phases."""
    return _Basis(harmonics, time_points)


def _block(values):
    """Real (2x2 per harmonic) form of multiplying complex amplitudes by ``values``."""
    n = values.size
    matrix = np.zeros((2 * n, 2 * n))
    idx = np.arange(n)
    matrix[2 * idx, 2 * idx] = values.real
    matrix[2 * idx, 2 * idx + 1] = values.imag
    matrix[2 * idx + 1, 2 * idx] = -values.imag
    matrix[2 * idx + 1, 2 * idx + 1] = values.real
    return matrix


def _linear_terms(omega, model, harmonics):
    """Per-harmonic complex operators: on z (``G_k``), on y (``B_k``) and their d/domega."""
    k = np.arange(1, harmonics + 1)
    s = 1j * k * omega
    wh = model.highpass_omega
    if wh > 0:
        hp_s = s * s / (s + wh)
        hp_s_ds = (s * s + 2 * s * wh) / (s + wh) ** 2
    else:
        hp_s, hp_s_ds = s, np.ones_like(s)
    m, kp, ki, kd = model.mass, model.pi_kp, model.pi_ki, model.damping_gain
    base = m * s * s + kd * hp_s
    base_ds = 2 * m * s + kd * hp_s_ds
    on_z = base + kp + ki / s
    on_z_ds = base_ds - ki / (s * s)
    return on_z, base, on_z_ds * 1j * k, base_ds * 1j * k


def _relative_coefficients(q, model):
    """Fourier coefficients of z from the unknowns (the mean is z_ref when Ki > 0)."""
    zq = np.array(q, dtype=float)
    if model.pi_ki > 0:
        zq[0] = model.position_setpoint
    return zq


def _residual(q, omega, model, basis, jacobian=True):
    """The balance ``R(q, omega)`` and, if asked, ``dR/dq`` and ``dR/domega``.

    ``R_k = [m s^2 + Kd HP(s) s] (z_k + y_k) + (Kp + Ki/s) z_k - N_k`` for k >= 1
    (``s = i k omega``), ``R_0 = m g - N_0 - Kp (z_ref - z_0) - Ki I_0``, with ``N`` the
    spring and friction forces by AFT; the unknown of slot 0 is ``I_0`` when Ki > 0, else
    ``z_0``. Units: [N].
    """
    zq = _relative_coefficients(q, model)
    z = basis.synthesis @ zq
    dz = basis.synthesis_derivative @ zq
    spring, spring_slope = model.spring(z)
    friction, friction_slope = model.friction(omega * dz)
    nonlinear = basis.analysis @ (spring + friction)
    on_z, on_y, on_z_dw, on_y_dw = _linear_terms(omega, model, basis.harmonics)
    linear = _block(on_z)
    y = np.zeros(2 * basis.harmonics)
    y[0] = model.amplitude
    residual = np.empty(basis.size)
    residual[1:] = linear @ zq[1:] + _block(on_y) @ y - nonlinear[1:]
    mean_motor = model.pi_kp * (model.position_setpoint - zq[0])
    if model.pi_ki > 0:
        mean_motor += model.pi_ki * q[0]
    residual[0] = model.mass * model.gravity - nonlinear[0] - mean_motor
    if not jacobian:
        return residual, None, None
    local = (basis.synthesis * spring_slope[:, None]
             + basis.synthesis_derivative * (omega * friction_slope)[:, None])
    d_q = -basis.analysis @ local
    d_q[1:, 1:] += linear
    if model.pi_ki > 0:
        d_q[:, 0] = 0.0
        d_q[0, 0] = -model.pi_ki
    else:
        d_q[0, 0] += model.pi_kp
    d_omega = -basis.analysis @ (friction_slope * dz)
    d_omega[1:] += _block(on_z_dw) @ zq[1:] + _block(on_y_dw) @ y
    return residual, d_q, d_omega


def _scales(model, omega, size):
    """Scales of the unknowns [m, or m*s for the integral's mean] for norms and arclength."""
    scale = np.full(size, model.amplitude)
    if model.pi_ki > 0:
        force = max(model.mass * model.gravity, model.stiction_force,
                    model.mass * model.amplitude * omega ** 2, 1.0)
        scale[0] = force / model.pi_ki
    return scale


def _newton(q, omega, model, basis, scale):
    """Damped Newton at fixed omega; returns ``(q, converged, iterations, residual norm)``."""
    force = max(model.mass * model.gravity, model.stiction_force,
                model.mass * model.amplitude * omega ** 2, 1e-12)
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


def _default_time_points(harmonics):
    """Phases per period for AFT and Hill: a power of two >= 8 H (aliasing of the
    regularised friction's steep tanh), at least 64."""
    return int(max(64, 2 ** int(np.ceil(np.log2(8 * harmonics)))))


def _check_settings(harmonics, time_points):
    harmonics = integer("harmonics", harmonics, 1)
    if time_points is None:
        time_points = _default_time_points(harmonics)
    time_points = integer("time_points", time_points, 4 * harmonics + 2)
    return harmonics, time_points


# ---------------------------------------------------------------- one solution
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
        measured = xd - w if m.highpass_omega > 0 else xd
        motor = (m.pi_kp * (m.position_setpoint - z) + m.pi_ki * integral
                 - m.damping_gain * measured)
        return {"time": basis.tau / omega, "relative_position": z, "relative_velocity": v,
                "highpass_state": w, "pi_integral": integral, "motor_force": motor,
                "payload_acceleration": synth(s * xd_k)}

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
    k_spring = -model.spring(model.position_setpoint)[1]
    rest_slope = -model.friction(0.0)[1]
    on_z, on_y, _, _ = _linear_terms(omega, model, 1)
    damping = rest_slope
    z1 = 0.0
    for _ in range(30):
        z1_new = -on_y[0] * model.amplitude / (on_z[0] + k_spring + 1j * omega * damping)
        z1 = z1_new if z1 == 0.0 else 0.5 * (z1 + z1_new)
        velocity = omega * abs(z1)
        level = (model.coulomb_force + (model.stiction_force - model.coulomb_force)
                 * np.exp(-model.stribeck_decay * velocity))
        equivalent = 4 * level / (np.pi * velocity) if velocity > 0 else np.inf
        damping = min(equivalent, rest_slope - model.viscous_damping) + model.viscous_damping
    q[1], q[2] = z1.real, -z1.imag
    static = model.mass * model.gravity - model.spring(model.position_setpoint)[0]
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
    frequency = positive("frequency", frequency)
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
    q = np.array(solution.coefficients, dtype=float)
    if solution.model.pi_ki > 0:
        q[0] = solution.integral_mean
    return q


def _solution(q, frequency, model, converged, iterations, norm):
    coefficients = _relative_coefficients(q, model)
    integral = float(q[0]) if model.pi_ki > 0 else 0.0
    return HarmonicBalanceSolution(float(frequency), coefficients, integral, model,
                                   bool(converged), int(iterations), float(norm))


# ---------------------------------------------------------------- Hill's method
def floquet_exponents(solution, *, time_points=None):
    """Floquet exponents of a periodic solution by Hill's method [1/s].

    The linearisation ``dx/dt = J(t) x`` about the solution, with ``x = e^{lambda t} p(t)``
    and ``p`` expanded in the solution's harmonics, gives the eigenproblem of the Hill
    matrix ``[J_{r-c} - i r w delta_rc]``; of its eigenvalues, the ``n`` whose
    eigenvectors weigh most on the central harmonic are the exponents (Lazarus & Thomas
    2010), ``n`` the states of :attr:`SmoothModel.states`.

    Parameters
    ----------
    solution : HarmonicBalanceSolution
        The periodic solution.
    time_points : int, optional
        Phases per period to expand ``J(t)`` [-]; default as for the solution.

    Returns
    -------
    ndarray of complex, shape (n,)
        The exponents [1/s], largest real part first; the Floquet multipliers are
        ``exp(exponent / frequency)``.
    """
    model = solution.model
    harmonics = solution.harmonics
    _, time_points = _check_settings(harmonics, time_points)
    series = solution.time_series(points=time_points)
    omega = 2 * np.pi * solution.frequency
    spring_slope = model.spring(series["relative_position"])[1]
    friction_slope = model.friction(series["relative_velocity"])[1]
    states = model.states
    n = len(states)
    index = {name: i for i, name in enumerate(states)}
    jac = np.zeros((n, n, time_points))
    m = model.mass
    jac[index["z"], index["v"]] = 1.0
    jac[index["v"], index["z"]] = (spring_slope - model.pi_kp) / m
    jac[index["v"], index["v"]] = (friction_slope - model.damping_gain) / m
    if "w" in index:
        jac[index["v"], index["w"]] = model.damping_gain / m
        jac[index["w"], index["v"]] = model.highpass_omega
        jac[index["w"], index["w"]] = -model.highpass_omega
    if "I" in index:
        jac[index["v"], index["I"]] = model.pi_ki / m
        jac[index["I"], index["z"]] = -1.0
    # Hill's matrix in the real Fourier basis (the same eigenvalues as the complex form
    # [J_{r-c} - i r w delta_rc], at a quarter of the cost): the Galerkin projection of
    # multiplying by J(t), minus w d/dtau.
    basis = _basis(harmonics, time_points)
    size = basis.size
    hill = np.zeros((n * size, n * size))
    for i in range(n):
        for j in range(n):
            if np.any(jac[i, j]):
                hill[i * size:(i + 1) * size, j * size:(j + 1) * size] = (
                    basis.analysis @ (jac[i, j][:, None] * basis.synthesis))
        hill[i * size:(i + 1) * size, i * size:(i + 1) * size] -= omega * basis.derivative
    with _single_threaded_blas():
        values, vectors = np.linalg.eig(hill)
    # weight of each eigenvector on the central harmonic of the complex form: a cos + b sin
    # is (a - ib)/2 e^{ik tau} + (a + ib)/2 e^{-ik tau}
    vectors = vectors.reshape(n, size, -1)
    centre = np.sum(np.abs(vectors[:, 0]) ** 2, axis=0)
    cos, sin = vectors[:, 1::2], vectors[:, 2::2]
    total = centre + 0.25 * np.sum(np.abs(cos - 1j * sin) ** 2 + np.abs(cos + 1j * sin) ** 2,
                                   axis=(0, 1))
    weight = centre / total
    # Each exponent appears as a family lambda + i k w; the member in the strip
    # |Im| <= w/2 is its representative. Of the candidates there, the n whose eigenvectors
    # weigh most on the central harmonic (the least affected by truncation) are taken; the
    # weight alone can pick two members of one real family and miss another exponent.
    in_strip = np.abs(values.imag) <= 0.5 * omega * (1 + 1e-9)
    order = np.argsort(-(weight + 2.0 * in_strip))
    chosen = values[order[:n]]
    return chosen[np.argsort(-chosen.real)]


@contextmanager
def _single_threaded_blas():
    """Run the enclosed linear algebra on one BLAS thread, then restore the count.

    Hill matrices are small (a few hundred rows): OpenBLAS's threads only cost there, and
    on a loaded machine they cost a lot (a 153 x 153 eigenproblem: 81 ms with numpy's
    default threads on two busy cores, 8.5 ms on one). numpy's bundled OpenBLAS is reached
    through its own ``set_num_threads`` symbol; elsewhere this does nothing.
    """
    setter, getter = _blas_thread_control()
    if setter is None:
        yield
        return
    previous = getter()
    setter(1)
    try:
        yield
    finally:
        setter(previous)


_BLAS_CONTROL = []


def _blas_thread_control():
    """``(set_num_threads, get_num_threads)`` of numpy's OpenBLAS, or ``(None, None)``."""
    if not _BLAS_CONTROL:
        found = (None, None)
        try:
            import ctypes

            with open("/proc/self/maps", encoding="ascii", errors="replace") as maps:
                paths = sorted({line.split()[-1] for line in maps
                                if "numpy" in line and "openblas" in line.lower()})
            for path in paths:
                library = ctypes.CDLL(path)
                for prefix, suffix in (("scipy_openblas", "64_"), ("openblas", "64_"),
                                       ("openblas", "")):
                    setter = getattr(library, f"{prefix}_set_num_threads{suffix}", None)
                    getter = getattr(library, f"{prefix}_get_num_threads{suffix}", None)
                    if setter is not None and getter is not None:
                        setter.argtypes, getter.restype = [ctypes.c_int], ctypes.c_int
                        found = (setter, getter)
                        break
                if found[0] is not None:
                    break
        except (OSError, AttributeError, IndexError):
            found = (None, None)
        _BLAS_CONTROL.append(found)
    return _BLAS_CONTROL[0]


def _is_stable(exponents, omega):
    return bool(np.max(exponents.real) < STABILITY_MARGIN * omega)


# ---------------------------------------------------------------- continuation
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

    def solution(self, index):
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

    def to_dict(self):
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


def _tangent(d_q, d_omega, scale, omega_scale, previous):
    """Unit tangent of the solution curve in scaled unknowns, oriented like ``previous``."""
    jac = np.hstack([d_q * scale[None, :], (d_omega * omega_scale)[:, None]])
    bordered = np.vstack([jac, previous[None, :]])
    rhs = np.zeros(jac.shape[0] + 1)
    rhs[-1] = 1.0
    tangent = np.linalg.solve(bordered, rhs)
    tangent /= np.linalg.norm(tangent)
    if tangent @ previous < 0:
        tangent = -tangent
    return tangent


def _corrector(u_pred, tangent, model, basis, scale, omega_scale):
    """Newton on the balance plus the arclength condition ``tangent . (u - u_pred) = 0``."""
    u = u_pred.copy()
    force = None
    for iteration in range(1, 16):
        q, omega = u[:-1] * scale, u[-1] * omega_scale
        if omega <= 0:
            return u, False, iteration
        residual, d_q, d_omega = _residual(q, omega, model, basis)
        force = max(model.mass * model.gravity, model.stiction_force,
                    model.mass * model.amplitude * omega ** 2, 1e-12)
        jac = np.vstack([np.hstack([d_q * scale[None, :], (d_omega * omega_scale)[:, None]]),
                         tangent[None, :]])
        rhs = -np.append(residual, tangent @ (u - u_pred))
        try:
            step = np.linalg.solve(jac, rhs)
        except np.linalg.LinAlgError:
            return u, False, iteration
        u = u + step
        if not np.all(np.isfinite(u)):
            return u, False, iteration
        if np.max(np.abs(step)) < NEWTON_TOLERANCE:
            residual = _residual(u[:-1] * scale, u[-1] * omega_scale, model, basis, False)[0]
            return u, bool(np.max(np.abs(residual)) / force < 1e-8), iteration
    return u, False, 16


def frequency_response_curve(model, frequency_range, *, harmonics=DEFAULT_HARMONICS,
                             time_points=None, max_points=2000, step=None):
    """Follow the smooth model's periodic response over a frequency range.

    Newton at the lower end (or at the first of 12 frequencies over the range, geometric,
    where it converges; the curve is then followed down and up from there), then
    pseudo-arclength continuation (Keller 1977) in the scaled unknowns
    ``(coefficients/scale, omega/omega_top)``: a predictor along the tangent, a corrector orthogonal to it, the step grown after easy corrections
    and halved after hard ones. Folds are where the tangent's frequency component changes
    sign; each point's stability is decided by :func:`floquet_exponents`.

    Parameters
    ----------
    model : SmoothModel
        The smooth model.
    frequency_range : (float, float)
        Lowest and highest frequency [Hz].
    harmonics : int
        Harmonics of z kept [-].
    time_points : int, optional
        Phases per period of the AFT [-]; default a power of two of at least ``8*harmonics``.
    max_points : int
        Points at most [-].
    step : float, optional
        First arclength step in scaled units [-]; default 1/200 of the range. Steps
        change by at most 1/150 of the range in frequency and 18 degrees in direction.

    Returns
    -------
    FrequencyResponseCurve
    """
    if not isinstance(model, SmoothModel):
        raise ParameterError(f"`model` must be a SmoothModel, got {type(model).__name__}.")
    try:
        low, high = (float(f) for f in frequency_range)
    except (TypeError, ValueError):
        raise ParameterError(f"`frequency_range` must be two frequencies (low, high) in Hz, "
                             f"got {frequency_range!r}.") from None
    if not (np.isfinite(low) and np.isfinite(high) and 0 < low < high):
        raise ParameterError(f"`frequency_range` must satisfy 0 < low < high (finite, Hz), got "
                             f"{frequency_range!r}.")
    harmonics, time_points = _check_settings(harmonics, time_points)
    max_points = integer("max_points", max_points, 2)
    with _single_threaded_blas():
        return _continue(model, low, high, harmonics, time_points, max_points, step)


def _continue(model, low, high, harmonics, time_points, max_points, step):
    """The body of :func:`frequency_response_curve` (arguments checked)."""
    basis = _basis(harmonics, time_points)
    omega_scale = 2 * np.pi * high
    scale = _scales(model, 2 * np.pi * high, basis.size)
    span = 1.0 - low / high
    ds = span / 200 if step is None else positive("step", step)
    ds_min = span * 1e-7
    frequency_step = span / MAX_POINTS_PER_RANGE  # largest change of omega/omega_top per step
    notes = []

    found = None
    for frequency in np.geomspace(low, high, START_ATTEMPTS):
        omega = 2 * np.pi * frequency
        q, converged, _, norm = _newton(_linear_guess(omega, model, basis), omega, model,
                                        basis, scale)
        if converged:
            found = frequency, q, norm
            break
    if found is None:
        notes.append(f"no periodic solution found at any of {START_ATTEMPTS} frequencies from "
                     f"{low:g} to {high:g} Hz (Newton's residual {norm:.2g}); try more "
                     "harmonics or a larger friction_velocity")
        return _curve([], [], model, harmonics, notes)
    frequency, q, norm = found
    if frequency > low:
        notes.append(f"the continuation started at {frequency:.4g} Hz (Newton failed below) "
                     "and went both ways from there")
    omega = 2 * np.pi * frequency
    u = np.append(q / scale, omega / omega_scale)
    _, d_q, d_omega = _residual(q, omega, model, basis)
    towards = np.zeros(u.size)
    towards[-1] = 1.0
    tangent = _tangent(d_q, d_omega, scale, omega_scale, towards)
    first = _point(u, scale, omega_scale, model, basis, norm)
    follow = dict(model=model, basis=basis, scale=scale, omega_scale=omega_scale, ds=ds,
                  ds_min=ds_min, frequency_step=frequency_step, notes=notes)
    below, below_tangents = [], []
    if frequency > low:
        below, below_tangents = _follow(u, -tangent, lambda w: w > 2 * np.pi * low,
                                        max_points // 2, **follow)
    above, above_tangents = _follow(u, tangent, lambda w: w < 2 * np.pi * high,
                                    max_points - len(below) - 1, **follow)
    # one list in rising arclength: the part below reversed (its tangents too)
    points = below[::-1] + [first] + above
    tangents = [-t for t in below_tangents[::-1]] + [tangent[-1]] + above_tangents
    if len(points) >= max_points:
        notes.append(f"stopped after {max_points} points (`max_points`)")
    return _curve(points, tangents, model, harmonics, notes)


def _follow(u, tangent, inside, max_points, *, model, basis, scale, omega_scale, ds, ds_min,
            frequency_step, notes):
    """Pseudo-arclength steps from ``u`` along ``tangent`` while ``inside(omega)``; returns
    the new points and the frequency components of their tangents."""
    points, tangents = [], []
    while len(points) < max_points and inside(u[-1] * omega_scale):
        u_new, ok, iterations = _corrector(u + ds * tangent, tangent, model, basis, scale,
                                           omega_scale)
        if ok:
            q_new, omega_new = u_new[:-1] * scale, u_new[-1] * omega_scale
            _, d_q, d_omega = _residual(q_new, omega_new, model, basis)
            new_tangent = _tangent(d_q, d_omega, scale, omega_scale, tangent)
            # small turns and frequency steps: no jump to another branch, a smooth drawing
            ok = (new_tangent @ tangent > MIN_TANGENT_COSINE and omega_new > 0
                  and abs(u_new[-1] - u[-1]) <= frequency_step)
        if not ok:
            ds *= 0.5
            if ds < ds_min:
                notes.append(f"continuation stopped at {u[-1] * omega_scale / (2 * np.pi):.4g} "
                             "Hz: the corrector no longer converges (a steep friction "
                             "transition or a branch point); try more harmonics or a larger "
                             "friction_velocity")
                break
            continue
        u, tangent = u_new, new_tangent
        points.append(_point(u, scale, omega_scale, model, basis, 0.0))
        tangents.append(tangent[-1])
        ds *= 1.5 if iterations <= 3 else 1.0 if iterations <= 6 else 0.5
    return points, tangents


def _point(u, scale, omega_scale, model, basis, norm):
    omega = u[-1] * omega_scale
    return _solution(u[:-1] * scale, omega / (2 * np.pi), model, True, 0, norm)


def _curve(points, tangents, model, harmonics, notes):
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
