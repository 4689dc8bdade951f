"""The stick-slip decisions and event location, written once for every kernel.

The single axis (:mod:`qzs.engine.kernels`, whose event-handling step also serves the
flagged lanes of :mod:`qzs.engine.lanes`) and the six coupled legs
(:mod:`qzs.engine.hexapod.stepping` around :mod:`qzs.engine.hexapod.dynamics`) follow one
stick-slip scheme (docs/model.md §4): a slipping leg is followed through its event value
``d v``, a locked one through its holding margin; a sign change inside a grid step is an
event, located by regula falsi on fresh Runge-Kutta steps from the step's start; there the
leg sticks if friction can hold it, or slips towards the net force. The decisions and the
location are here, once; each kernel supplies its dynamics (tuples of floats for one axis,
packed arrays for six legs) and calls them. Small functions of scalars, inlined by numba
where they are called (``inline="always"``), so a kernel compiles the very operations it
wrote out before, in the same order: the bits are unchanged.

What stays with each kernel, and why (docs/model.md §9, "One stepping core", with the
measurements):

- *which* events a step may hold and how many are handled: the single axis locates at most
  one transition per step (a slip's zero crossing, a plastic stop reached, a breakaway) and
  clamps a second plastic impact; the six legs locate up to ``MAX_EVENTS`` and switch legs
  that act alike together. A locked leg's margin that is negative at a step's start is
  released before the step on one axis and located at the start on six. Either change would
  change bits.
- settling: the six legs' complementarity loop (release the locked leg of largest excess,
  solve the others' holding forces again) has one leg on one axis, where it is the single
  decision of :func:`hold_margin` and :func:`release_direction` after the impulse that stops
  the slip;
- the Runge-Kutta stages: one tableau (:func:`qzs.engine.kernels.tableau`) and the same
  fused updates, but four loops over it, each shaped by what it steps: a tuple state with
  the right-hand side inlined once into the hot loop, a tuple state with the exact base
  motion around an event, six legs' arrays updated in place from the rate the last
  evaluation left, lanes stage by stage across cases. A generic loop taking the right-hand
  side and the update as function arguments compiled to the same machine code for the event
  paths but cost compile time (see docs/model.md §9).
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT as _JIT

__all__ = ["MODE_SLIP", "MODE_STICK", "MODE_WALL_LOW", "MODE_WALL_HIGH", "slip_event",
           "hold_margin", "release_direction", "crossed_zero", "secant_fraction",
           "illinois_step", "locate"]

#: Modes of a leg: slipping, stuck to the base by friction, resting on the lower or the
#: upper plastic stop (held by the stop and friction together).
MODE_SLIP, MODE_STICK, MODE_WALL_LOW, MODE_WALL_HIGH = 0, 1, 2, 3
#: Most refinements of an event's time (each one Runge-Kutta step).
LOCATE_ITERATIONS = 6


@njit(**_JIT, inline="always")
def slip_event(direction, v):
    """Event value of a slipping leg: ``d v`` [m/s], positive while it slips along ``d``.

    Parameters
    ----------
    direction : int or float
        Slip direction ``d`` [-], +1 or -1.
    v : float
        Slip velocity [m/s].

    Returns
    -------
    float
        ``direction * v``; its zero crossing is a stick or reversal event.
    """
    return direction * v


@njit(**_JIT, inline="always")
def hold_margin(mode, f_hold, fs):
    """How far the holding force is inside what friction (and a plastic stop) can give [N].

    Stuck: ``Fs - |F_hold|``. On the lower stop the stop takes any upward holding force, so
    only a downward one beyond ``Fs`` releases: ``F_hold + Fs``; on the upper stop
    ``Fs - F_hold``. Negative: the leg breaks away (:func:`release_direction`).

    Parameters
    ----------
    mode : int or float
        :data:`MODE_STICK`, :data:`MODE_WALL_LOW` or :data:`MODE_WALL_HIGH`.
    f_hold : float
        Force friction (and the stop) must supply to hold the leg [N].
    fs : float
        Static friction force ``Fs`` [N].

    Returns
    -------
    float
    """
    if mode == MODE_STICK:
        return fs - abs(f_hold)
    if mode == MODE_WALL_LOW:
        return f_hold + fs
    return fs - f_hold


@njit(**_JIT, inline="always")
def release_direction(mode, f_hold):
    """Slip direction of a leg that breaks away: towards the net force (friction continuous).

    Parameters
    ----------
    mode : int or float
        :data:`MODE_STICK`, :data:`MODE_WALL_LOW` or :data:`MODE_WALL_HIGH`.
    f_hold : float
        The holding force the leg needed [N].

    Returns
    -------
    int
        Stuck: ``-1`` if ``F_hold > 0`` else ``+1``; off the lower stop ``+1``, off the
        upper ``-1``.
    """
    if mode == MODE_STICK:
        return -1 if f_hold > 0.0 else 1
    return 1 if mode == MODE_WALL_LOW else -1


@njit(**_JIT, inline="always")
def crossed_zero(g0, g1):
    """Did a slip's event value reach zero in a step (``g0``, ``g1``: at its ends)?

    Parameters
    ----------
    g0, g1 : float
        :func:`slip_event` at the step's start and end.

    Returns
    -------
    bool
        ``g1 < 0``, or ``g1 == 0`` after a positive ``g0`` (a step that ends exactly at
        the crossing).
    """
    return g1 < 0.0 or (g1 == 0.0 and g0 > 0.0)


@njit(**_JIT, inline="always")
def secant_fraction(g0, g1):
    """Secant estimate of where in a step an event function falls from ``g0`` to ``g1``.

    Parameters
    ----------
    g0, g1 : float
        The event function at the step's start and end.

    Returns
    -------
    float
        ``g0 / (g0 - g1)`` if ``g0 > g1``, else 0 (the event at the start). Used to order
        events within a step; the event itself is located by :func:`locate`.
    """
    return g0 / (g0 - g1) if g0 > g1 else 0.0


@njit(**_JIT)
def illinois_step(at, g, g0, h, lo, hi, g_lo, g_hi, side):
    """One step of regula falsi (Illinois) on an event function ``g`` > 0 before the event.

    ``g`` is the value at the trial time ``at`` in the bracket ``[lo, hi]`` (values ``g_lo``
    > 0 and ``g_hi`` <= 0) of a step of length ``h`` whose event function started at ``g0``;
    ``side`` is the side the last trial fell on (0 at first). Converged when ``|g|`` is
    below 1e-15 of ``|g0|`` or the bracket below 1e-12 of ``h``; otherwise the bracket is
    narrowed, the retained end's value halved when the same side is kept twice (Illinois),
    and the next trial time is returned. Every driver's event location goes through it.

    Parameters
    ----------
    at : float
        Trial time from the step's start [s].
    g : float
        Event function at ``at``.
    g0 : float
        Event function at the step's start.
    h : float
        Step length [s].
    lo, hi : float
        The bracket [s].
    g_lo, g_hi : float
        Event function at its ends (the retained end's possibly halved).
    side : int
        Side of the last trial: 1 (kept ``lo``), -1 (kept ``hi``), 0 at first.

    Returns
    -------
    tuple
        ``(converged, at, lo, hi, g_lo, g_hi, side)``.
    """
    if abs(g) <= 1e-15 * (abs(g0) + 1e-300) or hi - lo <= 1e-12 * h:
        return True, at, lo, hi, g_lo, g_hi, side
    if g > 0.0:
        lo, g_lo = at, g
        if side == 1:
            g_hi *= 0.5
        side = 1
    else:
        hi, g_hi = at, g
        if side == -1:
            g_lo *= 0.5
        side = -1
    return False, lo + (hi - lo) * g_lo / (g_lo - g_hi), lo, hi, g_lo, g_hi, side


@njit(**_JIT, inline="always")
def locate(trial, data, g0, g1, h, state):
    """Locate an event inside a step of length ``h`` by regula falsi (Illinois).

    The first trial time is the secant's, ``h g0 / (g0 - g1)``; each trial is a fresh
    Runge-Kutta step of that length from the step's start, ``trial(at, data)``, whose event
    function then narrows the bracket (:func:`illinois_step`); at most
    :data:`LOCATE_ITERATIONS` trials, so that the event function is zero to round-off.
    Inlined where it is called, so that ``trial`` is a direct call and no function pointer
    is passed at run time (that would make the caller uncachable); each kernel calls it from
    one function of its own, so the loop is compiled once per kernel.

    Parameters
    ----------
    trial : numba function
        ``trial(at, data) -> (g, state)``: the state a Runge-Kutta step of length ``at`` [s]
        from the step's start reaches, and the event function there.
    data : tuple
        What ``trial`` needs besides ``at`` (the kernel's state and workspaces).
    g0, g1 : float
        The event function at the step's start (> 0, else the event is at the start) and
        end (<= 0).
    h : float
        Step length [s].
    state : object
        Returned as the state when the event is at the step's start (no trial made).

    Returns
    -------
    tuple
        ``(at, state)``: the event's time from the step's start [s] and the state of the
        last trial there.
    """
    if g0 <= 0.0:
        return 0.0, state
    lo, hi = 0.0, h
    g_lo, g_hi = g0, g1
    at = h * g0 / (g0 - g1)
    side = np.int64(0)  # not a literal: illinois_step compiles once, for int64
    for _ in range(LOCATE_ITERATIONS):
        g, state = trial(at, data)
        done, at, lo, hi, g_lo, g_hi, side = illinois_step(at, g, g0, h, lo, hi, g_lo, g_hi,
                                                           side)
        if done:
            break
    return at, state
