"""The loop broken at the motor force: continuous, sampled with a delay, and its responses.

``L = (Kp + Ki/s)*P_z + Kd*P_v`` with ``P_z = 1/(m s^2 + Cv s + k)`` and
``P_v = s*HP(s)*P_z`` (:func:`loop_transfer`); sampled as the simulator samples
(docs/model.md §5: forward-Euler integral, zero-order hold, analog high-pass), with an exact
discrete input delay (integer and fractional part of the period, Åström and Wittenmark's
modified z-transform: :func:`discretize_with_delay`, :func:`sampled_loop`). A continuous
loop with a delay uses a Padé approximant. :func:`frequency_response` evaluates any of them
on a grid; :func:`sampled_transmissibility` is the transmissibility of the linear loop with
a sampled, delayed controller.

References
----------
K. J. Åström, B. Wittenmark, *Computer-Controlled Systems*, 3rd ed., §2.3 (sampling a
system with a time delay).
"""
import math

import numpy as np

from qzs._validation import real
from qzs.analysis.linear import (close_loop, continuous_controller_matrices,
                                 controller_matrices, loop_constants, plant_matrices)
from qzs.errors import ParameterError
from qzs.model.controller import SENSORS
from qzs.model.registry import model_inputs

__all__ = ["loop_transfer", "sampled_loop", "discretize_with_delay", "frequency_response",
           "sampled_transmissibility", "PADE_ORDER"]

#: Order of the Padé approximant of a delay in a continuous loop [-].
PADE_ORDER = 6


def _plant_state_space(m, cv, k, w):
    """Force -> (z, measured velocity) with the base at rest: states z, v, high-pass w."""
    if w > 0:
        a = np.array([[0.0, 1.0, 0.0], [-k / m, -cv / m, 0.0], [0.0, w, -w]])
        b = np.array([[0.0], [1.0 / m], [0.0]])
        c = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -1.0]])
    else:
        a = np.array([[0.0, 1.0], [-k / m, -cv / m]])
        b = np.array([[0.0], [1.0 / m]])
        c = np.array([[1.0, 0.0], [0.0, 1.0]])
    return a, b, c


def loop_transfer(isolator=None, controller=None, relative_position=None, *, delay=0.0):
    """The continuous loop transfer ``L(s)`` broken at the motor force (python-control).

    ``L = (Kp + Ki/s)*P_z + Kd*P_v`` with ``P_z = 1/(m s^2 + Cv s + k)`` (force to relative
    position, base at rest) and ``P_v = s*HP(s)*P_z`` (force to the measured velocity); the
    loop closes as ``u = -L u``. A delay enters as a Padé approximant of order
    :data:`PADE_ORDER`. A controller with blocks: ``L = -K(s) P(s)``, the plant from the
    motor force to every sensor (:func:`qzs.analysis.linear.plant_system`, base at rest)
    and the whole controller back (:func:`qzs.analysis.linear.controller_system`).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops, and any blocks (no discrete linear controller: that loop is
        :func:`sampled_loop`'s); defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.
    delay : float
        Delay between the measurements and the motor force [s].

    Returns
    -------
    control.TransferFunction
        ``L(s)`` [-] (force per force).
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    delay = real("delay", delay, minimum=0.0)
    if controller.has_blocks:
        loop = control.ss(*_continuous_blocks_loop(isolator, controller, relative_position))
        if delay > 0:
            loop = loop * control.ss(control.tf(*control.pade(delay, PADE_ORDER)))
        return control.minreal(control.tf(loop), verbose=False)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    s = control.tf("s")
    plant = 1 / (m * s ** 2 + cv * s + k)
    highpass = s / (s + w) if w > 0 else 1
    pi = kp + (ki / s if ki > 0 else 0)
    loop = pi * plant + kd * s * highpass * plant
    if delay > 0:
        num, den = control.pade(delay, PADE_ORDER)
        loop = loop * control.tf(num, den)
    return control.minreal(control.tf(loop), verbose=False)


def _delayed_hold(a, b, period, delay):
    """``Phi, G0, G1``, whole periods and fraction [s] of a zero-order hold delayed by ``delay``."""
    from scipy.linalg import expm

    n_states = a.shape[0]
    whole = int(math.floor(delay / period + 1e-9))
    fraction = delay - whole * period
    if fraction < 1e-12 * period:
        fraction = 0.0

    def held(t):  # int_0^t exp(A s) ds B
        block = np.zeros((n_states + 1, n_states + 1))
        block[:n_states, :n_states] = a
        block[:n_states, n_states:] = b
        return expm(block * t)[:n_states, n_states:]

    phi = expm(a * period)
    g0 = held(period - fraction)
    g1 = expm(a * (period - fraction)) @ held(fraction) if fraction > 0 else np.zeros_like(g0)
    return phi, g0, g1, whole, fraction


def _sampled_response(isolator, controller, rate, delay, omega, relative_position=None):
    """``L(exp(j w T))`` of :func:`sampled_loop` on a grid, without its delay-line states.

    ``P(z) = C (zI - Phi)^-1 (G0 + G1/z) z^-n`` and the controller's row
    ``[Kp + Ki T/(z - 1), Kd]``: the same loop, evaluated with the plant's own 2-3 states.
    """
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    a, b, c = _plant_state_space(m, cv, k, w)
    period = 1.0 / rate
    phi, g0, g1, whole, _ = _delayed_hold(a, b, period, delay)
    z = np.exp(1j * np.asarray(omega, dtype=float) * period)
    n = a.shape[0]
    shifted = z[:, None, None] * np.eye(n)[None] - phi[None]
    held = g0[None] + g1[None] / z[:, None, None]
    plant = c[None] @ np.linalg.solve(shifted, held)  # (N, 2, 1)
    plant = plant[:, :, 0] * (z ** -whole)[:, None]
    pi = kp + (ki * period / (z - 1) if ki > 0 else 0)
    return pi * plant[:, 0] + kd * plant[:, 1]


def _delay_line(phi, g0, g1, whole, fraction, line):
    """``(Ad, Bd)`` of ``x[k+1] = Phi x[k] + G0 u[k-n] + G1 u[k-n-1]`` with the past inputs
    ``q_1 = u[k-1], ..., q_line = u[k-line]`` as states after the plant's."""
    n_states = phi.shape[0]
    size = n_states + line
    ad = np.zeros((size, size))
    bd = np.zeros((size, 1))
    ad[:n_states, :n_states] = phi
    if line:
        bd[n_states, 0] = 1.0
        for i in range(1, line):
            ad[n_states + i, n_states + i - 1] = 1.0
    if whole == 0:
        bd[:n_states] += g0
    else:
        ad[:n_states, n_states + whole - 1] += g0[:, 0]
    if fraction > 0:
        ad[:n_states, n_states + whole] += g1[:, 0]
    return ad, bd


def discretize_with_delay(a, b, c, period, delay=0.0):
    """Exact zero-order-hold discretisation with an input delay (modified z-transform).

    A delay ``tau = n*T + e*T`` (``0 <= e < 1``) holds each input for ``T`` starting ``tau``
    after its sample: ``x[k+1] = Phi*x[k] + G0*u[k-n] + G1*u[k-n-1]`` with
    ``G0 = int_0^{T-eT} exp(A s) ds B`` and ``G1 = exp(A (T-eT)) int_0^{eT} exp(A s) ds B``
    (Åström and Wittenmark §2.3); past inputs become states.

    Parameters
    ----------
    a, b, c : array_like
        Continuous state-space matrices (no feed-through), shapes (n, n), (n, 1), (p, n).
    period : float
        Sampling period T [s].
    delay : float
        Input delay [s].

    Returns
    -------
    control.StateSpace
        The discrete system, ``dt = period``.
    """
    import control

    a, b, c = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (a, b, c))
    period = real("period", period, minimum=0.0, strict=True)
    delay = real("delay", delay, minimum=0.0)
    phi, g0, g1, whole, fraction = _delayed_hold(a, b, period, delay)
    line = whole + (1 if fraction > 0 else 0)  # past inputs kept as states
    ad, bd = _delay_line(phi, g0, g1, whole, fraction, line)
    cd = np.hstack([c, np.zeros((c.shape[0], line))])
    return control.ss(ad, bd, cd, np.zeros((c.shape[0], 1)), period)


def sampled_loop(isolator=None, controller=None, rate=None, delay=0.0, relative_position=None):
    """The sampled loop transfer ``L(z)`` at the controller's rate (python-control).

    The simulator's sampled controller (docs/model.md §5): it reads the relative position and
    the measured velocity (the amplifier's analog high-pass stays in the plant), computes
    ``Kp*e + Ki*I`` with the forward-Euler integral ``I[n+1] = I[n] + T*e[n]``
    (``C_pi(z) = Kp + Ki*T/(z - 1)``) minus ``Kd*v``, and holds the force (zero-order hold)
    after ``delay``. The plant is discretised exactly (:func:`discretize_with_delay`).

    A controller with blocks (docs/design.md §6): its sampled part ``K_d`` (PI + damping
    and the compensation at ``rate``, a discrete linear controller at its own sample time;
    both: the same period) against the plant with its continuous part closed inside,
    held, delayed and read at the samples (exactly, as above; the payload's acceleration
    read with the force held until the sample): ``L(z) = -K_d(z) P_d(z)``, broken at the
    sampled force. The delay is the sampled part's (continuous parts have none).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops, and any blocks; defaults if omitted.
    rate : float, optional
        Controller rate [Hz]; default the controller's ``controller_rate`` (must then be > 0,
        unless the controller has a discrete linear controller).
    delay : float
        Delay from sampling to the motor force [s].
    relative_position : float, optional
        Operating point z [m]; default the setpoint.

    Returns
    -------
    control.StateSpace
        ``L(z)`` [-] with ``dt = 1/rate``.
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate if rate is None else rate
    if controller.has_blocks:
        rate = real("rate", rate, minimum=0.0)
        delay = real("delay", delay, minimum=0.0)
        return _SampledBlocks(isolator, controller, rate, delay, relative_position).loop()
    rate = real("rate", rate, minimum=0.0, strict=True,
                 fix="a sampled loop needs a controller rate in Hz")
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, relative_position)
    period = 1.0 / rate
    plant = discretize_with_delay(*_plant_state_space(m, cv, k, w), period, delay)
    # C(z) = [Kp + Ki*T/(z - 1), Kd] on (z, v): state I, I[n+1] = I[n] + T*z[n]
    if ki > 0:
        gains = control.ss([[1.0]], [[period, 0.0]], [[ki]], [[kp, kd]], period)
    else:
        gains = control.ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), [[kp, kd]],
                           period)
    return gains * plant


def frequency_response(system, omega):
    """Complex response of a SISO python-control system on a grid, vectorised.

    Parameters
    ----------
    system : control.StateSpace or control.TransferFunction
        Continuous (``dt = 0``) or discrete.
    omega : array_like
        Angular frequencies [rad/s].

    Returns
    -------
    ndarray of complex
        ``L(j*omega)``, or ``L(exp(j*omega*dt))`` for a discrete system [-].
    """
    import control

    space = control.ss(system)
    a, b, c, d = (np.asarray(x, dtype=float) for x in (space.A, space.B, space.C, space.D))
    omega = np.asarray(omega, dtype=float)
    dt = space.dt if space.dt not in (None, True) else 0
    points = np.exp(1j * omega * dt) if dt else 1j * omega
    if a.size == 0:
        return np.full(omega.shape, d[0, 0], dtype=complex)
    n = a.shape[0]
    shifted = points[:, None, None] * np.eye(n)[None] - a[None]
    solved = np.linalg.solve(shifted, np.broadcast_to(b.astype(complex), (omega.size, n, 1)))
    return (c[None] @ solved)[:, 0, 0] + d[0, 0]


def sampled_transmissibility(frequency, isolator=None, controller=None, *, rate=None,
                             delay=0.0, exact=False):
    """``|X/Y|`` [-] of the linear loop with a sampled controller and a delay.

    The controller's fundamental-frequency response (the sampled-data loop's response at the
    excitation's own frequency; aliased components left out, fine well below the Nyquist
    frequency): each gain times the zero-order hold ``(1 - exp(-jwT))/(jwT)`` and
    ``exp(-jw delay)``, the integral as ``Ki*T/(exp(jwT) - 1)``:

        T(jw) = (Cv s + k + C_pi) / (m s^2 + Cv s + k + C_pi + C_d s HP(s)).

    With ``rate`` 0 the controller is continuous (``C_pi = Kp + Ki/s``), delayed by ``delay``.

    ``exact`` (always, for a controller with blocks): the sampled-data loop's exact response
    at the excitation's frequency ``w`` instead (docs/design.md §6). The sampled sensors
    are ``s[k] = S(jw) y'' + P_d(z) u[k]`` (``S`` the base's path to the sensors with the
    continuous parts closed, ``P_d`` the held plant of :func:`sampled_loop`,
    ``z = exp(jwT)``), the held force ``u = K_d(z) s``, so ``u = K_d S y''/(1 - K_d P_d)``;
    the payload's acceleration at ``w`` is ``H_y(jw) y'' + H_u(jw) Z(jw) u`` with the held
    force's component at ``w``, ``Z = exp(-jw delay) (1 - exp(-jwT))/(jwT)``. The other
    components lie at ``w + 2 pi n/T``: the simulation's Fourier coefficient at ``w`` over
    whole periods is this one when ``1/(T f)`` is a whole number above 2. A continuous
    controller with blocks: the closed loop of :func:`qzs.analysis.linear.linearize`,
    its force delayed by ``exp(-jw delay)``.

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz], > 0.
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops, and any blocks; defaults if omitted.
    rate : float, optional
        Controller rate [Hz]; 0 continuous; default the controller's.
    delay : float
        Delay from sampling to the motor force [s].
    exact : bool
        The exact response at each frequency (always so with blocks); False keeps, for PI
        + damping, the gains-times-hold approximation above (the design search's cost).

    Returns
    -------
    ndarray
        Amplitude ratio [-].
    """
    isolator, controller = model_inputs(isolator, controller)
    rate = controller.controller_rate if rate is None else rate
    rate = real("rate", rate, minimum=0.0)
    delay = real("delay", delay, minimum=0.0)
    f = np.asarray(frequency, dtype=float)
    if not isinstance(exact, (bool, np.bool_)):
        raise ParameterError(f"`exact` must be True or False, got {exact!r}.", ("exact",))
    if controller.has_blocks or exact:
        linear = controller.linear
        if rate > 0 or (linear is not None and linear.discrete):
            return _SampledBlocks(isolator, controller, rate, delay, None).transmissibility(f)
        return _continuous_blocks_transmissibility(f, isolator, controller, delay)
    m, cv, k, kp, ki, kd, w = loop_constants(isolator, controller, None)
    s = 2j * np.pi * f
    lag = np.exp(-s * delay)
    if rate > 0:
        period = 1.0 / rate
        zoh = np.where(np.abs(s) > 0, (1 - np.exp(-s * period)) / (s * period + 1e-300), 1.0)
        pi = (kp + ki * period / (np.exp(s * period) - 1)) * zoh * lag
        damping = kd * zoh * lag
    else:
        pi = (kp + ki / s) * lag
        damping = kd * lag
    highpass = s / (s + w) if w > 0 else 1.0
    coupling = cv * s + k + pi
    return np.abs(coupling / (m * s ** 2 + coupling + damping * s * highpass))


# ---------------------------------------------------------------- a controller with blocks
def _responses(a, b, c, d, points):
    """``C (pI - A)^-1 B + D`` at each point of ``points``: shape (N, outputs, inputs)."""
    points = np.asarray(points, dtype=complex)
    n = a.shape[0]
    if n == 0:
        return np.broadcast_to(d.astype(complex), (points.size,) + d.shape).copy()
    shifted = points[:, None, None] * np.eye(n)[None] - a[None]
    solved = np.linalg.solve(shifted, np.broadcast_to(b.astype(complex), (points.size,) + b.shape))
    return c[None] @ solved + d[None]


def _continuous_blocks_loop(isolator, controller, relative_position):
    """``L = -K(s) P(s)`` of a controller with blocks, continuous, as ``(A, B, C, D)``."""
    return _series_loop(plant_matrices(isolator, controller, relative_position, base=False),
                        continuous_controller_matrices(isolator, controller))


def _series_loop(plant, controller):
    """``L = -K P``: the plant (one input, the sensors out) then the controller, negated."""
    a, b, c, d = plant
    ak, bk, ck, dk = controller
    n, nk = a.shape[0], ak.shape[0]
    a_l = np.block([[a, np.zeros((n, nk))], [bk @ c, ak]])
    b_l = np.vstack([b, bk @ d])
    return a_l, b_l, -np.hstack([dk @ c, ck]), -(dk @ d)


def _held_plant(plant, period, delay):
    """The plant held by a zero-order hold and read at the samples, ``delay`` after them.

    ``plant`` ``(A, B, C, D)`` with one input, the held force; its feed-through (the payload's
    acceleration) reads the force held until the sample. A delay ``n T + e T`` holds
    each force from ``n T + e T`` after its sample (Åström and Wittenmark §2.3):
    ``x[k+1] = Phi x[k] + G0 u[k-n] + G1 u[k-n-1]``, the past forces ``q_i = u[k-i]``
    (``i = 1 .. n+1``) states, and ``y[k] = C x[k] + D q_{n+1}`` (no feed-through).
    """
    a, b, c, d = plant
    phi, g0, g1, whole, fraction = _delayed_hold(a, b, period, delay)
    n, line = a.shape[0], whole + 1
    ad, bd = _delay_line(phi, g0, g1, whole, fraction, line)
    cd = np.zeros((c.shape[0], n + line))
    cd[:, :n] = c
    cd[:, n + whole] = d[:, 0]
    return ad, bd, cd, np.zeros((c.shape[0], 1))


class _SampledBlocks:
    """The sampled loop of a controller with blocks (docs/design.md §6).

    The controller's continuous part ``K_c`` closed around the plant (``P_c``, the held
    force in), held and sampled (``P_d``), its sampled part ``K_d`` at period ``T``:
    ``L(z) = -K_d(z) P_d(z)``, broken at the held force.
    """

    def __init__(self, isolator, controller, rate, delay, relative_position):
        continuous, discrete, period = controller_matrices(isolator, controller, rate)
        if discrete is None:
            raise ParameterError(
                "`rate` must be positive for a sampled loop, got 0 and no discrete linear "
                "controller; give a controller rate in Hz, or use loop_transfer for the "
                "continuous loop.", ("rate",))
        self.period, self.delay, self.discrete = period, delay, discrete
        self.continuous = continuous
        self.closed_base = close_loop(plant_matrices(isolator, controller, relative_position),
                                      continuous)
        closed = close_loop(plant_matrices(isolator, controller, relative_position, base=False),
                            continuous)
        sensors = len(SENSORS)
        self.held = _held_plant((closed[0], closed[1], closed[2][:sensors],
                                 closed[3][:sensors]), period, delay)

    def loop(self):
        """``L(z)`` as a python-control system, ``dt`` the period."""
        import control

        return control.ss(*_series_loop(self.held, self.discrete), self.period)

    def transmissibility(self, frequency):
        """The sampled-data loop's exact response at the excitation's own frequency.

        The sampled sensors ``s[k] = S(jw) y'' + P_d(z) u[k]`` (``S`` the base's path to the
        sensors with ``K_c`` closed, ``z = exp(jwT)``), the held force ``u = K_d s``; the
        payload's acceleration at ``w``: ``H_y(jw) y'' + H_u(jw) Z(jw) u`` with the hold's
        fundamental ``Z = exp(-jw tau) (1 - exp(-jwT))/(jwT)``. Exact for the component at
        ``w`` (the others lie at ``w + 2 pi n/T``).
        """
        omega = 2 * np.pi * np.asarray(frequency, dtype=float).ravel()
        s, z = 1j * omega, np.exp(1j * omega * self.period)
        acc = list(SENSORS).index("payload_acceleration")
        base = _responses(*self.closed_base, s)               # (N, sensors + 1, 2)
        plant = _responses(*self.held, z)[:, :, 0]            # (N, sensors)
        gains = _responses(*self.discrete, z)[:, 0, :]        # (N, sensors)
        hold = np.exp(-s * self.delay) * (1 - np.exp(-s * self.period)) / (s * self.period)
        sensors = base[:, :len(SENSORS), 0]
        force = np.sum(gains * sensors, axis=1) / (1 - np.sum(gains * plant, axis=1))
        response = base[:, acc, 0] + base[:, acc, 1] * hold * force
        return np.abs(response).reshape(np.shape(frequency))


def _continuous_blocks_transmissibility(frequency, isolator, controller, delay):
    """``|X/Y|`` of a continuous controller with blocks delayed by ``delay`` (exact lag)."""
    omega = 2 * np.pi * np.asarray(frequency, dtype=float).ravel()
    s = 1j * omega
    gains = _responses(*continuous_controller_matrices(isolator, controller), s)[:, 0, :]
    base = _responses(*plant_matrices(isolator, controller), s)  # (N, sensors, 2)
    lag = np.exp(-s * delay)
    acc = list(SENSORS).index("payload_acceleration")
    force = lag * np.sum(gains * base[:, :, 0], axis=1) / (
        1 - lag * np.sum(gains * base[:, :, 1], axis=1))
    return np.abs(base[:, acc, 0] + base[:, acc, 1] * force).reshape(np.shape(frequency))
