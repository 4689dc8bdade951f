"""The force laws of one leg, written once as numba functions (docs/model.md §3 and §5).

Every driver calls these: the single run and the lockstep batch through
:func:`qzs.engine.kernels.rhs`, and any later multi-leg model leg by leg. Scalars in,
scalars out, inlined where they are called, so that the compiled arithmetic is the
same wherever they are used. The numpy versions in :mod:`qzs.model.isolator` (for
plots and fits) are tested equal to these.
"""
import numpy as np
from numba import njit

from qzs.engine.arithmetic import JIT, exp, tanh
from qzs.model.springs import (OBLIQUE, POLYNOMIAL, TABLE_COUNT, TABLE_END_FORCE,
                               TABLE_END_SLOPE, TABLE_OUTSIDE, TABLE_POSITIONS, TANH)

__all__ = ["spring_law", "spring_energy_law", "spring_general", "spring_energy_general",
           "sliding_friction_law", "compliant_stop_law",
           "controller_law", "saturation_law", "compensation_law", "dither_law"]


@njit(**JIT, inline="always")
def spring_law(a, b, z):
    """MagSpring force ``-a*tanh(b*z)`` [N] at relative position ``z`` [m] (eq. 2).

    Parameters
    ----------
    a : float
        MagSpring force amplitude [N] (``spring_force``).
    b : float
        MagSpring shape coefficient [1/m] (``spring_shape``).
    z : float
        Relative position [m].

    Returns
    -------
    float
        Spring force [N].
    """
    return -a * tanh(b * z)


@njit(**JIT, inline="always")
def spring_energy_law(a, b, z):
    """Energy ``(a/b)*ln(cosh(b*z))`` [J] stored in the MagSpring, 0 at z = 0.

    Parameters
    ----------
    a : float
        MagSpring force amplitude [N] (``spring_force``).
    b : float
        MagSpring shape coefficient [1/m] (``spring_shape``), non-zero.
    z : float
        Relative position [m].

    Returns
    -------
    float
        Stored energy [J].
    """
    u = abs(b * z)
    return a / b * (u + np.log1p(np.exp(-2.0 * u)) - np.log(2.0))


@njit(**JIT, inline="always")
def _table_piece(M, at, z):
    """The piece of the packed table ``M[at:]`` that holds ``z``: binary search, as
    :func:`qzs.model.springs.evaluate_packed`. Returns ``(piece index, t = z - x_i)``."""
    n = int(M[at + TABLE_COUNT])
    first = at + TABLE_POSITIONS
    low, high = 0, n - 1
    while high - low > 1:
        middle = (low + high) // 2
        if z >= M[first + middle]:
            low = middle
        else:
            high = middle
    return low, z - M[first + low]


@njit(**JIT, inline="always")
def spring_general(M, at, z):
    """Force [N] at ``z`` [m] of the spring law packed in ``M`` from index ``at``.

    The law's code first, then its numbers (:meth:`qzs.model.springs.SpringLaw.pack`,
    docs/model.md §3.1); the arithmetic of :func:`qzs.model.springs.evaluate_packed`, the
    tanh's that of :func:`spring_law` (bit for bit). NaN outside a refusing table: the run
    then stops (the kernels' ``STATUS_OUTSIDE``).

    Parameters
    ----------
    M : ndarray
        An array holding the packed law.
    at : int
        Index of the law's code in ``M``.
    z : float
        Relative position [m].

    Returns
    -------
    float
        Spring force on the payload [N].
    """
    code = M[at]
    if code == TANH:
        return -M[at + 1] * tanh(M[at + 2] * z)
    if code == OBLIQUE:
        u = z - M[at + 5]
        length = np.hypot(u, M[at + 4])
        return M[at + 6] - M[at + 1] * u - 2.0 * M[at + 2] * (1.0 - M[at + 3] / length) * u
    if code == POLYNOMIAL:
        u = z - M[at + 1]
        force = 0.0
        for k in range(int(M[at + 2]) - 1, -1, -1):
            force = force * u + M[at + 3 + k]
        return force
    n = int(M[at + TABLE_COUNT])
    x0 = M[at + TABLE_POSITIONS]
    xn = M[at + TABLE_POSITIONS + n - 1]
    pieces = at + TABLE_POSITIONS + n
    if z < x0 or z > xn:
        if M[at + TABLE_OUTSIDE] == 0.0:
            return np.nan
        if z < x0:
            return M[pieces] + (z - x0) * M[pieces + 1]
        return M[at + TABLE_END_FORCE] + (z - xn) * M[at + TABLE_END_SLOPE]
    i, t = _table_piece(M, at, z)
    c = pieces + 4 * i
    return M[c] + t * (M[c + 1] + t * (M[c + 2] + t * M[c + 3]))


@njit(**JIT, inline="always")
def spring_energy_general(M, at, z):
    """Stored energy [J] at ``z`` [m] of the spring law packed in ``M`` from index ``at``.

    As :func:`spring_general` (:func:`spring_energy_law` for the tanh); NaN outside a
    refusing table.

    Parameters
    ----------
    M : ndarray
        An array holding the packed law.
    at : int
        Index of the law's code in ``M``.
    z : float
        Relative position [m].

    Returns
    -------
    float
        Stored energy [J], zero at the law's reference position (docs/model.md §3.1).
    """
    code = M[at]
    if code == TANH:
        return spring_energy_law(M[at + 1], M[at + 2], z)
    if code == OBLIQUE:
        u = z - M[at + 5]
        d = M[at + 4]
        spread = 2.0 * M[at + 3] / (np.hypot(u, d) + d)
        return u * (-M[at + 6] + u * (0.5 * M[at + 1] + M[at + 2] * (1.0 - spread)))
    if code == POLYNOMIAL:
        u = z - M[at + 1]
        work = 0.0
        for k in range(int(M[at + 2]) - 1, -1, -1):
            work = work * u + M[at + 3 + k] / (k + 1)
        return -work * u
    n = int(M[at + TABLE_COUNT])
    x0 = M[at + TABLE_POSITIONS]
    xn = M[at + TABLE_POSITIONS + n - 1]
    pieces = at + TABLE_POSITIONS + n
    energies = pieces + 4 * (n - 1)
    if z < x0 or z > xn:
        if M[at + TABLE_OUTSIDE] == 0.0:
            return np.nan
        if z < x0:
            t = z - x0
            return M[energies] - t * (M[pieces] + t * (M[pieces + 1] / 2.0))
        t = z - xn
        return M[energies + n - 1] - t * (M[at + TABLE_END_FORCE]
                                          + t * (M[at + TABLE_END_SLOPE] / 2.0))
    i, t = _table_piece(M, at, z)
    c = pieces + 4 * i
    return M[energies + i] - t * (M[c] + t * (M[c + 1] / 2.0 + t * (M[c + 2] / 3.0
                                                                    + t * (M[c + 3] / 4.0))))


@njit(**JIT, inline="always")
def sliding_friction_law(v, sign, fs, fc, cbc, cv, v_reg):
    """Friction [N] while slipping at ``v`` [m/s] in direction ``sign`` (+-1) (eq. 3).

    ``-[Fc + (Fs - Fc)*exp(-Cbc*|v|)]*sign - Cv*v``: it opposes the slip. ``sign``
    is the slip direction, continued analytically past ``v = 0`` so that the
    zero crossing the stepper locates is smooth. With a regularisation velocity
    ``v_reg > 0``, ``tanh(v/v_reg)`` takes the place of ``sign`` (the regularised
    model, docs/model.md §3): smooth through ``v = 0``, no stick-slip.

    Parameters
    ----------
    v : float
        Relative (slip) velocity [m/s].
    sign : float
        Slip direction, +1 or -1 (unused when ``v_reg > 0``).
    fs : float
        Stiction force Fs [N].
    fc : float
        Coulomb force Fc [N].
    cbc : float
        Stribeck decay coefficient Cbc [s/m].
    cv : float
        Viscous friction coefficient Cv [N*s/m].
    v_reg : float
        Regularisation velocity [m/s]; 0 for the exact model.

    Returns
    -------
    float
        Friction force on the payload [N].
    """
    level = fc + (fs - fc) * exp(-cbc * abs(v))
    if v_reg > 0.0:
        sign = tanh(v / v_reg)
    return -level * sign - cv * v


@njit(**JIT, inline="always")
def compliant_stop_law(z, v, z_low, z_high, stiffness, damping):
    """Compliant hard stop: ``(force, elastic force)`` [N] at ``z`` [m], ``v`` [m/s].

    A spring-damper ``k*pen + c*pen_rate`` beyond either stop that only pushes: the
    damper never pulls the payload back into the wall. The elastic part alone
    stores energy (``stiffness*pen**2/2``); the rest is dissipated.

    Parameters
    ----------
    z : float
        Relative position [m].
    v : float
        Relative velocity [m/s].
    z_low, z_high : float
        Positions of the lower and upper stop [m].
    stiffness : float
        Contact stiffness [N/m].
    damping : float
        Contact damping [N*s/m].

    Returns
    -------
    force, elastic_force : float
        Stop force on the payload and its elastic part [N]; both 0 between the stops.
    """
    f_stop = 0.0
    f_elastic = 0.0
    if z < z_low:
        f_elastic = stiffness * (z_low - z)
        f_stop = max(f_elastic - damping * v, 0.0)  # a stop pushes, never pulls
    elif z > z_high:
        f_elastic = -stiffness * (z - z_high)
        f_stop = min(f_elastic - damping * v, 0.0)
    return f_stop, f_elastic


@njit(**JIT, inline="always")
def controller_law(z_ref, kp, ki, kd, f_max, z, v_measured, integral):
    """PI + damping command: ``(F_pi, F_damp, F_motor, integral_rate)`` (docs/model.md §5).

    ``F_pi = Kp*e + Ki*integral`` with ``e = z_ref - z`` [m], ``F_damp = -Kd*v_measured``,
    ``F_motor`` their sum clipped to ``+-f_max`` [N]; the integral's rate is ``e``,
    or 0 while the motor saturates and ``e`` pushes further into saturation
    (anti-windup by conditional integration).

    Parameters
    ----------
    z_ref : float
        Position setpoint [m].
    kp : float
        Proportional gain [N/m].
    ki : float
        Integral gain [N/(m*s)].
    kd : float
        Active damping gain [N*s/m].
    f_max : float
        Motor force saturation [N].
    z : float
        Relative position [m].
    v_measured : float
        Measured (high-passed) velocity [m/s].
    integral : float
        Integral of the position error [m*s].

    Returns
    -------
    F_pi, F_damp, F_motor : float
        PI force, damping force and saturated motor command [N].
    integral_rate : float
        Rate of the integral [m].
    """
    error = z_ref - z
    f_pi = kp * error + ki * integral
    f_damp = -kd * v_measured
    command, rate = saturation_law(f_pi + f_damp, error, ki, f_max)
    return f_pi, f_damp, command, rate


@njit(**JIT, inline="always")
def saturation_law(command, error, ki, f_max):
    """The motor's saturation and the PI integral's anti-windup (docs/model.md §5).

    Parameters
    ----------
    command : float
        Sum of the controller's forces before saturation [N].
    error : float
        Position error ``z_ref - z`` [m].
    ki : float
        Integral gain [N/(m*s)].
    f_max : float
        Motor force saturation [N].

    Returns
    -------
    command : float
        The command clipped to ``+-f_max`` [N].
    integral_rate : float
        Rate of the PI integral [m]: ``error``, or 0 while the motor saturates and the
        error pushes further into saturation (conditional integration).
    """
    rate = error
    if command > f_max:
        command = f_max
        if error * ki > 0.0:
            rate = 0.0  # anti-windup: do not integrate further into saturation
    elif command < -f_max:
        command = -f_max
        if error * ki < 0.0:
            rate = 0.0
    return command, rate


@njit(**JIT, inline="always")
def compensation_law(v, sign, fraction, fs, fc, cbc, cv, v_reg, deadband):
    """Friction compensation's feedforward [N]: a fraction of the friction law, cancelled.

    ``-fraction * F_friction(v)`` with the compensator's own friction parameters
    (:func:`sliding_friction_law`, the same law), 0 within the velocity deadband
    ``|v| <= deadband``; so 0 at ``v = 0`` (stuck). It pushes along the slip.

    Parameters
    ----------
    v : float
        Measured relative (slip) velocity [m/s].
    sign : float
        Slip direction, +1 or -1, as the friction law takes it.
    fraction : float
        Fraction of the friction law compensated [-], in [0, 1.5].
    fs, fc : float
        The compensator's stiction and Coulomb forces [N].
    cbc : float
        The compensator's Stribeck decay coefficient [s/m].
    cv : float
        The compensator's viscous friction coefficient [N*s/m].
    v_reg : float
        The plant's regularisation velocity [m/s] (0: exact model).
    deadband : float
        Velocity deadband [m/s].

    Returns
    -------
    float
        Compensation force on the payload [N].
    """
    if abs(v) <= deadband:
        return 0.0
    return -fraction * sliding_friction_law(v, sign, fs, fc, cbc, cv, v_reg)


@njit(**JIT, inline="always")
def dither_law(t, amplitude, omega):
    """Dither force ``amplitude * sin(omega * t)`` [N] at time ``t`` [s].

    Parameters
    ----------
    t : float
        Time [s].
    amplitude : float
        Dither amplitude [N].
    omega : float
        Dither angular frequency [rad/s].

    Returns
    -------
    float
        Dither force [N].
    """
    return amplitude * np.sin(omega * t)
