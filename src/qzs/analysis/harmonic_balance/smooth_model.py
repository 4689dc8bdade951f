"""The smooth isolator model of harmonic balance, and the same model as an ODE.

The simulator's model (docs/model.md §2-5) with every non-smooth part made smooth or left
out, so that a periodic response is a zero of a smooth function of its Fourier coefficients
(docs/response.md §5):

* one degree of freedom, relative coordinates ``z = x - y``, ``v = dz/dt``, base
  ``y = A cos(w t)``;
* the spring law as it is: the MagSpring ``-a tanh(b z)`` of ``spring_force`` and
  ``spring_shape``, or the isolator's own law (``spring_law``, docs/model.md §3.1: its
  force and stiffness evaluated on the AFT's time samples; NaN outside a refusing table, so
  Newton backs off and a branch that leaves the table ends with a note);
* friction regularised: ``-[Fc + (Fs - Fc) exp(-Cbc |v|)] tanh(v/v_reg) - Cv v``, the sign
  function replaced by ``tanh(v/v_reg)`` (``friction_velocity`` = ``v_reg`` [m/s]); there
  is no sticking, a held payload creeps at a velocity of the order of ``v_reg``;
* the PI loop and the active damping through the amplifier's high-pass as in docs/model.md
  §5, without saturation and anti-windup; no hard stops; gravity as it is (the integral's
  mean carries what the spring does not).

Pure numpy; :func:`smooth_right_hand_side` is the same model as an ordinary differential
equation, for time-domain checks.
"""
from dataclasses import dataclass

import numpy as np

from qzs._validation import non_negative_real, positive_real
from qzs.errors import ParameterError
from qzs.model.isolator import (friction_force, friction_slope, other_spring_law,
                                spring_force, spring_stiffness)
from qzs.model.springs import SpringLaw, TanhSpring
from qzs.model.controller import refuse_blocks
from qzs.model.registry import model_inputs

__all__ = ["SmoothModel", "smooth_right_hand_side", "FRICTION_VELOCITY"]

#: Default regularisation velocity of the friction's sign function [m/s]. It must be small
#: beside the Stribeck velocity ``1/stribeck_decay`` (10 mm/s by default), or the regularised
#: law never reaches the stiction level: with Table 1 it peaks at 8.1 N of Fs = 10 N at
#: 1 mm/s (6.9 N at 2 mm/s, 9.4 N at 0.2 mm/s, which would need hundreds of harmonics).
FRICTION_VELOCITY = 1e-3


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
        MagSpring plateau force a [N] (unused with a ``spring_law``).
    spring_shape : float
        MagSpring transition coefficient b [1/m] (unused with a ``spring_law``).
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
    spring_law : SpringLaw or None
        The spring law (docs/model.md §3.1): None (default) is the MagSpring's tanh of
        ``spring_force`` and ``spring_shape``; a
        :class:`~qzs.model.springs.TanhSpring` must agree with those two fields and is
        kept as None (the same arithmetic); another law replaces the tanh.
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
    spring_law: SpringLaw | None = None

    def __post_init__(self):
        for name in ("mass", "spring_shape", "friction_velocity", "amplitude"):
            positive_real(name, getattr(self, name))
        for name in ("gravity", "spring_force", "stiction_force", "coulomb_force",
                     "stribeck_decay", "viscous_damping", "pi_kp", "pi_ki", "damping_gain",
                     "velocity_highpass"):
            non_negative_real(name, getattr(self, name))
        law = self.spring_law
        if law is not None and not isinstance(law, SpringLaw):
            raise ParameterError(
                f"`spring_law` must be a spring law (TanhSpring, ObliqueSpringQZS, "
                f"PolynomialSpring, TabulatedSpring) or None for the tanh of `spring_force` "
                f"and `spring_shape`, got {law!r}.", ("spring_law",))
        if isinstance(law, TanhSpring):
            if (law.plateau, law.shape) != (self.spring_force, self.spring_shape):
                raise ParameterError(
                    f"`spring_law` ({law.describe()}) and `spring_force`, `spring_shape` "
                    f"({self.spring_force!r} N, {self.spring_shape!r} 1/m) disagree: give the "
                    "MagSpring's numbers once, in the fields (spring_law=None).",
                    ("spring_law", "spring_force", "spring_shape"))
            object.__setattr__(self, "spring_law", None)

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
        refuse_blocks(controller, "the harmonic balance",
                      "simulate the steady state instead (qzs.simulate of a sine)")
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
                   stop_low=center - isolator.stroke_half, stop_high=center + isolator.stroke_half,
                   spring_law=other_spring_law(isolator))

    @property
    def friction_regularisation(self):
        """The regularisation velocity under the name the model's laws read [m/s].

        The spring and friction laws of :mod:`qzs.model.isolator` take the plant's
        parameters by name; a smooth model carries the same names, and its
        ``friction_velocity`` is their ``friction_regularisation``.
        """
        return self.friction_velocity

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

    def motor_force(self, relative_position, pi_integral, payload_velocity, highpass_state):
        """Unsaturated motor command [N]: PI on the position error, damping on the measured
        payload velocity (through the high-pass when ``velocity_highpass > 0``).

        Parameters
        ----------
        relative_position : float or ndarray
            Relative position z [m].
        pi_integral : float or ndarray
            Integral I of the position error [m*s].
        payload_velocity : float or ndarray
            Payload velocity dx/dt [m/s].
        highpass_state : float or ndarray
            State w of the high-pass [m/s] (unused without it).

        Returns
        -------
        float or ndarray
            ``Kp (z_ref - z) + Ki I - Kd v_measured`` [N], ``v_measured = dx/dt - w``.
        """
        measured = (payload_velocity - highpass_state if self.velocity_highpass > 0
                    else payload_velocity)
        return (self.pi_kp * (self.position_setpoint - relative_position)
                + self.pi_ki * pi_integral - self.damping_gain * measured)

    def spring(self, relative_position):
        """Spring force [N] and its slope dF/dz [N/m] at ``relative_position`` [m]: the
        model's laws, :func:`~qzs.model.isolator.spring_force` and minus
        :func:`~qzs.model.isolator.spring_stiffness` of the tanh, or the ``spring_law``'s
        ``force`` and minus its ``stiffness``.

        Parameters
        ----------
        relative_position : float or ndarray
            Relative position z [m].

        Returns
        -------
        force, slope : ndarray
            ``-a tanh(b z)`` [N] and ``-a b / cosh(b z)^2`` [N/m], or the law's; NaN
            where ``z`` is outside a refusing table (``outside='refuse'``), so that a
            Newton iterate there is rejected instead of raising.
        """
        law = self.spring_law
        if law is None:
            return (spring_force(relative_position, self),
                    -spring_stiffness(relative_position, self))
        z = np.asarray(relative_position, dtype=float)
        low, high = law.domain
        if low == -np.inf and high == np.inf:
            return law.force(z), -law.stiffness(z)
        inside = (z >= low) & (z <= high)  # NaN positions are outside too
        held = np.where(inside, z, low)
        return (np.where(inside, law.force(held), np.nan),
                np.where(inside, -law.stiffness(held), np.nan))

    def friction(self, relative_velocity):
        """Regularised friction force [N] and its slope dF/dv [N*s/m] at ``relative_velocity``:
        the model's laws, :func:`~qzs.model.isolator.friction_force` and
        :func:`~qzs.model.isolator.friction_slope`, with ``friction_velocity`` as v_reg.

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
        return friction_force(relative_velocity, self), friction_slope(relative_velocity, self)


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
    motor = model.motor_force(z, integral, xd, w)
    force = model.spring(z)[0] + friction_force(v, model) + motor - model.mass * model.gravity
    return np.array([v, force / model.mass - ydd, model.highpass_omega * (xd - w),
                     model.position_setpoint - z])
