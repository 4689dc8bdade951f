"""Linear stability of PI plus velocity feedback at the operating point: Routh-Hurwitz.

The payload slipping at the setpoint, Coulomb and Stribeck terms dropped, motor unsaturated,
base at rest (docs/model.md §10)::

    m*s^2 + Cv*s + k + Kp + Ki/s + Kd*s*HP(s) = 0,        HP(s) = s/(s + w_hp),

with ``k`` the spring's tangent stiffness (about 1.6 N/m: near zero). Cleared of fractions,
the characteristic polynomial is::

    no high-pass (w_hp = 0):  m*s^3 + (Cv + Kd)*s^2 + (k + Kp)*s + Ki
    with it:                  m*s^4 + (m*w + Cv + Kd)*s^3 + (Cv*w + k + Kp)*s^2
                              + ((k + Kp)*w + Ki)*s + Ki*w

and Routh-Hurwitz gives, besides positive coefficients, ``a2*a1 > a3*a0`` for the cubic,
i.e. ``Ki < (Cv + Kd)*(k + Kp)/m`` (so on a spring of zero stiffness the proportional gain
must exceed ``m*Ki/(Cv + Kd)``), and for the quartic ``a3*a2 > a4*a1`` and
``a3*a2*a1 > a4*a1^2 + a3^2*a0``. The last is a quadratic in ``a3 = m*w + Cv + Kd``: the
high-pass bounds the damping gain from above as well::

    Kd < a1*(a2 + sqrt(a2^2 - 4*a0*a4))/(2*a0) - m*w - Cv,

because below the corner the high-passed velocity feedback acts as an added mass
``Kd/w_hp`` in phase lead. :func:`routh_hurwitz` checks the closed form against the poles
python-control finds (:func:`closed_loop_poles`).
"""
import math
from dataclasses import dataclass

import numpy as np

from qzs.analysis.control_design.loop_transfers import loop_transfer
from qzs.analysis.linear import (close_loop, continuous_controller_matrices, loop_constants,
                                 plant_matrices)
from qzs.errors import ParameterError
from qzs.model.registry import model_inputs

__all__ = ["characteristic_polynomial", "RouthHurwitz", "routh_hurwitz", "integral_gain_limit",
           "damping_gain_limits", "closed_loop_poles"]


def _coefficients(m, cv, k, kp, ki, kd, w):
    """Characteristic polynomial, highest power first (fractions cleared, no spurious roots)."""
    big_k = k + kp
    if w > 0 and kd > 0:
        if ki > 0:
            return [m, m * w + cv + kd, cv * w + big_k, big_k * w + ki, ki * w]
        return [m, m * w + cv + kd, cv * w + big_k, big_k * w]
    if ki > 0:
        return [m, cv + kd, big_k, ki]
    return [m, cv + kd, big_k]


def _closed_form_controller(controller):
    """Refuse a controller the PI + damping closed forms cannot hold (dither is no feedback)."""
    blocks = [name for name in ("compensation", "linear") if getattr(controller, name) is not None]
    if blocks:
        raise ParameterError(
            f"`controller` has a {' and a '.join(blocks)} block: the closed forms here are PI + "
            "damping's; use closed_loop_poles or loop_stability, which take any controller.",
            ("controller",))


def characteristic_polynomial(isolator=None, controller=None, relative_position=None):
    """Coefficients of the closed loop's characteristic polynomial, highest power first.

    ``m s^2 + Cv s + k + Kp + Ki/s + Kd s HP(s)`` multiplied by ``s`` (when ``Ki > 0``) and by
    ``s + w_hp`` (when the high-pass is on and ``Kd > 0``): degree 2 to 4, no spurious root.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    relative_position : float, optional
        Operating point z [m] (the spring's tangent stiffness there); default the setpoint.

    Returns
    -------
    list of float
        Coefficients in SI units (``kg`` for the highest power).
    """
    isolator, controller = model_inputs(isolator, controller)
    _closed_form_controller(controller)
    return _coefficients(*loop_constants(isolator, controller, relative_position))


def _hurwitz_conditions(a):
    """Routh-Hurwitz conditions of a polynomial of degree 2-4: [(text, value)]; value > 0 holds."""
    n = len(a) - 1
    conditions = [(f"a{n - i} > 0", a[i]) for i in range(len(a))]
    if n == 3:
        a3, a2, a1, a0 = a
        conditions.append(("a2*a1 - a3*a0 > 0", a2 * a1 - a3 * a0))
    elif n == 4:
        a4, a3, a2, a1, a0 = a
        conditions.append(("a3*a2 - a4*a1 > 0", a3 * a2 - a4 * a1))
        conditions.append(("a3*a2*a1 - a4*a1^2 - a3^2*a0 > 0",
                           a3 * a2 * a1 - a4 * a1 ** 2 - a3 ** 2 * a0))
    return conditions


def closed_loop_poles(isolator=None, controller=None, relative_position=None):
    """Poles [rad/s] of the linearised closed loop, by python-control.

    The loop transfer of :func:`loop_transfer` closed with unit negative feedback
    (``control.feedback``): independent of the closed-form polynomial, so that the two
    check each other.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    ndarray of complex
        The closed-loop poles [rad/s] (pole-zero cancellations removed by ``minreal``; of a
        controller with blocks, every mode of the closed loop's state space).
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    if controller.has_blocks:  # every mode of the state space, none cancelled
        closed = close_loop(plant_matrices(isolator, controller, relative_position, base=False),
                            continuous_controller_matrices(isolator, controller))
        return np.asarray(np.linalg.eigvals(closed[0]), dtype=complex)
    loop = loop_transfer(isolator, controller, relative_position)
    closed = control.minreal(control.feedback(loop, 1), verbose=False)
    return np.asarray(closed.poles(), dtype=complex)


@dataclass(frozen=True)
class RouthHurwitz:
    """The linear stability of PI plus velocity feedback at the operating point.

    Attributes
    ----------
    coefficients : tuple of float
        Characteristic polynomial, highest power first (see
        :func:`characteristic_polynomial`).
    conditions : tuple of (str, float, bool)
        Each Routh-Hurwitz condition, its value and whether it holds.
    stable : bool
        Every condition holds.
    poles : ndarray
        Closed-loop poles from python-control [rad/s].
    largest_real_part : float
        Largest real part of the poles [1/s] (negative: stable).
    integral_gain_limit : float
        Largest stable ``Ki`` at this ``Kp`` and ``Kd`` [N/(m*s)].
    damping_gain_limits : tuple of float
        Stable range of ``Kd`` at these PI gains [N*s/m, N*s/m] (``inf`` above: no bound;
        NaN pair: none is stable).
    proportional_gain_minimum : float
        Least stable ``Kp`` at this ``Ki`` and ``Kd`` [N/m] (0 if any is stable).
    agrees : bool
        The closed form and python-control's poles agree on stability.
    """

    coefficients: tuple
    conditions: tuple
    stable: bool
    poles: np.ndarray
    largest_real_part: float
    integral_gain_limit: float
    damping_gain_limits: tuple
    proportional_gain_minimum: float
    agrees: bool

    def to_dict(self):
        """The numbers as a plain ``dict`` (poles as [real, imaginary] pairs)."""
        return {"coefficients": list(self.coefficients),
                "conditions": [{"condition": text, "value": value, "holds": holds}
                               for text, value, holds in self.conditions],
                "stable": self.stable,
                "poles": [[float(p.real), float(p.imag)] for p in self.poles],
                "largest_real_part": self.largest_real_part,
                "integral_gain_limit": self.integral_gain_limit,
                "damping_gain_limits": list(self.damping_gain_limits),
                "proportional_gain_minimum": self.proportional_gain_minimum,
                "agrees": self.agrees}


def _stable(numbers):
    return all(value > 0 for _, value in _hurwitz_conditions(_coefficients(*numbers)))


def integral_gain_limit(isolator=None, controller=None, relative_position=None):
    """Largest integral gain [N/(m*s)] for which the linear loop is stable.

    Without the high-pass, ``(Cv + Kd)*(k + Kp)/m`` (the cubic's Hurwitz condition). With
    it, the smaller of the quartic's two conditions solved for ``Ki`` (``a3*a2 > m*a1`` is
    linear in ``Ki``, ``a3*a2*a1 > m*a1^2 + a3^2*a0`` quadratic: its upper root).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies ``Kp``, ``Kd`` and the high-pass (its ``Ki`` is ignored).
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    float
        The limit [N/(m*s)]; 0 when no positive ``Ki`` is stable.
    """
    isolator, controller = model_inputs(isolator, controller)
    _closed_form_controller(controller)
    m, cv, k, kp, _, kd, w = loop_constants(isolator, controller, relative_position)
    big_k = k + kp
    if not (w > 0 and kd > 0):
        return max(0.0, (cv + kd) * big_k / m)
    a3, a2 = m * w + cv + kd, cv * w + big_k
    linear = a3 * a2 / m - big_k * w
    # a3*a2*(K w + Ki) - m*(K w + Ki)^2 - a3^2*w*Ki > 0, a quadratic in Ki
    qa, qb = -m, a3 * a2 - 2 * m * big_k * w - a3 ** 2 * w
    qc = a3 * a2 * big_k * w - m * (big_k * w) ** 2
    disc = qb * qb - 4 * qa * qc
    if disc < 0:
        return 0.0
    upper = (-qb - math.sqrt(disc)) / (2 * qa)
    return max(0.0, min(linear, upper))


def damping_gain_limits(isolator=None, controller=None, relative_position=None):
    """Stable range of the damping gain [N*s/m, N*s/m] at the controller's PI gains.

    Without the high-pass the cubic's condition ``(Cv + Kd)*(k + Kp) > m*Ki`` bounds ``Kd``
    from below only. With it the quartic's last condition is a quadratic in
    ``a3 = m*w + Cv + Kd`` with roots ``a1*(a2 -+ sqrt(a2^2 - 4*a0*a4))/(2*a0)``; ``a3`` must lie
    between them (and above ``a4*a1/a2``).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies ``Kp``, ``Ki`` and the high-pass (its ``Kd`` is ignored).
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    tuple of float
        ``(low, high)`` [N*s/m]; ``high`` is ``inf`` without an upper bound; ``(nan, nan)``
        when no damping gain is stable.
    """
    isolator, controller = model_inputs(isolator, controller)
    _closed_form_controller(controller)
    m, cv, k, kp, ki, _, w = loop_constants(isolator, controller, relative_position)
    big_k = k + kp
    if not w > 0 or ki == 0:
        if big_k <= 0:
            return (math.nan, math.nan)
        low = m * ki / big_k - cv if ki > 0 else -cv
        return (max(0.0, low), math.inf) if big_k > 0 else (math.nan, math.nan)
    a4, a2, a1, a0 = m, cv * w + big_k, big_k * w + ki, ki * w
    disc = a2 * a2 - 4 * a0 * a4
    if disc < 0 or a2 <= 0:
        return (math.nan, math.nan)
    root = math.sqrt(disc)
    low_a3 = max(a1 * (a2 - root) / (2 * a0), a4 * a1 / a2)
    high_a3 = a1 * (a2 + root) / (2 * a0)
    shift = m * w + cv
    low, high = low_a3 - shift, high_a3 - shift
    if high <= max(low, 0.0):
        return (math.nan, math.nan)
    return (max(0.0, low), high)


def _proportional_minimum(numbers):
    """Least Kp >= 0 for which the loop is stable (bisection on the closed-form conditions)."""
    m, cv, k, _, ki, kd, w = numbers

    def ok(kp):
        return _stable((m, cv, k, kp, ki, kd, w))

    if ok(0.0):
        return 0.0
    high = 1.0
    while not ok(high):
        high *= 2
        if high > 1e12:
            return math.nan
    low = 0.0
    for _ in range(200):
        mid = 0.5 * (low + high)
        low, high = (low, mid) if ok(mid) else (mid, high)
        if high - low <= 1e-12 * high:
            break
    return high


def routh_hurwitz(isolator=None, controller=None, relative_position=None):
    """Routh-Hurwitz stability of the linearised loop, checked against python-control.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    RouthHurwitz
    """
    isolator, controller = model_inputs(isolator, controller)
    _closed_form_controller(controller)
    numbers = loop_constants(isolator, controller, relative_position)
    a = _coefficients(*numbers)
    conditions = tuple((text, float(value), bool(value > 0))
                       for text, value in _hurwitz_conditions(a))
    stable = all(holds for _, _, holds in conditions)
    poles = closed_loop_poles(isolator, controller, relative_position)
    largest = float(np.max(poles.real)) if poles.size else -math.inf
    return RouthHurwitz(
        coefficients=tuple(float(c) for c in a), conditions=conditions, stable=stable,
        poles=poles, largest_real_part=largest,
        integral_gain_limit=integral_gain_limit(isolator, controller, relative_position),
        damping_gain_limits=damping_gain_limits(isolator, controller, relative_position),
        proportional_gain_minimum=_proportional_minimum(numbers),
        agrees=stable == (largest < 0))
