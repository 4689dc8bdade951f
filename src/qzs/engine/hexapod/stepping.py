"""The six-axis stepping: Runge-Kutta steps, events located inside them, output, the run.

Around the right-hand side of :mod:`qzs.engine.hexapod.dynamics`, in the scheme of the
single axis (:mod:`qzs.engine.kernels`): events (a slipping leg's ``d_i v_i`` or a locked
leg's margin ``Fs_i - |lambda_i|`` crossing zero) are located inside the step by regula
falsi, the step is split there, the modes are settled as a small complementarity problem
(largest excess released first, re-solved), and the step continues; at most
``MAX_EVENTS`` per step. Legs that act alike switch together (``SIMULTANEOUS``), so a
symmetric platform stays symmetric to rounding. :func:`_run` advances a run by grid steps
and records its output samples; it holds no GIL.
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT as _JIT
from qzs.engine.arithmetic import fma
from qzs.engine.hexapod.dynamics import (_advance_phases, _commands, _cross, _evaluate,
                                         _inertia_times, _linear_due, _matvec, _rest_frame,
                                         _sample, _sample_linear, _with_blocks)
from qzs.engine.hexapod.layout import (
    B_K1, B_K2, B_KE, B_KT, B_S, B_S1, B_TMP, B_TRIAL, C_ACC, C_BASE_ACC, C_BASE_POSE,
    C_BASE_VEL, C_DF, C_DS, C_EG, C_EK, C_ESP, C_EST, C_FCO, C_FDA, C_FDI, C_FFR, C_FLI,
    C_FMO, C_FOB, C_FPI, C_FSP, C_FST, S_X, V_FCO, V_FDI, V_FLI, V_FRESH,
    C_POSE, C_TIME, C_TWIST, C_V, C_VME, C_WB, C_WM, C_Z, CT_CONTACTS, CT_EVENTS,
    CT_IN_CONTACT, CT_STEP, CT_STICKS, LANES, LEG_COUNT, MODE_LOCK, MODE_SLIP,
    O_CONTACT, O_LOCKED, PL_CONTROL_STEPS, PL_CT, PL_G, PL_HOME, PL_IC, PL_MASS,
    PL_ROTATING, S_C, S_DF, S_DS, S_HP, S_V, S_W, S_WB, S_WM, STATUS_DIVERGED, STATUS_OK,
    STATUS_OUTSIDE, W_OUTSIDE,
    V_A, V_B, V_DIR, V_EV, V_FDA, V_FFR, V_FMO, V_FPI, V_FSP, V_FST, V_HDA, V_HMO, V_HPI,
    V_MODE, V_STOPK, V_V, V_VME, V_XB, V_Z, V_ZHIGH, V_ZLOW, W_ACC, W_AL, W_ALW, W_FSUM,
    W_GH, W_OM, W_OMW, W_RB, W_RR, W_VO, W_Y, W_YD, W_YDD)
from qzs.engine.kernels import (N_X, PHASE_PERIOD, X_OBSERVER, general_spring_energy, n_stages,
                                tableau)
from qzs.engine.laws import spring_energy_law
from qzs.engine.stickslip import MODE_STICK, crossed_zero, locate, release_direction, \
    secant_fraction

#: Flags for kernels called from kernels: a literal ``True``/``False`` would make numba compile
#: the callee once more for each literal value (``_evaluate`` three times: 20 s more compile).
_TRUE, _FALSE = np.bool_(True), np.bool_(False)
#: Most transitions located inside one grid step; more are caught at the next step's start.
MAX_EVENTS = 12
#: Most mode changes settled at one instant (the complementarity loop).
MAX_SETTLE = 24
#: Legs whose event value at a located transition is within this share of its value at the
#: (sub)step's start switch with the located leg (the location resolves 1e-12 of a step).
SIMULTANEOUS = 1e-9


# ---------------------------------------------------------------- Runge-Kutta
@njit(**_JIT)
def _rk(solver, t, h, s, k1, out, buf, plat, models, ex, tables, toff, ww, V, A, idx, vec):
    """One explicit Runge-Kutta step of length ``h`` from ``s`` (rate ``k1`` given) into ``out``.

    The diagonal tableau of :func:`qzs.engine.kernels.tableau` (euler, ode3, rk4); each update
    ``s + a k`` is one fused multiply-add, as in the single axis.
    """
    if models is not None:  # the state moves: a leg released at t slips now
        for i in range(LEG_COUNT):
            V[V_FRESH + i] = 0.0
    weight = tableau(solver, h, 0)[2]
    n = out.shape[0]  # N_ODE, or with the legs' blocks' states
    for j in range(n):
        out[j] = fma(weight, k1[j], s[j])
    previous = k1
    for stage in range(1, n_stages(solver)):
        offset, a, weight = tableau(solver, h, stage)
        tmp = buf[B_TMP]
        for j in range(n):
            tmp[j] = fma(a, previous[j], s[j])
        k = buf[B_K2 + stage - 1]
        _evaluate(t + offset, tmp, plat, models, ex, tables, toff, ww, V, A, idx, vec, k, _FALSE)
        for j in range(n):
            out[j] = fma(weight, k[j], out[j])
        previous = k


# ---------------------------------------------------------------- events and transitions
@njit(**_JIT)
def _first_event(V, ev0, ev1):
    """Leg (-1: none) and time fraction (secant) of the first transition in a (sub)step.

    Slipping leg: ``d v`` at the end negative (or reaching 0). Locked leg: margin at the end
    negative, or already negative at the start (missed earlier: released at once). An event
    value not positive at the start puts the event there.
    """
    best = 2.0
    leg = -1
    for i in range(LEG_COUNT):
        g0, g1 = ev0[i], ev1[i]
        if V[V_MODE + i] == MODE_SLIP:
            crossed = crossed_zero(g0, g1)
        else:
            crossed = g1 < 0.0 or g0 < 0.0
        theta = 2.0
        if crossed:
            theta = secant_fraction(g0, g1) if g0 > 0.0 else 0.0
        if theta < best:
            best = theta
            leg = i
    return leg, min(max(best, 0.0), 1.0)


@njit(**_JIT, inline="always")
def _event_trial(at, data):
    """The trial of :func:`qzs.engine.stickslip.locate`: a step of ``at`` [s], leg ``leg``'s event.

    ``data`` is ``(solver, leg, t, s, k1, buf, plat, models, ex, tables, toff, ww, V, A, idx,
    vec)``, the (sub)step's start; the state at ``t + at`` goes to ``buf[B_TRIAL]`` (the workspaces
    hold its evaluation). Returns the leg's event value there and True (a trial was made).
    """
    solver, leg, t, s, k1, buf, plat, models, ex, tables, toff, ww, V, A, idx, vec = data
    trial = buf[B_TRIAL]
    _rk(solver, t, at, s, k1, trial, buf, plat, models, ex, tables, toff, ww, V, A, idx, vec)
    _evaluate(t + at, trial, plat, models, ex, tables, toff, ww, V, A, idx, vec, buf[B_KT], _FALSE)
    return V[V_EV + leg], True


@njit(**_JIT)
def _locate(solver, leg, t, h, s, k1, g0, g1, buf, plat, models, ex, tables, toff, ww, V, A,
            idx, vec):
    """Leg ``leg``'s event located in ``[t, t + h]`` (:func:`qzs.engine.stickslip.locate`).

    Returns the time from ``t``: at most 6 Runge-Kutta steps from the (sub)step's start (each
    an :func:`_event_trial`); the state there is in ``buf[B_TRIAL]`` (``s`` when the event is
    at the start). A float, not the state array: returning the array to :func:`_grid_step`
    made the hexapod's every step slower (0.70 against 0.79 million steps per CPU second).
    """
    at, tried = locate(_event_trial, (solver, leg, t, s, k1, buf, plat, models, ex, tables, toff,
                                      ww, V, A, idx, vec), g0, g1, h, False)
    if not tried:
        trial = buf[B_TRIAL]
        for j in range(trial.shape[0]):
            trial[j] = s[j]
    return at


@njit(**_JIT, inline="always")
def _set_mode(V, i, mode, direction):
    """Mode and slip direction of leg ``i``, and of the padding lanes that copy leg 1; a leg
    released is marked ``FRESH`` (:func:`qzs.engine.hexapod.dynamics._slip`)."""
    V[V_MODE + i] = mode
    V[V_DIR + i] = direction
    V[V_FRESH + i] = 1.0 if mode == MODE_SLIP else 0.0
    if i == 0:
        for pad in range(LEG_COUNT, LANES):
            V[V_MODE + pad] = mode
            V[V_DIR + pad] = direction


@njit(**_JIT)
def _settle(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, newly):
    """Consistent modes at an instant: the complementarity loop of the locked legs.

    Repeatedly solve the locked legs' holding forces and release the one whose ``|lambda_i|``
    exceeds its ``Fs_i`` by most, slipping towards the net force (``d_i = -sign(lambda_i)``,
    friction continuous at ``Fs``), until every locked leg holds. With the other legs' modes
    fixed, a leg so released accelerates in ``d_i`` (its acceleration is a positive
    compliance times the excess ``|lambda_i| - Fs_i``); one that the later releases drive
    backwards is a zero crossing at the start of the next (sub)step. Ends with the
    right-hand side evaluated at ``(t, s)`` in the final modes (into ``d`` and the workspaces).
    """
    for _ in range(MAX_SETTLE):
        _evaluate(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, _TRUE)
        worst = -1
        excess = 0.0
        for i in range(LEG_COUNT):
            if V[V_MODE + i] != MODE_SLIP and V[V_EV + i] < excess:
                excess = V[V_EV + i]
                worst = i
        if worst < 0:
            return
        _set_mode(V, worst, MODE_SLIP, release_direction(MODE_STICK, V[V_FFR + worst]))
        newly[worst] = 0
    _evaluate(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, _TRUE)


@njit(**_JIT)
def _transition(leg, t, s, ev0, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, newly,
                counters):
    """Apply the located event of ``leg`` at ``(t, s)``, settle the modes, count stick events.

    A zero crossing locks the leg; a breakaway releases it towards the net force. Legs of the
    same mode whose event value there is no larger than the located leg's, to within
    ``SIMULTANEOUS`` of their value at the (sub)step's start ``ev0``, change with it: legs that
    act alike (a symmetric platform) switch together, whatever the rounding decided first.
    """
    for i in range(LEG_COUNT):
        newly[i] = 0
    _evaluate(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, _FALSE)
    crossing = V[V_MODE + leg] == MODE_SLIP
    level = max(V[V_EV + leg], 0.0)
    for i in range(LEG_COUNT):
        if (V[V_MODE + i] == MODE_SLIP) != crossing:
            continue
        if i == leg or V[V_EV + i] <= level + SIMULTANEOUS * abs(ev0[i]):
            if crossing:
                _set_mode(V, i, MODE_LOCK, V[V_DIR + i])
                newly[i] = 1
            else:
                _set_mode(V, i, MODE_SLIP, release_direction(MODE_STICK, V[V_FFR + i]))
    _settle(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, newly)
    for i in range(LEG_COUNT):
        if newly[i] != 0 and V[V_MODE + i] != MODE_SLIP:
            counters[CT_STICKS + i] += 1
    counters[CT_EVENTS] += 1


@njit(**_JIT)
def _grid_step(solver, t, h, buf, ev, plat, models, ex, tables, toff, ww, V, A, idx, vec, newly,
               counters):
    """Advance ``buf[B_S]`` (rate ``buf[B_K1]``, event values ``ev[0]``) by one grid step.

    Integrate the rest of the step in the current modes; if a transition falls inside, locate
    the first, split the step there, apply it and go on from there (at most ``MAX_EVENTS``
    times; beyond, transitions are caught at the next step's start). Ends with the state,
    its rate, its event values and the workspaces at ``t + h``.
    """
    s = buf[B_S]
    k1 = buf[B_K1]
    s1 = buf[B_S1]
    ke = buf[B_KE]
    elapsed = 0.0
    for events in range(MAX_EVENTS + 1):
        rest = h - elapsed
        _rk(solver, t + elapsed, rest, s, k1, s1, buf, plat, models, ex, tables, toff, ww, V, A,
            idx, vec)
        _evaluate(t + h, s1, plat, models, ex, tables, toff, ww, V, A, idx, vec, ke, _TRUE)
        for i in range(LEG_COUNT):
            ev[1, i] = V[V_EV + i]
        leg, theta = -1, 2.0
        if events < MAX_EVENTS:
            leg, theta = _first_event(V, ev[0], ev[1])
        if leg < 0:
            for j in range(s.shape[0]):
                s[j] = s1[j]
                k1[j] = ke[j]
            for i in range(LEG_COUNT):
                ev[0, i] = ev[1, i]
            return
        g0, g1 = ev[0, leg], ev[1, leg]
        at = _locate(solver, leg, t + elapsed, rest, s, k1, g0, g1, buf, plat, models, ex, tables,
                     toff, ww, V, A, idx, vec)
        trial = buf[B_TRIAL]
        for j in range(s.shape[0]):
            s[j] = trial[j]
        elapsed += at
        _transition(leg, t + elapsed, s, ev[0], plat, models, ex, tables, toff, ww, V, A, idx, vec,
                    k1, newly, counters)
        for i in range(LEG_COUNT):
            ev[0, i] = V[V_EV + i]
        if elapsed >= h:
            return


# ---------------------------------------------------------------- output
@njit(**_JIT, inline="always")
def _product(ww, i, j):
    """Entry ``(i, j)`` of ``R_b R_r``: the platform's orientation in the world."""
    return (ww[W_RB + 3 * i] * ww[W_RR + j] + ww[W_RB + 3 * i + 1] * ww[W_RR + 3 + j]
            + ww[W_RB + 3 * i + 2] * ww[W_RR + 6 + j])


@njit(**_JIT)
def _angles(ww):
    """``(rx, ry, rz)`` [rad] of ``R = R_b R_r = Rz Ry Rx``, as ``rotation_angles`` gives them."""
    r00, r10, r20 = _product(ww, 0, 0), _product(ww, 1, 0), _product(ww, 2, 0)
    cos_ry = np.hypot(r00, r10)
    ry = np.arctan2(-r20, cos_ry)
    if cos_ry > 1e-12:
        return np.arctan2(_product(ww, 2, 1), _product(ww, 2, 2)), ry, np.arctan2(r10, r00)
    return np.arctan2(-_product(ww, 1, 2), _product(ww, 1, 1)), ry, 0.0


@njit(**_JIT)
def _record(t, s, plat, models, ww, V, row, marks):
    """One output sample (``C_*`` channels, ``O_*`` flags) of the last evaluation at ``t``."""
    m = plat[PL_MASS]
    row[C_TIME] = t
    rotating = plat[PL_ROTATING] != 0.0
    for a in range(6):
        row[C_BASE_POSE + a] = ww[W_Y + a]
    for a in range(3):
        row[C_BASE_VEL + a] = ww[W_YD + a]
        row[C_BASE_VEL + 3 + a] = ww[W_OMW + a] if rotating else ww[W_YD + 3 + a]
        row[C_BASE_ACC + a] = ww[W_YDD + a]
        row[C_BASE_ACC + 3 + a] = ww[W_ALW + a] if rotating else ww[W_YDD + 3 + a]
    cx, cy, cz = s[S_C], s[S_C + 1], s[S_C + 2]
    rcx, rcy, rcz = _matvec(ww, W_RR, plat[PL_CT], plat[PL_CT + 1], plat[PL_CT + 2])
    ox, oy, oz = cx - rcx, cy - rcy, cz - rcz              # top frame origin in B
    px, py, pz = _matvec(ww, W_RB, ox, oy, oz)
    row[C_POSE] = ww[W_Y] + px
    row[C_POSE + 1] = ww[W_Y + 1] + py
    row[C_POSE + 2] = ww[W_Y + 2] + pz
    row[C_POSE + 3], row[C_POSE + 4], row[C_POSE + 5] = _angles(ww)
    vx, vy, vz = s[S_V], s[S_V + 1], s[S_V + 2]
    wx, wy, wz = s[S_W], s[S_W + 1], s[S_W + 2]
    obx, oby, obz = ww[W_OM], ww[W_OM + 1], ww[W_OM + 2]
    # velocity of the top frame origin and angular velocity, then the COM's (energy)
    t1 = _cross(wx, wy, wz, rcx, rcy, rcz)
    t2 = _cross(obx, oby, obz, ox, oy, oz)
    vox = ww[W_VO] + t2[0] + vx - t1[0]
    voy = ww[W_VO + 1] + t2[1] + vy - t1[1]
    voz = ww[W_VO + 2] + t2[2] + vz - t1[2]
    Wx, Wy, Wz = obx + wx, oby + wy, obz + wz
    row[C_TWIST], row[C_TWIST + 1], row[C_TWIST + 2] = _matvec(ww, W_RB, vox, voy, voz)
    row[C_TWIST + 3], row[C_TWIST + 4], row[C_TWIST + 5] = _matvec(ww, W_RB, Wx, Wy, Wz)
    # accelerations: the COM's from Newton, the angular one, then the top frame origin's
    acx = ww[W_FSUM] / m - plat[PL_G] * ww[W_GH]
    acy = ww[W_FSUM + 1] / m - plat[PL_G] * ww[W_GH + 1]
    acz = ww[W_FSUM + 2] / m - plat[PL_G] * ww[W_GH + 2]
    t3 = _cross(obx, oby, obz, wx, wy, wz)
    dWx = ww[W_AL] + ww[W_ACC + 3] + t3[0]
    dWy = ww[W_AL + 1] + ww[W_ACC + 4] + t3[1]
    dWz = ww[W_AL + 2] + ww[W_ACC + 5] + t3[2]
    t4 = _cross(dWx, dWy, dWz, -rcx, -rcy, -rcz)
    t5 = _cross(Wx, Wy, Wz, -rcx, -rcy, -rcz)
    t6 = _cross(Wx, Wy, Wz, t5[0], t5[1], t5[2])
    row[C_ACC], row[C_ACC + 1], row[C_ACC + 2] = _matvec(
        ww, W_RB, acx + t4[0] + t6[0], acy + t4[1] + t6[1], acz + t4[2] + t6[2])
    row[C_ACC + 3], row[C_ACC + 4], row[C_ACC + 5] = _matvec(ww, W_RB, dWx, dWy, dWz)
    spring, stop = 0.0, 0.0
    for i in range(LEG_COUNT):
        z = V[V_Z + i]
        row[C_Z + i] = z
        row[C_V + i] = V[V_V + i]
        row[C_FSP + i] = V[V_FSP + i]
        row[C_FFR + i] = V[V_FFR + i]
        row[C_FST + i] = V[V_FST + i]
        row[C_FMO + i] = V[V_FMO + i]
        row[C_FPI + i] = V[V_FPI + i]
        row[C_FDA + i] = V[V_FDA + i]
        row[C_VME + i] = V[V_VME + i]
        if models is None:  # the MagSpring's tanh on every leg
            spring += spring_energy_law(V[V_A + i], V[V_B + i], z)
        else:  # each leg's own law (docs/model.md §3.1)
            spring += general_spring_energy(models[i], z)
        pen = max(V[V_ZLOW + i] - z, 0.0) + max(z - V[V_ZHIGH + i], 0.0)
        stop += 0.5 * V[V_STOPK + i] * pen * pen
        marks[O_LOCKED + i] = V[V_MODE + i] != MODE_SLIP
        marks[O_CONTACT + i] = z < V[V_ZLOW + i] or z > V[V_ZHIGH + i]
    if models is not None:  # pruned by type without blocks and laws
        if _with_blocks(models):  # a row without blocks holds N_BASE_CHANNELS
            for i in range(LEG_COUNT):
                row[C_FCO + i] = V[V_FCO + i]
                row[C_FOB + i] = s[S_X + i * N_X + X_OBSERVER]
                row[C_FDI + i] = V[V_FDI + i]
                row[C_FLI + i] = V[V_FLI + i]
    row[C_WB] = s[S_WB]
    row[C_DF] = s[S_DF]
    row[C_WM] = s[S_WM]
    row[C_DS] = s[S_DS]
    t7 = _cross(obx, oby, obz, cx, cy, cz)
    Vx, Vy, Vz = ww[W_VO] + t7[0] + vx, ww[W_VO + 1] + t7[1] + vy, ww[W_VO + 2] + t7[2] + vz
    hx, hy, hz = _inertia_times(ww, plat, PL_IC, Wx, Wy, Wz)
    row[C_EK] = 0.5 * m * (Vx * Vx + Vy * Vy + Vz * Vz) + 0.5 * (Wx * hx + Wy * hy + Wz * hz)
    row[C_ESP] = spring
    height = plat[PL_HOME + 2] + ww[W_Y + 2] + ww[W_RB + 6] * cx + ww[W_RB + 7] * cy \
        + ww[W_RB + 8] * cz
    row[C_EG] = m * plat[PL_G] * height
    row[C_EST] = stop


# ---------------------------------------------------------------- the drivers
@njit(**_JIT)
def _finite(s):
    """Divergence test: every state entry finite (the blocks' too), relative speed below
    1e4 m/s."""
    for j in range(s.shape[0]):
        if not np.isfinite(s[j]):
            return False
    for a in range(3):
        if abs(s[S_V + a]) > 1e4:
            return False
    return True


@njit(**_JIT)
def _start(s, plat, models, ex, tables, toff, buf, ev, ww, V, A, idx, vec, newly, counters, row,
           marks):
    """Settle the modes at t = 0 from all legs locked; evaluate; record the first sample.

    The amplifiers' high-passes start settled (``w_i = xd_i(0)``, measured velocity 0); a
    sampled controller holds its outputs at ``t = 0`` (its first sample, which also advances
    the integrals, is at the start of the first step, as in the single axis).
    """
    for i in range(LEG_COUNT):
        _set_mode(V, i, MODE_LOCK, 1.0)
        newly[i] = 0
    _rest_frame(ww)
    _advance_phases(0.0, _TRUE, plat, ex, ww)
    _evaluate(0.0, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], _FALSE)
    for i in range(LEG_COUNT):
        s[S_HP + i] = V[V_XB + i]
    if plat[PL_CONTROL_STEPS] > 0.0:  # a sampled controller's outputs at t = 0, held
        _evaluate(0.0, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], _FALSE)
        _commands(plat, ww, V)
        for i in range(LANES):
            V[V_HPI + i] = V[V_FPI + i]
            V[V_HDA + i] = V[V_FDA + i]
            V[V_HMO + i] = V[V_FMO + i]
    _settle(0.0, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], newly)
    for j in range(s.shape[0]):
        buf[B_S, j] = s[j]
    for i in range(LEG_COUNT):
        ev[0, i] = V[V_EV + i]
        counters[CT_IN_CONTACT + i] = 1 if (V[V_Z + i] < V[V_ZLOW + i]
                                            or V[V_Z + i] > V[V_ZHIGH + i]) else 0
    _record(0.0, s, plat, models, ww, V, row, marks)


@njit(**_JIT, nogil=True)
def _run(solver, n_steps, decimation, h, s, plat, models, ex, tables, toff, buf, ev, ww, V, A,
         idx, vec, newly, counters, out, out_flags, row0):
    """Advance ``n_steps`` grid steps, recording every ``decimation``-th into ``out`` from ``row0``.

    The carried state (``buf[B_S]``, its rate ``buf[B_K1]``, event values ``ev[0]``, modes,
    counters and workspaces) persists in the arrays between calls, so cutting a run into
    calls changes nothing. Returns ``(status, rows written)``; ``s`` receives the state.
    Holds no GIL: platforms of a batch run in threads (:func:`simulate_hexapods`).
    """
    status = STATUS_OK
    row = row0
    step = counters[CT_STEP]
    control_steps = int(plat[PL_CONTROL_STEPS])
    for _ in range(n_steps):
        _advance_phases(step * h, step % PHASE_PERIOD == 0, plat, ex, ww)
        sampled = control_steps > 0 and step % control_steps == 0
        if sampled:
            _sample(step * h, plat, models, ww, V, buf[B_S], h)
        if models is not None and _linear_due(models, step):
            # a leg's discrete linear controller reads its sensors with the outputs the PI
            # and its blocks hold from now (they sample first, docs/model.md §5.1)
            _evaluate(step * h, buf[B_S], plat, models, ex, tables, toff, ww, V, A, idx, vec,
                      buf[B_KE], _FALSE)
            _sample_linear(step, models, V, buf[B_S])
            sampled = True
        if sampled:
            # a sample: the held outputs jump, so the modes are settled again (a locked leg
            # may break away right here) and the rate and event values are those after it
            _settle(step * h, buf[B_S], plat, models, ex, tables, toff, ww, V, A, idx, vec,
                    buf[B_K1], newly)
            for i in range(LEG_COUNT):
                ev[0, i] = V[V_EV + i]
        _grid_step(solver, step * h, h, buf, ev, plat, models, ex, tables, toff, ww, V, A, idx, vec,
                   newly, counters)
        if not _finite(buf[B_S]):
            status = STATUS_DIVERGED
            if models is not None and ww[W_OUTSIDE] != 0.0:
                status = STATUS_OUTSIDE  # the leg and where: ww[W_OUTSIDE:]
            break
        if models is not None and ww[W_OUTSIDE] != 0.0:
            # a refusing table's NaN marked in a trial the step did not keep: cleared once the
            # leg's force at the step's end is a number (else the rate carried to the next
            # step is NaN, and that step fails with the mark)
            if not np.isnan(V[V_FSP + int(ww[W_OUTSIDE]) - 1]):
                ww[W_OUTSIDE] = 0.0
        step += 1
        for i in range(LEG_COUNT):
            z = V[V_Z + i]
            now = 1 if (z < V[V_ZLOW + i] or z > V[V_ZHIGH + i]) else 0
            if now == 1 and counters[CT_IN_CONTACT + i] == 0:
                counters[CT_CONTACTS + i] += 1
            counters[CT_IN_CONTACT + i] = now
        if step % decimation == 0:
            _record(step * h, buf[B_S], plat, models, ww, V, out[row], out_flags[row])
            row += 1
    counters[CT_STEP] = step
    for j in range(s.shape[0]):
        s[j] = buf[B_S, j]
    return status, row - row0


# Stale cached kernels of this module are dropped with the others (qzs.engine.arithmetic:
# "hexapod/stepping" is one of its _KERNEL_MODULES).
