"""The six-axis right-hand side: base frame, kinematics, the locked legs' solve, the forces.

The dynamics of docs/hexapod.md ("Dynamics"): a rigid platform on six single-axis isolator
legs (:mod:`qzs.engine.laws`: MagSpring, Stribeck friction, compliant stops, PI + active
damping), driven by a base moving in up to six axes. Kernels in the style of
:mod:`qzs.engine.kernels` (arrays and floats in, no validation); the stepping around them
(Runge-Kutta, events, output) is :mod:`qzs.engine.hexapod.stepping`.

Frames. The *world* frame is the base frame at rest (``z`` up, gravity along ``-z``). The
moving *base frame* B has its origin at the point that coincides with the top frame origin
at home, ``o_home + p_b(t)``, and orientation ``R_b = Rz Ry Rx`` of the base angles: the base
pose ``q_b = (p_b, angles)`` is that point's displacement and the base's rotation, so a
platform rigidly carried by the base has exactly the base's pose. Base joints are fixed in
B (``beta_i = b_i - o_home``).

State (``S_*``, all vectors in B components): the platform's centre of mass ``c`` relative
to B's origin [m]; the unit quaternion of the platform's rotation relative to the base
``R_r`` (renormalised at every step end; ``R`` from a quaternion of any length is an exact
rotation); the COM velocity relative to B ``c'`` [m/s]; the relative angular velocity
``w`` [rad/s] (``R_r' = [w]x R_r``); per leg the charge amplifier's low-pass state [m/s]
and the PI integral [m*s]; the energy ledger [J]. Working relative to the base keeps a
platform locked to the base exactly at rest in these coordinates (``c' = w = 0`` to
rounding), as the single axis's relative coordinates do (docs/model.md §2).

Equations (Newton-Euler about the COM in the non-inertial frame B; ``w_b, a_b`` the base's
angular velocity and acceleration, ``a_O, v_O`` the acceleration and velocity of B's origin,
``g^`` the world's ``z`` axis, all in B components; ``I_B = R_r I_c R_r^T``)::

    m c''  = sum f_i u_i - m (g g^ + a_O + a_b x c + w_b x (w_b x c) + 2 w_b x c')
    I_B w' = sum f_i (rho_i x u_i) - W x I_B W - I_B (a_b - w x w_b),   W = w_b + w

with ``rho_i = R_r (t_i - c_t)`` the top joint from the COM. Leg ``i`` has length ``L_i`` and
unit vector ``u_i`` (base joint to top joint), slip velocity ``v_i = G_i nu`` with
``G_i = [u_i, rho_i x u_i]`` and ``nu = (c', w)``, and ``v_i' = G_i nu' + kappa_i`` with
``kappa_i = (|a_i'|^2 - v_i^2)/L_i + u_i . (w x (w x rho_i))``.

Stick-slip (docs/model.md §4 for six legs): a locked leg's friction is the unknown
``lambda_i`` that keeps ``v_i' = 0``; with the set S of locked legs,
``(G_S M^-1 G_S^T) lambda_S = -(G_S M^-1 (G^T f_0 + h) + kappa_S)`` is solved at every
right-hand-side evaluation (``L D L^T``; the minimum-norm solution when the locked legs'
constraints are redundant), and at step ends and transitions the locked legs' slip
velocities are reset to 0 by the impulse along them (booked in the ledger).
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT as _JIT
from qzs.engine.base_motion import advance_phase, base_motion_near, excitation_tuple
from qzs.engine.hexapod.layout import (
    LANES, LEG_COUNT, MODE_SLIP, PL_ACTIVE, PL_CENTRAL, PL_CKD, PL_CKI,
    PL_CKP, PL_CONTROL_STEPS, PL_G, PL_IC, PL_ICINV, PL_JINV, PL_MASS, PL_ROTATING, S_C,
    S_DF, S_DS, S_X, V_CMD, V_FCO, V_FDI, V_FFF, V_FLI, V_FRESH, V_HCO, V_HDI, V_HLI, V_XDD,
    V_YDD, S_HP, S_INT, S_Q, S_V, S_W, S_WB, S_WM, SOLVE_FACTORED, SOLVE_MIN_NORM, SOLVE_NONE, V_A,
    V_B, V_BX, V_BY, V_BZ, V_C0, V_CBC, V_CV, V_DHP, V_DINT, V_DIR, V_EV, V_F, V_FC, V_FDA,
    V_FEL, V_FFR, V_FGX, V_FGY, V_FGZ, V_FMAX, V_FMO, V_FPI, V_FS, V_FSP, V_FST, V_FUX,
    V_FUY, V_FUZ, V_GX, V_GY, V_GZ, V_HDA, V_HMO, V_HP, V_HPI, V_HPS, V_INT, V_KAP, V_KD,
    V_KI, V_KP, V_L, V_LHOME, V_MODE, V_MX, V_MY, V_MZ, V_PB, V_PF, V_PM, V_PS, V_STOPC,
    V_STOPK, V_TX, V_TY, V_TZ, V_UX, V_UY, V_UZ, V_V, V_VME, V_VR, V_XB, V_Z, V_ZHIGH,
    V_ZLOW, V_ZREF, W_ACC, W_AL, W_ALW, W_AO, W_CART, W_FSUM, W_GH, W_IBI, W_IMPULSE, W_OM,
    W_OMW, W_OUTSIDE, W_PHASE, W_PIVOTS, W_RB, W_RR, W_SOLVE, W_VO, W_Y, W_YD, W_YDD)
from qzs.engine.kernels import (M_BLOCKS, M_LINEAR_STEPS, N_X, X_OBSERVER, general_spring,
                                block_forces, block_rates, linear_sample, sample_blocks)
from qzs.engine.laws import (compliant_stop_law, controller_law, saturation_law,
                             sliding_friction_law, spring_law)
from qzs.engine.stickslip import MODE_STICK, hold_margin, slip_event

#: A Cholesky pivot below this share of the largest diagonal entry marks redundant locked legs.
RANK_TOLERANCE = 1e-10


# ---------------------------------------------------------------- small vector helpers
@njit(**_JIT, inline="always")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(**_JIT, inline="always")
def _matvec(M, o, x, y, z):
    """``M @ (x, y, z)`` for the 3x3 matrix stored row-major in ``M[o:o+9]``."""
    return (M[o] * x + M[o + 1] * y + M[o + 2] * z, M[o + 3] * x + M[o + 4] * y + M[o + 5] * z,
            M[o + 6] * x + M[o + 7] * y + M[o + 8] * z)


@njit(**_JIT, inline="always")
def _matTvec(M, o, x, y, z):
    """``M.T @ (x, y, z)`` for the 3x3 matrix stored row-major in ``M[o:o+9]``."""
    return (M[o] * x + M[o + 3] * y + M[o + 6] * z, M[o + 1] * x + M[o + 4] * y + M[o + 7] * z,
            M[o + 2] * x + M[o + 5] * y + M[o + 8] * z)


@njit(**_JIT, inline="always")
def _sum_legs(V, o):
    """The six legs' entries of row ``o`` of ``V``, summed pairwise (a fixed order)."""
    return ((V[o] + V[o + 1]) + (V[o + 2] + V[o + 3])) + (V[o + 4] + V[o + 5])


@njit(**_JIT, inline="always")
def _inertia_times(ww, plat, o, x, y, z):
    """``R_r C R_r^T (x, y, z)`` with ``C`` the 3x3 at ``plat[o:o+9]`` (``I_c`` or ``I_c^-1``)."""
    bx, by, bz = _matTvec(ww, W_RR, x, y, z)
    cx, cy, cz = _matvec(plat, o, bx, by, bz)
    return _matvec(ww, W_RR, cx, cy, cz)


@njit(**_JIT, inline="always")
def _congruence(R, ro, C, co, out, oo):
    """``out = R C R^T`` (3x3, row-major, at offsets ``ro``, ``co``, ``oo``)."""
    for i in range(3):
        r0, r1, r2 = R[ro + 3 * i], R[ro + 3 * i + 1], R[ro + 3 * i + 2]
        rc0 = r0 * C[co] + r1 * C[co + 3] + r2 * C[co + 6]
        rc1 = r0 * C[co + 1] + r1 * C[co + 4] + r2 * C[co + 7]
        rc2 = r0 * C[co + 2] + r1 * C[co + 5] + r2 * C[co + 8]
        for j in range(3):
            out[oo + 3 * i + j] = rc0 * R[ro + 3 * j] + rc1 * R[ro + 3 * j + 1] \
                + rc2 * R[ro + 3 * j + 2]


# ---------------------------------------------------------------- base motion and frame
@njit(**_JIT, inline="always")
def _base_frame(t, plat, ex, tables, toff, ww):
    """The base's motion at ``t`` [s] and the frame B it defines, into ``ww`` (``W_*``).

    Each active axis takes ``(y, y', y'')`` from
    :func:`qzs.engine.base_motion.base_motion_near` (translations [m], angles [rad]), its sine
    and cosine rotated from those at the step's start (``W_PHASE``) as in the single axis.
    ``R_b = Rz Ry Rx``; the angular velocity is ``E(angles) angles'`` and its rate
    ``E angles'' + E' angles'`` (world components), then everything is expressed in B: ``w_b``,
    ``a_b``, the origin's velocity and acceleration and the world's vertical ``g^ = R_b^T e_z``.
    Inlined into :func:`_evaluate`, its one caller (one copy to compile; the hot path gains 9 %).
    """
    for a in range(6):
        if plat[PL_ACTIVE + a] != 0.0:  # the others stay 0 (:func:`_rest_frame`)
            o = W_PHASE + 3 * a
            ww[W_Y + a], ww[W_YD + a], ww[W_YDD + a] = base_motion_near(
                t, ww[o], ww[o + 1], ww[o + 2], excitation_tuple(ex[a]),
                tables[:, toff[a]:toff[a + 1]])
    px, py, pz = ww[W_YD], ww[W_YD + 1], ww[W_YD + 2]
    ax, ay, az = ww[W_YDD], ww[W_YDD + 1], ww[W_YDD + 2]
    if plat[PL_ROTATING] == 0.0:  # R_b = I, w_b = a_b = 0, g^ = e_z (:func:`_rest_frame`)
        ww[W_VO], ww[W_VO + 1], ww[W_VO + 2] = px, py, pz
        ww[W_AO], ww[W_AO + 1], ww[W_AO + 2] = ax, ay, az
        return
    rx, ry, rz = ww[W_Y + 3], ww[W_Y + 4], ww[W_Y + 5]
    cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), np.sin(rz)
    R = (cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
         sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
         -sy, cy * sx, cy * cx)
    for k in range(9):
        ww[W_RB + k] = R[k]
    dx, dy, dz = ww[W_YD + 3], ww[W_YD + 4], ww[W_YD + 5]
    ddx, ddy, ddz = ww[W_YDD + 3], ww[W_YDD + 4], ww[W_YDD + 5]
    e1x, e1y, e1z = cz * cy, sz * cy, -sy      # Rz Ry e_x
    e2x, e2y = -sz, cz                         # Rz e_y
    omx = dx * e1x + dy * e2x
    omy = dx * e1y + dy * e2y
    omz = dx * e1z + dz
    # d/dt(Rz e_y) = (dz e_z) x Rz e_y; d/dt(Rz Ry e_x) = (dz e_z + dy Rz e_y) x Rz Ry e_x
    qx, qy, qz = _cross(dy * e2x, dy * e2y, dz, e1x, e1y, e1z)
    alx = ddx * e1x + ddy * e2x - dy * dz * cz + dx * qx
    aly = ddx * e1y + ddy * e2y - dy * dz * sz + dx * qy
    alz = ddx * e1z + ddz + dx * qz
    ww[W_OMW], ww[W_OMW + 1], ww[W_OMW + 2] = omx, omy, omz
    ww[W_ALW], ww[W_ALW + 1], ww[W_ALW + 2] = alx, aly, alz
    ww[W_OM], ww[W_OM + 1], ww[W_OM + 2] = _matTvec(ww, W_RB, omx, omy, omz)
    ww[W_AL], ww[W_AL + 1], ww[W_AL + 2] = _matTvec(ww, W_RB, alx, aly, alz)
    ww[W_VO], ww[W_VO + 1], ww[W_VO + 2] = _matTvec(ww, W_RB, px, py, pz)
    ww[W_AO], ww[W_AO + 1], ww[W_AO + 2] = _matTvec(ww, W_RB, ax, ay, az)
    ww[W_GH], ww[W_GH + 1], ww[W_GH + 2] = R[6], R[7], R[8]


@njit(**_JIT)
def _rest_frame(ww):
    """The base at rest in ``ww``: what :func:`_base_frame` leaves alone when it does not change."""
    for k in range(W_PHASE):
        ww[k] = 0.0
    ww[W_RB], ww[W_RB + 4], ww[W_RB + 8] = 1.0, 1.0, 1.0
    ww[W_RR], ww[W_RR + 4], ww[W_RR + 8] = 1.0, 1.0, 1.0
    ww[W_GH + 2] = 1.0


@njit(**_JIT)
def _advance_phases(t, exact, plat, ex, ww):
    """Each active axis's phase and its sine and cosine at ``t`` [s], rotated or ``exact``.

    As the single axis (docs/model.md §9): libm's sine and cosine every ``PHASE_PERIOD``
    steps, rotated from the previous step's in between.
    """
    for a in range(6):
        if plat[PL_ACTIVE + a] != 0.0:
            o = W_PHASE + 3 * a
            ww[o], ww[o + 1], ww[o + 2] = advance_phase(t, ww[o], ww[o + 1], ww[o + 2],
                                                        excitation_tuple(ex[a]), exact)


# ---------------------------------------------------------------- kinematics
@njit(**_JIT)
def _velocities(s, ww, V):
    """Every leg's slip rate ``v_i = G_i nu`` and ``kappa_i``, again after a projection.

    The same arithmetic as the velocity part of :func:`_evaluate`'s kinematics loop.
    """
    r00, r01, r02 = ww[W_RR], ww[W_RR + 1], ww[W_RR + 2]
    r10, r11, r12 = ww[W_RR + 3], ww[W_RR + 4], ww[W_RR + 5]
    r20, r21, r22 = ww[W_RR + 6], ww[W_RR + 7], ww[W_RR + 8]
    vx, vy, vz = s[S_V], s[S_V + 1], s[S_V + 2]
    wx, wy, wz = s[S_W], s[S_W + 1], s[S_W + 2]
    for i in range(LANES):
        tx, ty, tz = V[V_TX + i], V[V_TY + i], V[V_TZ + i]
        rx = r00 * tx + r01 * ty + r02 * tz
        ry = r10 * tx + r11 * ty + r12 * tz
        rz = r20 * tx + r21 * ty + r22 * tz
        ux, uy, uz = V[V_UX + i], V[V_UY + i], V[V_UZ + i]
        px, py, pz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx  # w x rho
        ax, ay, az = vx + px, vy + py, vz + pz   # top joint's velocity relative to B
        rate = ux * ax + uy * ay + uz * az
        nx, ny, nz = wy * pz - wz * py, wz * px - wx * pz, wx * py - wy * px
        V[V_VR + i] = rate
        V[V_KAP + i] = (ax * ax + ay * ay + az * az - rate * rate) / V[V_L + i] \
            + ux * nx + uy * ny + uz * nz


# ---------------------------------------------------------------- the locked legs' solve
@njit(**_JIT)
def _inverse_inertia_arms(plat, ww, V):
    """``I_B^-1`` (into ``ww``) and ``I_B^-1 (rho_i x u_i)`` of every leg (rows ``MX, MY, MZ``)."""
    _congruence(ww, W_RR, plat, PL_ICINV, ww, W_IBI)
    i00, i01, i02 = ww[W_IBI], ww[W_IBI + 1], ww[W_IBI + 2]
    i10, i11, i12 = ww[W_IBI + 3], ww[W_IBI + 4], ww[W_IBI + 5]
    i20, i21, i22 = ww[W_IBI + 6], ww[W_IBI + 7], ww[W_IBI + 8]
    for i in range(LANES):
        gx, gy, gz = V[V_GX + i], V[V_GY + i], V[V_GZ + i]
        V[V_MX + i] = i00 * gx + i01 * gy + i02 * gz
        V[V_MY + i] = i10 * gx + i11 * gy + i12 * gz
        V[V_MZ + i] = i20 * gx + i21 * gy + i22 * gz


@njit(**_JIT, inline="always")
def _coupling_row(V, i, inverse):
    """Row ``C0 + i`` of ``V``: ``G_i M^-1 G_j^T`` for every lane ``j`` (one vector loop).

    Called with a literal ``i``, so that the row's offset is a compile-time constant and LLVM
    can see it apart from the rows it reads (with ``i`` a loop variable it does not vectorise).
    """
    ux, uy, uz = V[V_UX + i] * inverse, V[V_UY + i] * inverse, V[V_UZ + i] * inverse
    gx, gy, gz = V[V_GX + i], V[V_GY + i], V[V_GZ + i]
    for j in range(LANES):
        V[V_C0 + i * LANES + j] = ux * V[V_UX + j] + uy * V[V_UY + j] + uz * V[V_UZ + j] \
            + gx * V[V_MX + j] + gy * V[V_MY + j] + gz * V[V_MZ + j]


@njit(**_JIT)
def _fill_locked(n, idx, m, V, A):
    """``A = G_S M^-1 G_S^T`` of the locked legs ``idx[:n]``.

    The coupling of every leg with every lane, ``G_i M^-1 G_j^T``, goes into the rows
    ``C0 + i`` of ``V`` (:func:`_coupling_row`); the locked legs' entries are gathered there.
    """
    inverse = 1.0 / m
    _coupling_row(V, 0, inverse)
    _coupling_row(V, 1, inverse)
    _coupling_row(V, 2, inverse)
    _coupling_row(V, 3, inverse)
    _coupling_row(V, 4, inverse)
    _coupling_row(V, 5, inverse)
    for k in range(n):
        row = V_C0 + idx[k] * LANES
        for l in range(n):
            A[k, l] = V[row + idx[l]]


@njit(**_JIT)
def _factor(A, n, ww):
    """``A[:n, :n] = L D L^T`` in place: unit ``L`` below the diagonal, ``1/D`` into
    ``ww[W_PIVOTS:]``. False if a pivot falls below ``RANK_TOLERANCE`` of the largest diagonal
    entry (redundant locked legs). No square roots, one division per column.
    """
    scale = 0.0
    for k in range(n):
        scale = max(scale, A[k, k])
    for j in range(n):
        for k in range(j):  # row j of L D, from the rows of L above
            value = A[j, k]
            for p in range(k):
                value -= A[j, p] * A[k, p]
            A[j, k] = value
        d = A[j, j]
        for k in range(j):
            lower = A[j, k] * ww[W_PIVOTS + k]
            d -= lower * A[j, k]
            A[j, k] = lower
        if not d > RANK_TOLERANCE * scale:
            return False
        ww[W_PIVOTS + j] = 1.0 / d
    return True


@njit(**_JIT)
def _min_norm_solve(A, b, n, x):
    """Minimum-norm solution of a consistent, rank-deficient ``A x = b`` (``A`` symmetric).

    Redundant locked legs (e.g. parallel legs) make the holding forces indeterminate; the
    minimum-norm forces share the load evenly among legs that act alike. By the eigenvectors
    of ``A`` (cyclic Jacobi rotations, to rounding), eigenvalues below ``RANK_TOLERANCE`` of
    the largest left out. ``A[:n, :n]`` is overwritten.
    """
    vectors = np.eye(n)
    for _ in range(60):
        off, diagonal = 0.0, 0.0
        for p in range(n):
            diagonal += A[p, p] * A[p, p]
            for q in range(p + 1, n):
                off += A[p, q] * A[p, q]
        if off <= 1e-32 * diagonal:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if A[p, q] == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * A[p, q])
                t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
                t = t if theta >= 0.0 else -t
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for k in range(n):  # A J
                    kp, kq = A[k, p], A[k, q]
                    A[k, p], A[k, q] = c * kp - s * kq, s * kp + c * kq
                for k in range(n):  # J^T (A J)
                    pk, qk = A[p, k], A[q, k]
                    A[p, k], A[q, k] = c * pk - s * qk, s * pk + c * qk
                for k in range(n):
                    kp, kq = vectors[k, p], vectors[k, q]
                    vectors[k, p], vectors[k, q] = c * kp - s * kq, s * kp + c * kq
    top = 0.0
    for k in range(n):
        top = max(top, abs(A[k, k]))
    for i in range(n):
        x[i] = 0.0
    for k in range(n):
        if abs(A[k, k]) > RANK_TOLERANCE * top:
            projection = 0.0
            for i in range(n):
                projection += vectors[i, k] * b[i]
            projection /= A[k, k]
            for i in range(n):
                x[i] += projection * vectors[i, k]


@njit(**_JIT)
def _solve_locked(n, idx, plat, ww, V, A, vec):
    """``(G_S M^-1 G_S^T) x = b`` for the locked legs ``idx[:n]``, ``b = vec[0]``, ``x = vec[1]``.

    The matrix depends on the positions only: it is built and factored once per evaluation
    (``ww[W_SOLVE]``) and serves the projection and the holding forces alike; ``L D L^T``, or
    the minimum-norm solution if the locked legs are redundant.
    """
    if ww[W_SOLVE] == SOLVE_NONE:
        _inverse_inertia_arms(plat, ww, V)
        _fill_locked(n, idx, plat[PL_MASS], V, A)
        ww[W_SOLVE] = SOLVE_FACTORED if _factor(A, n, ww) else SOLVE_MIN_NORM
    if ww[W_SOLVE] == SOLVE_FACTORED:
        for i in range(n):  # L y = b, then D z = y
            value = vec[0, i]
            for k in range(i):
                value -= A[i, k] * vec[1, k]
            vec[1, i] = value
        for i in range(n):
            vec[1, i] *= ww[W_PIVOTS + i]
        for i in range(n - 1, -1, -1):  # L^T x = z
            value = vec[1, i]
            for k in range(i + 1, n):
                value -= A[k, i] * vec[1, k]
            vec[1, i] = value
    else:
        _fill_locked(n, idx, plat[PL_MASS], V, A)
        _min_norm_solve(A, vec[0], n, vec[1])


@njit(**_JIT, inline="always")
def _locked_set(V, idx):
    """The locked legs into ``idx[:n]``; returns ``n`` (an int64, never a literal 0)."""
    n = np.int64(0)
    for i in range(LEG_COUNT):
        if V[V_MODE + i] != MODE_SLIP:
            idx[n] = i
            n += 1
    return n


@njit(**_JIT)
def _project(s, plat, ww, V, A, idx, vec):
    """Hold the locked legs' slip velocities at 0: the impulse along them that zeroes them.

    ``G_S M^-1 G_S^T P = -v_S``, ``nu += M^-1 G_S^T P``. Its energy is booked exactly as the
    single axis books its impulse (docs/model.md §4): ``sum P_i u_i . v_base,i`` to base work
    (by :func:`_evaluate`, from ``ww[W_IMPULSE:]``, once it has the base joints' rates),
    ``-sum P_i v_i / 2`` to friction dissipation. At a located zero crossing and at the end of
    a step it is of the order of the rounding and of the integrator's truncation error.
    """
    n = _locked_set(V, idx)
    if n == 0:
        return
    for k in range(n):
        vec[0, k] = -V[V_VR + idx[k]]
    _solve_locked(n, idx, plat, ww, V, A, vec)
    inverse = 1.0 / plat[PL_MASS]
    loss = 0.0
    for k in range(n):
        i = idx[k]
        p = vec[1, k]
        s[S_V] += p * V[V_UX + i] * inverse
        s[S_V + 1] += p * V[V_UY + i] * inverse
        s[S_V + 2] += p * V[V_UZ + i] * inverse
        s[S_W] += p * V[V_MX + i]
        s[S_W + 1] += p * V[V_MY + i]
        s[S_W + 2] += p * V[V_MZ + i]
        ww[W_IMPULSE + i] = p  # its base work is booked with the base joints' rates
        loss -= 0.5 * p * V[V_VR + i]
    s[S_DF] += loss


# ---------------------------------------------------------------- each leg's controller blocks
# ``models``: each leg's packed blocks and spring law, row ``i`` leg ``i``'s
# (``qzs.engine.kernels.M_*``), or ``None`` when no leg has blocks or a law (layout.py). Every
# kernel that reaches the blocks' code takes it as an argument and branches on ``models is not
# None``: numba prunes that branch by the argument's type before it types the callees, so a run
# without blocks or laws compiles none of the functions below nor the single axis's block
# kernels they call (benchmarks/compile_times.py --hexapod). A flag's value (in ``plat``) would not: numba compiles both branches' callees.
@njit(**_JIT, inline="always")
def _with_blocks(models):
    """Whether a leg's packed row holds controller blocks beyond PI + damping (``M_BLOCKS``):
    ``models`` also comes with spring laws alone, which leave the blocks' code out."""
    for i in range(LEG_COUNT):
        if models[i, M_BLOCKS] != 0.0:
            return True
    return False


@njit(**_JIT)
def _leg_springs(models, ww, V):
    """Each leg's spring force from its own law into row ``FSP`` (docs/model.md §3.1).

    The single axis's general spring (:func:`qzs.engine.kernels.general_spring`, the tanh's
    arithmetic bit for bit) on leg ``i``'s packed law (``models[i]`` from ``M_SPRING``) at
    its position (row ``Z``); the padding lanes copy leg 1. A refusing table's NaN outside
    it marks the first such leg in ``ww[W_OUTSIDE:]`` (its number, position and slip
    velocity) for the run's status.
    """
    for i in range(LEG_COUNT):
        z = V[V_Z + i]
        force = general_spring(models[i], z)
        if np.isnan(force) and ww[W_OUTSIDE] == 0.0:
            ww[W_OUTSIDE] = i + 1.0
            ww[W_OUTSIDE + 1] = z
            ww[W_OUTSIDE + 2] = V[V_V + i]
        V[V_FSP + i] = force
    for pad in range(LEG_COUNT, LANES):
        V[V_FSP + pad] = V[V_FSP]


@njit(**_JIT, inline="always")
def _leg_state(s, i):
    """Leg ``i``'s blocks' state (``qzs.engine.kernels.X_*``) as a tuple."""
    o = S_X + i * N_X
    return (s[o], s[o + 1], s[o + 2], s[o + 3], s[o + 4], s[o + 5], s[o + 6], s[o + 7],
            s[o + 8])


@njit(**_JIT, inline="always")
def _base_acceleration(ww, V, i):
    """Leg ``i``'s base accelerometer [m/s^2]: its base joint's acceleration along the leg.

    ``u_i . (a_O + a_b x b_i + w_b x (w_b x b_i))`` in B (a base that does not rotate leaves
    ``a_b = w_b = 0``): the single axis's base acceleration ``y''`` for a vertical leg.
    """
    bx, by, bz = V[V_BX + i], V[V_BY + i], V[V_BZ + i]
    obx, oby, obz = ww[W_OM], ww[W_OM + 1], ww[W_OM + 2]
    e1 = _cross(ww[W_AL], ww[W_AL + 1], ww[W_AL + 2], bx, by, bz)
    e2 = _cross(obx, oby, obz, bx, by, bz)
    e3 = _cross(obx, oby, obz, e2[0], e2[1], e2[2])
    return (V[V_UX + i] * (ww[W_AO] + e1[0] + e3[0]) + V[V_UY + i] * (ww[W_AO + 1] + e1[1] + e3[1])
            + V[V_UZ + i] * (ww[W_AO + 2] + e1[2] + e3[2]))


@njit(**_JIT, inline="always")
def _slip(V, i):
    """Leg ``i``'s slip velocity as its blocks read it [m/s]: 0 at the instant it is released.

    The single axis's slip velocity is exactly 0 there (it was held); a leg's is the
    platform's velocity along it, 0 to the rounding of the locked legs' projection. The
    compensation, a law that jumps at ``v = 0`` (docs/model.md §5.1), must not see that
    rounding: until the state moves (the next Runge-Kutta stage, ``FRESH`` cleared by
    :func:`qzs.engine.hexapod.stepping._rk`) a released leg reads 0.
    """
    return 0.0 if V[V_FRESH + i] != 0.0 else V[V_V + i]


@njit(**_JIT)
def _leg_blocks(t, s, plat, models, ww, V):
    """Each leg's blocks beyond PI + damping, added to its command (docs/model.md §5.1).

    Per leg, the single axis's :func:`qzs.engine.kernels.block_forces` on that leg's
    sensors (its encoder's error and slip velocity, its amplifier's velocity, its base
    accelerometer, :func:`_base_acceleration`) with its own packed blocks (``models[i]``)
    and state (:func:`_leg_state`); the motor force is the saturated sum with the PI and
    damping commands already in ``V`` (continuous, or held), and a continuous PI's integral
    stops by the same conditional integration. Writes the rows ``FCO, FDI, FLI`` (the
    blocks' forces), ``FFF`` (the feedforward), ``CMD`` (the command before saturation),
    ``YDD`` (the base accelerometer), ``FMO`` and ``DINT``.
    """
    sampled = plat[PL_CONTROL_STEPS] > 0.0
    for i in range(LEG_COUNT):
        error = V[V_ZREF + i] - V[V_Z + i]
        ydd = _base_acceleration(ww, V, i)
        held = (V[V_HPI + i], V[V_HDA + i], V[V_HMO + i], V[V_HCO + i], V[V_HDI + i],
                V[V_HLI + i])
        f_comp, f_dither, f_linear, feedforward = block_forces(
            t, error, _leg_state(s, i), _slip(V, i), V[V_DIR + i], ydd, V[V_VME + i], held,
            sampled, 0.0, models[i])
        command = V[V_FPI + i] + V[V_FDA + i] + f_comp + f_dither + f_linear
        f_motor, rate = saturation_law(command, error, V[V_KI + i], V[V_FMAX + i])
        V[V_FCO + i] = f_comp
        V[V_FDI + i] = f_dither
        V[V_FLI + i] = f_linear
        V[V_FFF + i] = feedforward
        V[V_CMD + i] = command
        V[V_YDD + i] = ydd
        V[V_FMO + i] = f_motor
        if not sampled:
            V[V_DINT + i] = rate
    for pad in range(LEG_COUNT, LANES):  # the padding lanes copy leg 1
        V[V_FMO + pad] = V[V_FMO]
        V[V_DINT + pad] = V[V_DINT]


@njit(**_JIT)
def _leg_block_rates(s, plat, models, ww, V, d):
    """Each leg's blocks' state rates into ``d`` (:func:`qzs.engine.kernels.block_rates`).

    After the platform's equation (``ww[W_ACC:]``) and the locked legs' holding forces
    (``FFR``): a leg's payload accelerometer reads its base accelerometer plus its slip
    acceleration ``v_i' = G_i nu' + kappa_i`` (0 while locked), the single axis's ``x''``
    for a vertical leg (row ``XDD``); its observer measures its friction (the holding force
    when locked) and stop force.
    """
    sampled = plat[PL_CONTROL_STEPS] > 0.0
    for i in range(LEG_COUNT):
        slip_rate = 0.0
        if V[V_MODE + i] == MODE_SLIP:
            slip_rate = (V[V_UX + i] * ww[W_ACC] + V[V_UY + i] * ww[W_ACC + 1]
                         + V[V_UZ + i] * ww[W_ACC + 2] + V[V_GX + i] * ww[W_ACC + 3]
                         + V[V_GY + i] * ww[W_ACC + 4] + V[V_GZ + i] * ww[W_ACC + 5]
                         + V[V_KAP + i])
        xdd = V[V_YDD + i] + slip_rate
        V[V_XDD + i] = xdd
        sensors = (V[V_ZREF + i] - V[V_Z + i], V[V_VME + i], xdd, V[V_YDD + i], _slip(V, i))
        rates = block_rates(_leg_state(s, i), sensors, V[V_FFR + i], V[V_FST + i],
                            V[V_FFF + i], V[V_FMO + i] - V[V_CMD + i], sampled, models[i])
        o = S_X + i * N_X
        for k in range(N_X):
            d[o + k] = rates[k]


@njit(**_JIT)
def _sample_blocks(t, plat, models, V, s, h):
    """Each leg's sampled blocks at a sample of the PI (:func:`qzs.engine.kernels.sample_blocks`).

    After :func:`_commands` (the PI and damping outputs in ``FPI, FDA``), from what the last
    evaluation left in ``V`` (friction, stop force, the linear output, the sensors): the
    observer advanced, the compensation and dither held (``HCO, HDI``), the motor's command
    saturated (``FMO``) and the integral's rate (``DINT``).
    """
    for i in range(LEG_COUNT):
        held = (V[V_HPI + i], V[V_HDA + i], V[V_HMO + i], V[V_HCO + i], V[V_HDI + i],
                V[V_HLI + i])
        f_comp, f_dither, f_motor, rate, x = sample_blocks(
            t, _leg_state(s, i), _slip(V, i), V[V_DIR + i], held, V[V_FFR + i], V[V_FST + i],
            V[V_FPI + i], V[V_FDA + i], V[V_FLI + i], V[V_ZREF + i] - V[V_Z + i], V[V_KI + i],
            V[V_FMAX + i], plat[PL_CONTROL_STEPS], h, 0.0, models[i])
        V[V_HCO + i] = f_comp
        V[V_HDI + i] = f_dither
        V[V_FMO + i] = f_motor
        V[V_DINT + i] = rate
        s[S_X + i * N_X + X_OBSERVER] = x[X_OBSERVER]
    for pad in range(LEG_COUNT, LANES):
        V[V_FMO + pad] = V[V_FMO]
        V[V_DINT + pad] = V[V_DINT]


@njit(**_JIT)
def _linear_due(models, step):
    """Whether a leg's discrete linear controller samples at grid step ``step``."""
    for i in range(LEG_COUNT):
        steps = int(models[i, M_LINEAR_STEPS])
        if steps > 0 and step % steps == 0:
            return True
    return False


@njit(**_JIT)
def _sample_linear(step, models, V, s):
    """Each leg's discrete linear controller that samples at grid step ``step``
    (:func:`qzs.engine.kernels.linear_sample`), from the sensors and the other commands of an
    evaluation at that instant: its output held (``HLI``), its states stepped in ``s``."""
    for i in range(LEG_COUNT):
        M = models[i]
        steps = int(M[M_LINEAR_STEPS])
        if steps > 0 and step % steps == 0:
            error = V[V_ZREF + i] - V[V_Z + i]
            sensors = (error, V[V_VME + i], V[V_XDD + i], V[V_YDD + i], _slip(V, i))
            output, x = linear_sample(M, _leg_state(s, i), sensors,
                                      V[V_FPI + i] + V[V_FDA + i] + V[V_FCO + i] + V[V_FDI + i],
                                      error, V[V_KI + i], V[V_FMAX + i])
            V[V_HLI + i] = output
            o = S_X + i * N_X
            for k in range(N_X):
                s[o + k] = x[k]


# ---------------------------------------------------------------- the right-hand side
@njit(**_JIT)
def _commands(plat, ww, V):
    """Every leg's controller outputs from its sensors (rows ``Z``, ``VME``, ``INT`` of ``V``).

    Per leg (``PL_CENTRAL`` 0): the single axis's :func:`~qzs.engine.laws.controller_law`
    on each leg. Centralised: the legs' errors ``e_i = z_ref,i - z_i`` and measured velocities
    mapped to the platform's axes by ``J^-1``, one PI + damping loop per axis (its integral in
    the ``INT`` row of that axis), the axes' commands mapped back to leg forces by ``J^-T``,
    each leg saturated at its own limit; an axis's integral stops while a saturated leg's
    share of it, ``(J^-T)_ij Ki_j e_j``, pushes that leg further into saturation (the single
    axis's conditional integration, docs/hexapod.md §9.5). Writes the rows ``FPI``, ``FDA``,
    ``FMO`` (commands before saturation, the motor force after) and ``DINT`` (the integrals'
    rates: per leg, or per axis).
    """
    if plat[PL_CENTRAL] == 0.0:
        for i in range(LANES):
            f_pi, f_damp, f_motor, rate = controller_law(
                V[V_ZREF + i], V[V_KP + i], V[V_KI + i], V[V_KD + i], V[V_FMAX + i], V[V_Z + i],
                V[V_VME + i], V[V_INT + i])
            V[V_FPI + i] = f_pi
            V[V_FDA + i] = f_damp
            V[V_FMO + i] = f_motor
            V[V_DINT + i] = rate
        return
    for j in range(6):  # the axes' errors and loops (J^-1 row-major: row j, column i)
        error, velocity = 0.0, 0.0
        for i in range(LEG_COUNT):
            inverse = plat[PL_JINV + 6 * j + i]
            error += inverse * (V[V_ZREF + i] - V[V_Z + i])
            velocity += inverse * V[V_VME + i]
        ww[W_CART + j] = error
        ww[W_CART + 6 + j] = plat[PL_CKP + j] * error + plat[PL_CKI + j] * V[V_INT + j]
        ww[W_CART + 12 + j] = -plat[PL_CKD + j] * velocity
    for i in range(LEG_COUNT):
        f_pi, f_damp = 0.0, 0.0
        for j in range(6):
            inverse = plat[PL_JINV + 6 * j + i]
            f_pi += inverse * ww[W_CART + 6 + j]
            f_damp += inverse * ww[W_CART + 12 + j]
        f_max = V[V_FMAX + i]
        V[V_FPI + i] = f_pi
        V[V_FDA + i] = f_damp
        V[V_FMO + i] = min(max(f_pi + f_damp, -f_max), f_max)
    for j in range(6):
        error = ww[W_CART + j]
        rate = error
        for i in range(LEG_COUNT):
            command = V[V_FPI + i] + V[V_FDA + i]
            push = plat[PL_JINV + 6 * j + i] * (plat[PL_CKI + j] * error)
            f_max = V[V_FMAX + i]
            if (command > f_max and push > 0.0) or (command < -f_max and push < 0.0):
                rate = 0.0
        V[V_DINT + j] = rate
    for pad in range(LEG_COUNT, LANES):  # the padding lanes copy leg 1
        V[V_FPI + pad] = V[V_FPI]
        V[V_FDA + pad] = V[V_FDA]
        V[V_FMO + pad] = V[V_FMO]
        V[V_DINT + pad] = V[V_DINT]


@njit(**_JIT)
def _sample(t, plat, models, ww, V, s, h):
    """A sampled controller's sample at ``t`` [s]: outputs from the sensors of the last
    evaluation, held.

    As the single axis's (docs/model.md §5): the outputs with the current integrals (with
    blocks, theirs too, :func:`_sample_blocks`), then the integrals advanced by forward Euler
    over the controller's period, ``I + rate N h``.
    """
    _commands(plat, ww, V)
    if models is not None:  # pruned by type without blocks (see _leg_blocks)
        if _with_blocks(models):
            _sample_blocks(t, plat, models, V, s, h)
    for i in range(LANES):
        V[V_HPI + i] = V[V_FPI + i]
        V[V_HDA + i] = V[V_FDA + i]
        V[V_HMO + i] = V[V_FMO + i]
    for i in range(LEG_COUNT):
        s[S_INT + i] = s[S_INT + i] + V[V_DINT + i] * plat[PL_CONTROL_STEPS] * h


@njit(**_JIT)
def _evaluate(t, s, plat, models, ex, tables, toff, ww, V, A, idx, vec, d, project):
    """The right-hand side at ``(t, s)`` into ``d``; every leg's forces and events into ``V``.

    1. the base's motion and frame (:func:`_base_frame`);
    2. kinematics: the rotation ``R_r`` (``I_B`` products go through it; ``I_B^-1`` is built
       only when legs are locked), and per leg ``L_i``, ``u_i``, the arm ``rho_i x u_i``, the
       slip rate ``v_i`` and ``kappa_i``;
    3. with ``project`` (step ends and transitions, never inner stages): the quaternion
       renormalised first, then the locked legs' slip velocities reset to 0 (:func:`_project`);
    4. every leg's forces from its laws (:mod:`qzs.engine.laws`); a locked leg has ``v = 0``
       and no sliding friction;
    5. Newton-Euler in B, the locked legs' holding forces ``lambda_S``, the ledger's rates, the
       event values (``d_i v_i`` slipping, ``Fs_i - |lambda_i|`` locked).

    The per-leg parts are loops over the ``LANES`` that LLVM vectorises. Steps 2-5 are one
    function on purpose: LLVM then keeps the platform's quantities in registers across them
    (the hexapod's throughput rose from 1/10 to about 1/8 of the single axis's), which numba's
    ``inline="always"`` of separate pieces also achieves, at a much longer cold compile.
    """
    _base_frame(t, plat, ex, tables, toff, ww)
    if project:
        scale = 1.0 / np.sqrt(s[S_Q] ** 2 + s[S_Q + 1] ** 2 + s[S_Q + 2] ** 2 + s[S_Q + 3] ** 2)
        for k in range(4):
            s[S_Q + k] *= scale
    # 2. kinematics
    qw, qx, qy, qz = s[S_Q], s[S_Q + 1], s[S_Q + 2], s[S_Q + 3]
    k = 2.0 / (qw * qw + qx * qx + qy * qy + qz * qz)  # exact rotation for any length of q
    r00, r01, r02 = 1.0 - k * (qy * qy + qz * qz), k * (qx * qy - qw * qz), k * (qx * qz + qw * qy)
    r10, r11, r12 = k * (qx * qy + qw * qz), 1.0 - k * (qx * qx + qz * qz), k * (qy * qz - qw * qx)
    r20, r21, r22 = k * (qx * qz - qw * qy), k * (qy * qz + qw * qx), 1.0 - k * (qx * qx + qy * qy)
    ww[W_RR], ww[W_RR + 1], ww[W_RR + 2] = r00, r01, r02
    ww[W_RR + 3], ww[W_RR + 4], ww[W_RR + 5] = r10, r11, r12
    ww[W_RR + 6], ww[W_RR + 7], ww[W_RR + 8] = r20, r21, r22
    ww[W_SOLVE] = SOLVE_NONE  # I_B^-1 and the locked legs' factor: built when first needed
    cx, cy, cz = s[S_C], s[S_C + 1], s[S_C + 2]
    vx, vy, vz = s[S_V], s[S_V + 1], s[S_V + 2]
    wx, wy, wz = s[S_W], s[S_W + 1], s[S_W + 2]
    for i in range(LANES):
        tx, ty, tz = V[V_TX + i], V[V_TY + i], V[V_TZ + i]
        rx = r00 * tx + r01 * ty + r02 * tz
        ry = r10 * tx + r11 * ty + r12 * tz
        rz = r20 * tx + r21 * ty + r22 * tz
        dx = cx + rx - V[V_BX + i]
        dy = cy + ry - V[V_BY + i]
        dz = cz + rz - V[V_BZ + i]
        length = np.sqrt(dx * dx + dy * dy + dz * dz)
        inverse = 1.0 / length
        ux, uy, uz = dx * inverse, dy * inverse, dz * inverse
        px, py, pz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx  # w x rho
        ax, ay, az = vx + px, vy + py, vz + pz   # top joint's velocity relative to B
        rate = ux * ax + uy * ay + uz * az
        nx, ny, nz = wy * pz - wz * py, wz * px - wx * pz, wx * py - wy * px
        V[V_UX + i], V[V_UY + i], V[V_UZ + i] = ux, uy, uz
        V[V_GX + i] = ry * uz - rz * uy
        V[V_GY + i] = rz * ux - rx * uz
        V[V_GZ + i] = rx * uy - ry * ux
        V[V_L + i] = length
        V[V_VR + i] = rate
        V[V_KAP + i] = (ax * ax + ay * ay + az * az - rate * rate) / length \
            + ux * nx + uy * ny + uz * nz
    # 3. the locked legs held at zero slip
    projected = project and _locked_set(V, idx) > 0
    if projected:
        for i in range(LEG_COUNT):
            ww[W_IMPULSE + i] = 0.0
        _project(s, plat, ww, V, A, idx, vec)
        _velocities(s, ww, V)
        vx, vy, vz = s[S_V], s[S_V + 1], s[S_V + 2]
        wx, wy, wz = s[S_W], s[S_W + 1], s[S_W + 2]
    # 4. leg forces
    m = plat[PL_MASS]
    g = plat[PL_G]
    for i in range(LEG_COUNT):
        V[V_HPS + i] = s[S_HP + i]
        V[V_INT + i] = s[S_INT + i]
    obx, oby, obz = ww[W_OM], ww[W_OM + 1], ww[W_OM + 2]
    vox, voy, voz = ww[W_VO], ww[W_VO + 1], ww[W_VO + 2]
    for i in range(LANES):  # what each leg's sensors read: encoder, accelerometer
        v = V[V_VR + i] if V[V_MODE + i] == MODE_SLIP else 0.0
        bx, by, bz = V[V_BX + i], V[V_BY + i], V[V_BZ + i]
        base_rate = V[V_UX + i] * (vox + oby * bz - obz * by) \
            + V[V_UY + i] * (voy + obz * bx - obx * bz) + V[V_UZ + i] * (voz + obx * by - oby * bx)
        xd = base_rate + v
        omega_hp = V[V_HP + i]
        V[V_Z + i] = V[V_L + i] - V[V_LHOME + i] + V[V_ZREF + i]
        V[V_V + i] = v
        V[V_XB + i] = base_rate
        V[V_VME + i] = xd - V[V_HPS + i] if omega_hp > 0.0 else xd
        V[V_DHP + i] = omega_hp * (xd - V[V_HPS + i])
    if plat[PL_CONTROL_STEPS] > 0.0:  # sampled: the outputs held since the last sample
        for i in range(LANES):
            V[V_FPI + i] = V[V_HPI + i]
            V[V_FDA + i] = V[V_HDA + i]
            V[V_FMO + i] = V[V_HMO + i]
            V[V_DINT + i] = 0.0
    else:
        _commands(plat, ww, V)
    if models is not None:  # pruned by type without blocks and spring laws
        if _with_blocks(models):  # each leg's own blocks (docs/model.md §5.1)
            _leg_blocks(t, s, plat, models, ww, V)
        _leg_springs(models, ww, V)  # each leg's own spring law (docs/model.md §3.1)
    for i in range(LANES):
        slipping = V[V_MODE + i] == MODE_SLIP
        v = V[V_V + i]
        z = V[V_Z + i]
        if models is None:  # the MagSpring's tanh on every leg
            f_spring = spring_law(V[V_A + i], V[V_B + i], z)
        else:
            f_spring = V[V_FSP + i]
        f_stop, f_elastic = compliant_stop_law(z, v, V[V_ZLOW + i], V[V_ZHIGH + i],
                                               V[V_STOPK + i], V[V_STOPC + i])
        f_motor = V[V_FMO + i]
        f_friction = sliding_friction_law(v, V[V_DIR + i], V[V_FS + i], V[V_FC + i],
                                          V[V_CBC + i], V[V_CV + i], 0.0)  # exact model
        f_friction = f_friction if slipping else 0.0
        V[V_FSP + i] = f_spring
        V[V_FST + i] = f_stop
        V[V_FEL + i] = f_elastic
        V[V_FFR + i] = f_friction
        f = f_spring + f_stop + f_motor + f_friction
        base_rate = V[V_XB + i]
        V[V_F + i] = f
        V[V_FUX + i] = f * V[V_UX + i]
        V[V_FUY + i] = f * V[V_UY + i]
        V[V_FUZ + i] = f * V[V_UZ + i]
        V[V_FGX + i] = f * V[V_GX + i]
        V[V_FGY + i] = f * V[V_GY + i]
        V[V_FGZ + i] = f * V[V_GZ + i]
        V[V_PB + i] = f * base_rate
        V[V_PF + i] = -f_friction * v
        V[V_PM + i] = f_motor * v
        V[V_PS + i] = -(f_stop - f_elastic) * v
        V[V_EV + i] = slip_event(V[V_DIR + i], V[V_VR + i])  # a locked leg's comes with lambda
    # 5. the platform: Newton-Euler in the moving frame B
    fx, fy, fz = _sum_legs(V, V_FUX), _sum_legs(V, V_FUY), _sum_legs(V, V_FUZ)
    tx, ty, tz = _sum_legs(V, V_FGX), _sum_legs(V, V_FGY), _sum_legs(V, V_FGZ)
    base_power, friction_loss = _sum_legs(V, V_PB), _sum_legs(V, V_PF)
    motor_power, stop_loss = _sum_legs(V, V_PM), _sum_legs(V, V_PS)
    for i in range(LEG_COUNT):
        d[S_HP + i] = V[V_DHP + i]
        d[S_INT + i] = V[V_DINT + i]
    if projected:  # the impulse's work through the base (see _project)
        work = 0.0
        for i in range(LEG_COUNT):
            work += ww[W_IMPULSE + i] * V[V_XB + i]
        s[S_WB] += work
    lin_x = fx / m - (g * ww[W_GH] + ww[W_AO])
    lin_y = fy / m - (g * ww[W_GH + 1] + ww[W_AO + 1])
    lin_z = fz / m - (g * ww[W_GH + 2] + ww[W_AO + 2])
    hx, hy, hz = _inertia_times(ww, plat, PL_IC, wx, wy, wz)
    if plat[PL_ROTATING] == 0.0:
        gyro = _cross(wx, wy, wz, hx, hy, hz)
        rot_x, rot_y, rot_z = _inertia_times(ww, plat, PL_ICINV, tx - gyro[0], ty - gyro[1],
                                             tz - gyro[2])
    else:  # the frame's fictitious forces
        abx, aby, abz = ww[W_AL], ww[W_AL + 1], ww[W_AL + 2]
        e1 = _cross(abx, aby, abz, cx, cy, cz)
        e2 = _cross(obx, oby, obz, cx, cy, cz)
        e3 = _cross(obx, oby, obz, e2[0], e2[1], e2[2])
        e4 = _cross(obx, oby, obz, vx, vy, vz)
        lin_x -= e1[0] + e3[0] + 2.0 * e4[0]
        lin_y -= e1[1] + e3[1] + 2.0 * e4[1]
        lin_z -= e1[2] + e3[2] + 2.0 * e4[2]
        Wx, Wy, Wz = obx + wx, oby + wy, obz + wz
        hx, hy, hz = _inertia_times(ww, plat, PL_IC, Wx, Wy, Wz)
        gyro = _cross(Wx, Wy, Wz, hx, hy, hz)
        rel = _cross(wx, wy, wz, obx, oby, obz)
        ix, iy, iz = _inertia_times(ww, plat, PL_IC, abx - rel[0], aby - rel[1], abz - rel[2])
        rot_x, rot_y, rot_z = _inertia_times(ww, plat, PL_ICINV, tx - gyro[0] - ix,
                                             ty - gyro[1] - iy, tz - gyro[2] - iz)
    n = _locked_set(V, idx)
    if n > 0:
        for k in range(n):
            i = idx[k]
            vec[0, k] = -(V[V_UX + i] * lin_x + V[V_UY + i] * lin_y + V[V_UZ + i] * lin_z
                          + V[V_GX + i] * rot_x + V[V_GY + i] * rot_y + V[V_GZ + i] * rot_z
                          + V[V_KAP + i])
        _solve_locked(n, idx, plat, ww, V, A, vec)
        inverse = 1.0 / m
        for k in range(n):
            i = idx[k]
            p = vec[1, k]
            lin_x += p * V[V_UX + i] * inverse
            lin_y += p * V[V_UY + i] * inverse
            lin_z += p * V[V_UZ + i] * inverse
            rot_x += p * V[V_MX + i]
            rot_y += p * V[V_MY + i]
            rot_z += p * V[V_MZ + i]
            V[V_FFR + i] = p
            V[V_F + i] += p
            V[V_EV + i] = hold_margin(MODE_STICK, p, V[V_FS + i])
            fx += p * V[V_UX + i]
            fy += p * V[V_UY + i]
            fz += p * V[V_UZ + i]
            base_power += p * V[V_XB + i]
    ww[W_ACC], ww[W_ACC + 1], ww[W_ACC + 2] = lin_x, lin_y, lin_z
    ww[W_ACC + 3], ww[W_ACC + 4], ww[W_ACC + 5] = rot_x, rot_y, rot_z
    ww[W_FSUM], ww[W_FSUM + 1], ww[W_FSUM + 2] = fx, fy, fz
    d[S_C], d[S_C + 1], d[S_C + 2] = vx, vy, vz
    # q' = (0, w) (x) q / 2: the rotation relative to the base, w in B components
    qw, qx, qy, qz = s[S_Q], s[S_Q + 1], s[S_Q + 2], s[S_Q + 3]
    d[S_Q] = -0.5 * (wx * qx + wy * qy + wz * qz)
    d[S_Q + 1] = 0.5 * (qw * wx + wy * qz - wz * qy)
    d[S_Q + 2] = 0.5 * (qw * wy + wz * qx - wx * qz)
    d[S_Q + 3] = 0.5 * (qw * wz + wx * qy - wy * qx)
    d[S_V], d[S_V + 1], d[S_V + 2] = lin_x, lin_y, lin_z
    d[S_W], d[S_W + 1], d[S_W + 2] = rot_x, rot_y, rot_z
    d[S_WB] = base_power
    d[S_DF] = friction_loss
    d[S_WM] = motor_power
    d[S_DS] = stop_loss
    if models is not None:
        if _with_blocks(models):
            _leg_block_rates(s, plat, models, ww, V, d)


# Stale cached kernels of this module are dropped with the others (qzs.engine.arithmetic:
# "hexapod/dynamics" is one of its _KERNEL_MODULES).
