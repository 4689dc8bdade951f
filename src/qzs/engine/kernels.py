"""Numba kernels of the isolator simulator: one force law, one stepper.

Arrays and floats in, a status code out; no validation and no Python objects
(scipy ``_ivp/rk.py`` style). The driver in :mod:`qzs.engine.lanes` advances one case
or many with these, for a single run, a batch and a cluster worker alike.

Inside the kernels the parameters, the excitation scalars and the state are
tuples of floats, not arrays: that keeps the hot path free of reference counting
and lets LLVM hold everything in registers. The packed arrays (pvlib ``spa``
style) are converted once per call of the driver, :func:`qzs.engine.lanes.run_lanes`.

ODE state (``S_*``): relative position z [m], relative velocity v [m/s], the
charge amplifier's low-pass state [m/s], the PI integral [m*s], then the energy
ledger [J] integrated with the motion: work by the base, friction dissipation,
motor work, stop dissipation. The persistent state array also holds the
zero-order-hold controller outputs (``A_*``). Integer flags (``I_*``): mode
(slipping, stuck to the base, resting on a plastic stop), slip direction, step
counter, contact flag and counters.

Stick-slip follows docs/model.md (and Modelica's ``MassWithStopAndFriction``): a
slipping payload is located at the zero crossing of v inside the step, then it
sticks if friction can hold it (``|F_hold| <= Fs``) or else reverses; a stuck
payload breaks away, located inside the step too, when ``|F_hold|`` exceeds Fs.
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT as _JIT
from qzs.engine.arithmetic import fma
from qzs.engine.base_motion import advance_phase, base_motion, base_motion_near, excitation_tuple
from qzs.engine.laws import (compensation_law, compliant_stop_law, controller_law,
                             dither_law, saturation_law, sliding_friction_law,
                             spring_energy_general, spring_energy_law, spring_general,
                             spring_law)
from qzs.engine.stickslip import (MODE_SLIP, MODE_STICK, MODE_WALL_HIGH, MODE_WALL_LOW,
                                  crossed_zero, hold_margin, locate, release_direction,
                                  secant_fraction, slip_event)
from qzs.model.sensors import MAX_STATES, SENSORS
from qzs.model.springs import TABLE, TABLE_OUTSIDE, TANH

# Packed parameters. P_VREG > 0 selects the regularised friction model: no stick-slip events,
# the mode stays slipping (docs/model.md §3).
(P_MASS, P_GRAVITY, P_SPRING_A, P_SPRING_B, P_FS, P_FC, P_CBC, P_CV, P_Z_LOW, P_Z_HIGH,
 P_STOP_K, P_STOP_C, P_PLASTIC, P_FMAX, P_ZREF, P_KP, P_KI, P_KD, P_HP_OMEGA,
 P_CONTROL_STEPS, P_DT, P_VREG) = range(22)
N_PARAMS = 22

# ODE state, then the held controller outputs of a sampled controller.
S_Z, S_V, S_HP, S_INT, S_W_BASE, S_D_FRICTION, S_W_MOTOR, S_D_STOP = range(8)
N_ODE = 8
A_F_PI, A_F_DAMP, A_F_MOTOR = range(N_ODE, N_ODE + 3)
# The holding margin of the last step (NaN: work it out again), carried across kernel calls so
# that where a run is cut into chunks changes nothing (docs/model.md §9).
A_MARGIN = N_ODE + 3
#: Most states of a user's linear controller (:class:`qzs.model.controller.LinearController`).
NX_MAX = MAX_STATES
#: The controller blocks' own ODE state (``X_*``, a tuple of its own in the kernels): the
#: linear controller's states ``X_X0 + i``, then the friction observer's estimate [N].
X_X0 = 0
X_OBSERVER = NX_MAX
N_X = NX_MAX + 1
#: Where the persistent state array keeps them, and the held outputs of the sampled blocks
#: (friction compensation, dither, linear controller).
A_X0 = A_MARGIN + 1
A_F_COMPENSATION, A_F_DITHER, A_F_LINEAR = range(A_X0 + N_X, A_X0 + N_X + 3)
N_STATE = A_X0 + N_X + 3
N_HELD = 6
#: The excitation's sine and cosine are computed exactly every this many steps and rotated in
#: between; kernel calls start on multiples of it, so chunking changes no bit (docs/model.md §9).
PHASE_PERIOD = 256

# The controller's blocks beyond PI + damping, packed per case (``M_*``, docs/model.md §5):
# a flag for any block, the friction compensation (fraction, the compensator's friction law,
# deadband, observer bandwidth), the dither, and the linear controller: on, states, sample
# period in grid steps (0: continuous), then its matrices A (NX_MAX x NX_MAX), B (NX_MAX x
# N_SENSORS, a column per sensor ``U_*``), C (NX_MAX), D (N_SENSORS) row by row, zero-padded,
# and its anti-windup gain.
(M_BLOCKS, M_COMP_FRACTION, M_COMP_FS, M_COMP_FC, M_COMP_CBC, M_COMP_CV, M_COMP_DEADBAND,
 M_OBSERVER_RATE, M_DITHER_AMPLITUDE, M_DITHER_OMEGA, M_LINEAR, M_LINEAR_STATES,
 M_LINEAR_STEPS) = range(13)
#: The sensors a linear controller may read (``U_*``): the position error z_ref - z [m], the
#: charge amplifier's payload velocity [m/s], payload and base acceleration [m/s^2], the
#: relative velocity [m/s].
U_ERROR, U_VELOCITY, U_PAYLOAD_ACCELERATION, U_BASE_ACCELERATION, U_RELATIVE_VELOCITY = range(5)
N_SENSORS = 5
assert tuple(SENSORS) == ("position_error", "measured_payload_velocity", "payload_acceleration",
                          "base_acceleration", "relative_velocity")
M_A = 13
M_B = M_A + NX_MAX * NX_MAX
M_C = M_B + NX_MAX * N_SENSORS
M_D = M_C + NX_MAX
M_ANTIWINDUP = M_D + N_SENSORS
#: The blocks' width (what the C model copies).
N_MODEL = M_ANTIWINDUP + NX_MAX
#: The spring law after the blocks (docs/model.md §3.1): its packed form
#: (:meth:`qzs.model.springs.SpringLaw.pack`, a table's pieces inline), the tanh's
#: ``[0, a, b]`` by default. A row is as wide as its law needs (a batch's rows, the widest
#: case's), N_MODEL_ROW with the tanh. A law other than the tanh (or any blocks) takes the
#: general path (:func:`general`).
M_SPRING = N_MODEL
N_MODEL_ROW = M_SPRING + 3
#: A linear controller of at most this many states takes the short loops (``_rows``).
NX_SHORT = 4
assert NX_MAX == 2 * NX_SHORT

# Integer flags.
I_MODE, I_DIRECTION, I_STEP, I_CONTACT, I_N_CONTACTS, I_N_STICKS = range(6)
N_FLAGS = 6
# The modes (MODE_SLIP, MODE_STICK, MODE_WALL_LOW, MODE_WALL_HIGH) are qzs.engine.stickslip's.

# Force breakdown returned by the right-hand side.
(F_Y, F_YD, F_YDD, F_SPRING, F_FRICTION, F_STOP, F_STOP_ELASTIC, F_MOTOR, F_PI, F_DAMP,
 F_V_MEASURED, F_HOLD, F_XDD, F_COMPENSATION, F_DITHER, F_LINEAR, F_OBSERVER) = range(17)
N_FORCES = 17

# Output channels.
(C_TIME, C_BASE_Y, C_BASE_YD, C_BASE_YDD, C_X, C_XD, C_XDD, C_Z, C_V, C_F_SPRING,
 C_F_FRICTION, C_F_STOP, C_F_MOTOR, C_F_PI, C_F_DAMP, C_V_MEASURED, C_W_BASE, C_D_FRICTION,
 C_W_MOTOR, C_D_STOP, C_E_KINETIC, C_E_SPRING, C_E_GRAVITY, C_E_STOP, C_F_COMPENSATION,
 C_F_DITHER, C_F_LINEAR, C_F_OBSERVER) = range(28)
N_CHANNELS = 28
#: The channels of every run; the last ones (the controller's blocks beyond PI + damping) are
#: recorded only with blocks, and an output row without them has N_BASE_CHANNELS columns.
N_BASE_CHANNELS = C_F_COMPENSATION
O_LOCKED, O_CONTACT = 0, 1

SOLVER_EULER, SOLVER_ODE3, SOLVER_RK4 = 0, 1, 2
#: A run's status: going; diverged; stopped outside a refusing spring table.
STATUS_OK, STATUS_DIVERGED, STATUS_OUTSIDE = 0, 1, 2

@njit(**_JIT)
def params_tuple(p):
    """The packed parameter array as a tuple."""
    return (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
            p[13], p[14], p[15], p[16], p[17], p[18], p[19], p[20], p[21])


@njit(**_JIT, inline="always")
def general(M):
    """Does the case packed as ``M`` take the general path: controller blocks beyond PI +
    damping, or a spring law other than the tanh (``M_SPRING``)?"""
    return M[M_BLOCKS] != 0.0 or M[M_SPRING] != TANH


def kernel_model(model):
    """The packed model row as the kernels take it: ``None`` on the default path (PI +
    damping, the tanh of ``P``), the row itself on the general path (:func:`general`).

    A kernel given ``None`` is compiled without the general path's code (numba prunes the
    branches on ``M is None``): a first run of the default model compiles none of the
    blocks' or the spring laws' code.
    """
    return model if model is not None and general(model) else None


@njit(**_JIT, inline="always")
def failure_status(M):
    """The status of a case that stopped on a non-finite state: :data:`STATUS_OUTSIDE`
    when its spring is a table that refuses positions outside it (its force is NaN there),
    else :data:`STATUS_DIVERGED`."""
    if M is not None and M[M_SPRING] == TABLE and M[M_SPRING + TABLE_OUTSIDE] == 0.0:
        return STATUS_OUTSIDE
    return STATUS_DIVERGED


@njit(**_JIT, inline="always")
def controller_output(P, z, v_measured, integral):
    """:func:`qzs.engine.laws.controller_law` with the packed parameters ``P``."""
    return controller_law(P[P_ZREF], P[P_KP], P[P_KI], P[P_KD], P[P_FMAX], z, v_measured,
                          integral)


@njit(**_JIT, inline="always")
def _linear_output(M, x, u):
    """Output ``C x + D u`` [N] of the linear controller (states ``x``, sensors ``u``).

    Loops of a constant length over the zero-padded rows (short ones for a small controller),
    so that they unroll and the tuples are indexed by constants; a zero-padded term adds an
    exact zero."""
    y = 0.0
    if M[M_LINEAR_STATES] <= NX_SHORT:
        for j in range(NX_SHORT):
            y = fma(M[M_C + j], x[X_X0 + j], y)
    else:
        for j in range(NX_MAX):
            y = fma(M[M_C + j], x[X_X0 + j], y)
    for k in range(N_SENSORS):
        y = fma(M[M_D + k], u[k], y)
    return y


@njit(**_JIT, inline="always")
def _linear_row(i, width, M, x, u, excess):
    """Row ``i`` of ``A x + B u + L excess`` over the first ``width`` states (a constant)."""
    rate = M[M_ANTIWINDUP + i] * excess
    row = M_A + i * NX_MAX
    for j in range(width):
        rate = fma(M[row + j], x[X_X0 + j], rate)
    row = M_B + i * N_SENSORS
    for k in range(N_SENSORS):
        rate = fma(M[row + k], u[k], rate)
    return rate


@njit(**_JIT, inline="always")
def _linear_rates(M, x, u, excess, observer):
    """``A x + B u + L excess`` as the blocks' state tuple, then ``observer`` in the
    observer's entry: a continuous linear controller's state rates, or a discrete one's next
    states (``excess``: the saturated motor force less the command [N], the back-calculation
    anti-windup, docs/model.md §5). A padded row is 0."""
    if M[M_LINEAR_STATES] <= NX_SHORT:
        return (_linear_row(0, NX_SHORT, M, x, u, excess),
                _linear_row(1, NX_SHORT, M, x, u, excess),
                _linear_row(2, NX_SHORT, M, x, u, excess),
                _linear_row(3, NX_SHORT, M, x, u, excess), 0.0, 0.0, 0.0, 0.0, observer)
    return (_linear_row(0, NX_MAX, M, x, u, excess), _linear_row(1, NX_MAX, M, x, u, excess),
            _linear_row(2, NX_MAX, M, x, u, excess), _linear_row(3, NX_MAX, M, x, u, excess),
            _linear_row(4, NX_MAX, M, x, u, excess), _linear_row(5, NX_MAX, M, x, u, excess),
            _linear_row(6, NX_MAX, M, x, u, excess), _linear_row(7, NX_MAX, M, x, u, excess),
            observer)


@njit(**_JIT, inline="always")
def _compensation(v, direction, v_reg, M):
    """The friction compensation's feedforward [N] at slip velocity ``v`` [m/s] (``v_reg``:
    the plant's regularisation velocity [m/s], 0 for the exact model)."""
    if M[M_COMP_FRACTION] == 0.0:
        return 0.0
    return compensation_law(v, direction, M[M_COMP_FRACTION], M[M_COMP_FS], M[M_COMP_FC],
                            M[M_COMP_CBC], M[M_COMP_CV], v_reg, M[M_COMP_DEADBAND])


# The blocks' functions are compiled once and called, not inlined into every caller of
# :func:`rhs` (eight entry points inline it): a run without blocks never calls them, and
# inlined they made its first compile 116 s of CPU instead of 47 (22 before blocks existed).
@njit(**_JIT)
def block_forces(t, error, x, v, direction, ydd, v_measured, held, sampled, v_reg, M):
    """The forces of the controller's blocks beyond PI + damping [N] (docs/model.md §5).

    One leg's blocks, for every driver (the single axis, the lanes, each leg of the
    hexapod): ``error`` the position error ``z_ref - z`` [m], ``v`` the slip velocity [m/s]
    in ``direction``, ``ydd`` the base's acceleration [m/s^2], ``v_measured`` the charge
    amplifier's velocity [m/s], ``held`` the sampled outputs (``A_F_*`` order), ``sampled``
    whether the PI and its blocks are sampled, ``v_reg`` the plant's regularisation velocity,
    ``M`` the packed blocks (``M_*``). Returns ``(compensation, dither, linear,
    feedforward)``: the friction compensation (its feedforward less the observer's estimate
    of the friction left), the dither and the linear controller's output (states ``x``); a
    sampled block's is the value it holds. ``feedforward`` is the compensation's feedforward
    alone.
    """
    feedforward = 0.0
    if sampled:
        f_comp, f_dither = held[3], held[4]
    else:
        feedforward = _compensation(v, direction, v_reg, M)
        f_comp = feedforward - x[X_OBSERVER]
        f_dither = 0.0
        if M[M_DITHER_AMPLITUDE] != 0.0:
            f_dither = dither_law(t, M[M_DITHER_AMPLITUDE], M[M_DITHER_OMEGA])
    f_linear = 0.0
    if M[M_LINEAR] != 0.0:
        if M[M_LINEAR_STEPS] > 0.0:
            f_linear = held[5]
        else:  # the payload's acceleration enters only through B (docs/model.md §5)
            f_linear = _linear_output(M, x, (error, v_measured, 0.0, ydd, v))
    return f_comp, f_dither, f_linear, feedforward


@njit(**_JIT)
def block_rates(x, sensors, f_friction, f_stop, feedforward, excess, sampled, M):
    """The rates of the blocks' state ``x`` (``X_*``) of one leg (docs/model.md §5).

    ``sensors`` the five sensors (``U_*``), ``f_friction + f_stop`` the friction (the
    holding force when stuck) and stop force [N], ``feedforward`` the compensation's
    feedforward [N], ``excess`` the saturated motor force less the command [N]. The
    observer's estimate follows the friction left after the feedforward (a sampled one
    steps at its samples, :func:`sample_blocks`); a continuous linear controller's states
    follow ``A x + B u + L excess``.
    """
    observer = 0.0
    if not sampled and M[M_OBSERVER_RATE] > 0.0:
        # the friction left after the feedforward, as the observer measures it
        observer = M[M_OBSERVER_RATE] * (f_friction + f_stop + feedforward - x[X_OBSERVER])
    if M[M_LINEAR] != 0.0 and M[M_LINEAR_STEPS] == 0.0:
        return _linear_rates(M, x, sensors, excess, observer)
    return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, observer)


@njit(**_JIT)
def sample_blocks(t, x, v, direction, held, f_friction, f_stop, f_pi, f_damp, f_linear, error,
                  ki, f_max, steps, dt, v_reg, M):
    """One leg's sampled blocks at a sample of the PI (docs/model.md §5).

    The observer advanced by forward Euler over the period (``steps`` grid steps of ``dt``
    [s]) from what it measures (``f_friction + f_stop`` [N] with the held outputs ``held``),
    the compensation with its new estimate, the dither at ``t``; then the motor's command
    with the PI's ``f_pi, f_damp`` and the linear output ``f_linear`` [N], saturated at
    ``f_max`` (the PI's anti-windup with ``error`` [m] and ``ki``). Returns
    ``(compensation, dither, motor force, integral rate, x)``.
    """
    if M[M_OBSERVER_RATE] > 0.0:
        # advanced by forward Euler over the period from what it measures now, the
        # feedforward applied until now being the held force plus the estimate it held
        applied = held[3] + x[X_OBSERVER]
        measured = f_friction + f_stop + applied
        observer = x[X_OBSERVER] + M[M_OBSERVER_RATE] * (
            measured - x[X_OBSERVER]) * steps * dt
        x = (x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], observer)
    feedforward = _compensation(v, direction, v_reg, M)
    f_comp = feedforward - x[X_OBSERVER]  # the new estimate, applied at once
    f_dither = 0.0
    if M[M_DITHER_AMPLITUDE] != 0.0:
        f_dither = dither_law(t, M[M_DITHER_AMPLITUDE], M[M_DITHER_OMEGA])
    command = f_pi + f_damp + f_comp + f_dither + f_linear
    f_motor, rate = saturation_law(command, error, ki, f_max)
    return f_comp, f_dither, f_motor, rate, x


@njit(**_JIT)
def linear_sample(M, x, sensors, others, error, ki, f_max):
    """A discrete linear controller's sample: ``(output, next x)`` (docs/model.md §5).

    Its output ``y = C x + D u`` [N] from the ``sensors`` (``U_*``), held to its next
    sample, and its next state ``A x + B u + L (F_motor - command)`` (back-calculation),
    ``command = others + y`` with ``others`` the rest of the motor's command [N],
    saturated at ``f_max`` (``error`` [m] and ``ki``: the PI's anti-windup).
    """
    output = _linear_output(M, x, sensors)
    command = others + output
    f_motor = saturation_law(command, error, ki, f_max)[0]
    return output, _linear_rates(M, x, sensors, f_motor - command, x[X_OBSERVER])


# The general path's laws, called from the inlined right-hand side, not inlined into it:
# numba's inliner copies an inlined function's callees into every caller before it prunes the
# branches a constant ``blocks`` or a ``None`` model rules out, and these copies made a default
# run's first compile about four times longer (benchmarks/compile_times.py).
@njit(**_JIT)
def general_spring(M, z):
    """The spring force [N] of the law packed in the model row ``M`` (at ``M_SPRING``) at
    ``z`` [m] (:func:`qzs.engine.laws.spring_general`); the six legs' too.

    Parameters
    ----------
    M : ndarray
        A packed model row (``M_*``).
    z : float
        Relative position [m].

    Returns
    -------
    float
        Spring force on the payload [N].
    """
    return spring_general(M, M_SPRING, z)


@njit(**_JIT)
def general_spring_energy(M, z):
    """The energy [J] stored in the spring law packed in the model row ``M`` at ``z`` [m]
    (:func:`qzs.engine.laws.spring_energy_general`); the six legs' too.

    Parameters
    ----------
    M : ndarray
        A packed model row (``M_*``).
    z : float
        Relative position [m].

    Returns
    -------
    float
        Stored energy [J].
    """
    return spring_energy_general(M, M_SPRING, z)


@njit(**_JIT)
def _saturated(command, error, ki, f_max):
    """:func:`qzs.engine.laws.saturation_law`: ``(motor force [N], integral rate [m])``."""
    return saturation_law(command, error, ki, f_max)


#: The blocks' rates of a controller without blocks (or of a sampled one): none.
_NO_RATES = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit(**_JIT, inline="always")
def rhs(t, y, yd, ydd, s, x, mode, direction, held, P, M, blocks):
    """Right-hand side at time ``t`` and base motion ``(y, yd, ydd)``.

    Returns ``(derivatives, forces, block rates)``: the rates of the plant's state ``s``
    (``S_*``), the force breakdown (``F_*``) and the rates of the blocks' state ``x``
    (``X_*``). ``m*xdd = F_spring(z) + F_friction(v) + F_stop(z, v) + F_motor - m*g``
    (docs/model.md); while held (stuck, or resting on a plastic stop) ``v = 0`` and
    ``xdd = ydd``. ``blocks``: the controller has blocks beyond PI + damping (``M``,
    :func:`block_forces`) or a spring law other than the tanh (the general path,
    :func:`general`: the spring from ``M``, :func:`qzs.engine.laws.spring_general`); without
    (a constant where it is inlined) the operations are those of PI + damping alone with the
    tanh of ``P``.
    """
    m = P[P_MASS]
    z = s[S_Z]
    v = s[S_V] if mode == MODE_SLIP else 0.0
    xd = yd + v
    if blocks:
        f_spring = general_spring(M, z)
    else:
        f_spring = spring_law(P[P_SPRING_A], P[P_SPRING_B], z)

    f_stop = 0.0
    f_elastic = 0.0
    if P[P_PLASTIC] == 0.0:
        f_stop, f_elastic = compliant_stop_law(z, v, P[P_Z_LOW], P[P_Z_HIGH], P[P_STOP_K],
                                               P[P_STOP_C])

    v_measured = xd - s[S_HP] if P[P_HP_OMEGA] > 0.0 else xd
    if P[P_CONTROL_STEPS] > 0.0:
        f_pi, f_damp, f_motor = held[0], held[1], held[2]
        integral_rate = 0.0
    else:
        f_pi, f_damp, f_motor, integral_rate = controller_output(P, z, v_measured, s[S_INT])
    f_comp = f_dither = f_linear = feedforward = 0.0
    command = f_motor
    if blocks:
        if M[M_BLOCKS] != 0.0:  # a law alone: PI + damping's command as it is
            f_comp, f_dither, f_linear, feedforward = block_forces(
                t, P[P_ZREF] - z, x, v, direction, ydd, v_measured, held,
                P[P_CONTROL_STEPS] > 0.0, P[P_VREG], M)
            command = f_pi + f_damp + f_comp + f_dither + f_linear
            f_motor, rate = _saturated(command, P[P_ZREF] - z, P[P_KI], P[P_FMAX])
            if P[P_CONTROL_STEPS] == 0.0:
                integral_rate = rate

    f_applied = f_spring + f_stop + f_motor - m * P[P_GRAVITY]
    f_hold = m * ydd - f_applied
    if mode == MODE_SLIP:
        f_friction = sliding_friction_law(v, direction, P[P_FS], P[P_FC], P[P_CBC], P[P_CV],
                                          P[P_VREG])
        xdd = (f_applied + f_friction) * (1.0 / m)  # one division per step, off the critical path
    else:
        f_friction = f_hold
        if mode == MODE_WALL_LOW:  # the stop takes the upward part, friction the rest
            f_wall = max(f_hold, 0.0)
            f_friction = f_hold - f_wall
            f_stop += f_wall
        elif mode == MODE_WALL_HIGH:
            f_wall = min(f_hold, 0.0)
            f_friction = f_hold - f_wall
            f_stop += f_wall
        xdd = ydd

    rates = _NO_RATES
    if blocks and M[M_BLOCKS] != 0.0:
        rates = block_rates(x, (P[P_ZREF] - z, v_measured, xdd, ydd, v), f_friction, f_stop,
                            feedforward, f_motor - command, P[P_CONTROL_STEPS] > 0.0, M)
    deriv = (v, xdd - ydd, P[P_HP_OMEGA] * (xd - s[S_HP]), integral_rate,
             (f_spring + f_friction + f_stop + f_motor) * yd, -f_friction * v, f_motor * v,
             -(f_stop - f_elastic) * v)
    force = (y, yd, ydd, f_spring, f_friction, f_stop, f_elastic, f_motor, f_pi, f_damp,
             v_measured, f_hold, xdd, f_comp, f_dither, f_linear, x[X_OBSERVER])
    return deriv, force, rates


@njit(**_JIT)
def rhs_at(t, s, x, mode, direction, held, P, M, E, table):
    """:func:`rhs` at time ``t`` [s] (evaluates the base motion itself)."""
    y, yd, ydd = base_motion(t, E, table)
    if M is None:  # pruned by type before inlining: one rhs compiled (kernel_model)
        return rhs(t, y, yd, ydd, s, x, mode, direction, held, P, M, False)
    return rhs(t, y, yd, ydd, s, x, mode, direction, held, P, M, general(M))


@njit(**_JIT, inline="always")
def _axpy(s, a, k):
    """``s + a * k`` entry by entry, each with one rounding (:func:`fma`)."""
    return (fma(a, k[0], s[0]), fma(a, k[1], s[1]), fma(a, k[2], s[2]), fma(a, k[3], s[3]),
            fma(a, k[4], s[4]), fma(a, k[5], s[5]), fma(a, k[6], s[6]), fma(a, k[7], s[7]))


@njit(**_JIT, inline="always")
def _axpy_blocks(x, a, k):
    """``x + a * k`` for the blocks' state tuple (:func:`_axpy`)."""
    return (fma(a, k[0], x[0]), fma(a, k[1], x[1]), fma(a, k[2], x[2]), fma(a, k[3], x[3]),
            fma(a, k[4], x[4]), fma(a, k[5], x[5]), fma(a, k[6], x[6]), fma(a, k[7], x[7]),
            fma(a, k[8], x[8]))


@njit(**_JIT, inline="always")
def n_stages(solver):
    """Number of right-hand-side evaluations per step of ``solver``."""
    if solver == SOLVER_EULER:
        return 1
    return 3 if solver == SOLVER_ODE3 else 4


@njit(**_JIT, inline="always")
def tableau(solver, h, stage):
    """Butcher tableau row of ``stage`` for a step ``h`` [s]: ``(offset, a, weight)``.

    All three solvers have a diagonal tableau: stage ``j`` is evaluated at
    ``t + offset`` from ``s + a * k[j - 1]``, and the step is ``s + sum(weight * k)``.
    Euler (order 1), Bogacki-Shampine ode3 without its error stage (order 3,
    Simulink's fixed-step ode3), classic RK4 (order 4).
    """
    if solver == SOLVER_EULER:
        return 0.0, 0.0, h
    if solver == SOLVER_ODE3:
        if stage == 0:
            return 0.0, 0.0, h * (2.0 / 9.0)
        if stage == 1:
            return 0.5 * h, 0.5 * h, h * (1.0 / 3.0)
        return 0.75 * h, 0.75 * h, h * (4.0 / 9.0)
    if stage == 0:
        return 0.0, 0.0, h * (1.0 / 6.0)
    if stage == 3:
        return h, h, h * (1.0 / 6.0)
    return 0.5 * h, 0.5 * h, h * (1.0 / 3.0)


@njit(**_JIT, inline="always")
def stage_bases(solver, t, h, E, table, phase, sin0, cos0):
    """Base motion at the stage times of a step from ``t`` (unused stages repeat the first)."""
    b0 = base_motion_near(t, phase, sin0, cos0, E, table)
    b1 = b2 = b3 = b0
    if solver != SOLVER_EULER:
        b1 = base_motion_near(t + tableau(solver, h, 1)[0], phase, sin0, cos0, E, table)
        last = 2 if solver == SOLVER_ODE3 else 3  # RK4's second and third stages share a time
        b_last = base_motion_near(t + tableau(solver, h, last)[0], phase, sin0, cos0, E, table)
        b2 = b_last if solver == SOLVER_ODE3 else b1
        b3 = b_last if solver != SOLVER_ODE3 else b0
    return b0, b1, b2, b3


@njit(**_JIT, inline="always")
def rk_step(solver, t, h, s, x, mode, direction, held, P, M, blocks, E, table, phase, sin0,
            cos0):
    """One explicit Runge-Kutta step (see :func:`tableau`) of length ``h`` [s] from ``s``, ``x``.

    ``phase, sin0, cos0`` are the excitation's phase and its sine and cosine at a
    nearby time (see :func:`qzs.engine.base_motion.base_motion_near`). The stages run
    in a loop with one inlined base motion and one inlined right-hand side (a copy per
    stage cost numba's inliner about 20 s of a cold start, docs/model.md §9); the
    weighted sum is accumulated stage by stage, in the same order as the batched
    stages of :mod:`qzs.engine.lanes` (whose base motion at each stage time,
    :func:`stage_bases`, is the same call), so both give the same bits. The blocks' states
    ``x`` are stepped with the plant's only with ``blocks`` (a constant where it is
    inlined); without, they are returned as they came. Returns ``(s, x)`` at ``t + h``.
    """
    result, k = s, s
    result_x, k_x = x, x
    for stage in range(n_stages(solver)):
        offset, a, weight = tableau(solver, h, stage)
        y, yd, ydd = base_motion_near(t + offset, phase, sin0, cos0, E, table)
        if blocks:  # a law alone (no blocks) leaves x as it came: its rates are all 0
            stepping = M[M_BLOCKS] != 0.0
            deriv, _, rates = rhs(t + offset, y, yd, ydd, s if stage == 0 else _axpy(s, a, k),
                                  _axpy_blocks(x, a, k_x) if stage > 0 and stepping else x,
                                  mode, direction, held, P, M, True)
            k, k_x = deriv, rates
            if stepping:
                result_x = _axpy_blocks(result_x, weight, k_x)
        else:
            k = rhs(t + offset, y, yd, ydd, s if stage == 0 else _axpy(s, a, k), x, mode,
                    direction, held, P, M, False)[0]
        result = _axpy(result, weight, k)
    return result, result_x


@njit(**_JIT)
def energies(y, yd, s, mode, P, M):
    """Kinetic, spring, gravity and stop-elastic energy [J] of the payload (the spring's
    from its law in ``M``, the tanh's from ``P``)."""
    z = s[S_Z]
    v = s[S_V] if mode == MODE_SLIP else 0.0
    m = P[P_MASS]
    pen = 0.0
    if P[P_PLASTIC] == 0.0:
        pen = max(P[P_Z_LOW] - z, 0.0) + max(z - P[P_Z_HIGH], 0.0)
    if M is not None and M[M_SPRING] != TANH:
        spring = general_spring_energy(M, z)
    else:
        spring = spring_energy_law(P[P_SPRING_A], P[P_SPRING_B], z)
    return (0.5 * m * (yd + v) ** 2,
            spring,
            m * P[P_GRAVITY] * (y + z),
            0.5 * P[P_STOP_K] * pen * pen)


@njit(**_JIT)
def _mechanical_energy(t, s, mode, P, M, E, table):
    y, yd, ydd = base_motion(t, E, table)
    e = energies(y, yd, s, mode, P, M)
    return e[0] + e[1] + e[2] + e[3]


@njit(**_JIT, inline="always")
def _with(s, index, value):
    """Copy of state tuple ``s`` with entry ``index`` replaced by ``value``."""
    return (value if index == 0 else s[0], value if index == 1 else s[1],
            value if index == 2 else s[2], value if index == 3 else s[3],
            value if index == 4 else s[4], value if index == 5 else s[5],
            value if index == 6 else s[6], value if index == 7 else s[7])


@njit(**_JIT, inline="always")
def state_tuple(state):
    """The plant's ODE state (``S_*``) of a persistent state array as a tuple."""
    return (state[0], state[1], state[2], state[3], state[4], state[5], state[6], state[7])


@njit(**_JIT, inline="always")
def blocks_tuple(state):
    """The controller blocks' state (``X_*``) of a persistent state array as a tuple."""
    return (state[A_X0], state[A_X0 + 1], state[A_X0 + 2], state[A_X0 + 3], state[A_X0 + 4],
            state[A_X0 + 5], state[A_X0 + 6], state[A_X0 + 7], state[A_X0 + 8])


@njit(**_JIT, inline="always")
def held_tuple(state):
    """The held outputs of a sampled controller (``A_F_*``) of a persistent state array."""
    return (state[A_F_PI], state[A_F_DAMP], state[A_F_MOTOR], state[A_F_COMPENSATION],
            state[A_F_DITHER], state[A_F_LINEAR])


@njit(**_JIT, inline="always")
def _book_impulse(t, s, ledger, E, table, P):
    """Set v to exactly 0 and book the impulse that does it (closes the energy ledger).

    Stopping a slip velocity ``v`` takes an impulse ``-m*v`` between payload and base.
    It does work ``-m*v*yd`` through the base and dissipates ``m*v**2/2`` in the
    element that supplies it (``ledger``: friction or stop); both are exact.
    """
    y, yd, ydd = base_motion(t, E, table)
    m = P[P_MASS]
    v = s[S_V]
    s = _with(s, S_V, 0.0)
    s = _with(s, S_W_BASE, s[S_W_BASE] - m * v * yd)
    return _with(s, ledger, s[ledger] + 0.5 * m * v * v)


@njit(**_JIT)
def _settle(t, s, x, direction, held, P, M, E, table):
    """At a zero crossing of v: stick if friction can hold the payload, else reverse.

    Returns ``(state, mode, direction)``. v is set to exactly 0 either way; the
    crossing is located to round-off, so the impulse booked for it is negligible.
    """
    s = _book_impulse(t, s, S_D_FRICTION, E, table, P)
    f_hold = rhs_at(t, s, x, np.int64(MODE_STICK), 0.0, held, P, M, E, table)[1][F_HOLD]
    if abs(f_hold) <= P[P_FS]:
        return s, MODE_STICK, direction
    return s, MODE_SLIP, release_direction(MODE_STICK, f_hold)


@njit(**_JIT)
def _hit_wall(t, s, x, low, held, P, M, E, table):
    """Perfectly plastic impact: v absorbed by the stop's impulse, z put on the stop.

    The payload then rests on the stop if friction and the stop can hold it,
    else it leaves at once (v = 0, slipping away from the stop). Returns
    ``(state, mode, direction)``.
    """
    s = _book_impulse(t, s, S_D_STOP, E, table, P)
    slip = np.int64(MODE_SLIP)
    before = _mechanical_energy(t, s, slip, P, M, E, table)
    s = _with(s, S_Z, P[P_Z_LOW] if low else P[P_Z_HIGH])
    # the move onto the stop (the impact is located to ~1e-12 m) is booked there too
    s = _with(s, S_D_STOP, s[S_D_STOP] + before - _mechanical_energy(t, s, slip, P, M, E, table))
    mode = MODE_WALL_LOW if low else MODE_WALL_HIGH
    f_hold = rhs_at(t, s, x, mode, 0.0, held, P, M, E, table)[1][F_HOLD]
    if hold_margin(mode, f_hold, P[P_FS]) < 0.0:
        return s, MODE_SLIP, release_direction(mode, f_hold)
    return s, mode, 0


@njit(**_JIT)
def _event_value(event, t, s, x, mode, direction, held, P, M, E, table):
    """The function whose sign change defines ``event`` (positive before it)."""
    if event == 1:
        return slip_event(direction, s[S_V])
    if event == 2:
        return s[S_Z] - P[P_Z_LOW]
    if event == 3:
        return P[P_Z_HIGH] - s[S_Z]
    f_hold = rhs_at(t, s, x, mode, 0.0, held, P, M, E, table)[1][F_HOLD]
    return hold_margin(mode, f_hold, P[P_FS])


@njit(**_JIT)
def _margin_near(t, s, x, mode, held, P, M, E, table, phase, sin0, cos0):
    """Holding margin at ``t`` with the excitation rotated from a nearby phase (no sin/cos)."""
    y, yd, ydd = base_motion_near(t, phase, sin0, cos0, E, table)
    if M is None:  # pruned by type before inlining (kernel_model)
        f_hold = rhs(t, y, yd, ydd, s, x, mode, 0.0, held, P, M, False)[1][F_HOLD]
    else:
        f_hold = rhs(t, y, yd, ydd, s, x, mode, 0.0, held, P, M, general(M))[1][F_HOLD]
    return hold_margin(mode, f_hold, P[P_FS])


@njit(**_JIT, inline="always")
def _first_event(t, h, s, s1, mode, direction, margin, margin1, P):
    """Kind (0: none) and time fraction (secant) of the first transition in a step.

    Only the exact friction model tracks the slip's zero crossing; the regularised one
    (``P_VREG > 0``) slips through it.
    """
    theta = 2.0
    event = 0
    if mode == MODE_SLIP:
        v0 = slip_event(direction, s[S_V])
        v1 = slip_event(direction, s1[S_V])
        if P[P_VREG] == 0.0 and crossed_zero(v0, v1):  # v reached zero: stick or reverse
            theta = secant_fraction(v0, v1)
            event = 1
        if P[P_PLASTIC] != 0.0:  # reached a plastic stop
            if s1[S_Z] < P[P_Z_LOW]:
                fraction = (s[S_Z] - P[P_Z_LOW]) / (s[S_Z] - s1[S_Z])
                if fraction < theta:
                    theta, event = fraction, 2
            elif s1[S_Z] > P[P_Z_HIGH]:
                fraction = (P[P_Z_HIGH] - s[S_Z]) / (s1[S_Z] - s[S_Z])
                if fraction < theta:
                    theta, event = fraction, 3
    elif margin1 < 0.0:  # friction (and stop) can no longer hold the payload
        theta = secant_fraction(margin, margin1)
        event = 4
    return event, min(max(theta, 0.0), 1.0)


@njit(**_JIT, inline="always")
def _any_event(s, s1, mode, direction, margin1, P):
    """Whether a step may hold a transition, without locating it (no division).

    False only when :func:`_first_event` finds none: a lane pass keeps such a step and
    hands every other one to :func:`grid_step`, which decides (docs/model.md §9).
    """
    if mode == MODE_SLIP:
        return ((P[P_VREG] == 0.0
                 and crossed_zero(slip_event(direction, s[S_V]), slip_event(direction, s1[S_V])))
                or (P[P_PLASTIC] != 0.0 and (s1[S_Z] < P[P_Z_LOW] or s1[S_Z] > P[P_Z_HIGH])))
    return margin1 < 0.0


@njit(**_JIT)
def _rk(solver, t, h, s, x, k0, k0_x, mode, direction, held, P, M, E, table):
    """The Runge-Kutta step of :func:`rk_step` for the event path, stage by stage.

    The same tableau and fused updates, in the same order; each stage calls the
    non-inlined :func:`rhs_at`, which evaluates the base motion exactly (libm sine)
    rather than rotating it from a nearby phase. Single runs and batches both take this
    path for the part of a step around an event, so they stay identical; compiling
    :func:`rk_step`'s inlined stages a second time here took about 70 s of a cold start
    (docs/model.md §9). ``k0, k0_x`` are the first stage's rates,
    ``rhs_at(t, s, x, ...)[0, 2]``: every trial step of an event's location starts from the
    same ``t``, ``s`` and ``x``, so :func:`_locate` evaluates them once for all of them. The
    blocks' states step with the plant's (their rates 0 without blocks). Returns ``(s, x)``.
    """
    result = _axpy(s, tableau(solver, h, 0)[2], k0)
    result_x = _axpy_blocks(x, tableau(solver, h, 0)[2], k0_x)
    k, k_x = k0, k0_x
    for stage in range(1, n_stages(solver)):
        offset, a, weight = tableau(solver, h, stage)
        k, _, k_x = rhs_at(t + offset, _axpy(s, a, k), _axpy_blocks(x, a, k_x), mode, direction,
                           held, P, M, E, table)
        result = _axpy(result, weight, k)
        result_x = _axpy_blocks(result_x, weight, k_x)
    return result, result_x


@njit(**_JIT, inline="always")
def _event_trial(at, data):
    """The trial of :func:`qzs.engine.stickslip.locate`: a step of ``at`` [s] and its event value.

    ``data`` is ``(solver, event, t, s, x, k0, k0_x, mode, direction, held, P, M, E, table)``,
    the step's start and its first stage's rates; returns ``(event value, (s, x))`` at
    ``t + at`` (:func:`_rk`, :func:`_event_value`).
    """
    solver, event, t, s, x, k0, k0_x, mode, direction, held, P, M, E, table = data
    state, state_x = _rk(solver, t, at, s, x, k0, k0_x, mode, float(direction), held, P, M, E,
                         table)
    return (_event_value(event, t + at, state, state_x, mode, direction, held, P, M, E, table),
            (state, state_x))


@njit(**_JIT)
def _locate(solver, event, t, h, s, x, g0, g1, mode, direction, held, P, M, E, table):
    """Event ``event`` located in ``[t, t + h]`` (:func:`qzs.engine.stickslip.locate`).

    Returns ``(time from t, (s, x) there)``: at most 6 Runge-Kutta steps from ``t`` (each an
    :func:`_event_trial`, all sharing their first stage), the event function then zero to
    round-off.
    """
    k0, k0_x = s, x
    if g0 > 0.0:  # else no trial is made
        k0, _, k0_x = rhs_at(t, s, x, mode, float(direction), held, P, M, E, table)
    return locate(_event_trial, (solver, event, t, s, x, k0, k0_x, mode, direction, held, P, M,
                                 E, table), g0, g1, h, (s, x))


@njit(**_JIT)
def grid_step(solver, t, h, s, x, mode, direction, held, P, M, blocks, E, table, margin, phase,
              sin0, cos0):
    """Advance one grid step, locating and handling at most one transition inside it.

    ``margin`` is the holding margin at ``t`` if known (NaN if not); ``phase,
    sin0, cos0`` the excitation's phase and its sine and cosine at ``t``; ``x`` the
    controller blocks' state, ``M`` the blocks and ``blocks`` whether there are any (a
    constant where this is inlined: without, ``x`` is returned as it came). Returns
    ``(state, blocks' state, mode, direction, margin, sticks, impacts)``: the holding margin
    at the end (NaN while slipping), the counts of new stick events and of plastic impacts
    in the step.
    """
    sticks = 0
    impacts = 0
    # a zero crossing missed earlier
    if mode == MODE_SLIP and P[P_VREG] == 0.0 and slip_event(direction, s[S_V]) < 0.0:
        s, mode, direction = _settle(t, s, x, direction, held, P, M, E, table)
        sticks += mode == MODE_STICK
        margin = np.nan
    if mode != MODE_SLIP:
        if margin != margin:  # NaN: not known yet
            margin = _margin_near(t, s, x, mode, held, P, M, E, table, phase, sin0, cos0)
        if margin < 0.0:
            f_hold = rhs_at(t, s, x, mode, 0.0, held, P, M, E, table)[1][F_HOLD]
            direction = release_direction(mode, f_hold)
            mode = MODE_SLIP

    s1, x1 = rk_step(solver, t, h, s, x, mode, float(direction), held, P, M, blocks, E, table,
                     phase, sin0, cos0)
    margin1 = np.nan
    if mode != MODE_SLIP:
        margin1 = _margin_near(t + h, s1, x1, mode, held, P, M, E, table, phase, sin0, cos0)
    event, theta = _first_event(t, h, s, s1, mode, direction, margin, margin1, P)
    if event == 0:
        return s1, x1, mode, direction, margin1, sticks, impacts

    g0 = margin if event == 4 else _event_value(event, t, s, x, mode, direction, held, P, M, E,
                                                table)
    g1 = margin1 if event == 4 else _event_value(event, t + h, s1, x1, mode, direction, held,
                                                 P, M, E, table)
    at, (s_event, x_event) = _locate(solver, event, t, h, s, x, g0, g1, mode, direction, held,
                                     P, M, E, table)
    if not blocks:
        x_event = x  # unchanged without blocks: a constant of the caller's loop
    t_event = t + at
    if event == 1:
        s_event, mode, direction = _settle(t_event, s_event, x_event, direction, held, P, M, E,
                                           table)
        sticks += mode == MODE_STICK
    elif event == 2 or event == 3:
        s_event, mode, direction = _hit_wall(t_event, s_event, x_event, event == 2, held, P, M,
                                             E, table)
        impacts += 1
    else:
        f_hold = rhs_at(t_event, s_event, x_event, mode, 0.0, held, P, M, E, table)[1][F_HOLD]
        direction = release_direction(mode, f_hold)
        mode = MODE_SLIP
    rest = h - at
    s1, x1 = s_event, x_event
    if rest > 0.0:
        k0, _, k0_x = rhs_at(t_event, s_event, x_event, mode, float(direction), held, P, M, E,
                             table)
        s1, x1 = _rk(solver, t_event, rest, s_event, x_event, k0, k0_x, mode, float(direction),
                     held, P, M, E, table)
        if not blocks:
            x1 = x
    if mode == MODE_SLIP and P[P_PLASTIC] != 0.0:  # a second event, not located: clamp
        if s1[S_Z] < P[P_Z_LOW] or s1[S_Z] > P[P_Z_HIGH]:
            s1, mode, direction = _hit_wall(t + h, s1, x1, s1[S_Z] < P[P_Z_LOW], held, P, M,
                                            E, table)
            impacts += 1
    margin1 = np.nan
    if mode != MODE_SLIP:
        margin1 = _margin_near(t + h, s1, x1, mode, held, P, M, E, table, phase, sin0, cos0)
    return s1, x1, mode, direction, margin1, sticks, impacts


@njit(**_JIT)
def sample_controller(t, s, x, mode, direction, held, P, M, E, table):
    """Sampled controller: read z and the measured velocity; returns ``(held, s, x)``.

    The PI and damping forces with the current integral, then the integral advanced by one
    sample period (docs/model.md §5); with blocks, the observer advanced from what it
    measures at the sample, the compensation with its new estimate, and the dither. ``held`` is what the
    controller held until now (a discrete linear controller's output is its own,
    :func:`sample_linear`).
    """
    y, yd, ydd = base_motion(t, E, table)
    xd = yd + (s[S_V] if mode == MODE_SLIP else 0.0)
    v_measured = xd - s[S_HP] if P[P_HP_OMEGA] > 0.0 else xd
    f_pi, f_damp, f_motor, rate = controller_output(P, s[S_Z], v_measured, s[S_INT])
    f_comp, f_dither = held[3], held[4]
    if M is not None and M[M_BLOCKS] != 0.0:
        v = s[S_V] if mode == MODE_SLIP else 0.0
        force = rhs(t, y, yd, ydd, s, x, mode, float(direction), held, P, M, True)[1]
        f_comp, f_dither, f_motor, rate, x = sample_blocks(
            t, x, v, float(direction), held, force[F_FRICTION], force[F_STOP], f_pi, f_damp,
            force[F_LINEAR], P[P_ZREF] - s[S_Z], P[P_KI], P[P_FMAX], P[P_CONTROL_STEPS],
            P[P_DT], P[P_VREG], M)
    s = _with(s, S_INT, s[S_INT] + rate * P[P_CONTROL_STEPS] * P[P_DT])
    return (f_pi, f_damp, f_motor, f_comp, f_dither, held[5]), s, x


@njit(**_JIT)
def sample_linear(t, s, x, mode, direction, held, P, M, E, table):
    """A discrete linear controller's sample at ``t``: returns ``(held, x)``.

    It reads its sensors (the payload's acceleration with the force held until now),
    outputs ``y = C x + D u``, held to its next sample, and steps its state
    ``x <- A x + B u + L (F_motor - command)`` (back-calculation, docs/model.md §5).
    """
    force = rhs_at(t, s, x, mode, float(direction), held, P, M, E, table)[1]
    v = s[S_V] if mode == MODE_SLIP else 0.0
    u = (P[P_ZREF] - s[S_Z], force[F_V_MEASURED], force[F_XDD], force[F_YDD], v)
    output, x = linear_sample(
        M, x, u, force[F_PI] + force[F_DAMP] + force[F_COMPENSATION] + force[F_DITHER],
        P[P_ZREF] - s[S_Z], P[P_KI], P[P_FMAX])
    return (held[0], held[1], held[2], held[3], held[4], output), x


@njit(**_JIT)
def record(t, s, x, mode, direction, held, P, M, E, table, row, row_flags, phase, sin0, cos0):
    """Write one output sample (channels ``C_*``) of the state at time ``t``.

    ``phase, sin0, cos0``: the excitation's phase and its sine and cosine near ``t``.
    """
    y, yd, ydd = base_motion_near(t, phase, sin0, cos0, E, table)
    if M is None:  # pruned by type before inlining (kernel_model)
        force = rhs(t, y, yd, ydd, s, x, mode, float(direction), held, P, M, False)[1]
    else:
        force = rhs(t, y, yd, ydd, s, x, mode, float(direction), held, P, M, general(M))[1]
    v = s[S_V] if mode == MODE_SLIP else 0.0
    row[C_TIME] = t
    row[C_BASE_Y] = force[F_Y]
    row[C_BASE_YD] = force[F_YD]
    row[C_BASE_YDD] = force[F_YDD]
    row[C_X] = force[F_Y] + s[S_Z]
    row[C_XD] = force[F_YD] + v
    row[C_XDD] = force[F_XDD]
    row[C_Z] = s[S_Z]
    row[C_V] = v
    row[C_F_SPRING] = force[F_SPRING]
    row[C_F_FRICTION] = force[F_FRICTION]
    row[C_F_STOP] = force[F_STOP]
    row[C_F_MOTOR] = force[F_MOTOR]
    row[C_F_PI] = force[F_PI]
    row[C_F_DAMP] = force[F_DAMP]
    row[C_V_MEASURED] = force[F_V_MEASURED]
    row[C_W_BASE] = s[S_W_BASE]
    row[C_D_FRICTION] = s[S_D_FRICTION]
    row[C_W_MOTOR] = s[S_W_MOTOR]
    row[C_D_STOP] = s[S_D_STOP]
    row[C_E_KINETIC], row[C_E_SPRING], row[C_E_GRAVITY], row[C_E_STOP] = energies(
        force[F_Y], force[F_YD], s, mode, P, M)
    if M is not None and M[M_BLOCKS] != 0.0:  # a row without blocks holds N_BASE_CHANNELS
        row[C_F_COMPENSATION] = force[F_COMPENSATION]
        row[C_F_DITHER] = force[F_DITHER]
        row[C_F_LINEAR] = force[F_LINEAR]
        row[C_F_OBSERVER] = force[F_OBSERVER]
    row_flags[O_LOCKED] = mode != MODE_SLIP
    row_flags[O_CONTACT] = _in_contact(s, mode, P)


@njit(**_JIT, inline="always")
def _in_contact(s, mode, P):
    return mode >= MODE_WALL_LOW or s[S_Z] < P[P_Z_LOW] or s[S_Z] > P[P_Z_HIGH]


@njit(**_JIT)
def evaluate(t, state, flags, p, m, ex, table, row, row_flags):
    """Record the persistent state (arrays, as the driver keeps it) at ``t``."""
    E = excitation_tuple(ex)
    phase, sin0, cos0 = advance_phase(t, 0.0, 0.0, 1.0, E, np.bool_(True))
    record(t, state_tuple(state), blocks_tuple(state), flags[I_MODE], flags[I_DIRECTION],
           held_tuple(state), params_tuple(p), m, E, table, row, row_flags, phase, sin0, cos0)


@njit(**_JIT)
def hold_force(t, state, p, m, ex, table):
    """Force friction must supply to keep the payload stuck at ``state`` [N], and the forces."""
    return rhs_at(t, state_tuple(state), blocks_tuple(state), np.int64(MODE_STICK), 0.0,
                  held_tuple(state), params_tuple(p), m, excitation_tuple(ex), table)[1]
