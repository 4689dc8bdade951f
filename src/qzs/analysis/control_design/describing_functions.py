"""Describing functions of the friction law as a memoryless function of slip velocity.

The friction law as a memoryless nonlinearity of the slip velocity, in the PI loop, has a
real describing function (``4*Fc/(pi*A)`` for Coulomb friction,
:func:`coulomb_describing_function`; the whole law numerically by python-control,
:func:`friction_describing_function`) whose ``-1/N`` lies on the negative real axis, which
a linearly stable loop's Nyquist curve reaches only as ``w -> 0``: it predicts no limit
cycle, ever. It cannot: the stuck phase, in which the integral winds up, has no place in a
velocity law (Olsson 1996; Armstrong-Hélouvry and Amin 1996). :mod:`.hunting` has the
stick-slip element that does predict the cycle.

A friction compensation changes that: the guide's law less the motor's feedforward, the net
law (:class:`NetFrictionNonlinearity`), has a negative describing function where it
over-compensates, and meets the loop at its resonance: a cycle of the payload sliding
through its reversals (:func:`predict_sliding_cycle`, docs/model.md §5; the describing
function by quadrature, :func:`net_describing_function`).

References
----------
H. Olsson, "Describing function analysis of a system with friction", Proc. IEEE CCA 1995.
B. Armstrong-Hélouvry, B. Amin, "PID control in the presence of static friction: a
comparison of algebraic and describing function analysis", Automatica 32(5), 1996.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from qzs.analysis.control_design.loop_transfers import frequency_response as frequency_response_of
from qzs.analysis.linear import close_loop, continuous_controller_matrices, plant_matrices
from qzs.errors import ParameterError
from qzs.model.controller import SENSORS
from qzs.model.registry import model_inputs

__all__ = ["coulomb_describing_function", "FrictionNonlinearity", "NetFrictionNonlinearity",
           "friction_describing_function", "net_describing_function", "friction_velocity_loop",
           "SlidingCycle", "predict_sliding_cycle", "SLIDING_AMPLITUDES",
           "SLIDING_FREQUENCIES"]


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


class NetFrictionNonlinearity(FrictionNonlinearity):
    """The guide's friction net of the motor's compensation, as a function of slip velocity.

    ``n(v) = f(v) - fraction*[f'(v) + Cv' v]*[|v| > deadband] + fraction*Cv'*v`` [N]: the
    plant's Coulomb and Stribeck terms ``f`` (:class:`FrictionNonlinearity`) less the
    compensator's feedforward (its own law ``f'``, ``Cv'``, outside its deadband), with the
    feedforward's viscous slope ``fraction*Cv'`` added back: that slope is linear and
    belongs to the loop (:func:`qzs.analysis.linear.controller_system`), as the plant's
    ``Cv`` does. The friction force on the payload is ``-n(v)``: over-compensation
    (``fraction*f' > f``) makes it push along the slip, a negative damping (docs/model.md §5).

    Parameters
    ----------
    stiction_force, coulomb_force : float
        The plant's Fs, Fc [N].
    stribeck_decay : float
        The plant's Cbc [s/m].
    fraction : float
        Fraction compensated [-].
    law : tuple of float
        The compensator's ``(Fs' [N], Fc' [N], Cbc' [s/m], Cv' [N*s/m])``.
    deadband : float
        The compensator's velocity deadband [m/s].
    """

    def __init__(self, stiction_force, coulomb_force, stribeck_decay, fraction, law,
                 deadband=0.0):
        super().__init__(stiction_force, coulomb_force, stribeck_decay)
        self.fraction = float(fraction)
        self.compensator = FrictionNonlinearity(*law[:3])
        self.compensator_viscous = float(law[3])
        self.deadband = float(deadband)

    @classmethod
    def of(cls, isolator, compensation):
        """The net law of a plant and a :class:`~qzs.model.controller.FrictionCompensation`.

        Parameters
        ----------
        isolator : IsolatorParameters
            The plant.
        compensation : FrictionCompensation or None
            The compensation (None: the plant's law alone, fraction 0).

        Returns
        -------
        NetFrictionNonlinearity
        """
        if compensation is None:
            return cls(isolator.stiction_force, isolator.coulomb_force,
                       isolator.stribeck_decay, 0.0, (0.0, 0.0, 0.0, 0.0))
        return cls(isolator.stiction_force, isolator.coulomb_force, isolator.stribeck_decay,
                   compensation.fraction, compensation.law(isolator), compensation.deadband)

    def __call__(self, velocity):
        v = float(np.squeeze(velocity))
        slope = self.fraction * self.compensator_viscous
        net = super().__call__(v) + slope * v
        if abs(v) > self.deadband and v != 0.0:
            net -= self.fraction * (self.compensator(v) + self.compensator_viscous * v)
        return net


def friction_describing_function(isolator=None, amplitude=None, *, points=4096,
                                 controller=None):
    """Describing function [N*s/m] of the friction law in slip velocity (python-control).

    With a controller that compensates friction, of the net law
    (:class:`NetFrictionNonlinearity`): negative where the compensation over-compensates.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Supplies ``stiction_force``, ``coulomb_force`` and ``stribeck_decay``.
    amplitude : float or array_like
        Slip-velocity amplitudes [m/s], > 0.
    points : int
        Samples per period of python-control's numerical integration [-].
    controller : ControllerParameters, optional
        Its ``compensation`` block, if any, is netted out of the law.

    Returns
    -------
    ndarray of complex
        ``N(A)`` [N*s/m] (real up to round-off: a memoryless odd function).
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    if amplitude is None:
        raise ParameterError("`amplitude` is required: the slip-velocity amplitudes in m/s.",
                             ("amplitude",))
    if controller.compensation is None:
        law = FrictionNonlinearity(isolator.stiction_force, isolator.coulomb_force,
                                   isolator.stribeck_decay)
    else:
        law = NetFrictionNonlinearity.of(isolator, controller.compensation)
    return np.asarray(control.describing_function(law, np.atleast_1d(amplitude),
                                                  num_points=int(points)))


#: Amplitudes [m/s] the net law's describing function is solved on: ``logspace(*...)``.
SLIDING_AMPLITUDES = (-7.0, 2.0, 361)
#: Frequencies [rad/s] where the loop's phase crossings are looked for: ``logspace(*...)``.
SLIDING_FREQUENCIES = (-3.0, 5.0, 4001)


def net_describing_function(law, amplitude):
    """Describing function [N*s/m] of an odd memoryless law of slip velocity, by quadrature.

    ``N(A) = 4/(pi A) int_0^{pi/2} n(A sin t) sin t dt`` (scipy's ``quad``, the deadband's
    and the Stribeck decay's scales as break points): real, exact to about 1e-10 where
    python-control's sampled integral (:func:`friction_describing_function`) is good to
    about its sample spacing.

    Parameters
    ----------
    law : FrictionNonlinearity or NetFrictionNonlinearity
        The law ``n(v)`` [N].
    amplitude : float or array_like
        Slip-velocity amplitudes [m/s], > 0.

    Returns
    -------
    ndarray
        ``N(A)`` [N*s/m], of the shape of ``amplitude``.
    """
    from scipy.integrate import quad

    amplitudes = np.asarray(amplitude, dtype=float)
    if np.any(~np.isfinite(amplitudes)) or np.any(amplitudes <= 0):
        raise ParameterError(f"`amplitude` must be positive slip-velocity amplitudes in m/s, "
                             f"got {amplitude!r}.", ("amplitude",))
    scales = [1.0 / law.stribeck_decay] if law.stribeck_decay > 0 else []
    if isinstance(law, NetFrictionNonlinearity):
        scales += [law.deadband] if law.deadband > 0 else []
        scales += ([1.0 / law.compensator.stribeck_decay]
                   if law.compensator.stribeck_decay > 0 else [])
    out = np.empty(amplitudes.shape)
    for index, a in np.ndenumerate(amplitudes):
        breaks = sorted({math.asin(v / a) for v in scales if 0 < v < a})
        value = quad(lambda t: law(a * math.sin(t)) * math.sin(t), 0.0, math.pi / 2,
                     points=breaks or None, limit=200, epsabs=0.0, epsrel=1e-11)[0]
        out[index] = 4.0 * value / (math.pi * a)
    return out


@dataclass(frozen=True)
class SlidingCycle:
    """A limit cycle of the payload sliding through its reversals, by describing function.

    The net friction law (:class:`NetFrictionNonlinearity`) against the linear loop that
    carries its force to the slip velocity (docs/model.md §5); over-compensation makes
    the law's describing function negative, and where ``-1/N(A)`` meets the loop's Nyquist
    curve the payload oscillates about the setpoint without sticking.

    Attributes
    ----------
    hunts : bool
        A stable cycle is predicted (and the loop is linearly stable).
    velocity_amplitude : float
        First harmonic of the slip velocity in that cycle [m/s] (NaN if none).
    frequency : float
        Its frequency [Hz] (NaN if none).
    period : float
        ``1/frequency`` [s] (NaN if none).
    amplitude : float
        First harmonic of the relative position, ``velocity_amplitude/(2 pi frequency)`` [m].
    breakaway_ratio : float
        ``m A w / Fs`` [-]: the first harmonic's inertia force at a reversal over the
        breakaway force; the payload slides through its reversals (the law without stiction
        applies) when it is well above 1 (``in_regime``).
    in_regime : bool
        ``breakaway_ratio > 1``.
    distortion : float
        ``|G(3jw)|/(3 |G(jw)|)`` [-]: the third harmonic a relay-like law leaves in the slip
        velocity, relative to the first; the describing function's error is of its order.
    intersections : tuple of (float, float, bool)
        Every intersection: velocity amplitude [m/s], frequency [Hz], stable.
    linear_stable : bool
        The loop without the friction's nonlinear part is stable.
    reasons : dict
        Name -> why a number is undefined, or what the analysis leaves out.
    """

    hunts: bool
    velocity_amplitude: float
    frequency: float
    period: float
    amplitude: float
    breakaway_ratio: float
    in_regime: bool
    distortion: float
    intersections: tuple
    linear_stable: bool
    reasons: dict = field(default_factory=dict)

    def to_dict(self):
        """The prediction as a plain ``dict``."""
        out = dict(self.__dict__)
        out["intersections"] = [list(p) for p in self.intersections]
        return out


def friction_velocity_loop(isolator=None, controller=None, relative_position=None):
    """The linear loop a friction force sees: slip velocity per force on the payload [m/(N*s)].

    The plant and the whole controller's linear part closed (:func:`qzs.analysis.linear.
    controller_system`, frictionless-guide limit, base at rest), from a force on the payload
    to the relative velocity; with a friction observer of bandwidth ``w_o`` times its
    high-pass ``s/(s + w_o)`` (the observer cancels the slow part of whatever friction it
    measures). A sampled PI + damping enters as its continuous counterpart.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        The controller; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    control.StateSpace
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    a, b, c, d = close_loop(plant_matrices(isolator, controller, relative_position, base=False),
                            continuous_controller_matrices(isolator, controller))
    row = list(SENSORS).index("relative_velocity")
    loop = control.ss(a, b, c[row:row + 1], d[row:row + 1])
    compensation = controller.compensation
    if compensation is not None and compensation.observer_bandwidth > 0:
        corner = 2 * np.pi * compensation.observer_bandwidth
        loop = loop * control.ss(control.tf([1.0, 0.0], [1.0, corner]))
    return loop


def _winding(response, point):
    """How often the closed Nyquist curve ``G(jw)``, ``w`` over the real line, winds about a point.

    ``response`` on increasing ``w > 0``; the curve for ``w < 0`` is its mirror image, and it
    closes through ``G(0)`` and ``G(j inf)`` (0 for the loops here).
    """
    curve = np.concatenate([np.conj(response[::-1]), response, np.conj(response[-1:])])
    angle = np.unwrap(np.angle(curve - point))
    return int(round((angle[-1] - angle[0]) / (2 * np.pi)))


def predict_sliding_cycle(isolator=None, controller=None, relative_position=None):
    """The sliding limit cycle of over-compensated friction, by describing function.

    The net friction law ``n(v)`` (:class:`NetFrictionNonlinearity`, its describing function
    ``N(A)`` real: :func:`net_describing_function`) in negative feedback with the loop
    ``G(s)`` of :func:`friction_velocity_loop`: a cycle where ``1 + N(A) G(jw) = 0``, i.e.
    at a frequency where ``G(jw)`` is real, ``g``, with ``N(A) = -1/g``. The loop's velocity
    response is real and positive at its resonance, ``1/c`` with ``c`` its net damping, so
    a positive ``N`` (friction that opposes the slip) never meets it, and a negative one
    (over-compensation, ``fraction*f' > f``) does, where ``-N(A) = c``. Stable (Loeb) when
    ``-1/N`` leaves the region the Nyquist curve encircles as ``A`` grows. The law has no
    stuck state: the cycle holds while the payload slides through its reversals
    (``breakaway_ratio > 1``; below, it sticks there and the stick-slip relay of
    :func:`~qzs.analysis.control_design.hunting.predict_hunting` takes over).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        The controller (its compensation, if any, is netted out of the friction law);
        defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    SlidingCycle
    """
    from scipy.optimize import brentq

    isolator, controller = model_inputs(isolator, controller)
    loop = friction_velocity_loop(isolator, controller, relative_position)
    law = NetFrictionNonlinearity.of(isolator, controller.compensation)
    reasons = {}
    if controller.controller_rate > 0:
        reasons["sampled"] = (f"the controller is sampled at {controller.controller_rate:g} Hz: "
                              "analysed as continuous (good well below its Nyquist frequency)")
    if controller.dither is not None:
        reasons["dither"] = "the dither is left out (it is no feedback)"
    a = np.asarray(loop.A, dtype=float)
    linear_stable = bool(np.all(np.linalg.eigvals(a).real < 0)) if a.size else True
    omega = np.logspace(*SLIDING_FREQUENCIES[:2], int(SLIDING_FREQUENCIES[2]))
    response = frequency_response_of(loop, omega)
    found = []
    if not linear_stable:
        reasons["hunts"] = ("the loop is linearly unstable without the friction's nonlinear "
                            "part: no cycle bounded by friction; the motion grows to the "
                            "motor's saturation or the stops (loop_stability)")
    elif law.stiction_force <= 0 and law.fraction * max(law.compensator.stiction_force,
                                                        law.compensator.coulomb_force) <= 0:
        reasons["hunts"] = "no Coulomb or Stribeck friction, nor any compensated: no cycle"
    else:
        amplitudes = np.logspace(*SLIDING_AMPLITUDES[:2], int(SLIDING_AMPLITUDES[2]))
        values = net_describing_function(law, amplitudes)
        imag = response.imag
        for i in np.flatnonzero(np.sign(imag[:-1]) * np.sign(imag[1:]) < 0):
            w = brentq(lambda x: frequency_response_of(loop, np.array([x]))[0].imag,
                       omega[i], omega[i + 1], xtol=1e-14, rtol=1e-13)
            g = frequency_response_of(loop, np.array([w]))[0].real
            target = -1.0 / g
            gap = values - target
            for j in np.flatnonzero(np.sign(gap[:-1]) * np.sign(gap[1:]) < 0):
                amp = brentq(lambda x: net_describing_function(law, x) - target,
                             amplitudes[j], amplitudes[j + 1], xtol=1e-15, rtol=1e-12)
                stable = _loeb_stable(law, response, amp)
                found.append((float(amp), float(w / (2 * np.pi)), stable))
        if not found:
            reasons["hunts"] = ("-1/N of the net friction law does not meet the loop's "
                                "Nyquist curve: no sliding cycle")
    stable_cycles = [c for c in found if c[2]]
    nan = math.nan
    if stable_cycles:
        amp, f, _ = max(stable_cycles)
        w = 2 * np.pi * f
        ratio = (isolator.mass * amp * w / law.stiction_force if law.stiction_force > 0
                 else math.inf)
        third = abs(frequency_response_of(loop, np.array([3 * w]))[0])
        distortion = third / (3 * abs(frequency_response_of(loop, np.array([w]))[0]))
        if ratio <= 1:
            reasons["in_regime"] = (f"m A w = {ratio * law.stiction_force:.3g} N does not "
                                    f"exceed the breakaway force {law.stiction_force:.3g} N: "
                                    "the payload sticks at the reversals (stick-slip, "
                                    "predict_hunting), the sliding law is a rough model")
        return SlidingCycle(hunts=True, velocity_amplitude=amp, frequency=f, period=1 / f,
                            amplitude=amp / w, breakaway_ratio=ratio, in_regime=ratio > 1,
                            distortion=float(distortion), intersections=tuple(found),
                            linear_stable=linear_stable, reasons=reasons)
    if found:
        reasons["hunts"] = "every intersection is an unstable cycle (Loeb): none persists"
    for name in ("velocity_amplitude", "frequency", "period", "amplitude", "breakaway_ratio",
                 "distortion"):
        reasons[name] = reasons["hunts"]
    return SlidingCycle(hunts=False, velocity_amplitude=nan, frequency=nan, period=nan,
                        amplitude=nan, breakaway_ratio=nan, in_regime=False, distortion=nan,
                        intersections=tuple(found), linear_stable=linear_stable,
                        reasons=reasons)


def _loeb_stable(law, response, amplitude, step=0.02):
    """A cycle at ``amplitude`` is stable: ``-1/N`` encircled just below it, not just above."""
    below, above = net_describing_function(law, amplitude * np.array([1 - step, 1 + step]))
    return (_winding(response, -1.0 / below) != 0) and (_winding(response, -1.0 / above) == 0)
