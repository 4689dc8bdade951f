"""Hunting at rest: the stick-slip element in the integral loop, by describing functions.

Combining the payload with its friction (Olsson's remedy) gives a stick-slip element in the
*integral* loop: the payload stays stuck while the integral force ``u`` is within ``Fs`` of
``K*zeta`` (``K = k + Kp``, ``zeta = z - z_ref``); when it breaks away it slides, and stops
(inertia carries it past the least force that keeps it sliding, the quasi-static re-stick
level ``F_r = min_v [Fc + (Fs - Fc)*exp(-Cbc*v) + Cv*v]``, :func:`restick_force`) with its
stuck position moved by a jump ``J`` in force units, integrated from rest over the one slip
(:func:`slip_jump`). While one slip happens per half cycle this element is a relay with
hysteresis in force units: output ``K*zeta = +-d``, ``d = J/2``, switching at ``u = +-h``,
``h = Fs - d``. The linear part from its output back to its input is
``G(s) = Ki/(s*(m s^2 + Cv s + K + Kd s HP(s)))`` (:func:`integral_loop`). Its describing
function (python-control's ``relay_hysteresis_nonlinearity``) meets ``G`` at one amplitude
and frequency: a hunting cycle, square in position with plateaus ``+-d/K`` [m], whose exact
period with instant slips is ``4*h*K/(Ki*d)``. No slip jump (the Stribeck dip does not beat
the damping: the payload creeps) or no integral: no hunting. :func:`predict_hunting` runs
both analyses, this one and the memoryless friction law's of :mod:`.describing_functions`.

With a friction compensation (docs/model.md §5) the slip integrates the net law (the
compensation pushes along the slip beyond its deadband) and the integral loop's viscous term
is ``Cv - fraction*Cv'``: the jump grows with the fraction, and from ``J >= 2 Fs`` the slip
no longer re-sticks (no relay). A friction observer or a user's linear controller is refused:
the relay does not model them.

References
----------
H. Olsson, K. J. Åström, "Friction generated limit cycles", IEEE Trans. Control Syst.
Technol. 9(4), 2001.
"""
import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from qzs._validation import real
from qzs.analysis.control_design.describing_functions import (FrictionNonlinearity,
                                                              predict_sliding_cycle)
from qzs.analysis.control_design.linear_stability import _stable
from qzs.analysis.linear import loop_constants
from qzs.errors import ParameterError
from qzs.model.registry import model_inputs

__all__ = ["restick_force", "slip_jump", "HuntingPrediction", "integral_loop",
           "hunting_stiffness", "predict_hunting", "SLIP_JUMP_FLOOR", "RELAY_FREQUENCIES",
           "RELAY_AMPLITUDE_POINTS", "RELAY_AMPLITUDE_SPAN"]

#: A slip jump below this share of the stiction force is the start kick's creep, not a slip [-].
SLIP_JUMP_FLOOR = 1e-4
#: The relay's frequency grid handed to python-control: ``np.logspace(*RELAY_FREQUENCIES)``
#: [rad/s] (an intersection outside it is no cycle).
RELAY_FREQUENCIES = (-5, 3, 500)
#: Amplitudes of the relay's locus: ``h*(1 + logspace(-9, log10(span*(h + 2d)/h), points))``
#: [N], up to ``h + span*(h + 2d)``.
RELAY_AMPLITUDE_POINTS = 80
RELAY_AMPLITUDE_SPAN = 20


def restick_force(isolator=None, controller=None):
    """Least driving force [N] that keeps the payload sliding: the re-stick level.

    ``min over v >= 0 of Fc + (Fs - Fc)*exp(-Cbc*v) + Cv*v``: at ``v* = ln(Cbc*(Fs - Fc)/Cv)/Cbc``
    when ``Cbc*(Fs - Fc) > Cv`` (the Stribeck dip is steeper than the viscous rise), else at
    ``v = 0`` (then ``Fs``: no slip jump, no hunting). With a friction compensation, the
    least of the net steady force (the law less the compensation's feedforward, beyond its
    deadband), found numerically; NaN when the net force is not positive at some velocity
    (it pushes along the slip: the payload never re-sticks by itself).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Its friction compensation, if any, is netted out.

    Returns
    -------
    float
        ``F_r`` [N].
    """
    isolator, controller = model_inputs(isolator, controller)
    law = _compensation_law(isolator, controller)
    if law is not None:
        return _net_restick_force(isolator, law)
    fs, fc = isolator.stiction_force, isolator.coulomb_force
    cbc, cv = isolator.stribeck_decay, isolator.viscous_damping
    drop = cbc * (fs - fc)
    if cv <= 0:
        return fc
    if drop <= cv:
        return fs
    velocity = math.log(drop / cv) / cbc
    return fc + cv / cbc + cv * velocity


def _net_restick_force(isolator, law):
    """:func:`restick_force` of the net steady force with a compensation ``law``."""
    from scipy.optimize import minimize_scalar

    fs, fc = isolator.stiction_force, isolator.coulomb_force
    cbc, cv = isolator.stribeck_decay, isolator.viscous_damping
    fraction, fs_c, fc_c, cbc_c, cv_c, deadband = law
    if cv - fraction * cv_c < 0:
        return math.nan  # the net force falls without bound as the slip speeds up

    def net(v):
        value = fc + (fs - fc) * np.exp(-cbc * v) + cv * v
        beyond = v > deadband
        return value - np.where(beyond, fraction * (fc_c + (fs_c - fc_c) * np.exp(-cbc_c * v)
                                                    + cv_c * v), 0.0)

    grid = np.concatenate([[0.0], np.logspace(-9, 3, 4001)])
    values = net(grid)
    i = int(np.argmin(values))
    low, high = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    if high > low:
        best = minimize_scalar(lambda v: float(net(v)), bounds=(low, high), method="bounded",
                               options={"xatol": 1e-12})
        values[i] = min(values[i], best.fun)
    return float(values[i]) if values[i] > 0 else math.nan


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
    isolator, controller = model_inputs(isolator, controller)
    _relay_controller(controller)
    m, cv, k, kp, _, kd, w = loop_constants(isolator, controller, relative_position)
    return _slip(m, cv, k + kp, kd, w, isolator.stiction_force, isolator.coulomb_force,
                 isolator.stribeck_decay, _compensation_law(isolator, controller))


def _compensation_law(isolator, controller):
    """``(fraction, Fs', Fc', Cbc', Cv', deadband)`` of the compensation, or None."""
    compensation = controller.compensation
    if compensation is None or compensation.fraction == 0.0:
        return None
    return (compensation.fraction, *compensation.law(isolator), compensation.deadband)


def _relay_controller(controller):
    """Refuse what the stick-slip relay cannot hold: a user's linear controller, an observer."""
    if controller.linear is not None:
        raise ParameterError(
            "`controller` has a LinearController: the stick-slip relay is that of the PI "
            "integral loop (PI + damping + friction compensation); use "
            "predict_sliding_cycle for a sliding cycle, and a simulation for stick-slip.",
            ("controller",))
    compensation = controller.compensation
    if compensation is not None and compensation.observer_bandwidth > 0:
        raise ParameterError(
            "`controller` has a friction observer: while the payload sticks it integrates "
            "the holding force (an integral action of its own), which the stick-slip relay "
            "does not model; use predict_sliding_cycle for a sliding cycle, and a "
            "simulation for stick-slip.", ("controller",))


def _slip(m, cv, k_total, kd, w, fs, fc, cbc, compensation=None):
    """:func:`slip_jump` of the loop constants: ``(jump [N], duration [s])``, LSODA.

    ``compensation``: ``(fraction, Fs', Fc', Cbc', Cv', deadband)`` of a friction
    compensation pushing along the slip beyond its deadband, or None.
    """
    from scipy.integrate import solve_ivp

    if fs <= 0 or k_total <= 0:
        return 0.0, math.nan

    def rates(_, y):
        v, force, lagged = y
        friction = fc + (fs - fc) * math.exp(-cbc * max(v, 0.0))
        if compensation is not None and v > compensation[5]:
            fraction, fs_c, fc_c, cbc_c, cv_c, _ = compensation
            friction -= fraction * (fc_c + (fs_c - fc_c) * math.exp(-cbc_c * v) + cv_c * v)
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
    _relay_controller(controller)
    m, cv, k, kp, ki, kd, w = _relay_constants(isolator, controller, relative_position)
    s = control.tf("s")
    return control.minreal(control.tf(ki / (s * _fast_denominator(m, cv, k + kp, kd, w))),
                           verbose=False)


def _relay_constants(isolator, controller, relative_position):
    """:func:`~qzs.analysis.linear.loop_constants` with the compensation's viscous slope
    netted out of ``Cv`` (``Cv - fraction*Cv'``; the same tuple without compensation)."""
    numbers = loop_constants(isolator, controller, relative_position)
    law = _compensation_law(isolator, controller)
    if law is None:
        return numbers
    m, cv, k, kp, ki, kd, w = numbers
    return m, cv - law[0] * law[4], k, kp, ki, kd, w


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
    half_width = real("half_width", half_width, minimum=0.0, strict=True)

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


def predict_hunting(isolator=None, controller=None, relative_position=None, *,
                    memoryless=True):
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
    memoryless : bool
        Also intersect the memoryless friction law with the velocity loop (about three
        quarters of the time); False leaves ``friction_intersections`` empty, with a
        reason, and changes nothing else (the design search's ``hunting_amplitude``).

    Returns
    -------
    HuntingPrediction
    """
    isolator, controller = model_inputs(isolator, controller)
    _relay_controller(controller)
    numbers = tuple(_relay_constants(isolator, controller, relative_position))
    m, cv, k, kp, ki, kd, w = numbers
    k_total = k + kp
    reasons = {}
    if controller.dither is not None:
        reasons["dither"] = "the dither is left out (it is no feedback)"
    if not memoryless:
        friction = []
        reasons["friction_intersections"] = "not computed (memoryless=False)"
    elif controller.compensation is None:
        friction = _memoryless_intersections(isolator, numbers)
    else:
        friction = [(a, f) for a, f, _ in predict_sliding_cycle(
            isolator, controller, relative_position).intersections]
    jump = slip_jump(isolator, controller, relative_position)[0]
    d = 0.5 * jump
    h = isolator.stiction_force - d
    nan = math.nan
    amplitude_u = frequency = first = nan
    hunts = in_regime = False
    reason = _why_no_relay_cycle(isolator, ki, d, k_total)
    if reason:
        reasons["hunts"] = reason
    else:
        cycle = _relay_cycle(isolator, controller, relative_position, numbers, d, h, reasons)
        if cycle is not None:
            amplitude_u, frequency, first, in_regime = cycle
            hunts = True
    for name in ("integral_force_amplitude", "frequency", "period", "first_harmonic_amplitude"):
        if not hunts:
            reasons.setdefault(name, reasons.get("hunts", "no limit cycle predicted"))
    plateau = d / k_total if (d > 0 and k_total > 0 and h > 0) else nan
    relay_period = (4 * h * k_total / (ki * d) if (ki > 0 and d > 0 and k_total > 0 and h > 0)
                    else nan)
    if not math.isfinite(plateau):
        reasons.setdefault("amplitude", reasons.get("hunts", "no slip jump"))
    if not math.isfinite(relay_period):
        reasons.setdefault("relay_period", reasons.get("hunts", "no cycle"))
    if not h > 0:
        reasons["switching_force"] = reasons.get("hunts", "the slip does not re-stick")
    restick = restick_force(isolator, controller)
    if math.isnan(restick):
        reasons["steady_restick_force"] = ("the net friction pushes along the slip at some "
                                           "velocity (over-compensation): no re-stick level")
    return HuntingPrediction(
        friction_intersections=tuple(friction), steady_restick_force=restick,
        slip_jump=jump, relay_output=d, switching_force=h if h > 0 else nan,
        stiffness=k_total, hunts=hunts,
        integral_force_amplitude=amplitude_u, frequency=frequency,
        period=1 / frequency if hunts and frequency > 0 else nan,
        amplitude=plateau, first_harmonic_amplitude=first, relay_period=relay_period,
        in_regime=in_regime, reasons=reasons)


def _memoryless_intersections(isolator, numbers):
    """The friction law alone, a memoryless function of slip velocity, in the PI loop.

    Intersections (velocity amplitude [m/s], frequency [Hz]) of its ``-1/N`` with the velocity
    loop's Nyquist curve; none without stiction or for a linearly unstable loop.
    """
    import warnings

    import control

    m, cv, k, kp, ki, kd, w = numbers
    if not (isolator.stiction_force > 0 and _stable((m, cv, k, kp, ki, kd, w))):
        return []
    law = FrictionNonlinearity(isolator.stiction_force, isolator.coulomb_force,
                               isolator.stribeck_decay)
    loop = _velocity_loop(m, cv, k + kp, ki, kd, w)
    amplitudes = np.logspace(-6, 1, 36)
    omega = np.logspace(-4, 4, 400)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        response = control.describing_function_response(loop, law, amplitudes, omega=omega)
    return [(float(a), float(wi) / (2 * np.pi)) for a, wi in response.intersections]


def _why_no_relay_cycle(isolator, ki, d, k_total):
    """Why the stick-slip element cannot cycle ('' when it may)."""
    if ki <= 0:
        return "no integral action: nothing winds up while the payload is stuck"
    if isolator.stiction_force <= 0:
        return "no stiction: the payload never sticks"
    if d <= 0:
        return ("no slip jump: after breaking away the payload creeps and stops "
                "where it broke away (the Stribeck dip does not beat the damping)")
    if d >= isolator.stiction_force:
        return ("the slip does not re-stick: where it stops, the force exceeds the breakaway "
                "force the other way (over-compensation); the payload slides on "
                "(predict_sliding_cycle)")
    if k_total <= 0:
        return "no stiffness K = k + Kp: the stuck position is undefined"
    return ""


def _relay_cycle(isolator, controller, relative_position, numbers, d, h, reasons):
    """The stick-slip relay ``(d, h)`` in the integral loop: its cycle, or None.

    Returns ``(integral force amplitude [N], frequency [Hz], first harmonic of the position
    [m], in regime)`` at the first intersection of the relay's ``-1/N`` with
    :func:`integral_loop`'s Nyquist curve; writes why into ``reasons`` when there is none, or
    when the intersection lies outside the one-slip-per-half-cycle regime.
    """
    import warnings

    import control

    m, cv, k, kp, ki, kd, w = numbers
    element = control.relay_hysteresis_nonlinearity(d, h)
    g = integral_loop(isolator, controller, relative_position)
    top = h + 2 * d
    amplitudes = h * (1 + np.logspace(-9, math.log10(RELAY_AMPLITUDE_SPAN * top / h),
                                      RELAY_AMPLITUDE_POINTS))
    omega = np.logspace(*RELAY_FREQUENCIES)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        response = control.describing_function_response(g, element, amplitudes, omega=omega)
    found = [(float(a), float(wi)) for a, wi in response.intersections if a >= h and wi > 0]
    if not found:
        reasons["hunts"] = "the element's -1/N does not meet the integral loop's Nyquist curve"
        return None
    amplitude_u, w_cycle = found[0]
    in_regime = amplitude_u < top
    harmonic_force = abs(element.describing_function(amplitude_u)) * amplitude_u
    first = harmonic_force / abs(_fast_denominator(m, cv, k + kp, kd, w)(1j * w_cycle))
    if not in_regime:
        reasons["in_regime"] = (f"the intersection's amplitude {amplitude_u:.3g} N exceeds "
                                f"h + 2d = {top:.3g} N: the element slips more than once "
                                "per half cycle there, the relay is a rough model")
    return amplitude_u, w_cycle / (2 * np.pi), first, in_regime
