"""The six-axis kernels' packed layouts: per-leg rows, platform constants, state, output.

Named offsets into the flat arrays that the kernels (:mod:`~qzs.engine.hexapod.dynamics`,
:mod:`~qzs.engine.hexapod.stepping`), the packing (:mod:`~qzs.engine.hexapod.prepare`),
the driver (:mod:`~qzs.engine.hexapod.simulate`) and the result
(:mod:`~qzs.engine.hexapod.result`) share; numba compiles these module-level integers in
as constants.
"""
from qzs.defaults import AXES  # the six axes of a pose: translations [m], rotation angles [rad]
from qzs.engine.kernels import N_X
from qzs.model.hexapod import LEG_COUNT

__all__ = ["AXES", "LANES"]

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
# controller's held outputs (PI, damping, motor); with blocks beyond PI + damping
# (docs/model.md §5.1) their forces (compensation, dither, linear controller), the
# compensation's feedforward, the unsaturated command, the base's and the top joint's
# acceleration along the leg (sensors), the held outputs of sampled blocks and a mark of the
# legs released at the current instant (their slip velocity still 0 for the blocks' sensors,
# as the single axis's is, until the state moves); and six rows of the legs' coupling
# ``G_i M^-1 G_j^T`` (row ``C0 + i``, lane ``j``); ``V_*`` is each row's offset.
N_ROWS = 79 + LEG_COUNT - 1
(V_A, V_B, V_FS, V_FC, V_CBC, V_CV, V_ZLOW, V_ZHIGH, V_STOPK, V_STOPC, V_FMAX, V_ZREF, V_KP, V_KI,
 V_KD, V_HP, V_LHOME, V_BX, V_BY, V_BZ, V_TX, V_TY, V_TZ, V_MODE, V_DIR, V_HPS, V_INT, V_UX, V_UY,
 V_UZ, V_GX, V_GY, V_GZ, V_MX, V_MY, V_MZ, V_L, V_VR, V_KAP, V_Z, V_V, V_FSP, V_FST, V_FEL, V_FMO,
 V_FPI, V_FDA, V_VME, V_FFR, V_F, V_XB, V_EV, V_DHP, V_DINT, V_FUX, V_FUY, V_FUZ, V_FGX, V_FGY,
 V_FGZ, V_PB, V_PF, V_PM, V_PS, V_HPI, V_HDA, V_HMO, V_FCO, V_FDI, V_FLI, V_FFF, V_CMD, V_YDD,
 V_XDD, V_HCO, V_HDI, V_HLI, V_FRESH, V_C0) = range(0, 79 * LANES, LANES)
# Platform ``plat``: mass, gravity, COM in the top frame, inertia and its inverse (row-major),
# home position, which base axes move, whether the base rotates; the control: grid steps per
# controller sample (0: continuous), centralised (1) or per leg (0), and the Cartesian loops'
# ``J^-1`` (row-major) and gains per axis (proportional, integral, damping).
(PL_MASS, PL_G, PL_CT, PL_IC, PL_ICINV, PL_HOME, PL_ACTIVE, PL_ROTATING, PL_CONTROL_STEPS,
 PL_CENTRAL, PL_JINV, PL_CKP, PL_CKI, PL_CKD) = (0, 1, 2, 5, 14, 23, 26, 32, 33, 34, 35, 71, 77,
                                                83)
N_PLAT = 89
# The legs' controller blocks beyond PI + damping and spring laws, ``models``: with blocks on
# any leg or a leg's spring a law other than the MagSpring's tanh, each leg's packed model row
# (``qzs.engine.kernels.M_*``, :func:`qzs.engine.prepare.pack_model`: its blocks, then its law
# at ``M_SPRING``), an array (LEG_COUNT, the widest row; :func:`qzs.engine.prepare.stack_models`);
# without, ``None``. The kernels take it as an argument and branch on ``models is not None``,
# which numba prunes by type before it compiles a callee: a run without blocks or laws compiles
# none of their code (dynamics.py). With ``models``, the blocks' code runs only when a leg has
# blocks (``M_BLOCKS``, ``dynamics._with_blocks``): a run with laws
# alone keeps the state and output of a run without blocks.

# ODE state; with blocks, each leg's blocks' state (``qzs.engine.kernels.X_*``: a linear
# controller's states, the friction observer's estimate) follows: leg ``i``'s at
# ``S_X + i * N_X`` (without, the state ends at ``N_ODE``).
S_C, S_Q, S_V, S_W, S_HP, S_INT, S_WB, S_DF, S_WM, S_DS = 0, 3, 7, 10, 13, 19, 25, 26, 27, 28
N_ODE = 29
S_X = N_ODE
N_ODE_BLOCKS = N_ODE + LEG_COUNT * N_X

# Platform workspace ``ww``: the base motion and frame, the platform's rotation and inertia,
# its accelerations, the sum of the leg forces, the state of the locked legs' factorisation,
# its reciprocal pivots, the impulses of the last projection (0 if none), per axis the
# excitation's phase and its sine and cosine at the start of the step (persistent: carried
# across kernel calls), the Cartesian loops' errors, PI and damping commands per axis, and
# where a leg's spring table first refused its position (leg number from 1, 0 for none; the
# position [m] and slip velocity [m/s] there; cleared after a step that ends with a force).
(W_Y, W_YD, W_YDD, W_RB, W_OM, W_AL, W_VO, W_AO, W_GH, W_OMW, W_ALW, W_RR, W_IBI, W_ACC,
 W_FSUM, W_SOLVE, W_PIVOTS, W_IMPULSE, W_PHASE, W_CART, W_OUTSIDE) = (
    0, 6, 12, 18, 27, 30, 33, 36, 39, 42, 45, 48, 57, 66, 72, 75, 76, 82, 88, 106, 124)
N_WORK = 127
SOLVE_NONE, SOLVE_FACTORED, SOLVE_MIN_NORM = 0.0, 1.0, 2.0
# Rows of the state buffers ``buf`` (N_BUF, N_ODE).
B_S, B_K1, B_S1, B_KE, B_TMP, B_K2, B_K3, B_K4, B_TRIAL, B_KT = range(10)
N_BUF = 10
# Counters.
CT_STEP, CT_EVENTS, CT_STICKS, CT_CONTACTS, CT_IN_CONTACT = 0, 1, 2, 8, 14
N_COUNTERS = 20

MODE_SLIP, MODE_LOCK = 0.0, 1.0
#: A run's status: going; diverged; stopped where a leg left a spring table that refuses
#: positions outside it (its force NaN there), as the single axis's ``STATUS_OUTSIDE``.
STATUS_OK, STATUS_DIVERGED, STATUS_OUTSIDE = 0, 1, 2

# Output channels: time, poses and motions [6 each], per-leg blocks [6 each], the ledger.
C_TIME, C_POSE, C_TWIST, C_BASE_POSE, C_BASE_VEL, C_BASE_ACC, C_ACC = 0, 1, 7, 13, 19, 25, 31
(C_Z, C_V, C_FSP, C_FFR, C_FST, C_FMO, C_FPI, C_FDA, C_VME) = (37, 43, 49, 55, 61, 67, 73, 79,
                                                               85)
C_WB, C_DF, C_WM, C_DS, C_EK, C_ESP, C_EG, C_EST = 91, 92, 93, 94, 95, 96, 97, 98
#: The channels of every run; a controller with blocks adds each leg's block forces (an
#: output row without them has N_BASE_CHANNELS columns, with them N_CHANNELS).
N_BASE_CHANNELS = 99
C_FCO, C_FOB, C_FDI, C_FLI = 99, 105, 111, 117
N_CHANNELS = 123
O_LOCKED, O_CONTACT = 0, 6
N_FLAGS = 12
