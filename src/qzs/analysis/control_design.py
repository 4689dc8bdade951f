"""Controller design at the operating point: static balance, stability, margins, hunting.

Pure analysis (python-control, numpy, scipy; no simulation): the numbers behind
``qzs design`` (docs/design.md), each in closed form where one exists, checked against
python-control.

**Static design** (:func:`static_design`): what the MagSpring carries at the setpoint, the
static deficit ``m*g - F_spring(z_ref)`` the PI integral must supply, the motor force left
for control, and the payloads spring and motor can hold.

**Linear stability** (:func:`routh_hurwitz`): the payload slipping at the setpoint, Coulomb
and Stribeck terms dropped, motor unsaturated, base at rest (docs/model.md §10)::

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
``Kd/w_hp`` in phase lead.

**Sampled loop** (:func:`loop_margins`, :func:`required_controller_rate`): the loop broken at
the motor force, ``L = (Kp + Ki/s)*P_z + Kd*P_v`` with ``P_z = 1/(m s^2 + Cv s + k)`` and
``P_v = s*HP(s)*P_z``; sampled as the simulator samples (docs/model.md §5: forward-Euler
integral, zero-order hold, analog high-pass), with an exact discrete input delay (integer
and fractional part of the period, Åström and Wittenmark's modified z-transform);
margins by :func:`control.stability_margins`. A continuous loop with a delay uses a Padé
approximant.

**Hunting** (:func:`predict_hunting`): two describing-function analyses (python-control's
:func:`control.describing_function_response`). The friction law as a memoryless
nonlinearity of the slip velocity, in the PI loop, has a real describing function
(``4*Fc/(pi*A)`` for Coulomb friction) whose ``-1/N`` lies on the negative real axis, which a
linearly stable loop's Nyquist curve reaches only as ``w -> 0``: it predicts no limit cycle,
ever. It cannot: the stuck phase, in which the integral winds up, has no place in a
velocity law (Olsson 1996; Armstrong-Hélouvry and Amin 1996). Combining the payload with
its friction (Olsson's remedy) gives a stick-slip element in the *integral* loop: the payload
stays stuck while the integral force ``u`` is within ``Fs`` of ``K*zeta`` (``K = k + Kp``,
``zeta = z - z_ref``); when it breaks away it slides, and stops (inertia carries it past the
least force that keeps it sliding, the quasi-static re-stick level
``F_r = min_v [Fc + (Fs - Fc)*exp(-Cbc*v) + Cv*v]``) with its stuck position moved by a jump
``J`` in force units, integrated from rest over the one slip (:func:`slip_jump`). While one
slip happens per half cycle this element is a relay with hysteresis in force units: output
``K*zeta = +-d``, ``d = J/2``, switching at ``u = +-h``, ``h = Fs - d``. The linear part from
its output back to its input is ``G(s) = Ki/(s*(m s^2 + Cv s + K + Kd s HP(s)))``. Its
describing function (python-control's ``relay_hysteresis_nonlinearity``) meets ``G`` at one
amplitude and frequency: a hunting cycle, square in position with plateaus ``+-d/K`` [m],
whose exact period with instant slips is ``4*h*K/(Ki*d)``. No slip jump (the Stribeck dip
does not beat the damping: the payload creeps) or no integral: no hunting.

References
----------
H. Olsson, K. J. Åström, "Friction generated limit cycles", IEEE Trans. Control Syst.
Technol. 9(4), 2001; H. Olsson, "Describing function analysis of a system with friction",
Proc. IEEE CCA 1995. B. Armstrong-Hélouvry, B. Amin, "PID control in the presence of
static friction: a comparison of algebraic and describing function analysis",
Automatica 32(5), 1996. K. J. Åström, B. Wittenmark, *Computer-Controlled Systems*,
3rd ed., §2.3 (sampling a system with a time delay).
"""
import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from qzs.analysis.linear import loop_constants
from qzs.errors import ParameterError
from qzs.model.isolator import spring_force
from qzs.model.registry import model_inputs

__all__ = ["StaticDesign", "static_design", "characteristic_polynomial", "RouthHurwitz",
           "routh_hurwitz", "integral_gain_limit", "damping_gain_limits",
           "closed_loop_poles", "constant_force_band", "integral_loop", "loop_transfer", "sampled_loop", "discretize_with_delay",
           "LoopMargins", "loop_margins", "stability_margins_of", "frequency_response", "required_controller_rate",
           "sampled_transmissibility", "coulomb_describing_function",
           "FrictionNonlinearity", "friction_describing_function", "restick_force", "slip_jump",
           "HuntingPrediction", "predict_hunting", "hunting_stiffness",
           "PAPER_ADDED_MASS"]

#: Mass the paper added on top of the moving parts to balance the MagSpring [kg] (Section 4).
PAPER_ADDED_MASS = 5.5
#: Default margins a sampled design must keep: gain margin [dB] and phase margin [deg].
GAIN_MARGIN_MIN = 6.0
PHASE_MARGIN_MIN = 30.0
#: A slip jump below this share of the stiction force is the start kick's creep, not a slip [-].
SLIP_JUMP_FLOOR = 1e-4
#: Order of the Padé approximant of a delay in a continuous loop [-].
PADE_ORDER = 6


def _number(name, value, *, minimum=0.0, strict=False, fix=""):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"`{name}` must be a number, got {value!r}{fix}.")
    value = float(value)
    if not math.isfinite(value) or value < minimum or (strict and value == minimum):
        bound = f"> {minimum:g}" if strict else f">= {minimum:g}"
        raise ParameterError(f"`{name}` must be a finite number {bound}, got {value!r}{fix}.")
    return value


def _range(name, values, unit, *, minimum=0.0):
    try:
        low, high = (float(v) for v in values)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be two numbers (low, high) in {unit}, got "
                             f"{values!r}.") from None
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise ParameterError(f"`{name}` must satisfy {minimum:g} <= low <= high (finite, {unit}), "
                             f"got {values!r}; give e.g. ({max(minimum, 1.0):g}, 2) {unit}.")
    return low, high


# ---------------------------------------------------------------- static design
@dataclass(frozen=True)
class StaticDesign:
    """What the MagSpring carries at the operating point, and what is left for control.

    Attributes
    ----------
    position_setpoint : float
        Operating point z_ref [m].
    spring_force_at_setpoint : float
        Upward force of the MagSpring at the setpoint, ``F_spring(z_ref) = -a*tanh(b*z_ref)`` [N].
    weight : float
        Weight ``m*g`` of the moving mass [N].
    static_deficit : float
        ``m*g - spring force`` [N]: what the PI integral must supply at rest (negative: the
        spring pushes up more than the weight, the motor must hold it down).
    motor_force_max : float
        Motor saturation [N].
    motor_force_left : float
        ``F_max - |static deficit|`` [N]: force left for the loops; negative: the motor
        cannot hold the payload at the setpoint at all.
    balanced_mass : float
        Mass the spring alone carries at the setpoint, ``spring force/g`` [kg] (NaN
        without gravity).
    holdable_mass : tuple of float
        Masses spring and saturated motor can hold at the setpoint [kg, kg]:
        ``(spring force - F_max)/g`` to ``(spring force + F_max)/g``.
    constant_force_band : tuple of float
        Relative positions [m, m] around the setpoint inside the constant-force region
        (spring force within 1 % of its plateau): the edge ``-atanh(0.99)/b`` above the
        setpoint, mirrored below it.
    spring_force_band : tuple of float
        Least and largest spring force over that band [N, N].
    mass_range : tuple of float
        The payload masses considered [kg, kg] (the design's range; the mass itself if none).
    deficit_range : tuple of float
        Static deficit at the lightest and heaviest of them [N, N].
    motor_force_left_min : float
        Least force left for control over the mass range [N].
    moving_mass_without_added : float
        The moving mass less the paper's added 5.5 kg [kg] (its rig without the payload).
    deficit_without_added : float
        Static deficit of that lighter moving mass [N]: beyond ``-F_max`` the motor could not
        hold the spring down, which is why the paper added the payload.
    reasons : dict
        Name -> why a number is NaN.
    """

    position_setpoint: float
    spring_force_at_setpoint: float
    weight: float
    static_deficit: float
    motor_force_max: float
    motor_force_left: float
    balanced_mass: float
    holdable_mass: tuple
    constant_force_band: tuple
    spring_force_band: tuple
    mass_range: tuple
    deficit_range: tuple
    motor_force_left_min: float
    moving_mass_without_added: float
    deficit_without_added: float
    reasons: dict = field(default_factory=dict)

    def to_dict(self):
        """The numbers as a plain ``dict`` (tuples as lists)."""
        return {name: (list(value) if isinstance(value, tuple) else value)
                for name, value in self.__dict__.items()}


def constant_force_band(isolator=None, controller=None):
    """Relative positions [m, m] of the constant-force band around the setpoint.

    Above the setpoint the band ends at the spring's constant-force edge
    (:attr:`IsolatorParameters.constant_force_edge`, the spring within 1 % of its
    plateau); below it the band is mirrored (the paper: a region of about 60 mm with the
    setpoint in its middle; the ``tanh`` fit itself stays flat below).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies the setpoint; defaults if omitted.

    Returns
    -------
    tuple of float
        ``(low, high)`` [m]; ``high`` is the edge, ``low = 2*z_ref - edge``.

    Raises
    ------
    ParameterError
        The setpoint lies above the edge, outside the constant-force region.
    """
    isolator, controller = model_inputs(isolator, controller)
    edge = isolator.constant_force_edge
    setpoint = controller.position_setpoint
    if setpoint >= edge:
        raise ParameterError(
            f"the `position_setpoint` ({setpoint:g} m) lies at or above the spring's "
            f"constant-force edge ({edge:.4g} m): the design needs the setpoint inside the "
            "constant-force region; lower it (e.g. -0.060 m).")
    return (2 * setpoint - edge, edge)


def static_design(isolator=None, controller=None, *, mass_range=None):
    """The static design at the setpoint: spring load, deficit and the force left for control.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies the setpoint; defaults if omitted.
    mass_range : tuple of float, optional
        Payload masses to consider [kg, kg]; default the isolator's mass alone.

    Returns
    -------
    StaticDesign
    """
    isolator, controller = model_inputs(isolator, controller)
    z_ref = controller.position_setpoint
    lifted = float(spring_force(z_ref, isolator))
    g = isolator.gravity
    weight = isolator.mass * g
    deficit = weight - lifted
    f_max = isolator.motor_force_max
    reasons = {}
    if g > 0:
        balanced = lifted / g
        holdable = (max(0.0, (lifted - f_max) / g), (lifted + f_max) / g)
    else:
        balanced, holdable = math.nan, (math.nan, math.nan)
        reason = "no gravity: the payload's weight does not load the spring"
        reasons.update(balanced_mass=reason, holdable_mass=reason)
    band = constant_force_band(isolator, controller)
    forces = spring_force(np.linspace(band[0], band[1], 201), isolator)
    masses = (isolator.mass, isolator.mass) if mass_range is None else _range(
        "mass_range", mass_range, "kg", minimum=1e-12)
    deficits = (masses[0] * g - lifted, masses[1] * g - lifted)
    left_min = f_max - max(abs(d) for d in deficits)
    bare = isolator.mass - PAPER_ADDED_MASS
    if bare > 0:
        bare_deficit = bare * g - lifted
    else:
        bare_deficit = math.nan
        reasons["deficit_without_added"] = (f"the moving mass ({isolator.mass:g} kg) is not "
                                            f"above the paper's added {PAPER_ADDED_MASS:g} kg")
    return StaticDesign(
        position_setpoint=z_ref, spring_force_at_setpoint=lifted, weight=weight,
        static_deficit=deficit, motor_force_max=f_max, motor_force_left=f_max - abs(deficit),
        balanced_mass=balanced, holdable_mass=holdable, constant_force_band=band,
        spring_force_band=(float(forces.min()), float(forces.max())), mass_range=masses,
        deficit_range=deficits, motor_force_left_min=left_min,
        moving_mass_without_added=bare if bare > 0 else math.nan,
        deficit_without_added=bare_deficit, reasons=reasons)


# ---------------------------------------------------------------- linear stability
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
        The closed-loop poles [rad/s] (pole-zero cancellations removed by ``minreal``).
    """
    import control

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


# ---------------------------------------------------------------- loops and margins
def _plant_state_space(m, cv, k, w):
    """Force -> (z, measured velocity) with the base at rest: states z, v, high-pass w."""
    if w > 0:
        a = np.array([[0.0, 1.0, 0.0], [-k / m, -cv / m, 0.0], [0.0, w, -w]])
        b = np.array([[0.0], [1.0 / m], [0.0]])
        c = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -1.0]])
    else:
        a = np.array([[0.0, 1.0], [-k / m, -cv / m]])
        b = np.array([[0.0], [1.0 / m]])
        c = np.array([[1.0, 0.0], [0.0, 1.0]])
    return a, b, c


def loop_transfer(isolator=None, controller=None, relative_position=None, *, delay=0.0):
    """The continuous loop transfer ``L(s)`` broken at the motor force (python-control).

    ``L = (Kp + Ki/s)*P_z + Kd*P_v`` with ``P_z = 1/(m s^2 + Cv s + k)`` (force to relative
    position, base at rest) and ``P_v = s*HP(s)*P_z`` (force to the measured velocity); the
    loop closes as ``u = -L u``. A delay enters as a Padé approximant of order
    :data:`PADE_ORDER`.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.
    delay : float
        Delay between the measurements and the motor force [s].

    Returns
    -------
    control.TransferFunction
        ``L(s)`` [-] (force per force).
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    delay = _number("delay", delay)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    s = control.tf("s")
    plant = 1 / (m * s ** 2 + cv * s + k)
    highpass = s / (s + w) if w > 0 else 1
    pi = kp + (ki / s if ki > 0 else 0)
    loop = pi * plant + kd * s * highpass * plant
    if delay > 0:
        num, den = control.pade(delay, PADE_ORDER)
        loop = loop * control.tf(num, den)
    return control.minreal(control.tf(loop), verbose=False)


def _delayed_hold(a, b, period, delay):
    """``Phi, G0, G1``, whole periods and fraction [s] of a zero-order hold delayed by ``delay``."""
    from scipy.linalg import expm

    n_states = a.shape[0]
    whole = int(math.floor(delay / period + 1e-9))
    fraction = delay - whole * period
    if fraction < 1e-12 * period:
        fraction = 0.0

    def held(t):  # int_0^t exp(A s) ds B
        block = np.zeros((n_states + 1, n_states + 1))
        block[:n_states, :n_states] = a
        block[:n_states, n_states:] = b
        return expm(block * t)[:n_states, n_states:]

    phi = expm(a * period)
    g0 = held(period - fraction)
    g1 = expm(a * (period - fraction)) @ held(fraction) if fraction > 0 else np.zeros_like(g0)
    return phi, g0, g1, whole, fraction


def _sampled_response(isolator, controller, rate, delay, omega, relative_position=None):
    """``L(exp(j w T))`` of :func:`sampled_loop` on a grid, without its delay-line states.

    ``P(z) = C (zI - Phi)^-1 (G0 + G1/z) z^-n`` and the controller's row
    ``[Kp + Ki T/(z - 1), Kd]``: the same loop, evaluated with the plant's own 2-3 states.
    """
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    a, b, c = _plant_state_space(m, cv, k, w)
    period = 1.0 / rate
    phi, g0, g1, whole, _ = _delayed_hold(a, b, period, delay)
    z = np.exp(1j * np.asarray(omega, dtype=float) * period)
    n = a.shape[0]
    shifted = z[:, None, None] * np.eye(n)[None] - phi[None]
    held = g0[None] + g1[None] / z[:, None, None]
    plant = c[None] @ np.linalg.solve(shifted, held)  # (N, 2, 1)
    plant = plant[:, :, 0] * (z ** -whole)[:, None]
    pi = kp + (ki * period / (z - 1) if ki > 0 else 0)
    return pi * plant[:, 0] + kd * plant[:, 1]


def discretize_with_delay(a, b, c, period, delay=0.0):
    """Exact zero-order-hold discretisation with an input delay (modified z-transform).

    A delay ``tau = n*T + e*T`` (``0 <= e < 1``) holds each input for ``T`` starting ``tau``
    after its sample: ``x[k+1] = Phi*x[k] + G0*u[k-n] + G1*u[k-n-1]`` with
    ``G0 = int_0^{T-eT} exp(A s) ds B`` and ``G1 = exp(A (T-eT)) int_0^{eT} exp(A s) ds B``
    (Åström and Wittenmark §2.3); past inputs become states.

    Parameters
    ----------
    a, b, c : array_like
        Continuous state-space matrices (no feed-through), shapes (n, n), (n, 1), (p, n).
    period : float
        Sampling period T [s].
    delay : float
        Input delay [s].

    Returns
    -------
    control.StateSpace
        The discrete system, ``dt = period``.
    """
    import control

    a, b, c = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (a, b, c))
    period = _number("period", period, strict=True)
    delay = _number("delay", delay)
    n_states = a.shape[0]
    phi, g0, g1, whole, fraction = _delayed_hold(a, b, period, delay)
    line = whole + (1 if fraction > 0 else 0)  # past inputs kept as states
    size = n_states + line
    ad = np.zeros((size, size))
    bd = np.zeros((size, 1))
    ad[:n_states, :n_states] = phi
    # past inputs q_1 = u[k-1], ..., q_line = u[k-line]
    if line:
        bd[n_states, 0] = 1.0
        for i in range(1, line):
            ad[n_states + i, n_states + i - 1] = 1.0
    if whole == 0:
        bd[:n_states] += g0
    else:
        ad[:n_states, n_states + whole - 1] += g0[:, 0]
    if fraction > 0:
        ad[:n_states, n_states + whole] += g1[:, 0]
    cd = np.hstack([c, np.zeros((c.shape[0], line))])
    return control.ss(ad, bd, cd, np.zeros((c.shape[0], 1)), period)


def sampled_loop(isolator=None, controller=None, rate=None, delay=0.0, relative_position=None):
    """The sampled loop transfer ``L(z)`` at the controller's rate (python-control).

    The simulator's sampled controller (docs/model.md §5): it reads the relative position and
    the measured velocity (the amplifier's analog high-pass stays in the plant), computes
    ``Kp*e + Ki*I`` with the forward-Euler integral ``I[n+1] = I[n] + T*e[n]``
    (``C_pi(z) = Kp + Ki*T/(z - 1)``) minus ``Kd*v``, and holds the force (zero-order hold)
    after ``delay``. The plant is discretised exactly (:func:`discretize_with_delay`).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    rate : float, optional
        Controller rate [Hz]; default the controller's ``controller_rate`` (must then be > 0).
    delay : float
        Delay from sampling to the motor force [s].
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    control.StateSpace
        ``L(z)`` [-] with ``dt = 1/rate``.
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate if rate is None else rate
    rate = _number("rate", rate, strict=True,
                   fix="; a sampled loop needs a controller rate in Hz")
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    period = 1.0 / rate
    plant = discretize_with_delay(*_plant_state_space(m, cv, k, w), period, delay)
    # C(z) = [Kp + Ki*T/(z - 1), Kd] on (z, v): state I, I[n+1] = I[n] + T*z[n]
    if ki > 0:
        gains = control.ss([[1.0]], [[period, 0.0]], [[ki]], [[kp, kd]], period)
    else:
        gains = control.ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), [[kp, kd]],
                           period)
    return gains * plant


@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of the loop broken at the motor force.

    Attributes
    ----------
    rate : float
        Controller rate [Hz]; 0 for the continuous loop.
    delay : float
        Delay from sampling to the motor force [s].
    stable : bool
        The closed loop is stable (poles in the left half plane, or inside the unit circle).
    gain_margin : float
        Gain margin [dB]: over every frequency where the phase is -180 deg (mod 360), the
        smallest ``|20*log10|L||``, the gain change (up, or down for a conditionally
        stable loop) that puts ``L`` on -1; ``inf`` if the phase never gets there.
    phase_margin : float
        Phase margin [deg]: over every crossover ``|L| = 1`` (this loop has up to three:
        the PI's, and two around the damping loop's band), the smallest angle between
        ``L`` and -1; NaN if ``|L|`` never crosses 1.
    gain_crossover_frequency : float
        The crossover that sets the phase margin [Hz] (NaN if none).
    phase_crossover_frequency : float
        The -180 deg crossing that sets the gain margin [Hz] (NaN if none).
    reasons : dict
        Name -> why a number is undefined.
    """

    rate: float
    delay: float
    stable: bool
    gain_margin: float
    phase_margin: float
    gain_crossover_frequency: float
    phase_crossover_frequency: float
    reasons: dict = field(default_factory=dict)

    def meets(self, gain_margin_min=GAIN_MARGIN_MIN, phase_margin_min=PHASE_MARGIN_MIN):
        """Stable with at least these margins.

        Parameters
        ----------
        gain_margin_min : float
            Least gain margin [dB].
        phase_margin_min : float
            Least phase margin [deg].

        Returns
        -------
        bool
        """
        phase_ok = (self.phase_margin >= phase_margin_min if math.isfinite(self.phase_margin)
                    else True)
        return bool(self.stable and self.gain_margin >= gain_margin_min and phase_ok)

    def to_dict(self):
        """The margins as a plain ``dict``."""
        return dict(self.__dict__)


def frequency_response(system, omega):
    """Complex response of a SISO python-control system on a grid, vectorised.

    Parameters
    ----------
    system : control.StateSpace or control.TransferFunction
        Continuous (``dt = 0``) or discrete.
    omega : array_like
        Angular frequencies [rad/s].

    Returns
    -------
    ndarray of complex
        ``L(j*omega)``, or ``L(exp(j*omega*dt))`` for a discrete system [-].
    """
    import control

    space = control.ss(system)
    a, b, c, d = (np.asarray(x, dtype=float) for x in (space.A, space.B, space.C, space.D))
    omega = np.asarray(omega, dtype=float)
    dt = space.dt if space.dt not in (None, True) else 0
    points = np.exp(1j * omega * dt) if dt else 1j * omega
    if a.size == 0:
        return np.full(omega.shape, d[0, 0], dtype=complex)
    n = a.shape[0]
    shifted = points[:, None, None] * np.eye(n)[None] - a[None]
    solved = np.linalg.solve(shifted, np.broadcast_to(b.astype(complex), (omega.size, n, 1)))
    return (c[None] @ solved)[:, 0, 0] + d[0, 0]


def _crossings(x, values):
    """Interpolated points where ``values`` changes sign between neighbours of ``x``."""
    sign = np.sign(values)
    found = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    return [x[i] + (x[i + 1] - x[i]) * values[i] / (values[i] - values[i + 1]) for i in found]


def _margins(response, omega, stable, rate, delay, extra_reasons=None):
    """Margins from a loop's response on a grid: every crossover, the worst of each kind."""
    log_w = np.log(omega)
    magnitude_db = 20 * np.log10(np.maximum(np.abs(response), 1e-300))
    phase = np.unwrap(np.angle(response))
    reasons = dict(extra_reasons or {})
    pm, f_gc = math.inf, math.nan
    for lw in _crossings(log_w, magnitude_db):
        angle = float(np.interp(lw, log_w, phase))
        distance = 180.0 - abs(math.degrees(math.remainder(angle, 2 * math.pi)))
        if distance < pm:
            pm, f_gc = distance, math.exp(lw) / (2 * np.pi)
    gm, f_pc = math.inf, math.nan
    turns = (phase + np.pi) / (2 * np.pi)  # integer where the phase is -180 deg (mod 360)
    for level in range(int(np.floor(turns.min())), int(np.ceil(turns.max())) + 1):
        for lw in _crossings(log_w, turns - level):
            distance = abs(float(np.interp(lw, log_w, magnitude_db)))
            if distance < gm:
                gm, f_pc = distance, math.exp(lw) / (2 * np.pi)
    if rate > 0:  # the response is real at the Nyquist frequency: a crossing may sit on it
        last = response[-1]
        if abs(last.imag) <= 1e-9 * abs(last) and last.real < 0:
            distance = abs(float(magnitude_db[-1]))
            if distance < gm:
                gm, f_pc = distance, rate / 2
    if not math.isfinite(pm):
        pm = math.nan
        reasons["phase_margin"] = "|L| never crosses 1 on the frequencies examined"
        reasons["gain_crossover_frequency"] = reasons["phase_margin"]
    if not math.isfinite(gm):
        reasons["gain_margin"] = ("the phase never reaches -180 deg: no gain change makes the "
                                  "loop unstable")
        reasons["phase_crossover_frequency"] = reasons["gain_margin"]
    if not stable:
        reasons["stable"] = ("a closed-loop pole lies outside the stability region: the margins "
                             "of an unstable loop are not margins")
    return LoopMargins(rate=float(rate), delay=float(delay), stable=bool(stable),
                       gain_margin=float(gm), phase_margin=float(pm),
                       gain_crossover_frequency=float(f_gc),
                       phase_crossover_frequency=float(f_pc), reasons=reasons)


#: Points per decade of the frequency grid the margins are read from [-].
MARGIN_POINTS_PER_DECADE = 400
#: Lowest angular frequency of that grid [rad/s] (the PI crossover lies near 0.5 rad/s).
MARGIN_LOWEST = 1e-4


def loop_margins(isolator=None, controller=None, rate=None, delay=0.0, relative_position=None):
    """Gain and phase margins of the loop, continuous or sampled (python-control).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    rate : float, optional
        Controller rate [Hz]; 0 for the continuous loop; default the controller's.
    delay : float
        Delay from sampling to the motor force [s] (a Padé approximant when continuous).
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    LoopMargins
    """
    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate if rate is None else rate
    rate = _number("rate", rate)
    delay = _number("delay", delay)
    if rate > 0:
        import control

        loop = sampled_loop(isolator, controller, rate, delay, relative_position)
        poles = np.asarray(control.feedback(loop, 1).poles(), dtype=complex)
        omega = _margin_grid(np.pi * rate)
        response = _sampled_response(isolator, controller, rate, delay, omega, relative_position)
        return _margins(response, omega, bool(np.all(np.abs(poles) < 1.0 - 1e-12)), rate, delay)
    return stability_margins_of(loop_transfer(isolator, controller, relative_position),
                                delay=delay)


def _margin_grid(top):
    decades = math.log10(top / MARGIN_LOWEST)
    return np.logspace(math.log10(MARGIN_LOWEST), math.log10(top),
                       int(decades * MARGIN_POINTS_PER_DECADE) + 1)


def stability_margins_of(loop, *, delay=0.0):
    """Margins of any SISO loop ``L`` (closed as ``u = -L u``), continuous or discrete.

    Read from the loop's response on a log grid (:data:`MARGIN_POINTS_PER_DECADE` points
    per decade from :data:`MARGIN_LOWEST` rad/s to the Nyquist frequency of a discrete loop,
    or to ten times its fastest pole or zero and at least 1e4 rad/s), every crossover
    counted (see :class:`LoopMargins`); stability from the closed loop's poles. A delay of a
    continuous loop enters the response exactly (``exp(-j w delay)``) and the poles through
    a Padé approximant; a discrete loop carries its delay in its states
    (:func:`discretize_with_delay`), so ``delay`` must then be 0.

    Parameters
    ----------
    loop : control.StateSpace or control.TransferFunction
        The loop transfer [-].
    delay : float
        Delay of a continuous loop [s].

    Returns
    -------
    LoopMargins
        With ``rate = 1/dt`` for a discrete loop (0 continuous).
    """
    import control

    delay = _number("delay", delay)
    dt = loop.dt if loop.dt not in (None, True) else 0
    if dt:
        if delay > 0:
            raise ParameterError("`delay` must be 0 for a discrete loop: discretise the delay "
                                 "into it (discretize_with_delay).")
        rate = 1.0 / dt
        top = np.pi * rate
        poles = np.asarray(control.feedback(loop, 1).poles(), dtype=complex)
        stable = bool(np.all(np.abs(poles) < 1.0 - 1e-12))
    else:
        rate = 0.0
        closed = loop
        if delay > 0:
            num, den = control.pade(delay, PADE_ORDER)
            closed = loop * control.tf(num, den)
        poles = np.asarray(control.feedback(closed, 1).poles(), dtype=complex)
        stable = bool(np.all(poles.real < 0))
        features = np.concatenate([np.abs(np.asarray(loop.poles(), dtype=complex)),
                                   np.abs(np.asarray(loop.zeros(), dtype=complex))])
        top = max(1e4, 10 * float(features.max()) if features.size else 0.0)
    omega = _margin_grid(top)
    response = frequency_response(loop, omega)
    if not dt and delay > 0:
        response = response * np.exp(-1j * omega * delay)
    return _margins(response, omega, stable, rate, delay)


def required_controller_rate(isolator=None, controller=None, delay=0.0, *,
                             gain_margin_min=GAIN_MARGIN_MIN, phase_margin_min=PHASE_MARGIN_MIN,
                             rate_range=(1.0, 1e5)):
    """The lowest controller rate [Hz] from which on the sampled loop keeps the margins.

    The margins of a sampled loop approach the continuous loop's as the rate grows, but not
    monotonically: far below the loop's bandwidth the amplifier's high-pass empties the
    measured velocity between samples and a slow loop can be stable again. So the rates of
    ``rate_range`` are scanned downwards from the top on a log grid (10 per decade) to the
    first that fails, and the boundary is refined by bisection in ``log(rate)`` between it
    and the passing rate above: every rate from the answer up passes.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    delay : float
        Delay from sampling to the motor force [s].
    gain_margin_min : float
        Least gain margin [dB].
    phase_margin_min : float
        Least phase margin [deg].
    rate_range : tuple of float
        Rates searched [Hz, Hz].

    Returns
    -------
    rate : float
        The lowest rate [Hz] (to 1 %); NaN if even the highest fails.
    reason : str
        Why NaN ('' otherwise).
    """
    isolator, controller = model_inputs(isolator, controller)
    low, high = _range("rate_range", rate_range, "Hz", minimum=1e-9)
    delay = _number("delay", delay)

    def ok(rate):
        return loop_margins(isolator, controller, rate, delay).meets(gain_margin_min,
                                                                    phase_margin_min)

    if not ok(high):
        return math.nan, (f"even at {high:g} Hz the sampled loop does not keep a gain margin of "
                          f"{gain_margin_min:g} dB and a phase margin of {phase_margin_min:g} deg "
                          f"(delay {delay:g} s); lower the damping gain or the delay")
    grid = np.logspace(math.log10(high), math.log10(low),
                       max(2, int(10 * math.log10(high / low)) + 1))
    passing = high
    for rate in grid[1:]:
        if not ok(rate):
            failing = rate
            break
        passing = rate
    else:
        return low, ""
    while passing / failing > 1.01:
        mid = math.sqrt(failing * passing)
        failing, passing = (failing, mid) if ok(mid) else (mid, passing)
    return passing, ""


def sampled_transmissibility(frequency, isolator=None, controller=None, *, rate=None,
                             delay=0.0):
    """``|X/Y|`` [-] of the linear loop with a sampled controller and a delay.

    The controller's fundamental-frequency response (the sampled-data loop's response at the
    excitation's own frequency; aliased components left out, fine well below the Nyquist
    frequency): each gain times the zero-order hold ``(1 - exp(-jwT))/(jwT)`` and
    ``exp(-jw delay)``, the integral as ``Ki*T/(exp(jwT) - 1)``:

        T(jw) = (Cv s + k + C_pi) / (m s^2 + Cv s + k + C_pi + C_d s HP(s)).

    With ``rate`` 0 the controller is continuous (``C_pi = Kp + Ki/s``), delayed by ``delay``.

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz], > 0.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.
    rate : float, optional
        Controller rate [Hz]; 0 continuous; default the controller's.
    delay : float
        Delay from sampling to the motor force [s].

    Returns
    -------
    ndarray
        Amplitude ratio [-].
    """
    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate if rate is None else rate
    rate = _number("rate", rate)
    delay = _number("delay", delay)
    f = np.asarray(frequency, dtype=float)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, None)
    s = 2j * np.pi * f
    lag = np.exp(-s * delay)
    if rate > 0:
        period = 1.0 / rate
        zoh = np.where(np.abs(s) > 0, (1 - np.exp(-s * period)) / (s * period + 1e-300), 1.0)
        pi = (kp + ki * period / (np.exp(s * period) - 1)) * zoh * lag
        damping = kd * zoh * lag
    else:
        pi = (kp + ki / s) * lag
        damping = kd * lag
    highpass = s / (s + w) if w > 0 else 1.0
    coupling = cv * s + k + pi
    return np.abs(coupling / (m * s ** 2 + coupling + damping * s * highpass))


# ---------------------------------------------------------------- describing functions
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


def friction_describing_function(isolator=None, amplitude=None, *, points=4096):
    """Describing function [N*s/m] of the friction law in slip velocity (python-control).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Supplies ``stiction_force``, ``coulomb_force`` and ``stribeck_decay``.
    amplitude : float or array_like
        Slip-velocity amplitudes [m/s], > 0.
    points : int
        Samples per period of python-control's numerical integration [-].

    Returns
    -------
    ndarray of complex
        ``N(A)`` [N*s/m] (real up to round-off: a memoryless odd function).
    """
    import control

    isolator, _ = model_inputs(isolator, None)
    if amplitude is None:
        raise ParameterError("`amplitude` is required: the slip-velocity amplitudes in m/s.")
    law = FrictionNonlinearity(isolator.stiction_force, isolator.coulomb_force,
                               isolator.stribeck_decay)
    return np.asarray(control.describing_function(law, np.atleast_1d(amplitude),
                                                  num_points=int(points)))


def restick_force(isolator=None):
    """Least driving force [N] that keeps the payload sliding: the re-stick level.

    ``min over v >= 0 of Fc + (Fs - Fc)*exp(-Cbc*v) + Cv*v``: at ``v* = ln(Cbc*(Fs - Fc)/Cv)/Cbc``
    when ``Cbc*(Fs - Fc) > Cv`` (the Stribeck dip is steeper than the viscous rise), else at
    ``v = 0`` (then ``Fs``: no slip jump, no hunting).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.

    Returns
    -------
    float
        ``F_r`` [N].
    """
    isolator, _ = model_inputs(isolator, None)
    fs, fc = isolator.stiction_force, isolator.coulomb_force
    cbc, cv = isolator.stribeck_decay, isolator.viscous_damping
    drop = cbc * (fs - fc)
    if cv <= 0:
        return fc
    if drop <= cv:
        return fs
    velocity = math.log(drop / cv) / cbc
    return fc + cv / cbc + cv * velocity


def slip_jump(isolator=None, controller=None, relative_position=None):
    """Force [N] by which one slip from rest moves the stuck position ``K*zeta``.

    The payload stuck, the loop's force on it ``F = u - K*zeta`` just above the breakaway
    force ``Fs``, the integral force ``u`` held (it changes little during the short slip):

        m v' = F - [Fc + (Fs - Fc) exp(-Cbc v)] - Cv v - Kd (v - w),
        F'   = -K v,      w' = w_hp (v - w)      (the amplifier's high-pass, settled at rest)

    integrated (scipy, LSODA) from ``F = Fs*(1 + 1e-6)`` until the payload stops (``v`` back
    to 0). The jump is ``Fs - F`` at that instant: the inertia carries the payload past the
    quasi-static re-stick level :func:`restick_force`, so the jump is larger than
    ``Fs - F_r``. No jump when the Stribeck dip cannot beat the damping: the payload creeps
    by the start kick's share only (below :data:`SLIP_JUMP_FLOOR` of ``Fs``, reported as 0).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies ``Kp`` (with the spring's tangent stiffness, ``K``), ``Kd`` and the high-pass.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    jump : float
        ``Fs - F`` when the payload stops [N] (0: it never broke into a slip).
    duration : float
        Length of the slip [s] (NaN if it did not end within the time allowed).
    """
    from scipy.integrate import solve_ivp

    isolator, controller = model_inputs(isolator, controller)
    m, cv, k, kp, _, kd, w = loop_constants(isolator, controller, relative_position)
    fs, fc, cbc = isolator.stiction_force, isolator.coulomb_force, isolator.stribeck_decay
    k_total = k + kp
    if fs <= 0 or k_total <= 0:
        return 0.0, math.nan

    def rates(_, y):
        v, force, lagged = y
        friction = fc + (fs - fc) * math.exp(-cbc * max(v, 0.0))
        return [(force - friction - cv * v - kd * (v - lagged)) / m, -k_total * v,
                w * (v - lagged)]

    def stopped(_, y):
        return y[0] + 1e-15
    stopped.terminal, stopped.direction = True, -1
    horizon = 40 * (m / max(cv, 1e-9) + max(cv, 1e-9) / k_total + (1 / w if w > 0 else 0))
    horizon = min(horizon, 1e4)
    solution = solve_ivp(rates, (0.0, horizon), [0.0, fs * (1 + 1e-6), 0.0], method="LSODA",
                         events=stopped, rtol=1e-8, atol=[1e-12, 1e-9 * max(fs, 1.0), 1e-12])
    if solution.status != 1:
        return 0.0, math.nan
    jump = max(0.0, fs - float(solution.y[1, -1]))
    if jump < SLIP_JUMP_FLOOR * fs:  # the kick's own creep: no slip
        jump = 0.0
    return jump, float(solution.t[-1])


@dataclass(frozen=True)
class HuntingPrediction:
    """What describing functions predict about a stick-slip limit cycle at rest.

    Attributes
    ----------
    friction_intersections : tuple of (float, float)
        Intersections (velocity amplitude [m/s], frequency [Hz]) of the memoryless friction
        law's ``-1/N`` with the PI loop's Nyquist curve: none for a linearly stable loop.
    steady_restick_force : float
        Quasi-static re-stick level ``F_r`` [N] (:func:`restick_force`).
    slip_jump : float
        Jump ``J`` of the stuck position in force units over one slip [N] (:func:`slip_jump`).
    relay_output : float
        Half the slip jump, ``d = J/2`` [N].
    switching_force : float
        Switching level of the relay, ``h = Fs - d`` [N].
    stiffness : float
        ``K = k(z_ref) + Kp`` [N/m].
    hunts : bool
        The stick-slip element's describing function meets the integral loop.
    integral_force_amplitude : float
        Amplitude of the integral force at the intersection [N] (NaN if none).
    frequency : float
        Predicted hunting frequency [Hz] (NaN if none).
    period : float
        ``1/frequency`` [s].
    amplitude : float
        Predicted plateau of the position about the setpoint, ``d/K`` [m].
    first_harmonic_amplitude : float
        First harmonic of the position at the intersection [m].
    relay_period : float
        Exact period of the relay-integrator cycle with instant slips, ``4*h*K/(Ki*d)`` [s]
        (the describing function's square-wave error is about 23 %).
    in_regime : bool
        The intersection lies where the element slips once per half cycle
        (``A < h + 2*d``), the regime in which it is a relay with hysteresis.
    reasons : dict
        Name -> why a number is undefined.
    """

    friction_intersections: tuple
    steady_restick_force: float
    slip_jump: float
    relay_output: float
    switching_force: float
    stiffness: float
    hunts: bool
    integral_force_amplitude: float
    frequency: float
    period: float
    amplitude: float
    first_harmonic_amplitude: float
    relay_period: float
    in_regime: bool
    reasons: dict = field(default_factory=dict)

    def to_dict(self):
        """The prediction as a plain ``dict``."""
        out = dict(self.__dict__)
        out["friction_intersections"] = [list(p) for p in self.friction_intersections]
        return out


def _fast_denominator(m, cv, k_total, kd, w):
    """``m s^2 + Cv s + K + Kd s HP(s)`` as a python-control transfer function."""
    import control

    s = control.tf("s")
    highpass = s / (s + w) if w > 0 else 1
    return m * s ** 2 + cv * s + k_total + kd * s * highpass


def _velocity_loop(m, cv, k_total, ki, kd, w):
    """Slip velocity per friction force with the PI loop closed (base at rest)."""
    import control

    s = control.tf("s")
    integral = ki / s if ki > 0 else 0
    return control.minreal(control.tf(s / (_fast_denominator(m, cv, k_total, kd, w) + integral)),
                           verbose=False)


def integral_loop(isolator=None, controller=None, relative_position=None):
    """``G(s) = Ki/(s*(m s^2 + Cv s + K + Kd s HP(s)))`` [-]: the stick-slip element's loop.

    From the element's output (the stuck position in force units, ``K*zeta`` [N]) back to
    its input (the integral force [N]), sign of negative feedback.

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
    control.TransferFunction
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    s = control.tf("s")
    return control.minreal(control.tf(ki / (s * _fast_denominator(m, cv, k + kp, kd, w))),
                           verbose=False)


def hunting_stiffness(isolator=None, controller=None, half_width=None):
    """Least proportional gain [N/m] whose predicted hunting plateau ``d/K`` fits a half-width.

    ``d = J(K)/2`` from :func:`slip_jump`, which depends on ``K = k + Kp`` only mildly: the
    smallest ``Kp`` with ``J/(2K) <= half_width`` by bisection (the plateau falls with ``K``).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Damping loop and high-pass (its ``Kp`` is varied).
    half_width : float
        Half-width of the band about the setpoint [m].

    Returns
    -------
    float
        The least ``Kp`` [N/m] (0 if no slip jump even at ``Kp = 0``; NaN above 1e5 N/m).
    """
    isolator, controller = model_inputs(isolator, controller)
    half_width = _number("half_width", half_width, strict=True)

    def plateau(kp):
        trial = dataclasses.replace(controller, pi_kp=kp)
        k_total = loop_constants(isolator, trial, None)[2] + kp
        return slip_jump(isolator, trial)[0] / (2 * k_total)

    if plateau(0.0) <= half_width:
        return 0.0
    low, high = 0.0, 1.0
    while plateau(high) > half_width:
        low, high = high, 2 * high
        if high > 1e5:
            return math.nan
    while high - low > 1e-3 * high:
        mid = 0.5 * (low + high)
        low, high = (mid, high) if plateau(mid) > half_width else (low, mid)
    return high


def predict_hunting(isolator=None, controller=None, relative_position=None):
    """Describing-function prediction of hunting at rest (python-control).

    Two analyses (see the module's text): the memoryless friction law in the velocity loop
    (:func:`control.describing_function_response` with :class:`FrictionNonlinearity`), and
    the stick-slip element (python-control's ``relay_hysteresis_nonlinearity(d, h)``,
    ``d = J/2``, ``h = Fs - d``, ``J`` from :func:`slip_jump`) in the integral loop
    :func:`integral_loop`.

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
    HuntingPrediction
    """
    import warnings

    import control

    isolator, controller = model_inputs(isolator, controller)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    k_total = k + kp
    reasons = {}
    # 1. the friction law alone, a memoryless function of slip velocity
    friction = []
    if isolator.stiction_force > 0 and _stable((m, cv, k, kp, ki, kd, w)):
        law = FrictionNonlinearity(isolator.stiction_force, isolator.coulomb_force,
                                   isolator.stribeck_decay)
        loop = _velocity_loop(m, cv, k_total, ki, kd, w)
        amplitudes = np.logspace(-6, 1, 36)
        omega = np.logspace(-4, 4, 400)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            response = control.describing_function_response(loop, law, amplitudes, omega=omega)
        friction = [(float(a), float(wi) / (2 * np.pi)) for a, wi in response.intersections]
    # 2. the stick-slip element in the integral loop
    jump = slip_jump(isolator, controller, relative_position)[0]
    d = 0.5 * jump
    h = isolator.stiction_force - d
    nan = math.nan
    amplitude_u = frequency = first = nan
    hunts = in_regime = False
    if ki <= 0:
        reasons["hunts"] = "no integral action: nothing winds up while the payload is stuck"
    elif isolator.stiction_force <= 0:
        reasons["hunts"] = "no stiction: the payload never sticks"
    elif d <= 0:
        reasons["hunts"] = ("no slip jump: after breaking away the payload creeps and stops "
                            "where it broke away (the Stribeck dip does not beat the damping)")
    elif k_total <= 0:
        reasons["hunts"] = "no stiffness K = k + Kp: the stuck position is undefined"
    else:
        element = control.relay_hysteresis_nonlinearity(d, h)
        g = integral_loop(isolator, controller, relative_position)
        top = h + 2 * d
        amplitudes = h * (1 + np.logspace(-9, math.log10(20 * top / h), 80))
        omega = np.logspace(-5, 3, 500)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            response = control.describing_function_response(g, element, amplitudes,
                                                            omega=omega)
        found = [(float(a), float(wi)) for a, wi in response.intersections
                 if a >= h and wi > 0]
        if found:
            amplitude_u, w_cycle = found[0]
            hunts = True
            in_regime = amplitude_u < top
            frequency = w_cycle / (2 * np.pi)
            harmonic_force = abs(element.describing_function(amplitude_u)) * amplitude_u
            first = harmonic_force / abs(_fast_denominator(m, cv, k_total, kd, w)(1j * w_cycle))
            if not in_regime:
                reasons["in_regime"] = (f"the intersection's amplitude {amplitude_u:.3g} N exceeds "
                                        f"h + 2d = {top:.3g} N: the element slips more than once "
                                        "per half cycle there, the relay is a rough model")
        else:
            reasons["hunts"] = "the element's -1/N does not meet the integral loop's Nyquist curve"
    for name in ("integral_force_amplitude", "frequency", "period", "first_harmonic_amplitude"):
        if not hunts:
            reasons.setdefault(name, reasons.get("hunts", "no limit cycle predicted"))
    plateau = d / k_total if (d > 0 and k_total > 0) else nan
    relay_period = 4 * h * k_total / (ki * d) if (ki > 0 and d > 0 and k_total > 0) else nan
    if not math.isfinite(plateau):
        reasons.setdefault("amplitude", reasons.get("hunts", "no slip jump"))
    if not math.isfinite(relay_period):
        reasons.setdefault("relay_period", reasons.get("hunts", "no cycle"))
    return HuntingPrediction(
        friction_intersections=tuple(friction), steady_restick_force=restick_force(isolator),
        slip_jump=jump, relay_output=d, switching_force=h, stiffness=k_total, hunts=hunts,
        integral_force_amplitude=amplitude_u, frequency=frequency,
        period=1 / frequency if hunts and frequency > 0 else nan,
        amplitude=plateau, first_harmonic_amplitude=first, relay_period=relay_period,
        in_regime=in_regime, reasons=reasons)
