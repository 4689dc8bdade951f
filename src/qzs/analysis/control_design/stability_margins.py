"""Gain and phase margins of the loop, continuous or sampled, and the rate a design needs.

The margins of the loop broken at the motor force (:mod:`.loop_transfers`) are read from its
response on a log grid, every crossover counted (:func:`loop_margins`,
:func:`stability_margins_of`); stability from the closed loop's poles (python-control).
:func:`required_controller_rate` is the lowest controller rate from which on the sampled
loop keeps given margins.
"""
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from qzs._format import decibels
from qzs._validation import interval, real
from qzs.analysis.control_design.loop_transfers import (PADE_ORDER, _continuous_blocks_loop,
                                                        _SampledBlocks,
                                                        _sampled_response, frequency_response,
                                                        loop_transfer, sampled_loop)
from qzs.analysis.linear import close_loop, continuous_controller_matrices, plant_matrices
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import model_inputs

__all__ = ["LoopMargins", "loop_margins", "stability_margins_of", "required_controller_rate",
           "LoopStability", "loop_stability",
           "GAIN_MARGIN_MIN", "PHASE_MARGIN_MIN", "MARGIN_POINTS_PER_DECADE", "MARGIN_LOWEST"]

#: Default margins a sampled design must keep: gain margin [dB] and phase margin [deg].
GAIN_MARGIN_MIN = 6.0
PHASE_MARGIN_MIN = 30.0
#: Points per decade of the frequency grid the margins are read from [-].
MARGIN_POINTS_PER_DECADE = 400
#: Lowest angular frequency of that grid [rad/s] (the PI crossover lies near 0.5 rad/s).
MARGIN_LOWEST = 1e-4


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
        stable loop) that puts ``L`` on -1; ``inf`` if the phase never gets there. NaN
        for an unstable loop, which has no margins (nor crossovers): ``reasons`` says so,
        with the gain change that would restore stability.
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

    def meets(self, gain_margin_min: float = GAIN_MARGIN_MIN,
              phase_margin_min: float = PHASE_MARGIN_MIN) -> bool:
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

    def to_dict(self) -> dict[str, Any]:
        """The margins as a plain ``dict``."""
        return dict(self.__dict__)


def _crossings(x, values):
    """Interpolated points where ``values`` changes sign between neighbours of ``x``."""
    sign = np.sign(values)
    found = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    return [x[i] + (x[i + 1] - x[i]) * values[i] / (values[i] - values[i + 1]) for i in found]


def _margins(response, omega, stable, rate, delay, extra_reasons=None):
    """Margins from a loop's response on a grid: every crossover, the worst of each kind."""
    log_w = np.log(omega)
    magnitude_db = decibels(response, 1e-300)
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
    if not stable:  # no margin: what reads as one is the change that would restore stability
        reasons["stable"] = ("a closed-loop pole lies outside the stability region: the margins "
                             "of an unstable loop are not margins")
        unstable = "the closed loop is unstable: it has no margin"
        reasons["gain_margin"] = unstable + (
            f" ({gm:.3g} dB is the gain change at {f_pc:.3g} Hz that would make it stable)"
            if math.isfinite(gm) else "")
        reasons["phase_margin"] = unstable
        reasons["gain_crossover_frequency"] = reasons["phase_crossover_frequency"] = unstable
        gm = pm = f_gc = f_pc = math.nan
    return LoopMargins(rate=float(rate), delay=float(delay), stable=bool(stable),
                       gain_margin=float(gm), phase_margin=float(pm),
                       gain_crossover_frequency=float(f_gc),
                       phase_crossover_frequency=float(f_pc), reasons=reasons)


def loop_margins(isolator: IsolatorParameters | None = None,
                 controller: ControllerParameters | None = None, rate: float | None = None,
                 delay: float = 0.0, relative_position: float | None = None) -> LoopMargins:
    """Gain and phase margins of the loop, continuous or sampled (python-control).

    A controller with blocks (docs/design.md §6): its loop is sampled wherever a part of it
    is (PI + damping at ``rate``, a discrete linear controller at its own sample time),
    broken at the sampled force with the continuous parts closed inside the plant
    (:func:`~qzs.analysis.control_design.loop_transfers.sampled_loop`); else continuous
    (:func:`~qzs.analysis.control_design.loop_transfers.loop_transfer`).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops, and any blocks; defaults if omitted.
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
    rate = real("rate", rate, minimum=0.0)
    delay = real("delay", delay, minimum=0.0)
    if controller.has_blocks:
        return _blocks_margins(isolator, controller, rate, delay, relative_position)
    if rate > 0:
        import control

        loop = sampled_loop(isolator, controller, rate, delay, relative_position)
        poles = np.asarray(control.feedback(loop, 1).poles(), dtype=complex)
        omega = _margin_grid(np.pi * rate)
        response = _sampled_response(isolator, controller, rate, delay, omega, relative_position)
        return _margins(response, omega, bool(np.all(np.abs(poles) < 1.0 - 1e-12)), rate, delay)
    return stability_margins_of(loop_transfer(isolator, controller, relative_position),
                                delay=delay)


def _blocks_margins(isolator, controller, rate, delay, relative_position):
    """:func:`loop_margins` of a controller with blocks: sampled if any part is."""
    import control

    linear = controller.linear
    if rate > 0 or (linear is not None and linear.discrete):
        loop = sampled_loop(isolator, controller, rate, delay, relative_position)
        poles = np.asarray(control.feedback(loop, 1).poles(), dtype=complex)
        omega = _margin_grid(np.pi / loop.dt)
        return _margins(frequency_response(loop, omega), omega,
                        bool(np.all(np.abs(poles) < 1.0 - 1e-12)), 1.0 / loop.dt, delay)
    loop = control.ss(*_continuous_blocks_loop(isolator, controller, relative_position))
    return stability_margins_of(loop, delay=delay)


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

    delay = real("delay", delay, minimum=0.0)
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
    if controller.linear is not None and controller.linear.discrete:
        raise ParameterError(
            "`controller` has a discrete LinearController, which runs at its own sample time: "
            "required_controller_rate scans the rate of PI + damping alone; make the linear "
            "controller continuous, or check its rate with loop_margins.", ("controller",))
    low, high = interval("rate_range", rate_range, "Hz", minimum=1e-9)
    delay = real("delay", delay, minimum=0.0)

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


@dataclass(frozen=True)
class LoopStability:
    """Whether a controller's loop is stable at the operating point, and with what margins.

    The loop as the simulator runs it: continuous, or sampled wherever a part of the
    controller is (``controller_rate``, a discrete linear controller's ``sample_time``), no
    delay; linearised as :func:`qzs.analysis.linear.linearize` (docs/model.md §10). An
    unstable controller is accepted: what decides is the closed loop.

    Attributes
    ----------
    stable : bool
        Every closed-loop pole strictly inside the stability region (left half plane, or
        the unit circle for a sampled loop).
    sampled : bool
        The loop is sampled (its poles are in the z-plane).
    period : float
        Sample period of the loop [s] (0: continuous).
    margins : LoopMargins
        Gain and phase margins of the loop broken at the motor force (NaN, with the reason,
        when unstable).
    poles : ndarray of complex
        Closed-loop poles, every mode of the plant and the controller [rad/s] (of a sampled
        loop: in the z-plane [-]).
    unstable_poles : ndarray of complex
        Those outside the stability region [rad/s] (sampled: [-]).
    controller_poles : ndarray of complex
        Poles of the controller alone [rad/s]; of a sampled loop, its sampled part's, in the
        z-plane [-].
    controller_unstable : bool
        The controller alone (each part, continuous and sampled) is unstable (an integrator
        is marginal, not unstable).
    reasons : dict
        Name -> why the loop is unstable, or why a number is undefined.
    """

    stable: bool
    sampled: bool
    period: float
    margins: LoopMargins
    poles: np.ndarray
    unstable_poles: np.ndarray
    controller_poles: np.ndarray
    controller_unstable: bool
    reasons: dict = field(default_factory=dict)

    @property
    def message(self) -> str:
        """One line: stable with its margins, or unstable and why."""
        m = self.margins
        if not self.stable:
            return "unstable loop: " + self.reasons["stable"]
        gain = ("no -180 deg crossing (infinite gain margin)" if math.isinf(m.gain_margin)
                else f"gain margin {m.gain_margin:.3g} dB at {m.phase_crossover_frequency:.3g} Hz")
        phase = ("|L| never crosses 1" if math.isnan(m.phase_margin)
                 else f"phase margin {m.phase_margin:.3g} deg at "
                      f"{m.gain_crossover_frequency:.3g} Hz")
        return f"stable loop: {gain}, {phase}"

    def to_dict(self) -> dict[str, Any]:
        """The verdict as a plain ``dict`` (poles as lists of [real, imaginary])."""
        out = {name: getattr(self, name) for name in ("stable", "sampled", "period",
                                                       "controller_unstable")}
        out["margins"] = self.margins.to_dict()
        for name in ("poles", "unstable_poles", "controller_poles"):
            out[name] = [[float(p.real), float(p.imag)] for p in getattr(self, name)]
        out["reasons"] = dict(self.reasons)
        out["message"] = self.message
        return out


def _eigenvalues(a):
    return np.asarray(np.linalg.eigvals(a) if a.size else np.zeros(0), dtype=complex)


def _outside(poles, sampled, margin=0.0):
    return (np.abs(poles) >= 1.0 - margin) if sampled else (poles.real >= -margin)


def loop_stability(isolator: IsolatorParameters | None = None,
                   controller: ControllerParameters | None = None,
                   relative_position: float | None = None) -> LoopStability:
    """Whether a controller's loop is stable, with its margins, and why not when it is not.

    The one verdict on a controller (:class:`LoopStability`): the closed loop's poles from
    its state space (every mode, none cancelled), the margins from :func:`loop_margins` at
    the controller's own rate(s). A controller that is unstable alone is accepted; an
    unstable loop is flagged (``stable`` False), with its poles and the margins' reasons.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        The controller, with or without blocks; defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    LoopStability
    """
    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate
    linear = controller.linear
    sampled = rate > 0 or (linear is not None and linear.discrete)
    margins = loop_margins(isolator, controller, rate, 0.0, relative_position)
    continuous, own, period = None, np.zeros(0, complex), 0.0
    if sampled:
        loop = _SampledBlocks(isolator, controller, rate, 0.0, relative_position)
        closed, continuous, period = (close_loop(loop.held, loop.discrete), loop.continuous,
                                      loop.period)
        own = _eigenvalues(loop.discrete[0])
    else:
        parts = continuous_controller_matrices(isolator, controller)
        closed = close_loop(plant_matrices(isolator, controller, relative_position, base=False),
                            parts)
        own = _eigenvalues(parts[0])
    poles = _eigenvalues(closed[0])
    unstable = poles[_outside(poles, sampled, 1e-12)]
    reasons = dict(margins.reasons)
    if unstable.size:
        worst = unstable[np.argmax(np.abs(unstable) if sampled else unstable.real)]
        where = (f"|z| = {abs(worst):.6g}, {abs(np.angle(worst)) / (2 * np.pi * period):.3g} Hz"
                 if sampled else f"growth rate {worst.real:.3g} 1/s, "
                                 f"{abs(worst.imag) / (2 * np.pi):.3g} Hz")
        compensation = controller.compensation
        fix = ("lower the gains, or add phase lead where the loop crosses over"
               + (", or compensate less of the guide's viscous friction (the fraction, or "
                  "the compensator's viscous_damping)" if compensation is not None
                  and compensation.fraction > 0 else ""))
        reasons["stable"] = (f"{unstable.size} closed-loop pole(s) outside the stability "
                             f"region, the worst at {where}; {fix}")
    controller_unstable = bool(np.any(_outside(own, sampled, -1e-9)) or (
        continuous is not None and np.any(_outside(_eigenvalues(continuous[0]), False, -1e-9))))
    if controller_unstable:
        reasons["controller_unstable"] = ("the controller alone is unstable: accepted, the "
                                          "closed loop decides")
    return LoopStability(stable=not unstable.size, sampled=sampled, period=float(period),
                         margins=margins, poles=poles, unstable_poles=unstable,
                         controller_poles=own, controller_unstable=controller_unstable,
                         reasons=reasons)
