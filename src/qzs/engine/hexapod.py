"""Six-leg Stewart platform of isolator legs: rigid-body dynamics with exact stick-slip per leg.

The dynamics of docs/hexapod.md ("Dynamics"): a rigid platform on six single-axis isolator
legs (:mod:`qzs.engine.laws`: MagSpring, Stribeck friction, compliant stops, PI + active
damping), driven by a base moving in up to six axes. Kernels in the style of
:mod:`qzs.engine.kernels` (arrays and floats in, a status out, no validation), then the
validated driver :func:`simulate_hexapod` and its result :class:`HexapodResult`.

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
velocities are reset to 0 by the impulse along them (booked in the ledger). Events (a
slipping leg's ``d_i v_i`` or a locked leg's margin ``Fs_i - |lambda_i|`` crossing zero) are
located inside the step by regula falsi, the step is split there, the modes are settled as a
small complementarity problem (largest excess released first, re-solved), and the step
continues; at most ``MAX_EVENTS`` per step.
Legs that act alike switch together (``SIMULTANEOUS``), so a symmetric platform stays
symmetric to rounding.
"""
import time as _time
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from qzs import defaults
from qzs._validation import choice, positive, worker_count
from qzs.analysis.statistics import RunStatistics
from qzs.engine.arithmetic import JIT as _JIT
from qzs.engine.arithmetic import fma
from qzs.engine.base_motion import advance_phase, base_motion_near, excitation_tuple
from qzs.engine.kernels import PHASE_PERIOD, illinois_step, n_stages, tableau
from qzs.engine.laws import (compliant_stop_law, controller_law, sliding_friction_law,
                             spring_energy_law, spring_law)
from qzs.engine.prepare import steps_per_sample
from qzs.engine.stability import SOLVERS, largest_stable_step, stability_test
from qzs.engine.simulate import PREVIEW_SAMPLES, _available_memory, _DeferredInterrupt
from qzs.errors import CaseError, ParameterError, SimulationError, StabilityError, Terminated
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine
from qzs.model.hexapod import (LEG_COUNT, CartesianController, HexapodGeometry,
                               PlatformParameters, jacobian, static_leg_forces)
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import unit_of

__all__ = ["simulate_hexapod", "simulate_hexapods", "hexapod_stability_test", "HexapodResult",
           "AXES", "HEXAPOD_CHANNELS", "HEXAPOD_FLAGS", "hexapod_file_layout"]

#: The six axes of a pose, in order: translations [m], then rotation angles [rad].
AXES = ("x", "y", "z", "rx", "ry", "rz")
_EXCITATIONS = (Chirp, Sine, RandomExcitation, DisplacementRecord)

# ---------------------------------------------------------------- packed layouts
#: Lanes of the per-leg arrays: the six legs and two padding lanes (copies of leg 1), so that
#: every per-leg loop runs over 8 lanes that LLVM vectorises (docs/model.md §9: no fast-math,
#: a vector lane computes the very bits scalar code would).
LANES = 8
# Rows of the flat per-leg array ``V`` (row ``r`` of lane ``i`` at ``r * LANES + i``, a
# compile-time stride: LLVM sees that the rows cannot overlap). Parameters and geometry
# (base joint from B's origin, top joint from the COM in the top frame), the mode (0 slipping,
# 1 locked) and slip direction, the filter and integral states, the kinematics, the forces,
# the event value, the filter and integral rates, per leg the terms the platform sums (force
# and moment components, the powers of the ledger: base, friction, motor, stop), a sampled
# controller's held outputs (PI, damping, motor), and six rows of the legs' coupling
# ``G_i M^-1 G_j^T`` (row ``C0 + i``, lane ``j``).
(R_A, R_B, R_FS, R_FC, R_CBC, R_CV, R_ZLOW, R_ZHIGH, R_STOPK, R_STOPC, R_FMAX, R_ZREF, R_KP, R_KI,
 R_KD, R_HP, R_LHOME, R_BX, R_BY, R_BZ, R_TX, R_TY, R_TZ, R_MODE, R_DIR, R_HPS, R_INT, R_UX, R_UY,
 R_UZ, R_GX, R_GY, R_GZ, R_MX, R_MY, R_MZ, R_L, R_VR, R_KAP, R_Z, R_V, R_FSP, R_FST, R_FEL, R_FMO,
 R_FPI, R_FDA, R_VME, R_FFR, R_F, R_XB, R_EV, R_DHP, R_DINT, R_FUX, R_FUY, R_FUZ, R_FGX, R_FGY,
 R_FGZ, R_PB, R_PF, R_PM, R_PS, R_HPI, R_HDA, R_HMO, R_C0) = range(68)
N_ROWS = 68 + LEG_COUNT - 1
(V_A, V_B, V_FS, V_FC, V_CBC, V_CV, V_ZLOW, V_ZHIGH, V_STOPK, V_STOPC, V_FMAX, V_ZREF, V_KP, V_KI,
 V_KD, V_HP, V_LHOME, V_BX, V_BY, V_BZ, V_TX, V_TY, V_TZ, V_MODE, V_DIR, V_HPS, V_INT, V_UX, V_UY,
 V_UZ, V_GX, V_GY, V_GZ, V_MX, V_MY, V_MZ, V_L, V_VR, V_KAP, V_Z, V_V, V_FSP, V_FST, V_FEL, V_FMO,
 V_FPI, V_FDA, V_VME, V_FFR, V_F, V_XB, V_EV, V_DHP, V_DINT, V_FUX, V_FUY, V_FUZ, V_FGX, V_FGY,
 V_FGZ, V_PB, V_PF, V_PM, V_PS, V_HPI, V_HDA, V_HMO, V_C0) = range(0, 68 * LANES, LANES)
# Platform ``plat``: mass, gravity, COM in the top frame, inertia and its inverse (row-major),
# home position, which base axes move, whether the base rotates; the control: grid steps per
# controller sample (0: continuous), centralised (1) or per leg (0), and the Cartesian loops'
# ``J^-1`` (row-major) and gains per axis (proportional, integral, damping).
(PL_MASS, PL_G, PL_CT, PL_IC, PL_ICINV, PL_HOME, PL_ACTIVE, PL_ROTATING, PL_CONTROL_STEPS,
 PL_CENTRAL, PL_JINV, PL_CKP, PL_CKI, PL_CKD) = (0, 1, 2, 5, 14, 23, 26, 32, 33, 34, 35, 71, 77,
                                                83)
N_PLAT = 89

# ODE state.
S_C, S_Q, S_V, S_W, S_HP, S_INT, S_WB, S_DF, S_WM, S_DS = 0, 3, 7, 10, 13, 19, 25, 26, 27, 28
N_ODE = 29

# Platform workspace ``ww``: the base motion and frame, the platform's rotation and inertia,
# its accelerations, the sum of the leg forces, the state of the locked legs' factorisation,
# its reciprocal pivots, the impulses of the last projection (0 if none), per axis the
# excitation's phase and its sine and cosine at the start of the step (persistent: carried
# across kernel calls), and the Cartesian loops' errors, PI and damping commands per axis.
(W_Y, W_YD, W_YDD, W_RB, W_OM, W_AL, W_VO, W_AO, W_GH, W_OMW, W_ALW, W_RR, W_IBI, W_ACC,
 W_FSUM, W_SOLVE, W_PIVOTS, W_IMPULSE, W_PHASE, W_CART) = (0, 6, 12, 18, 27, 30, 33, 36, 39, 42,
                                                           45, 48, 57, 66, 72, 75, 76, 82, 88,
                                                           106)
N_WORK = 124
SOLVE_NONE, SOLVE_FACTORED, SOLVE_MIN_NORM = 0.0, 1.0, 2.0
# Rows of the state buffers ``buf`` (N_BUF, N_ODE).
B_S, B_K1, B_S1, B_KE, B_TMP, B_K2, B_K3, B_K4, B_TRIAL, B_KT = range(10)
N_BUF = 10
# Counters.
CT_STEP, CT_EVENTS, CT_STICKS, CT_CONTACTS, CT_IN_CONTACT = 0, 1, 2, 8, 14
N_COUNTERS = 20

MODE_SLIP, MODE_LOCK = 0.0, 1.0
#: Flags for kernels called from kernels: a literal ``True``/``False`` would make numba compile
#: the callee once more for each literal value (``_evaluate`` three times: 20 s more compile).
_TRUE, _FALSE = np.bool_(True), np.bool_(False)
STATUS_OK, STATUS_DIVERGED = 0, 1
#: Most transitions located inside one grid step; more are caught at the next step's start.
MAX_EVENTS = 12
#: Most mode changes settled at one instant (the complementarity loop).
MAX_SETTLE = 24
#: Legs whose event value at a located transition is within this share of its value at the
#: (sub)step's start switch with the located leg (the location resolves 1e-12 of a step).
SIMULTANEOUS = 1e-9
#: A Cholesky pivot below this share of the largest diagonal entry marks redundant locked legs.
RANK_TOLERANCE = 1e-10

# Output channels: time, poses and motions [6 each], per-leg blocks [6 each], the ledger.
C_TIME, C_POSE, C_TWIST, C_BASE_POSE, C_BASE_VEL, C_BASE_ACC, C_ACC = 0, 1, 7, 13, 19, 25, 31
(C_Z, C_V, C_FSP, C_FFR, C_FST, C_FMO, C_FPI, C_FDA, C_VME) = (37, 43, 49, 55, 61, 67, 73, 79,
                                                               85)
C_WB, C_DF, C_WM, C_DS, C_EK, C_ESP, C_EG, C_EST = 91, 92, 93, 94, 95, 96, 97, 98
N_CHANNELS = 99
O_LOCKED, O_CONTACT = 0, 6
N_FLAGS = 12


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
def _sample(plat, ww, V, s, h):
    """A sampled controller's sample: outputs from the sensors of the last evaluation, held.

    As the single axis's (docs/model.md §5): the outputs with the current integrals, then the
    integrals advanced by forward Euler over the controller's period, ``I + rate N h``.
    """
    _commands(plat, ww, V)
    for i in range(LANES):
        V[V_HPI + i] = V[V_FPI + i]
        V[V_HDA + i] = V[V_FDA + i]
        V[V_HMO + i] = V[V_FMO + i]
    for i in range(LEG_COUNT):
        s[S_INT + i] = s[S_INT + i] + V[V_DINT + i] * plat[PL_CONTROL_STEPS] * h


@njit(**_JIT)
def _evaluate(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, project):
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
    for i in range(LANES):
        slipping = V[V_MODE + i] == MODE_SLIP
        v = V[V_V + i]
        z = V[V_Z + i]
        f_spring = spring_law(V[V_A + i], V[V_B + i], z)
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
        V[V_EV + i] = V[V_DIR + i] * V[V_VR + i]  # slipping; a locked leg's comes with lambda
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
            V[V_EV + i] = V[V_FS + i] - abs(p)
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


# ---------------------------------------------------------------- Runge-Kutta
@njit(**_JIT)
def _rk(solver, t, h, s, k1, out, buf, plat, ex, tables, toff, ww, V, A, idx, vec):
    """One explicit Runge-Kutta step of length ``h`` from ``s`` (rate ``k1`` given) into ``out``.

    The diagonal tableau of :func:`qzs.engine.kernels.tableau` (euler, ode3, rk4); each update
    ``s + a k`` is one fused multiply-add, as in the single axis.
    """
    weight = tableau(solver, h, 0)[2]
    for j in range(N_ODE):
        out[j] = fma(weight, k1[j], s[j])
    previous = k1
    for stage in range(1, n_stages(solver)):
        offset, a, weight = tableau(solver, h, stage)
        tmp = buf[B_TMP]
        for j in range(N_ODE):
            tmp[j] = fma(a, previous[j], s[j])
        k = buf[B_K2 + stage - 1]
        _evaluate(t + offset, tmp, plat, ex, tables, toff, ww, V, A, idx, vec, k, _FALSE)
        for j in range(N_ODE):
            out[j] = fma(weight, k[j], out[j])
        previous = k


# ---------------------------------------------------------------- events and transitions
@njit(**_JIT)
def _first_event(V, ev0, ev1):
    """Leg (-1: none) and time fraction (secant) of the first transition in a (sub)step.

    Slipping leg: ``d v`` at the end negative (or reaching 0). Locked leg: margin at the end
    negative, or already negative at the start (missed earlier: released at once).
    """
    best = 2.0
    leg = -1
    for i in range(LEG_COUNT):
        g0, g1 = ev0[i], ev1[i]
        theta = 2.0
        if V[V_MODE + i] == MODE_SLIP:
            if g1 < 0.0 or (g1 == 0.0 and g0 > 0.0):
                theta = g0 / (g0 - g1) if g0 > 0.0 else 0.0
        elif g1 < 0.0 or g0 < 0.0:
            theta = g0 / (g0 - g1) if (g0 > 0.0 and g0 > g1) else 0.0
        if theta < best:
            best = theta
            leg = i
    return leg, min(max(best, 0.0), 1.0)


@njit(**_JIT)
def _locate(solver, leg, t, h, s, k1, g0, g1, buf, plat, ex, tables, toff, ww, V, A, idx, vec):
    """Refine leg ``leg``'s event in ``[t, t + h]`` by regula falsi (Illinois).

    As :func:`qzs.engine.kernels._locate`: each iterate a fresh Runge-Kutta step of the trial
    length from the (sub)step's start, at most 6; stop when the event function is below
    1e-15 of its start value or the bracket below 1e-12 of the step. Returns the time from
    ``t``; the state there is in ``buf[B_TRIAL]``.
    """
    trial = buf[B_TRIAL]
    if g0 <= 0.0:
        for j in range(N_ODE):
            trial[j] = s[j]
        return 0.0
    lo, hi = 0.0, h
    g_lo, g_hi = g0, g1
    at = h * g0 / (g0 - g1)
    side = 0
    for _ in range(6):
        _rk(solver, t, at, s, k1, trial, buf, plat, ex, tables, toff, ww, V, A, idx, vec)
        _evaluate(t + at, trial, plat, ex, tables, toff, ww, V, A, idx, vec, buf[B_KT], _FALSE)
        g = V[V_EV + leg]
        done, at, lo, hi, g_lo, g_hi, side = illinois_step(at, g, g0, h, lo, hi, g_lo, g_hi, side)
        if done:
            break
    return at


@njit(**_JIT, inline="always")
def _set_mode(V, i, mode, direction):
    """Mode and slip direction of leg ``i``, and of the padding lanes that copy leg 1."""
    V[V_MODE + i] = mode
    V[V_DIR + i] = direction
    if i == 0:
        for pad in range(LEG_COUNT, LANES):
            V[V_MODE + pad] = mode
            V[V_DIR + pad] = direction


@njit(**_JIT)
def _settle(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, newly):
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
        _evaluate(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, _TRUE)
        worst = -1
        excess = 0.0
        for i in range(LEG_COUNT):
            if V[V_MODE + i] != MODE_SLIP and V[V_EV + i] < excess:
                excess = V[V_EV + i]
                worst = i
        if worst < 0:
            return
        _set_mode(V, worst, MODE_SLIP, -1.0 if V[V_FFR + worst] > 0.0 else 1.0)
        newly[worst] = 0
    _evaluate(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, _TRUE)


@njit(**_JIT)
def _transition(leg, t, s, ev0, plat, ex, tables, toff, ww, V, A, idx, vec, d, newly, counters):
    """Apply the located event of ``leg`` at ``(t, s)``, settle the modes, count stick events.

    A zero crossing locks the leg; a breakaway releases it towards the net force. Legs of the
    same mode whose event value there is no larger than the located leg's, to within
    ``SIMULTANEOUS`` of their value at the (sub)step's start ``ev0``, change with it: legs that
    act alike (a symmetric platform) switch together, whatever the rounding decided first.
    """
    for i in range(LEG_COUNT):
        newly[i] = 0
    _evaluate(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, _FALSE)
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
                _set_mode(V, i, MODE_SLIP, -1.0 if V[V_FFR + i] > 0.0 else 1.0)
    _settle(t, s, plat, ex, tables, toff, ww, V, A, idx, vec, d, newly)
    for i in range(LEG_COUNT):
        if newly[i] != 0 and V[V_MODE + i] != MODE_SLIP:
            counters[CT_STICKS + i] += 1
    counters[CT_EVENTS] += 1


@njit(**_JIT)
def _grid_step(solver, t, h, buf, ev, plat, ex, tables, toff, ww, V, A, idx, vec, newly,
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
        _rk(solver, t + elapsed, rest, s, k1, s1, buf, plat, ex, tables, toff, ww, V, A, idx,
            vec)
        _evaluate(t + h, s1, plat, ex, tables, toff, ww, V, A, idx, vec, ke, _TRUE)
        for i in range(LEG_COUNT):
            ev[1, i] = V[V_EV + i]
        leg, theta = -1, 2.0
        if events < MAX_EVENTS:
            leg, theta = _first_event(V, ev[0], ev[1])
        if leg < 0:
            for j in range(N_ODE):
                s[j] = s1[j]
                k1[j] = ke[j]
            for i in range(LEG_COUNT):
                ev[0, i] = ev[1, i]
            return
        g0, g1 = ev[0, leg], ev[1, leg]
        at = _locate(solver, leg, t + elapsed, rest, s, k1, g0, g1, buf, plat, ex, tables, toff,
                     ww, V, A, idx, vec)
        trial = buf[B_TRIAL]
        for j in range(N_ODE):
            s[j] = trial[j]
        elapsed += at
        _transition(leg, t + elapsed, s, ev[0], plat, ex, tables, toff, ww, V, A, idx, vec, k1,
                    newly, counters)
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
def _record(t, s, plat, ww, V, row, marks):
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
        spring += spring_energy_law(V[V_A + i], V[V_B + i], z)
        pen = max(V[V_ZLOW + i] - z, 0.0) + max(z - V[V_ZHIGH + i], 0.0)
        stop += 0.5 * V[V_STOPK + i] * pen * pen
        marks[O_LOCKED + i] = V[V_MODE + i] != MODE_SLIP
        marks[O_CONTACT + i] = z < V[V_ZLOW + i] or z > V[V_ZHIGH + i]
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
    """Divergence test: every state entry finite, relative speed below 1e4 m/s."""
    for j in range(N_ODE):
        if not np.isfinite(s[j]):
            return False
    for a in range(3):
        if abs(s[S_V + a]) > 1e4:
            return False
    return True


@njit(**_JIT)
def _start(s, plat, ex, tables, toff, buf, ev, ww, V, A, idx, vec, newly, counters, row, marks):
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
    _evaluate(0.0, s, plat, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], _FALSE)
    for i in range(LEG_COUNT):
        s[S_HP + i] = V[V_XB + i]
    if plat[PL_CONTROL_STEPS] > 0.0:  # a sampled controller's outputs at t = 0, held
        _evaluate(0.0, s, plat, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], _FALSE)
        _commands(plat, ww, V)
        for i in range(LANES):
            V[V_HPI + i] = V[V_FPI + i]
            V[V_HDA + i] = V[V_FDA + i]
            V[V_HMO + i] = V[V_FMO + i]
    _settle(0.0, s, plat, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1], newly)
    for j in range(N_ODE):
        buf[B_S, j] = s[j]
    for i in range(LEG_COUNT):
        ev[0, i] = V[V_EV + i]
        counters[CT_IN_CONTACT + i] = 1 if (V[V_Z + i] < V[V_ZLOW + i]
                                            or V[V_Z + i] > V[V_ZHIGH + i]) else 0
    _record(0.0, s, plat, ww, V, row, marks)


@njit(**_JIT, nogil=True)
def _run(solver, n_steps, decimation, h, s, plat, ex, tables, toff, buf, ev, ww, V, A, idx, vec,
         newly, counters, out, out_flags, row0):
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
        if control_steps > 0 and step % control_steps == 0:
            # a sample: the held outputs jump, so the modes are settled again (a locked leg
            # may break away right here) and the rate and event values are those after it
            _sample(plat, ww, V, buf[B_S], h)
            _settle(step * h, buf[B_S], plat, ex, tables, toff, ww, V, A, idx, vec, buf[B_K1],
                    newly)
            for i in range(LEG_COUNT):
                ev[0, i] = V[V_EV + i]
        _grid_step(solver, step * h, h, buf, ev, plat, ex, tables, toff, ww, V, A, idx, vec,
                   newly, counters)
        if not _finite(buf[B_S]):
            status = STATUS_DIVERGED
            break
        step += 1
        for i in range(LEG_COUNT):
            z = V[V_Z + i]
            now = 1 if (z < V[V_ZLOW + i] or z > V[V_ZHIGH + i]) else 0
            if now == 1 and counters[CT_IN_CONTACT + i] == 0:
                counters[CT_CONTACTS + i] += 1
            counters[CT_IN_CONTACT + i] = now
        if step % decimation == 0:
            _record(step * h, buf[B_S], plat, ww, V, out[row], out_flags[row])
            row += 1
    counters[CT_STEP] = step
    for j in range(N_ODE):
        s[j] = buf[B_S, j]
    return status, row - row0


# Stale cached kernels of this module are dropped with the others (qzs.engine.arithmetic:
# "hexapod" is one of its _KERNEL_MODULES).


# ---------------------------------------------------------------- validation and packing
def _per_leg(name, value, kind):
    """One parameter object or a sequence of six (one per leg), as a tuple of six."""
    if isinstance(value, kind):
        return (value,) * LEG_COUNT
    if isinstance(value, (list, tuple)) and len(value) == LEG_COUNT \
            and all(isinstance(v, kind) for v in value):
        return tuple(value)
    raise ParameterError(f"`{name}` must be a {kind.__name__} or a sequence of six (one per "
                         f"leg), got {value!r}.")


def _excitations(excitation):
    """The base excitation as ``{axis: excitation}`` of the axes that move."""
    if excitation is None:
        return {}
    if not isinstance(excitation, dict):
        raise ParameterError(
            f"`excitation` must be a dict from axis names {AXES} to excitations (Chirp, Sine, "
            f"RandomExcitation, DisplacementRecord) or None, got {type(excitation).__name__}; "
            "e.g. excitation={'z': Chirp(duration=20.0)}.")
    unknown = [key for key in excitation if key not in AXES]
    if unknown:
        raise ParameterError(f"`excitation` has unknown axis name(s) {unknown!r}; the axes are "
                             f"{AXES} (translations [m], rotation angles [rad]).")
    moving = {}
    for axis in AXES:
        value = excitation.get(axis)
        if value is None:
            continue
        if not isinstance(value, _EXCITATIONS):
            raise ParameterError(
                f"`excitation[{axis!r}]` must be a Chirp, Sine, RandomExcitation, "
                f"DisplacementRecord or None, got {type(value).__name__}.")
        moving[axis] = value
    return moving


def _static_forces(geometry, platform):
    """The static leg forces of the weight [N]; the minimum-norm ones for redundant legs."""
    try:
        return static_leg_forces(geometry, platform)
    except np.linalg.LinAlgError:  # parallel legs: the geometry class refuses them, a test may not
        from qzs.model.hexapod import jacobian, weight_wrench

        return np.linalg.lstsq(jacobian(geometry).T, weight_wrench(platform), rcond=None)[0]


def hexapod_stability_test(geometry, platform, isolator=None, controller=None,
                           solver=defaults.SIMULATION["solver"]):
    """``stable(dt)``: does a step ``dt`` [s] integrate every leg stably (docs/hexapod.md §9.7)?

    Each leg's stiff modes (its stop contact, its loops) acting on the lightest mass the
    legs move, ``1/max eig(G M^-1 G^T)``, by the single axis's test
    (:func:`qzs.engine.stability.stability_test`); what :func:`simulate_hexapod` checks.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass and inertia of the moving platform.
    isolator, controller : IsolatorParameters, ControllerParameters or sequences of six
        The legs; defaults if omitted.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator.

    Returns
    -------
    callable
        ``stable(dt) -> bool``.
    """
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    mass = _effective_leg_mass(geometry, platform)
    tests = [stability_test(replace(iso, mass=mass), con, solver)
             for iso, con in zip(isolators, controllers)]
    return lambda dt: all(test(dt) for test in tests)


def _effective_leg_mass(geometry, platform):
    """``1/max eig(G M^-1 G^T)`` [kg]: the lightest mass a leg (or all legs at once) moves."""
    arms = geometry.top_joints - platform.center_of_mass
    vectors = geometry.top_joints + geometry.home_position - geometry.base_joints
    units = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    rows = np.hstack([units, np.cross(arms, units)])
    inverse = np.zeros((6, 6))
    inverse[:3, :3] = np.eye(3) / platform.mass
    inverse[3:, 3:] = np.linalg.inv(platform.inertia)
    return 1.0 / float(np.max(np.linalg.eigvalsh(rows @ inverse @ rows.T)))


@dataclass
class _Prepared:
    geometry: HexapodGeometry
    platform: PlatformParameters
    isolators: tuple
    controllers: tuple
    excitation: dict
    duration: float
    dt: float
    sample_rate: float
    decimation: int
    solver: str
    solver_code: int
    V: np.ndarray
    plat: np.ndarray
    ex: np.ndarray
    tables: np.ndarray
    toff: np.ndarray
    state: np.ndarray
    cartesian: object = None


def _prepare(geometry, platform, isolator, controller, excitation, duration, dt, sample_rate,
             solver, progress, cartesian=None):
    """Validate every argument of :func:`simulate_hexapod` and pack the kernels' arrays."""
    if not isinstance(geometry, HexapodGeometry):
        raise ParameterError(f"`geometry` must be a HexapodGeometry (e.g. from cubic_geometry or "
                             f"radial_geometry), got {type(geometry).__name__}.")
    if not isinstance(platform, PlatformParameters):
        raise ParameterError(f"`platform` must be a PlatformParameters, got "
                             f"{type(platform).__name__}.")
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    moving = _excitations(excitation)
    solver = choice("solver", solver, tuple(SOLVERS))
    solver_code = SOLVERS[solver][0]
    if not isinstance(progress, (bool, np.bool_)):
        raise ParameterError(f"`progress` must be True or False, got {progress!r}.")
    for leg, (iso, con) in enumerate(zip(isolators, controllers)):
        if iso.stop_model != "compliant":
            raise ParameterError(
                f"leg {leg + 1}: `stop_model` {iso.stop_model!r} is not supported by the hexapod "
                "(its stops are compliant contacts only); use stop_model='compliant'.")
        if getattr(iso, "friction_regularisation", 0.0) != 0.0:
            raise ParameterError(
                f"leg {leg + 1}: `friction_regularisation` ({iso.friction_regularisation!r} m/s) "
                "must be 0: the hexapod integrates the exact stick-slip model only.")
        if con.controller_rate != controllers[0].controller_rate:
            raise ParameterError(
                f"leg {leg + 1}: `controller_rate` ({con.controller_rate!r} Hz) differs from leg "
                f"1's ({controllers[0].controller_rate!r} Hz): the legs' loops run on one "
                "controller, sampled together; give every leg the same rate.")
        if iso.stroke_half != geometry.stroke_half:
            raise ParameterError(
                f"leg {leg + 1}: the isolator's `stroke_half` ({iso.stroke_half!r} m) differs "
                f"from the geometry's ({geometry.stroke_half!r} m); both describe the leg's guide, "
                "give them the same value.")
        center = con.position_setpoint if iso.stop_center is None else iso.stop_center
        if not center - iso.stroke_half <= con.position_setpoint <= center + iso.stroke_half:
            raise ParameterError(
                f"leg {leg + 1}: the `position_setpoint` ({con.position_setpoint!r} m), where the "
                f"leg starts at home, must lie between the stops [{center - iso.stroke_half:g}, "
                f"{center + iso.stroke_half:g}] m; move it or `stop_center`.")
    if duration is None:
        lengths = [e.duration for e in moving.values() if e.duration is not None]
        if not lengths:
            raise ParameterError(
                "`duration` is required when no excitation defines one (a Sine has no length; "
                "without excitation there is none); pass e.g. duration=10.0 [s].")
        duration = min(lengths)
    duration = positive("duration", duration)
    for axis, value in moving.items():
        if value.duration is not None and duration > value.duration * (1 + 1e-12):
            raise ParameterError(
                f"`duration` ({duration!r} s) exceeds the length of `excitation[{axis!r}]` "
                f"({value.duration!r} s); shorten the run or lengthen that excitation.")
    dt = positive("dt", dt)
    sample_rate = positive("sample_rate", sample_rate)
    if dt > duration:
        raise ParameterError(f"`dt` ({dt!r} s) must not exceed `duration` ({duration!r} s).")
    decimation = steps_per_sample(sample_rate, dt, "sample_rate")
    control_rate = controllers[0].controller_rate
    control_steps = 0 if control_rate == 0 else steps_per_sample(control_rate, dt,
                                                                 "controller_rate")
    if cartesian is not None and not isinstance(cartesian, CartesianController):
        raise ParameterError(
            f"`cartesian` must be a CartesianController (e.g. CartesianController.from_legs("
            f"geometry, controller)) or None for per-leg loops, got {type(cartesian).__name__}.")
    if not hexapod_stability_test(geometry, platform, isolators, controllers, solver)(dt):
        mass = _effective_leg_mass(geometry, platform)
        limit = min(largest_stable_step(replace(i, mass=mass), c, solver)
                    for i, c in zip(isolators, controllers))
        raise StabilityError(
            f"`dt` ({dt!r} s) is too large for a stable {solver} integration of this hexapod "
            f"(stiffest mode: a leg's stop contact or loop acting on the {mass:.3g} kg the "
            f"legs move at least); the largest stable step is {limit:.3g} s. Reduce `dt`, "
            "or soften `stop_stiffness`.")

    V = np.zeros(N_ROWS * LANES)
    for i, (iso, con) in enumerate(zip(isolators, controllers)):
        center = con.position_setpoint if iso.stop_center is None else iso.stop_center
        values = {R_A: iso.spring_force, R_B: iso.spring_shape, R_FS: iso.stiction_force,
                  R_FC: iso.coulomb_force, R_CBC: iso.stribeck_decay, R_CV: iso.viscous_damping,
                  R_ZLOW: center - iso.stroke_half, R_ZHIGH: center + iso.stroke_half,
                  R_STOPK: iso.stop_stiffness, R_STOPC: iso.stop_damping,
                  R_FMAX: iso.motor_force_max, R_ZREF: con.position_setpoint, R_KP: con.pi_kp,
                  R_KI: con.pi_ki, R_KD: con.damping_gain,
                  R_HP: 2 * np.pi * con.velocity_highpass, R_DIR: 1.0}
        base = geometry.base_joints[i] - geometry.home_position
        top = geometry.top_joints[i] - platform.center_of_mass
        values.update({R_BX: base[0], R_BY: base[1], R_BZ: base[2], R_TX: top[0], R_TY: top[1],
                       R_TZ: top[2]})
        for row, value in values.items():
            V[row * LANES + i] = value
    rows = V.reshape(N_ROWS, LANES)
    rows[:, LEG_COUNT:] = rows[:, :1]  # the padding lanes copy leg 1
    plat = np.zeros(N_PLAT)
    plat[PL_MASS], plat[PL_G] = platform.mass, platform.gravity
    plat[PL_CT:PL_CT + 3] = platform.center_of_mass
    plat[PL_IC:PL_IC + 9] = np.asarray(platform.inertia).ravel()
    plat[PL_ICINV:PL_ICINV + 9] = np.linalg.inv(platform.inertia).ravel()
    plat[PL_HOME:PL_HOME + 3] = geometry.home_position
    plat[PL_CONTROL_STEPS] = control_steps
    if cartesian is not None:
        point = cartesian.point_in_top_frame(platform)
        inverse = np.linalg.inv(jacobian(geometry, point=point))
        plat[PL_CENTRAL] = 1.0
        plat[PL_JINV:PL_JINV + 36] = inverse.ravel()
        plat[PL_CKP:PL_CKP + 6] = cartesian.position_gain
        plat[PL_CKI:PL_CKI + 6] = cartesian.integral_gain
        plat[PL_CKD:PL_CKD + 6] = cartesian.damping_gain
    ex = np.zeros((6, 8))
    pieces, offsets = [], [0]
    for a, axis in enumerate(AXES):
        if axis in moving:
            scalars, table = moving[axis].pack()
            ex[a] = scalars
            plat[PL_ACTIVE + a] = 1.0
            pieces.append(np.asarray(table, dtype=float))
        else:
            pieces.append(np.zeros((5, 2)))
        offsets.append(offsets[-1] + pieces[-1].shape[1])
    plat[PL_ROTATING] = float(any(axis in moving for axis in AXES[3:]))
    tables = np.ascontiguousarray(np.concatenate(pieces, axis=1))
    toff = np.asarray(offsets, dtype=np.int64)

    state = np.zeros(N_ODE)
    state[S_C:S_C + 3] = platform.center_of_mass  # at home: c = o + R_r c_t, o = 0, R_r = I
    state[S_Q] = 1.0
    ww = np.zeros(N_WORK)
    _rest_frame(ww)
    _evaluate(0.0, state, plat, ex, tables, toff, ww, V, np.zeros((6, 6)),
              np.zeros(LEG_COUNT, dtype=np.int64), np.zeros((2, LEG_COUNT)), np.zeros(N_ODE),
              False)
    rows[R_LHOME] = rows[R_L]  # the kernels' own arithmetic: z = z_ref exactly at home
    # PI preload (docs/model.md §5 for each leg): the motor carries the static leg load the
    # spring does not (stops untouched at the setpoint), the base at rest.
    loads = _static_forces(geometry, platform)
    needed = np.zeros(LEG_COUNT)
    for i, (iso, con) in enumerate(zip(isolators, controllers)):
        spring = -iso.spring_force * np.tanh(iso.spring_shape * con.position_setpoint)
        needed[i] = np.clip(loads[i] - spring, -iso.motor_force_max, iso.motor_force_max)
        if cartesian is None and con.pi_ki > 0:
            state[S_INT + i] = needed[i] / con.pi_ki
    if cartesian is not None:  # the same leg forces from the axes' integrals, J^-T Ki I = f
        wrench = jacobian(geometry, point=cartesian.point_in_top_frame(platform)).T @ needed
        held = cartesian.integral_gain > 0
        state[S_INT:S_INT + LEG_COUNT][held] = wrench[held] / cartesian.integral_gain[held]
    return _Prepared(geometry, platform, isolators, controllers, moving, duration, dt,
                     sample_rate, decimation, solver, solver_code, V, plat, ex, tables, toff,
                     state, cartesian)


def simulate_hexapod(geometry, platform, isolator=None, controller=None, *, excitation=None,
                     duration=None, dt=defaults.SIMULATION["dt"],
                     sample_rate=defaults.SIMULATION["sample_rate"],
                     solver=defaults.SIMULATION["solver"], cartesian=None, progress=False,
                     sink=None, interruptible=False):
    """Simulate a six-leg platform of isolator legs under a base moving in up to six axes.

    A rigid platform on six single-axis isolator legs (docs/hexapod.md, "Dynamics"): each
    leg's MagSpring, Stribeck friction with exact stick-slip, compliant stops and its own PI
    loop with active damping through the amplifier's high-pass, exactly the laws of
    docs/model.md §3-5; the platform by Newton-Euler with gravity; the legs' moving masses
    lumped into the platform. Every argument is checked before any integration.

    Parameters
    ----------
    geometry : HexapodGeometry
        Joints and legs' stroke (:func:`~qzs.model.hexapod.cubic_geometry`,
        :func:`~qzs.model.hexapod.radial_geometry`).
    platform : PlatformParameters
        Mass (platform, payload and the legs' moving parts), inertia about the centre of
        mass, centre of mass and gravity.
    isolator : IsolatorParameters or sequence of six, optional
        Each leg's plant; Table 1 defaults if omitted. Its ``mass`` and ``gravity`` are not
        used (the platform's are); ``stroke_half`` must equal the geometry's; compliant stops
        only.
    controller : ControllerParameters or sequence of six, optional
        Each leg's loop; defaults if omitted. Continuous (``controller_rate`` 0) or sampled
        with zero-order hold, every leg at the same rate (one controller), as the single
        axis's (docs/model.md §5). With ``cartesian``, its ``position_setpoint``,
        ``velocity_highpass`` and ``controller_rate`` are used and its gains are not.
    excitation : dict, optional
        Base motion: axis name (``"x"``, ``"y"``, ``"z"`` [m], ``"rx"``, ``"ry"``, ``"rz"``
        [rad]) to a Chirp, Sine, RandomExcitation or DisplacementRecord (its amplitude in that
        axis's unit). The base pose is the displacement of the base point under the top frame
        origin at home and the base's rotation ``Rz Ry Rx`` about it. Default: no base motion.
    duration : float, optional
        Simulated time [s]; default the shortest excitation's length (required when none
        defines one).
    dt : float
        Integration step [s]; default 1e-4.
    sample_rate : float
        Output sample rate [Hz]; ``1/dt`` must be a whole multiple of it.
    solver : {"ode3", "rk4", "euler"}
        Fixed-step integrator (Bogacki-Shampine 3rd order by default).
    cartesian : CartesianController, optional
        Centralised control: the PI and damping loops on the platform's six axes, mapped
        through the Jacobian (docs/hexapod.md §9.5); default None, a loop per leg.
    progress : bool
        Show a progress bar over the simulated time.
    sink : callable, optional
        ``sink(data, flags)`` receives every output sample, chunk by chunk, in time order
        (``data`` with :data:`HEXAPOD_CHANNELS`' columns, ``flags`` with
        :data:`HEXAPOD_FLAGS`'); memory then stays bounded however long the run, and the
        result holds every sample only up to 200,000 of them, else every k-th
        (``run["preview_every"]``); its summary covers every sample
        (:class:`qzs.iotools.hexapod_files.HexapodWriter` is such a sink).
    interruptible : bool
        Ctrl-C ends the run after the chunk under way; the result (and the sink) then hold
        what was simulated, and ``run["completed"]`` is False.

    Returns
    -------
    HexapodResult

    Raises
    ------
    ParameterError
        Invalid argument (names it, its value and the fix); ``StabilityError`` if ``dt``
        exceeds the largest stable step.
    SimulationError
        The state diverged (the message names the time and state).
    """
    run = _prepare(geometry, platform, isolator, controller, excitation, duration, dt,
                   sample_rate, solver, progress, cartesian)
    if sink is not None and not callable(sink):
        raise ParameterError(f"`sink` must be a callable sink(data, flags) or None, got "
                             f"{type(sink).__name__}.")
    if not isinstance(interruptible, (bool, np.bool_)):
        raise ParameterError(f"`interruptible` must be True or False, got {interruptible!r}.")
    h = run.dt
    n_steps = int(round(run.duration / h))
    n_out = n_steps // run.decimation + 1
    chunk = run.decimation * max(1, 200_000 // run.decimation)
    if sink is None:
        needed = n_out * (8 * N_CHANNELS + N_FLAGS)
        available = _available_memory()
        if available is not None and needed > 0.5 * available:
            raise ParameterError(
                f"a {run.duration:g} s hexapod run at {run.sample_rate:g} Hz keeps "
                f"{needed / 1024 ** 3:.2f} GiB of samples, more than half the memory available; "
                "lower the `sample_rate` or the `duration`, or stream it to a file "
                "(`qzs hexapod simulate --out FILE.nc`, qzs.workflows.hexapod.simulate_setup("
                "..., out=...)).")
        every = 1
        out = np.empty((n_out, N_CHANNELS))
        out_flags = np.zeros((n_out, N_FLAGS), dtype=np.bool_)
    else:  # one chunk's buffer; the result keeps every ``every``-th sample as a preview
        every = 1 if n_out <= PREVIEW_SAMPLES else -(-n_out // PREVIEW_SAMPLES)
        out = np.empty((chunk // run.decimation + 1, N_CHANNELS))
        out_flags = np.zeros((out.shape[0], N_FLAGS), dtype=np.bool_)
        preview, preview_flags = [], []
    statistics = _Statistics([0.5 * (run.V[V_ZLOW + i] + run.V[V_ZHIGH + i])
                              for i in range(LEG_COUNT)])
    s = run.state
    V = run.V
    buf = np.zeros((N_BUF, N_ODE))
    ev = np.zeros((2, LEG_COUNT))
    ww = np.zeros(N_WORK)
    A, vec = np.zeros((LEG_COUNT, LEG_COUNT)), np.zeros((2, LEG_COUNT))
    idx = np.zeros(LEG_COUNT, dtype=np.int64)
    newly = np.zeros(LEG_COUNT, dtype=np.int64)
    counters = np.zeros(N_COUNTERS, dtype=np.int64)
    arrays = (run.plat, run.ex, run.tables, run.toff)
    work = (buf, ev, ww, V, A, idx, vec, newly, counters)

    def absorb(first, count, total):
        """Rows ``first:first+count`` of the buffer are new; ``total`` came before them."""
        block, marks = out[first:first + count], out_flags[first:first + count]
        statistics.add(block, marks)
        if sink is not None:
            sink(block, marks)
            keep = np.arange((-total) % every, count, every)
            preview.append(block[keep].copy())
            preview_flags.append(marks[keep].copy())

    _start(s, *arrays, *work, out[0], out_flags[0])
    _run(run.solver_code, 0, run.decimation, h, s, *arrays, *work, out, out_flags,
         1)  # compiles (or loads) the kernel: the clock counts integration only
    absorb(0, 1, 0)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=run.duration, unit="s", desc="simulating hexapod", leave=False)
    rows, done, completed, interrupted = 1, 0, True, False
    deferred = _DeferredInterrupt() if interruptible else None
    start = _time.perf_counter()
    try:
        if deferred is not None:  # Ctrl-C stops the run between chunks: rows stay whole
            deferred.install()
        while done < n_steps and not interrupted:
            n = min(chunk, n_steps - done)
            row0 = rows if sink is None else 0
            status, written = _run(run.solver_code, n, run.decimation, h, s, *arrays, *work,
                                   out, out_flags, row0)
            absorb(row0, written, rows)
            rows += written
            if status != STATUS_OK:
                failed = int(counters[CT_STEP])
                raise SimulationError(
                    f"the hexapod simulation diverged at t = {failed * h:.6g} s (last state: "
                    f"centre of mass {s[S_C:S_C + 3].tolist()} m and velocity "
                    f"{s[S_V:S_V + 3].tolist()} m/s relative to the base, leg positions "
                    f"{V[V_Z:V_Z + LEG_COUNT].tolist()} m); check the gains and parameters, or "
                    "reduce `dt`.")
            done = int(counters[CT_STEP])
            if bar is not None:
                bar.update(n * h)
            interrupted = deferred is not None and deferred.requested
        if deferred is not None and deferred.terminated:
            raise Terminated(deferred.terminated)
        completed = done >= n_steps
    except KeyboardInterrupt:
        if not interruptible:
            raise
        completed = False
    finally:
        if deferred is not None:
            deferred.restore()
        if bar is not None:
            bar.close()
    elapsed = _time.perf_counter() - start
    info = dict(solver=run.solver, dt=h, sample_rate=run.sample_rate, duration=run.duration,
                steps=int(counters[CT_STEP]), elapsed=elapsed, samples=rows,
                events=int(counters[CT_EVENTS]),
                stick_events=[int(v) for v in counters[CT_STICKS:CT_STICKS + LEG_COUNT]],
                stop_contacts=[int(v) for v in counters[CT_CONTACTS:CT_CONTACTS + LEG_COUNT]],
                stops=[(float(V[V_ZLOW + i]), float(V[V_ZHIGH + i])) for i in range(LEG_COUNT)],
                control="centralised" if run.cartesian is not None else "per leg",
                controller_rate=run.controllers[0].controller_rate, completed=completed,
                preview_every=every)
    if sink is None:
        data, data_flags = out[:rows], out_flags[:rows]
    else:
        data, data_flags = np.concatenate(preview), np.concatenate(preview_flags)
    return HexapodResult(data, data_flags, geometry=run.geometry, platform=run.platform,
                         isolators=run.isolators, controllers=run.controllers,
                         excitation=run.excitation, run=info, statistics=statistics.result())


def simulate_hexapods(runs, *, workers=None, progress=False):
    """Simulate several platforms at once, in threads (the hexapod kernel holds no GIL).

    Every run is checked before any integration starts (a bad one is named by its index);
    each gives the very numbers :func:`simulate_hexapod` gives it alone. The six legs of
    one platform already fill the kernel's vector lanes (:data:`LANES`), so platforms are
    batched across cores, one thread each, rather than in lanes.

    Parameters
    ----------
    runs : sequence of dict
        Keyword arguments of :func:`simulate_hexapod`, one dict per platform (``geometry``
        and ``platform`` required); ``progress`` and ``sink`` are not accepted.
    workers : int, optional
        Threads; default the machine's core count (at most the number of runs).
    progress : bool
        A progress bar over the platforms.

    Returns
    -------
    list of HexapodResult
        In the order of ``runs``.

    Raises
    ------
    CaseError
        A run's arguments are invalid (attributes ``index`` and ``reason``).
    ParameterError
        ``runs`` is empty or holds no dicts, or ``workers`` is not a positive integer.
    """
    from concurrent.futures import ThreadPoolExecutor

    runs = list(runs)
    if not runs:
        raise ParameterError("`runs` is empty: give at least one dict of simulate_hexapod "
                             "arguments.")
    workers = worker_count(workers, len(runs))  # checked before any run is set up
    names = ("geometry", "platform", "isolator", "controller", "excitation", "duration", "dt",
             "sample_rate", "solver", "cartesian")
    for i, arguments in enumerate(runs):
        if not isinstance(arguments, dict):
            raise ParameterError(f"`runs[{i}]` must be a dict of simulate_hexapod arguments, "
                                 f"got {type(arguments).__name__}.")
        unknown = sorted(set(arguments) - set(names))
        if unknown or "geometry" not in arguments or "platform" not in arguments:
            raise ParameterError(f"`runs[{i}]` needs `geometry` and `platform` and may have "
                                 f"{list(names[2:])}; got {sorted(arguments)}.")
        try:  # every run checked before any integration (it packs again when it starts: cheap)
            _prepare(arguments["geometry"], arguments["platform"], arguments.get("isolator"),
                     arguments.get("controller"), arguments.get("excitation"),
                     arguments.get("duration"),
                     arguments.get("dt", defaults.SIMULATION["dt"]),
                     arguments.get("sample_rate", defaults.SIMULATION["sample_rate"]),
                     arguments.get("solver", defaults.SIMULATION["solver"]), False,
                     arguments.get("cartesian"))
        except ParameterError as error:
            raise CaseError(i, str(error)) from error
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(runs), unit="platform", desc="simulating hexapods")

    def one(arguments):
        result = simulate_hexapod(**arguments)
        if bar is not None:
            bar.update()
        return result

    try:
        with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="qzs-hexapod") as pool:
            return list(pool.map(one, runs))
    finally:
        if bar is not None:
            bar.close()


# ---------------------------------------------------------------- the result
_TRANSLATION = ("m", "m", "m", "rad", "rad", "rad")
_RATE = ("m/s", "m/s", "m/s", "rad/s", "rad/s", "rad/s")
_ACCELERATION = ("m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2")
#: Output channels: name -> (first column, dimension (None: time only, "dof" or "leg"),
#: unit (per dof for "dof" variables), description).
HEXAPOD_CHANNELS = {
    "time": (C_TIME, None, "s", "time since the start of the run"),
    "platform_pose": (C_POSE, "dof", _TRANSLATION,
                      "platform pose relative to home: displacement of the top frame origin "
                      "and rotation angles (R = Rz Ry Rx), world frame"),
    "platform_twist": (C_TWIST, "dof", _RATE,
                       "velocity of the top frame origin and angular velocity, world frame"),
    "platform_acceleration": (C_ACC, "dof", _ACCELERATION,
                              "acceleration of the top frame origin and angular acceleration, "
                              "world frame"),
    "base_pose": (C_BASE_POSE, "dof", _TRANSLATION,
                  "base pose: displacement of the base point under the top frame origin at "
                  "home and rotation angles (R = Rz Ry Rx)"),
    "base_velocity": (C_BASE_VEL, "dof", _RATE,
                      "velocity of that base point and the base's angular velocity, world frame"),
    "base_acceleration": (C_BASE_ACC, "dof", _ACCELERATION,
                          "acceleration of that base point and the base's angular "
                          "acceleration, world frame"),
    "relative_position": (C_Z, "leg", "m",
                          "leg relative position z_i = L_i - L_i,home + z_ref (its encoder)"),
    "relative_velocity": (C_V, "leg", "m/s", "leg slip velocity v_i = dL_i/dt (0 when locked)"),
    "spring_force": (C_FSP, "leg", "N", "MagSpring force along the leg, on the platform"),
    "friction_force": (C_FFR, "leg", "N",
                       "friction force along the leg (the holding force when locked)"),
    "stop_force": (C_FST, "leg", "N", "hard-stop force along the leg"),
    "motor_force": (C_FMO, "leg", "N", "motor force along the leg (saturated)"),
    "pi_force": (C_FPI, "leg", "N", "PI position-loop command (before saturation)"),
    "damping_force": (C_FDA, "leg", "N", "active damping command (before saturation)"),
    "measured_velocity": (C_VME, "leg", "m/s",
                          "top joint's absolute velocity along the leg seen by the controller "
                          "(high-passed)"),
    "base_work": (C_WB, None, "J", "work done by the base through the legs"),
    "friction_dissipation": (C_DF, None, "J", "energy dissipated by the legs' friction"),
    "motor_work": (C_WM, None, "J", "work done by the motors"),
    "stop_dissipation": (C_DS, None, "J", "energy dissipated in the hard stops"),
    "kinetic_energy": (C_EK, None, "J", "kinetic energy of the platform (translation + rotation)"),
    "spring_energy": (C_ESP, None, "J", "energy stored in the six MagSprings"),
    "gravity_energy": (C_EG, None, "J", "gravitational potential energy m*g*z of the centre of "
                                        "mass (world frame)"),
    "stop_energy": (C_EST, None, "J", "elastic energy stored in the compliant stops"),
}
#: Boolean outputs per leg: name -> (first column, description).
HEXAPOD_FLAGS = {
    "locked": (O_LOCKED, "leg held at zero slip by friction"),
    "stop_contact": (O_CONTACT, "leg beyond one of its stops (in contact)"),
}
_FLAG_MEANINGS = {"locked": "slipping locked", "stop_contact": "free contact"}


def _attribute(value):
    """A value as a NetCDF-storable attribute (None -> "none", booleans -> 0/1)."""
    if value is None:
        return "none"
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, np.ndarray):
        return value.astype(float).ravel()
    if isinstance(value, (list, tuple)):
        array = np.asarray(value)
        return array.astype(np.int64 if array.dtype.kind in "iub" else float).ravel()
    return value


def hexapod_file_layout():
    """The CF-1.10 layout of a hexapod run's file: variables and coordinates with attributes.

    One place for what :meth:`HexapodResult.to_xarray` builds and what
    :class:`qzs.iotools.hexapod_files.HexapodWriter` streams (docs/model.md §7): every
    variable has ``units`` and ``long_name``; a ``dof`` variable mixes translations and
    rotations, so its ``units`` lists one unit per dof (``units_by_dof`` names them); flags
    are booleans with ``flag_values`` and ``flag_meanings``; time in plain seconds.

    Returns
    -------
    dict
        ``{"variables": {name: (dims, attrs)}, "coordinates": {name: (dims, values,
        attrs)}}`` (the ``time`` coordinate's values are the run's own).
    """
    variables = {}
    for name, (_, dim, unit, doc) in HEXAPOD_CHANNELS.items():
        if name == "time":
            continue
        attrs = {"long_name": doc}
        if dim == "dof":
            attrs["units"] = ", ".join(unit)
            attrs["units_by_dof"] = "; ".join(f"{a}: {u}" for a, u in zip(AXES, unit))
        else:
            attrs["units"] = unit
        variables[name] = (("time",) if dim is None else ("time", dim), attrs)
    for name, (_, doc) in HEXAPOD_FLAGS.items():
        variables[name] = (("time", "leg"), {
            "units": "1", "long_name": doc, "flag_values": np.array([0, 1], dtype=np.int8),
            "flag_meanings": _FLAG_MEANINGS[name]})
    coordinates = {
        "time": (("time",), None, {
            "units": "s", "standard_name": "time", "axis": "T",
            "long_name": "time since the start of the run",
            "comment": "relative run time without a calendar date: units 's' instead of "
                       "'s since <date>' (docs/model.md §7)"}),
        "dof": (("dof",), list(AXES), {"long_name": "degree of freedom: translations x, y, z "
                                                    "[m], rotations rx, ry, rz [rad]",
                                       "units": "1"}),
        "leg": (("leg",), np.arange(1, LEG_COUNT + 1), {"long_name": "leg number",
                                                         "units": "1"})}
    return {"variables": variables, "coordinates": coordinates}


class HexapodResult:
    """Time series and metadata of one hexapod run (:func:`simulate_hexapod`).

    Channels are attributes and items (``result.platform_pose``, ``result["locked"]``):
    arrays of shape (n,) for ``time`` and the energy ledger, (n, 6) per degree of freedom
    (``x, y, z, rx, ry, rz``) or per leg (legs 1 to 6); see :data:`HEXAPOD_CHANNELS` and
    :data:`HEXAPOD_FLAGS` for names and units. The object only holds and delegates.

    Parameters
    ----------
    data : ndarray, shape (n_samples, N_CHANNELS)
        The output samples.
    flags : ndarray of bool, shape (n_samples, 12)
        Locked and contact flags of the six legs.
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass, inertia, centre of mass and gravity.
    isolators : tuple of IsolatorParameters
        The six legs' plants.
    controllers : tuple of ControllerParameters
        The six legs' loops.
    excitation : dict
        Axis name -> excitation of the axes that moved.
    run : dict
        Solver, ``dt`` [s], ``sample_rate`` [Hz], ``duration`` [s], ``steps``, ``elapsed`` [s]
        (integration only), ``samples``, ``events`` (located transitions), per leg
        ``stick_events`` and ``stop_contacts``, ``stops`` (per leg, [m]), ``control``,
        ``controller_rate`` [Hz], ``completed`` (False if interrupted) and
        ``preview_every`` (the stride of the samples held when the run streamed to a file).
    statistics : dict, optional
        The summary's statistics over every sample (see ``_Statistics``); computed from
        ``data`` if omitted.
    """

    def __init__(self, data, flags, *, geometry, platform, isolators, controllers, excitation,
                 run, statistics=None):
        self._data = data
        self._flags = flags
        self.geometry = geometry
        self.platform = platform
        self.isolators = tuple(isolators)
        self.controllers = tuple(controllers)
        self.excitation = dict(excitation)
        self.run = run
        if statistics is None:  # from the samples held
            running = _Statistics([0.5 * (low + high) for low, high in run["stops"]])
            running.add(data, flags)
            statistics = running.result()
        self.statistics = statistics

    def __getitem__(self, name):
        if name in HEXAPOD_CHANNELS:
            column, dim = HEXAPOD_CHANNELS[name][:2]
            return self._data[:, column] if dim is None else self._data[:, column:column + 6]
        if name in HEXAPOD_FLAGS:
            column = HEXAPOD_FLAGS[name][0]
            return self._flags[:, column:column + 6]
        raise KeyError(f"no channel {name!r}; channels are "
                       f"{', '.join([*HEXAPOD_CHANNELS, *HEXAPOD_FLAGS])}.")

    def __getattr__(self, name):
        if name.startswith("_") or (name not in HEXAPOD_CHANNELS and name not in HEXAPOD_FLAGS):
            raise AttributeError(name)
        return self[name]

    def __len__(self):
        return self._data.shape[0]

    def __repr__(self):
        return (f"<HexapodResult {len(self)} samples, {self['time'][-1]:.6g} s, "
                f"{self.run['solver']} dt={self.run['dt']:g} s>")

    @property
    def steps_per_second(self):
        """Integration throughput of the run [steps/s]."""
        return self.run["steps"] / max(self.run["elapsed"], 1e-12)

    def mechanical_energy(self):
        """Kinetic + spring + gravity + stop elastic energy [J] at each sample."""
        return (self["kinetic_energy"] + self["spring_energy"] + self["gravity_energy"]
                + self["stop_energy"])

    def energy_residual(self):
        """Energy-ledger imbalance [J]: change of mechanical energy minus the net work.

        ``dE - (W_base + W_motor - D_friction - D_stop)``; zero up to the integrator's
        truncation error.
        """
        energy = self.mechanical_energy()
        net = (self["base_work"] + self["motor_work"] - self["friction_dissipation"]
               - self["stop_dissipation"])
        return energy - energy[0] - net

    def metadata(self):
        """Every parameter and run setting with its unit: ``{key: (value, unit)}``.

        Keys ``platform.<name>``, ``geometry.<name>``, ``isolator.<name>`` and
        ``controller.<name>`` (one value, or six per leg where the legs differ),
        ``excitation.<axis>`` (the class) and ``excitation.<axis>.<field>``, ``run.<key>``.
        """
        import dataclasses

        meta = {}
        for name in ("base_joints", "top_joints", "home_position", "stroke_half"):
            meta[f"geometry.{name}"] = (getattr(self.geometry, name), "m")
        for field in dataclasses.fields(self.platform):
            meta[f"platform.{field.name}"] = (getattr(self.platform, field.name),
                                              field.metadata.get("unit", ""))
        for section, objects in (("isolator", self.isolators), ("controller", self.controllers)):
            for field in dataclasses.fields(objects[0]):
                values = [getattr(o, field.name) for o in objects]
                value = values[0] if all(v == values[0] for v in values) else values
                meta[f"{section}.{field.name}"] = (value, unit_of(field.name))
        for axis, value in self.excitation.items():
            meta[f"excitation.{axis}"] = (type(value).__name__, "")
            for field in dataclasses.fields(value):
                item = getattr(value, field.name)
                if not isinstance(item, np.ndarray):
                    unit = field.metadata.get("unit", "")
                    if axis in AXES[3:]:
                        unit = unit.replace("m", "rad") if unit in ("m", "m/s", "m/s^2") else unit
                    meta[f"excitation.{axis}.{field.name}"] = (item, unit)
        units = {"dt": "s", "sample_rate": "Hz", "duration": "s", "elapsed": "s", "stops": "m"}
        for key, value in self.run.items():
            meta[f"run.{key}"] = (value, units.get(key, "1" if key != "solver" else "-"))
        return meta

    def to_xarray(self):
        """The run as an ``xarray.Dataset`` with dimensions ``time``, ``dof`` and ``leg``.

        CF-1.10 as :meth:`qzs.engine.results.SimulationResult.to_xarray` (time in plain
        seconds, docs/model.md §7): every variable has ``units`` and ``long_name``; a
        ``dof`` variable mixes translations and rotations, so its ``units`` lists one unit
        per dof in the order of the ``dof`` coordinate (``units_by_dof`` says so by name);
        flags are booleans with ``flag_values`` and ``flag_meanings``. Parameters and run
        settings are global attributes with their units in ``<key>_units``.
        """
        import xarray as xr

        layout = hexapod_file_layout()
        variables = {name: (dims, self[name], attrs)
                     for name, (dims, attrs) in layout["variables"].items()}
        coords = {name: (dims, self["time"] if name == "time" else values, attrs)
                  for name, (dims, values, attrs) in layout["coordinates"].items()}
        return xr.Dataset(variables, coords=coords, attrs=self.global_attributes())

    def global_attributes(self):
        """The file's global attributes: CF conventions, provenance, every parameter and run
        setting (``<key>`` with its unit in ``<key>_units``)."""
        import datetime

        from qzs._version import __version__

        now = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
        attrs = {"Conventions": "CF-1.10",
                 "title": "qzs simulation of a six-leg platform of semi-active QZS isolator legs",
                 "source": f"qzs {__version__}: fixed-step hexapod dynamics with exact stick-slip "
                           "per leg (model: docs/hexapod.md, docs/model.md)",
                 "history": f"{now} qzs {__version__}: qzs.simulate_hexapod (Python), solver "
                            f"{self.run['solver']}, dt {self.run['dt']} s, "
                            f"{self.run['steps']} steps",
                 "qzs_version": __version__}
        for key, (value, unit) in self.metadata().items():
            attrs[key] = _attribute(value)
            if unit:
                attrs[f"{key}_units"] = unit
        return attrs

    def summary(self):
        """One-screen text summary: per leg stroke used, contacts, time locked, motor RMS."""
        return _summary_text(self)

    def save(self, path):
        """Write the run to a NetCDF file (:func:`qzs.iotools.hexapod_files.save_hexapod_result`).

        Parameters
        ----------
        path : str or Path
            Target ``.nc`` file.

        Returns
        -------
        Path
        """
        from qzs.iotools.hexapod_files import save_hexapod_result

        return save_hexapod_result(self, path)

    def plot(self, **kwargs):
        """Plot the run (see :func:`qzs.viz.hexapod.plot_hexapod`).

        Parameters
        ----------
        **kwargs
            Passed to :func:`qzs.viz.hexapod.plot_hexapod` (``path``, ``title``).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.hexapod import plot_hexapod

        return plot_hexapod(self, **kwargs)


class _Statistics:
    """Running statistics of a hexapod run over every output sample, chunk by chunk.

    What the summary reports, exact over the whole run however it is stored (in memory
    or streamed to a file with only a preview kept): per leg the largest distance from the
    stops' centre [m], the share of samples locked [-], the motor force's RMS and largest
    magnitude [N]; the largest relative translation [m] and rotation [rad] of the platform;
    the largest energy-ledger residual [J] and |base work| [J].
    """

    def __init__(self, centers):
        self._legs = RunStatistics(centers)  # the single axis's statistics, a leg per case
        self._rows = 0
        self._motor_max = np.zeros(LEG_COUNT)
        self._translation = self._rotation = 0.0
        self._residual = self._base_work = 0.0
        self._energy0 = None

    def add(self, block, flags):
        """Absorb output rows ``block`` (``N_CHANNELS`` columns) and their ``flags``."""
        if block.shape[0] == 0:
            return
        motor = block[:, C_FMO:C_FMO + LEG_COUNT]
        self._legs.add(block[:, C_Z:C_Z + LEG_COUNT].T, motor.T,
                       flags[:, O_LOCKED:O_LOCKED + LEG_COUNT].T)
        self._motor_max = np.maximum(self._motor_max, np.max(np.abs(motor), axis=0))
        pose = block[:, C_POSE:C_POSE + 6] - block[:, C_BASE_POSE:C_BASE_POSE + 6]
        self._translation = max(self._translation, float(np.max(np.abs(pose[:, :3]))))
        self._rotation = max(self._rotation, float(np.max(np.abs(pose[:, 3:]))))
        energy = block[:, C_EK] + block[:, C_ESP] + block[:, C_EG] + block[:, C_EST]
        if self._energy0 is None:
            self._energy0 = float(energy[0])
        net = block[:, C_WB] + block[:, C_WM] - block[:, C_DF] - block[:, C_DS]
        self._residual = max(self._residual,
                             float(np.max(np.abs(energy - self._energy0 - net))))
        self._base_work = max(self._base_work, float(np.max(np.abs(block[:, C_WB]))))
        self._rows += block.shape[0]

    def result(self):
        """The statistics as a dict of floats and per-leg lists, with their units in the keys."""
        legs = self._legs.result()
        return {"samples": self._rows, "stroke_used_m": legs["peak_stroke"].tolist(),
                "locked_share": legs["locked_fraction"].tolist(),
                "motor_rms_N": legs["motor_force_rms"].tolist(),
                "motor_max_N": self._motor_max.tolist(),
                "relative_translation_max_m": self._translation,
                "relative_rotation_max_rad": self._rotation,
                "energy_residual_max_J": self._residual, "base_work_max_J": self._base_work}


def _summary_text(result):
    """The text of :meth:`HexapodResult.summary` (from the statistics of every sample)."""
    run = result.run
    stats = result.statistics
    moving = ", ".join(f"{axis}: {type(e).__name__}" for axis, e in result.excitation.items())
    residual = stats["energy_residual_max_J"]
    scale = max(stats["base_work_max_J"], 1e-300)
    lines = [f"Hexapod run: {run['duration']:g} s, {run['solver']} dt = {run['dt']:g} s, "
             f"{run['steps']:,} steps in {run['elapsed']:.3g} s "
             f"({result.steps_per_second:,.0f} steps/s), {run['events']:,} located transitions",
             f"Base excitation: {moving or 'none'}",
             f"Platform: {result.platform.mass:g} kg, gravity {result.platform.gravity:g} m/s^2",
             "Control: " + ("PI + damping loops on the platform's axes (centralised)"
                            if run.get("control") == "centralised" else "a PI + damping loop "
                            "per leg")
             + (f", sampled at {run['controller_rate']:g} Hz (zero-order hold)"
                if run.get("controller_rate") else ", continuous"),
             "",
             "leg  stroke used [mm]  of [mm]  contacts  locked [%]  stick events  "
             "motor RMS [N]  motor max [N]"]
    for i in range(LEG_COUNT):
        low, high = run["stops"][i]
        lines.append(f"{i + 1:>3}  {1e3 * stats['stroke_used_m'][i]:16.2f}  "
                     f"{1e3 * (high - low) / 2:7.1f}  "
                     f"{run['stop_contacts'][i]:8d}  {100 * stats['locked_share'][i]:10.1f}  "
                     f"{run['stick_events'][i]:12d}  {stats['motor_rms_N'][i]:13.2f}  "
                     f"{stats['motor_max_N'][i]:13.2f}")
    lines += ["",
              f"Platform relative to base: translation up to "
              f"{1e3 * stats['relative_translation_max_m']:.3g} mm, rotation up to "
              f"{1e3 * stats['relative_rotation_max_rad']:.3g} mrad",
              f"Energy ledger residual: max {residual:.3g} J ({residual / scale:.2g} of the "
              f"largest |base work|)"]
    if not run.get("completed", True):
        lines.append(f"Interrupted: {run['samples']:,} samples up to "
                     f"t = {run['steps'] * run['dt']:.6g} s of {run['duration']:g} s.")
    if run.get("preview_every", 1) > 1:
        lines.append(f"In memory: every {run['preview_every']}th sample (a preview; the file "
                     "holds them all)")
    return "\n".join(lines)
