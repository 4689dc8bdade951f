"""The driver kernels: advance one case, or a batch of cases in lockstep.

Every case of a batch takes the same grid step at the same time, so the base
motion at the Runge-Kutta stages is computed once per step for all of them. The
cases are held structure-of-arrays (one row per quantity, one column, a *lane*,
per case) and each step is two passes over the lanes:

1. the Runge-Kutta step of every lane, stage by stage, in short loops that LLVM
   vectorises (several lanes per instruction). A lane is flagged, and left as
   it was, when it needs more: a transition inside the step (stick, slip,
   impact), a holding margin not known yet, or a non-finite state;
2. for the flagged lanes only, the full event-locating step of
   :func:`qzs.engine.kernels.grid_step`.

At an output sample, one more vectorised pass computes the channels of every lane
(:func:`_sample_lanes`, the operations of :func:`qzs.engine.kernels.record`), and only the
channels the caller asks for are stored (:func:`_keep`).

No fast-math is used (see :mod:`qzs.engine.kernels`): a lane computes the same bits
in a vector register as in scalar code, and pass 1 takes the same operations in
the same order as :func:`qzs.engine.kernels.grid_step` does for an ordinary step. So
:func:`run_single`, the one-case driver that steps with ``grid_step`` alone,
and :func:`run_lanes` give identical numbers, whatever the other lanes are.
"""
import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from qzs.engine import kernels as K
from qzs.engine.base_motion import advance_phase, base_motion_near, excitation_tuple
from qzs.engine.stickslip import hold_margin, slip_event

# Rows of the lane-state array: the persistent state (``K.S_*`` and ``K.A_*``) first.
R_MARGIN = K.A_MARGIN  # the holding margin is part of the persistent state
(R_MODE, R_DIRECTION, R_CONTACT, R_CONTACTS, R_STICKS,
 R_FAILED, R_BLOCKS) = range(K.N_STATE, K.N_STATE + 7)
N_ROWS = K.N_STATE + 7
# Rows of the per-step scratch array: the running weighted sum, the stage input, the flag. (A
# lane whose controller has blocks beyond PI + damping, with states of their own, steps in
# pass 2.)
T_SUM, T_INPUT, T_FLAGGED = 0, K.N_ODE, K.N_ODE + 4
N_SCRATCH = K.N_ODE + 5
# Rows of a sample's scratch array: the output channels (``K.C_*``), then the two flags.
Q_LOCKED, Q_CONTACT = K.N_CHANNELS + K.O_LOCKED, K.N_CHANNELS + K.O_CONTACT
N_RECORD = K.N_CHANNELS + 2
#: Most lanes per call. Lane arrays are flat, row ``i`` of lane ``c`` at ``i * W + c``
#: with the row stride ``W`` a compile-time constant: LLVM then sees that the rows of
#: an array cannot overlap and vectorises the lane loops with two overlap checks. ``W``
#: is not a power of two so that a lane's rows fall in different cache sets.
MAX_LANES = 1024
W = MAX_LANES + 8
STATUS_TOO_MANY_LANES = -1
#: Pass 1 runs over a multiple of ``LANE_BLOCK`` lanes when the remainder holds at least
#: ``PAD_FROM`` lanes: LLVM's vectorised lane loops take 4 lanes per AVX2 instruction, two
#: instructions per iteration, and leave the remainder to scalar code, where a lane costs
#: about as much as the one-case kernel's step (120-140 ns here) against 60-70 ns in the
#: vector loop. A call with 7 cases (the paper's 14 distinct cases on 2 cores) ran them all
#: in the remainder, 920-980 ns a step; padded to 8, 530 ns. A smaller remainder costs less
#: than the padding. The padding lanes are frozen copies of lane 0: failed lanes, computed
#: in pass 1 and never stored, stepped, recorded or returned.
LANE_BLOCK = 8
PAD_FROM = 3
assert MAX_LANES % LANE_BLOCK == 0
#: Pass 1 is compiled in variants, each with a value a call can fix as a constant, so
#: that LLVM drops the code it makes unreachable (the same bits either way):
#: ``exact``, every lane of the call has the exact stick-slip friction (``P_VREG = 0``,
#: fixed for the call): the stages skip the regularised friction's ``tanh``, a third
#: ``exp`` per stage; ``slipping``, no lane is locked (stuck or resting) at this step (the
#: modes change in pass 2 only): the end of the step skips the holding margin.
assert K.P_VREG == K.N_PARAMS - 1  # the last entry of _params

_JIT = K._JIT
# grid_step inlined into the one-case driver, where it is the hot path
_grid_step_inline = njit(**_JIT, inline="always")(getattr(K.grid_step, "py_func", K.grid_step))


@intrinsic
def _at(typingctx, row, c):
    """Index ``row * W + c`` of row ``row``, lane ``c`` in a lane array, unsigned.

    numba adds a negative-index wraparound to a signed index; LLVM folds it away in
    small lane loops, but not in the stage loops once the regularised friction's third
    ``exp`` made them larger, and it then stopped vectorising them. An unsigned index
    has none. An intrinsic (two instructions in place) rather than an inlined function:
    numba's inlining of its hundred uses cost 10 s of compiling.
    """
    if not (isinstance(row, types.Integer) and isinstance(c, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        i64 = ir.IntType(64)
        row_, c_ = (context.cast(builder, value, kind, types.int64)
                    for value, kind in zip(args, signature.args))
        return builder.add(builder.mul(row_, ir.Constant(i64, W)), c_)
    return types.uint64(row, c), codegen


@njit(**_JIT, inline="always")
def _params(PP, c, exact=False):
    """The parameter tuple of lane ``c`` (``K.P_*``); ``P_VREG`` the constant 0 if ``exact``."""
    v_reg = 0.0 if exact else PP[_at(K.P_VREG, c)]
    return (PP[_at(0, c)], PP[_at(1, c)], PP[_at(2, c)], PP[_at(3, c)], PP[_at(4, c)],
            PP[_at(5, c)], PP[_at(6, c)], PP[_at(7, c)], PP[_at(8, c)], PP[_at(9, c)],
            PP[_at(10, c)], PP[_at(11, c)], PP[_at(12, c)], PP[_at(13, c)], PP[_at(14, c)],
            PP[_at(15, c)], PP[_at(16, c)], PP[_at(17, c)], PP[_at(18, c)], PP[_at(19, c)],
            PP[_at(20, c)], v_reg)


@njit(**_JIT, inline="always")
def _state(L, c):
    return (L[_at(0, c)], L[_at(1, c)], L[_at(2, c)], L[_at(3, c)], L[_at(4, c)],
            L[_at(5, c)], L[_at(6, c)], L[_at(7, c)])


@njit(**_JIT, inline="always")
def _blocks(L, c):
    """Lane ``c``'s controller blocks' state (``K.X_*``)."""
    a = K.A_X0
    return (L[_at(a, c)], L[_at(a + 1, c)], L[_at(a + 2, c)], L[_at(a + 3, c)],
            L[_at(a + 4, c)], L[_at(a + 5, c)], L[_at(a + 6, c)], L[_at(a + 7, c)],
            L[_at(a + 8, c)])


@njit(**_JIT, inline="always")
def _store_blocks(L, c, x):
    a = K.A_X0
    (L[_at(a, c)], L[_at(a + 1, c)], L[_at(a + 2, c)], L[_at(a + 3, c)], L[_at(a + 4, c)],
     L[_at(a + 5, c)], L[_at(a + 6, c)], L[_at(a + 7, c)], L[_at(a + 8, c)]) = x


@njit(**_JIT, inline="always")
def _held(L, c):
    return (L[_at(K.A_F_PI, c)], L[_at(K.A_F_DAMP, c)], L[_at(K.A_F_MOTOR, c)],
            L[_at(K.A_F_COMPENSATION, c)], L[_at(K.A_F_DITHER, c)], L[_at(K.A_F_LINEAR, c)])


@njit(**_JIT, inline="always")
def _finite(s, P):
    """The divergence test: finite, within 100 strokes of the stops and below 1e4 m/s."""
    bound = 100.0 * (P[K.P_Z_HIGH] - P[K.P_Z_LOW]) + abs(P[K.P_Z_LOW]) + abs(P[K.P_Z_HIGH])
    return (np.isfinite(s[K.S_Z]) and np.isfinite(s[K.S_V]) and np.isfinite(s[K.S_HP])
            and np.isfinite(s[K.S_INT]) and abs(s[K.S_Z]) <= bound and abs(s[K.S_V]) <= 1e4)


@njit(**_JIT, inline="always")
def _finite_blocks(x):
    """The controller blocks' states are finite (an unstable controller diverges)."""
    finite = True
    for i in range(K.N_X):
        finite = finite and np.isfinite(x[i])
    return finite


@njit(**_JIT, inline="always")
def _store(L, c, s, margin, contact, P):
    """Put the end-of-step state of lane ``c``; counts a new compliant-stop contact."""
    (L[_at(0, c)], L[_at(1, c)], L[_at(2, c)], L[_at(3, c)], L[_at(4, c)], L[_at(5, c)],
     L[_at(6, c)], L[_at(7, c)]) = s
    L[_at(R_MARGIN, c)] = margin
    new_contact = contact and L[_at(R_CONTACT, c)] == 0.0 and P[K.P_PLASTIC] == 0.0
    L[_at(R_CONTACT, c)] = 1.0 if contact else 0.0
    L[_at(R_CONTACTS, c)] += 1.0 if new_contact else 0.0


@njit(**_JIT, inline="always")
def _stage_lanes(exact, n, a_next, weight, base, L, T, PP, M0, source, at_input, at_sum):
    """One Runge-Kutta stage of every lane: ``k`` at the stage input, added to the sum.

    The stage input and the running sum are read from ``source`` (rows from
    ``at_input`` and ``at_sum``): the state itself for the first stage, the
    scratch array ``T`` after. Then the next stage's input ``s + a_next * k`` goes
    to ``T``. The right-hand side reads the motion states only (z, v, filter,
    integral); the ledger rates just add up. The controller is PI + damping alone here
    (``M0``, no blocks): a lane with blocks is stepped in pass 2.
    """
    for c in range(n):
        x = (source[_at(at_input, c)], source[_at(at_input + 1, c)],
             source[_at(at_input + 2, c)], source[_at(at_input + 3, c)], 0.0, 0.0, 0.0, 0.0)
        k = K.rhs(0.0, base[0], base[1], base[2], x, K._NO_RATES, int(L[_at(R_MODE, c)]),
                  L[_at(R_DIRECTION, c)], _held(L, c), _params(PP, c, exact), M0, False)[0]
        T[_at(T_SUM, c)] = K.fma(weight, k[0], source[_at(at_sum, c)])
        T[_at(T_SUM + 1, c)] = K.fma(weight, k[1], source[_at(at_sum + 1, c)])
        T[_at(T_SUM + 2, c)] = K.fma(weight, k[2], source[_at(at_sum + 2, c)])
        T[_at(T_SUM + 3, c)] = K.fma(weight, k[3], source[_at(at_sum + 3, c)])
        T[_at(T_SUM + 4, c)] = K.fma(weight, k[4], source[_at(at_sum + 4, c)])
        T[_at(T_SUM + 5, c)] = K.fma(weight, k[5], source[_at(at_sum + 5, c)])
        T[_at(T_SUM + 6, c)] = K.fma(weight, k[6], source[_at(at_sum + 6, c)])
        T[_at(T_SUM + 7, c)] = K.fma(weight, k[7], source[_at(at_sum + 7, c)])
        T[_at(T_INPUT, c)] = K.fma(a_next, k[0], L[_at(0, c)])
        T[_at(T_INPUT + 1, c)] = K.fma(a_next, k[1], L[_at(1, c)])
        T[_at(T_INPUT + 2, c)] = K.fma(a_next, k[2], L[_at(2, c)])
        T[_at(T_INPUT + 3, c)] = K.fma(a_next, k[3], L[_at(3, c)])


@njit(**_JIT, inline="always")
def _finish_lanes(slipping, n, b_end, L, T, PP, M0):
    """End the step of every lane: store it, or flag the lane for pass 2.

    What :func:`qzs.engine.kernels.grid_step` does after its Runge-Kutta step when
    nothing happens in it. A flagged lane keeps its state at ``t``. ``slipping``: no
    lane is held, so none needs its holding margin. Returns how many lanes pass 2
    has to step: the flagged ones that have not failed (a failed or padding lane
    is flagged at every step and left as it is; so is a lane with controller blocks).
    """
    flagged_lanes = 0
    for c in range(n):
        s = _state(L, c)
        s1 = (T[_at(T_SUM, c)], T[_at(T_SUM + 1, c)], T[_at(T_SUM + 2, c)],
              T[_at(T_SUM + 3, c)], T[_at(T_SUM + 4, c)], T[_at(T_SUM + 5, c)],
              T[_at(T_SUM + 6, c)], T[_at(T_SUM + 7, c)])
        P = _params(PP, c)
        mode = K.MODE_SLIP if slipping else int(L[_at(R_MODE, c)])
        direction = L[_at(R_DIRECTION, c)]
        margin = L[_at(R_MARGIN, c)]
        margin1 = np.nan
        if mode != K.MODE_SLIP:
            force = K.rhs(0.0, b_end[0], b_end[1], b_end[2], s1, K._NO_RATES, K.MODE_STICK, 0.0,
                          _held(L, c), P, M0, False)[1]
            margin1 = hold_margin(mode, force[K.F_HOLD], P[K.P_FS])
        if mode == K.MODE_SLIP:  # no zero crossing missed (none is tracked when regularised)
            ready = P[K.P_VREG] > 0.0 or slip_event(direction, s[K.S_V]) >= 0.0
        else:
            ready = margin >= 0.0
        failed = L[_at(R_FAILED, c)] != 0.0 or L[_at(R_BLOCKS, c)] != 0.0
        flagged = (not ready or K._any_event(s, s1, mode, direction, margin1, P)
                   or not _finite(s1, P) or failed)
        T[_at(T_FLAGGED, c)] = 1.0 if flagged else 0.0
        flagged_lanes += flagged and L[_at(R_FAILED, c)] == 0.0  # a failed lane is left alone
        if not flagged:
            _store(L, c, s1, margin1, K._in_contact(s1, mode, P), P)
    return flagged_lanes


# Each loop of pass 1 is a function of its own per variant: one function holding all three
# loops took LLVM ten times as long to compile.
@njit(**_JIT)
def _first_stage_exact(n, a_next, weight, base, L, T, PP, M0):
    _stage_lanes(True, n, a_next, weight, base, L, T, PP, M0, L, 0, 0)


@njit(**_JIT)
def _stage_exact(n, a_next, weight, base, L, T, PP, M0):
    _stage_lanes(True, n, a_next, weight, base, L, T, PP, M0, T, T_INPUT, T_SUM)


@njit(**_JIT)
def _first_stage_any(n, a_next, weight, base, L, T, PP, M0):
    _stage_lanes(False, n, a_next, weight, base, L, T, PP, M0, L, 0, 0)


@njit(**_JIT)
def _stage_any(n, a_next, weight, base, L, T, PP, M0):
    _stage_lanes(False, n, a_next, weight, base, L, T, PP, M0, T, T_INPUT, T_SUM)


@njit(**_JIT)
def _finish_slipping(n, b_end, L, T, PP, M0):
    return _finish_lanes(True, n, b_end, L, T, PP, M0)


@njit(**_JIT)
def _finish_any(n, b_end, L, T, PP, M0):
    return _finish_lanes(False, n, b_end, L, T, PP, M0)


@njit(**_JIT, inline="always")
def _write_channels(Q, c, t, s, mode, force, P):
    """Lane ``c``'s channels but the energies, from its state and forces, into ``Q``."""
    v = s[K.S_V] if mode == K.MODE_SLIP else 0.0
    Q[_at(K.C_TIME, c)] = t
    Q[_at(K.C_BASE_Y, c)] = force[K.F_Y]
    Q[_at(K.C_BASE_YD, c)] = force[K.F_YD]
    Q[_at(K.C_BASE_YDD, c)] = force[K.F_YDD]
    Q[_at(K.C_X, c)] = force[K.F_Y] + s[K.S_Z]
    Q[_at(K.C_XD, c)] = force[K.F_YD] + v
    Q[_at(K.C_XDD, c)] = force[K.F_XDD]
    Q[_at(K.C_Z, c)] = s[K.S_Z]
    Q[_at(K.C_V, c)] = v
    Q[_at(K.C_F_SPRING, c)] = force[K.F_SPRING]
    Q[_at(K.C_F_FRICTION, c)] = force[K.F_FRICTION]
    Q[_at(K.C_F_STOP, c)] = force[K.F_STOP]
    Q[_at(K.C_F_MOTOR, c)] = force[K.F_MOTOR]
    Q[_at(K.C_F_PI, c)] = force[K.F_PI]
    Q[_at(K.C_F_DAMP, c)] = force[K.F_DAMP]
    Q[_at(K.C_V_MEASURED, c)] = force[K.F_V_MEASURED]
    Q[_at(K.C_W_BASE, c)] = s[K.S_W_BASE]
    Q[_at(K.C_D_FRICTION, c)] = s[K.S_D_FRICTION]
    Q[_at(K.C_W_MOTOR, c)] = s[K.S_W_MOTOR]
    Q[_at(K.C_D_STOP, c)] = s[K.S_D_STOP]
    Q[_at(K.C_F_COMPENSATION, c)] = force[K.F_COMPENSATION]
    Q[_at(K.C_F_DITHER, c)] = force[K.F_DITHER]
    Q[_at(K.C_F_LINEAR, c)] = force[K.F_LINEAR]
    Q[_at(K.C_F_OBSERVER, c)] = force[K.F_OBSERVER]
    Q[_at(Q_LOCKED, c)] = 1.0 if mode != K.MODE_SLIP else 0.0
    Q[_at(Q_CONTACT, c)] = 1.0 if K._in_contact(s, mode, P) else 0.0


@njit(**_JIT, inline="always")
def _sample_lanes(exact, n, t, base, L, PP, M0, Q):
    """The output channels of every lane at a sample, but the energies, into ``Q``.

    What :func:`qzs.engine.kernels.record` computes, with the same operations in the same
    order (the right-hand side's forces at the state), lane by lane in a loop LLVM
    vectorises; the caller keeps the channels it wants (:func:`_keep`). The controller is
    PI + damping alone here (``M0``); :func:`_sample_blocks` writes the lanes with blocks.
    """
    for c in range(n):
        s = _state(L, c)
        mode = int(L[_at(R_MODE, c)])
        P = _params(PP, c, exact)
        force = K.rhs(t, base[0], base[1], base[2], s, K._NO_RATES, mode,
                      L[_at(R_DIRECTION, c)], _held(L, c), P, M0, False)[1]
        _write_channels(Q, c, t, s, mode, force, P)


@njit(**_JIT)
def _sample_exact(n, t, base, L, PP, M0, Q):
    _sample_lanes(True, n, t, base, L, PP, M0, Q)


@njit(**_JIT)
def _sample_any(n, t, base, L, PP, M0, Q):
    _sample_lanes(False, n, t, base, L, PP, M0, Q)


@njit(**_JIT)
def _sample_blocks(n, t, base, L, PP, models, Q):
    """The channels of the lanes whose controller has blocks, lane by lane, with the blocks
    (over what the vectorised pass wrote for them)."""
    for c in range(n):
        if L[_at(R_BLOCKS, c)] == 0.0 or L[_at(R_FAILED, c)] != 0.0:
            continue
        s = _state(L, c)
        mode = int(L[_at(R_MODE, c)])
        P = _params(PP, c)
        force = K.rhs(t, base[0], base[1], base[2], s, _blocks(L, c), mode,
                      L[_at(R_DIRECTION, c)], _held(L, c), P, models[c], True)[1]
        _write_channels(Q, c, t, s, mode, force, P)


@njit(**_JIT)
def _keep(exact, n, t, base, L, PP, M0, models, blocks, Q, columns, energies, out, out_flags,
          lane0, row):
    """Record a sample: the channels ``columns`` and both flags of every lane that has not
    failed, to ``out[column, lane0 + c, row]`` and ``out_flags[flag, lane0 + c, row]``.

    The same numbers as :func:`qzs.engine.kernels.record`: the channels from one vectorised
    pass (:func:`_sample_lanes`), the energies (libm's ``exp`` and ``log1p``) lane by lane
    and only when ``energies`` (a column asks for them).
    """
    if exact:
        _sample_exact(n, t, base, L, PP, M0, Q)
    else:
        _sample_any(n, t, base, L, PP, M0, Q)
    if blocks:
        _sample_blocks(n, t, base, L, PP, models, Q)
    if energies:
        for c in range(n):
            if L[_at(R_FAILED, c)] == 0.0:
                (Q[_at(K.C_E_KINETIC, c)], Q[_at(K.C_E_SPRING, c)], Q[_at(K.C_E_GRAVITY, c)],
                 Q[_at(K.C_E_STOP, c)]) = K.energies(base[0], base[1], _state(L, c),
                                                      int(L[_at(R_MODE, c)]), _params(PP, c),
                                                      models[c])
    for k in range(columns.size):
        column = columns[k]
        for c in range(n):
            if L[_at(R_FAILED, c)] == 0.0:
                out[column, lane0 + c, row] = Q[_at(column, c)]
    for c in range(n):
        if L[_at(R_FAILED, c)] == 0.0:
            out_flags[K.O_LOCKED, lane0 + c, row] = Q[_at(Q_LOCKED, c)] != 0.0
            out_flags[K.O_CONTACT, lane0 + c, row] = Q[_at(Q_CONTACT, c)] != 0.0


@njit(**_JIT)
def _vector_pass(exact, slipping, solver, n, h, L, T, PP, M0, bases, b_end):
    """Pass 1: the Runge-Kutta step of every lane; returns how many lanes it flagged.

    Stage by stage (``K.tableau``, in the order of ``K.rk_step``) with the
    intermediate values in ``T``: each loop is short, its iterations independent,
    and LLVM vectorises it. ``exact`` and ``slipping`` pick the variants (see above).
    """
    stages = K.n_stages(solver)
    for stage in range(stages):
        weight = K.tableau(solver, h, stage)[2]
        a_next = K.tableau(solver, h, stage + 1)[1] if stage + 1 < stages else 0.0
        base = bases[stage]
        if stage == 0:
            if exact:
                _first_stage_exact(n, a_next, weight, base, L, T, PP, M0)
            else:
                _first_stage_any(n, a_next, weight, base, L, T, PP, M0)
        elif exact:
            _stage_exact(n, a_next, weight, base, L, T, PP, M0)
        else:
            _stage_any(n, a_next, weight, base, L, T, PP, M0)
    if slipping:
        return _finish_slipping(n, b_end, L, T, PP, M0)
    return _finish_any(n, b_end, L, T, PP, M0)


@njit(**_JIT, inline="always")
def _sample_times(step, control_steps, linear_steps):
    """Does the sampled controller (PI and its blocks), and does a discrete linear
    controller, sample at ``step``?"""
    return (control_steps > 0 and step % control_steps == 0,
            linear_steps > 0 and step % linear_steps == 0)


@njit(**_JIT, nogil=True)
def run_lanes(solver, step0, n_steps, decimation, states, flags, params, models, ex, table,
              columns, out, out_flags, lane0, row0, status, rows):
    """Advance every case ``n_steps`` grid steps from ``step0``, recording every ``decimation``-th.

    Row ``c`` of ``states`` (``K.N_STATE``), ``flags`` (``K.N_FLAGS``), ``params``
    (``K.N_PARAMS``) and ``models`` (``K.M_*``: the controller's blocks, the spring law) is
    case ``c``;
    the excitation ``ex, table`` is shared. A sample of case
    ``c`` goes to ``out[column, lane0 + c, row]`` for each channel of ``columns`` (``K.C_*``;
    the other channels are not computed, but the energies only if asked) and to
    ``out_flags[flag, lane0 + c, row]`` for both flags (``K.O_*``), rows from ``row0``.
    ``states`` and ``flags`` carry the
    cases between calls. A case whose ``status`` is not ``K.STATUS_OK`` is left
    alone; one that diverges (non-finite, beyond 100 strokes or 1e4 m/s) gets
    ``K.STATUS_DIVERGED`` (``K.STATUS_OUTSIDE`` when its spring is a refusing table, whose
    force is NaN outside it), keeps its last finite state and, in ``flags[c,
    K.I_STEP]``, that state's step. ``rows[c]`` gets the rows case ``c`` wrote.
    At most ``MAX_LANES`` cases per call: returns ``K.STATUS_OK``, or
    ``STATUS_TOO_MANY_LANES`` (and does nothing) for more. A case whose controller has
    blocks beyond PI + damping, or whose spring law is not the tanh (``K.general``), is
    stepped in pass 2 at every step. ``models`` is as wide as its widest case's law.
    """
    n = states.shape[0]
    if n > MAX_LANES:
        return STATUS_TOO_MANY_LANES
    E = excitation_tuple(ex)
    PP = np.zeros(K.N_PARAMS * W)
    L = np.zeros(N_ROWS * W)
    T = np.zeros(N_SCRATCH * W)
    Q = np.zeros(N_RECORD * W)
    M0 = np.zeros(K.N_MODEL_ROW)  # PI + damping, the tanh of P
    energies = False
    for k in range(columns.size):
        energies = energies or K.C_E_KINETIC <= columns[k] <= K.C_E_STOP
    failed_step = np.full(n, -1, dtype=np.int64)
    sampled = False
    blocks = False
    for c in range(n):
        for i in range(K.N_PARAMS):
            PP[_at(i, c)] = params[c, i]
        for i in range(K.N_STATE):
            L[_at(i, c)] = states[c, i]
        L[_at(R_MODE, c)] = flags[c, K.I_MODE]
        L[_at(R_DIRECTION, c)] = flags[c, K.I_DIRECTION]
        L[_at(R_CONTACT, c)] = flags[c, K.I_CONTACT]
        L[_at(R_CONTACTS, c)] = flags[c, K.I_N_CONTACTS]
        L[_at(R_STICKS, c)] = flags[c, K.I_N_STICKS]
        L[_at(R_FAILED, c)] = 0.0 if status[c] == K.STATUS_OK else 1.0
        general = K.general(models[c])  # blocks, or a spring law other than the tanh
        L[_at(R_BLOCKS, c)] = 1.0 if general else 0.0
        rows[c] = 0
        sampled = (sampled or params[c, K.P_CONTROL_STEPS] > 0.0
                   or models[c, K.M_LINEAR_STEPS] > 0.0)
        blocks = blocks or general
    h = params[0, K.P_DT] if n > 0 else 0.0
    exact = True  # every lane of the exact model (fixed for the call)
    locked = 0  # lanes stuck or resting on a plastic stop (their mode changes in pass 2 only)
    for c in range(n):
        exact = exact and PP[_at(K.P_VREG, c)] == 0.0
        locked += int(L[_at(R_MODE, c)] != K.MODE_SLIP)
    lanes = n if n % LANE_BLOCK < PAD_FROM else n + LANE_BLOCK - n % LANE_BLOCK  # padded
    for c in range(n, lanes):
        for i in range(K.N_PARAMS):
            PP[_at(i, c)] = PP[_at(i, 0)]
        for i in range(N_ROWS):
            L[_at(i, c)] = L[_at(i, 0)]
        L[_at(R_FAILED, c)] = 1.0
    step = step0
    row = row0
    phase, sin0, cos0 = advance_phase(step * h, 0.0, 0.0, 1.0, E, np.bool_(True))
    for _ in range(n_steps):
        t = step * h
        if sampled:
            for c in range(n):
                if L[_at(R_FAILED, c)] != 0.0:
                    continue
                controller, linear = _sample_times(step, int(PP[_at(K.P_CONTROL_STEPS, c)]),
                                                   int(models[c, K.M_LINEAR_STEPS]))
                if controller or linear:
                    s = _state(L, c)
                    x = _blocks(L, c)
                    held = _held(L, c)
                    mode = int(L[_at(R_MODE, c)])
                    direction = int(L[_at(R_DIRECTION, c)])
                    if controller:
                        held, s, x = K.sample_controller(t, s, x, mode, direction, held,
                                                         _params(PP, c), models[c], E, table)
                    if linear:
                        held, x = K.sample_linear(t, s, x, mode, direction, held,
                                                  _params(PP, c), models[c], E, table)
                    (L[_at(K.A_F_PI, c)], L[_at(K.A_F_DAMP, c)], L[_at(K.A_F_MOTOR, c)],
                     L[_at(K.A_F_COMPENSATION, c)], L[_at(K.A_F_DITHER, c)],
                     L[_at(K.A_F_LINEAR, c)]) = held
                    L[_at(K.S_INT, c)] = s[K.S_INT]
                    if L[_at(R_BLOCKS, c)] != 0.0:
                        _store_blocks(L, c, x)
                    L[_at(R_MARGIN, c)] = np.nan
        bases = K.stage_bases(solver, t, h, E, table, phase, sin0, cos0)
        b_end = base_motion_near(t + h, phase, sin0, cos0, E, table)
        if _vector_pass(exact, locked == 0, solver, lanes, h, L, T, PP, M0, bases, b_end) > 0:
            for c in range(n):  # pass 2: the flagged lanes
                if T[_at(T_FLAGGED, c)] == 0.0 or L[_at(R_FAILED, c)] != 0.0:
                    continue
                P = _params(PP, c)
                s1, x1, mode, direction, margin, sticks, impacts = K.grid_step(
                    solver, t, h, _state(L, c), _blocks(L, c), int(L[_at(R_MODE, c)]),
                    int(L[_at(R_DIRECTION, c)]), _held(L, c), P, models[c],
                    L[_at(R_BLOCKS, c)] != 0.0, E, table, L[_at(R_MARGIN, c)], phase, sin0,
                    cos0)
                if not _finite(s1, P) or (L[_at(R_BLOCKS, c)] != 0.0
                                          and not _finite_blocks(x1)):
                    L[_at(R_FAILED, c)] = 1.0
                    failed_step[c] = step
                    rows[c] = row - row0
                    continue
                locked += int(mode != K.MODE_SLIP) - int(L[_at(R_MODE, c)] != K.MODE_SLIP)
                L[_at(R_MODE, c)] = mode
                L[_at(R_DIRECTION, c)] = direction
                L[_at(R_CONTACTS, c)] += impacts
                L[_at(R_STICKS, c)] += sticks
                _store(L, c, s1, margin, K._in_contact(s1, mode, P), P)
                if L[_at(R_BLOCKS, c)] != 0.0:
                    _store_blocks(L, c, x1)
        step += 1
        # rotate the excitation's sine/cosine to the next step; exact every PHASE_PERIOD steps
        phase, sin0, cos0 = advance_phase(step * h, phase, sin0, cos0, E,
                                          step % K.PHASE_PERIOD == 0)
        if step % decimation == 0:
            base = base_motion_near(step * h, phase, sin0, cos0, E, table)
            _keep(exact, lanes, step * h, base, L, PP, M0, models, blocks, Q, columns,
                  energies, out, out_flags, lane0, row)
            row += 1

    for c in range(n):
        if status[c] != K.STATUS_OK:
            continue
        for i in range(K.N_STATE):
            states[c, i] = L[_at(i, c)]
        flags[c, K.I_MODE] = int(L[_at(R_MODE, c)])
        flags[c, K.I_DIRECTION] = int(L[_at(R_DIRECTION, c)])
        flags[c, K.I_CONTACT] = int(L[_at(R_CONTACT, c)])
        flags[c, K.I_N_CONTACTS] = int(L[_at(R_CONTACTS, c)])
        flags[c, K.I_N_STICKS] = int(L[_at(R_STICKS, c)])
        if failed_step[c] >= 0:
            status[c] = K.failure_status(models[c])
            flags[c, K.I_STEP] = failed_step[c]
        else:
            flags[c, K.I_STEP] = step
            rows[c] = row - row0
    return K.STATUS_OK


def single_kernel(model):
    """The one-case kernel for a case packed as ``model`` (``K.M_*``): :func:`run_single`,
    or :func:`run_single_blocks` when its controller has blocks beyond PI + damping or its
    spring law is not the tanh (:func:`qzs.engine.kernels.general`)."""
    return run_single_blocks if K.general(model) else run_single


def _single(blocks, name, doc):
    """The one-case kernel ``name``, its ``blocks`` a constant of the closure (not an argument,
    nor an inlined body's): numba prunes the branches on it before it inlines anything, so
    :func:`run_single` inlines none of the blocks' code (an inlined body with ``blocks`` as
    an argument made its first compile about 3x longer, benchmarks/compile_times.py)."""

    def kernel(solver, n_steps, decimation, state, flags, p, m, ex, table, out, out_flags, row0):
        M = m if blocks else None  # None: no general path is compiled (K.kernel_model)
        P = K.params_tuple(p)
        E = excitation_tuple(ex)
        h = P[K.P_DT]
        control_steps = int(P[K.P_CONTROL_STEPS])
        linear_steps = int(m[K.M_LINEAR_STEPS]) if blocks else 0
        s = K.state_tuple(state)
        x = K.blocks_tuple(state)
        held = K.held_tuple(state)
        mode = flags[K.I_MODE]
        direction = flags[K.I_DIRECTION]
        contact = flags[K.I_CONTACT]
        step = flags[K.I_STEP]
        status = K.STATUS_OK
        row = row0
        margin = state[K.A_MARGIN]
        phase, sin0, cos0 = advance_phase(step * h, 0.0, 0.0, 1.0, E, np.bool_(True))
        for _ in range(n_steps):
            t = step * h
            if control_steps > 0 or linear_steps > 0:
                controller, linear = _sample_times(step, control_steps, linear_steps)
                if controller:
                    held, s, x = K.sample_controller(t, s, x, mode, direction, held, P, M, E,
                                                     table)
                    margin = np.nan
                if blocks and linear:
                    held, x = K.sample_linear(t, s, x, mode, direction, held, P, M, E, table)
                    margin = np.nan
            s1, x1, mode1, direction1, margin1, sticks, impacts = _grid_step_inline(
                solver, t, h, s, x, mode, direction, held, P, M, blocks, E, table, margin, phase,
                sin0, cos0)
            if not _finite(s1, P) or (blocks and not _finite_blocks(x1)):
                status = K.failure_status(M)
                break
            s, x, mode, direction, margin = s1, x1, mode1, direction1, margin1
            step += 1
            # rotate the excitation's sine/cosine to the next step (exact every PHASE_PERIOD)
            phase, sin0, cos0 = advance_phase(step * h, phase, sin0, cos0, E,
                                              step % K.PHASE_PERIOD == 0)
            flags[K.I_N_STICKS] += sticks
            flags[K.I_N_CONTACTS] += impacts
            now = K._in_contact(s, mode, P)
            if now and contact == 0 and P[K.P_PLASTIC] == 0.0:
                flags[K.I_N_CONTACTS] += 1
            contact = 1 if now else 0
            if step % decimation == 0:
                K.record(step * h, s, x, mode, direction, held, P, M, E, table, out[row],
                         out_flags[row], phase, sin0, cos0)
                row += 1
        for i in range(K.N_ODE):
            state[i] = s[i]
        if blocks:
            for i in range(K.N_X):
                state[K.A_X0 + i] = x[i]
        (state[K.A_F_PI], state[K.A_F_DAMP], state[K.A_F_MOTOR], state[K.A_F_COMPENSATION],
         state[K.A_F_DITHER], state[K.A_F_LINEAR]) = held
        state[K.A_MARGIN] = margin
        flags[K.I_MODE] = mode
        flags[K.I_DIRECTION] = direction
        flags[K.I_CONTACT] = contact
        flags[K.I_STEP] = step
        return status, row - row0

    kernel.__name__ = kernel.__qualname__ = name
    kernel.__doc__ = doc
    return njit(**_JIT, nogil=True)(kernel)


run_single = _single(False, "run_single", """One case: :func:`run_lanes` with a single lane, without the lanes' bookkeeping.

    Every step is :func:`qzs.engine.kernels.grid_step`, which takes the very same
    operations as a lane's step in :func:`run_lanes` (pass 1 for an ordinary
    step, pass 2 for one with a transition), so the numbers are identical.
    ``m`` holds the controller's blocks and the spring law (``K.M_*``): this kernel is for PI
    + damping with the tanh of ``p`` (``m`` is not read), :func:`run_single_blocks` for the
    general path. Returns ``(status, rows_written)``; on divergence ``state`` holds the last
    finite state and ``flags[K.I_STEP]`` its step.
    """)

run_single_blocks = _single(True, "run_single_blocks", """:func:`run_single` for the general path: a controller with blocks beyond PI + damping, or
    a spring law other than the tanh (``m``).

    One kernel for every such controller and law (its blocks and law are data), compiled on
    its first use; the same operations as a lane of :func:`run_lanes` with blocks (its pass
    2). Stops with ``K.STATUS_OUTSIDE`` where a refusing spring table's force is NaN.
    """)
