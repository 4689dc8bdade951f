"""Linear analysis at the operating point (python-control).

Linearising eq. (1) about the setpoint while the payload slips, with the
Coulomb and Stribeck terms left out (they have no linear part at v = 0) and the
motor unsaturated, gives the closed loop

    m*s^2*X = -(k + c*s)*Z - (Kp + Ki/s)*Z - Kd*HP(s)*s*X,      Z = X - Y,

with ``k`` the MagSpring's tangent stiffness at the setpoint, ``c`` the viscous
friction, ``HP(s) = s/(s + w_hp)`` the charge amplifier's high-pass. Hence the
absolute transmissibility

    T(s) = X/Y = (c*s + k + Kp + Ki/s) / (m*s^2 + c*s + k + Kp + Ki/s + Kd*s*HP(s)).

This is the frictionless-guide limit the nonlinear simulator must reproduce
(tests), and the overlay shown with nonlinear transmissibility curves.

A controller with blocks (a user's ``LinearController``, friction compensation) closes the
same plant through one linear system instead of the closed form (docs/model.md §10): the
plant with every sensor a controller may read (:func:`plant_system`), the whole controller
from those sensors to the motor force (:func:`controller_system`: PI + damping, the
compensation's linear part, the user's controller), and the two closed
(:func:`close_loop`). A controller without blocks keeps the closed form, operation for
operation.
"""
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from qzs.errors import ParameterError
from qzs.model.controller import SENSORS, ControllerParameters
from qzs.model.isolator import IsolatorParameters, spring_stiffness
from qzs.model.registry import model_inputs

if TYPE_CHECKING:
    import control

__all__ = ["LinearModel", "linearize", "linear_transmissibility", "loop_constants",
           "plant_system", "controller_system", "plant_matrices", "controller_matrices",
           "continuous_controller_matrices", "close_loop", "PLANT_STATES"]


@dataclass(frozen=True)
class LinearModel:
    """Linearised closed loop at the operating point.

    Attributes
    ----------
    transfer_function : control.TransferFunction
        Base displacement -> payload displacement, ``X/Y`` (dimensionless).
    state_space : control.StateSpace
        The same, as a state-space model (input y, output x).
    stiffness : float
        Total stiffness at the setpoint, spring + Kp [N/m].
    undamped_natural_frequency : float
        ``sqrt(stiffness/m)/(2*pi)`` [Hz]: about 0.08 Hz passive, 0.45 Hz with Kp = 50 N/m;
        NaN where the stiffness is negative (a spring law's negative stiffness outweighs Kp:
        the loop has no undamped oscillation, its static equilibrium is unstable).
    natural_frequency : float
        Natural frequency of the dominant (least-damped oscillatory) pole pair [Hz].
    damping_ratio : float
        Its damping ratio [-].
    poles : ndarray
        Closed-loop poles [rad/s].
    """

    transfer_function: "control.TransferFunction"
    state_space: "control.StateSpace"
    stiffness: float
    undamped_natural_frequency: float
    natural_frequency: float
    damping_ratio: float
    poles: np.ndarray

    def transmissibility(self, frequency: ArrayLike) -> float | NDArray[np.float64]:
        """``|X/Y|`` at ``frequency`` [Hz] (amplitude ratio).

        Parameters
        ----------
        frequency : float or array_like
            Frequency [Hz].

        Returns
        -------
        float or ndarray
            Amplitude ratio ``|X/Y|`` [-], of the shape of ``frequency``.
        """
        response = self.transfer_function(2j * np.pi * np.asarray(frequency, dtype=float))
        return np.abs(response)


def loop_constants(isolator, controller, relative_position=None):
    """The linear closed loop's constants at an operating point, the one place they are read.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        PI and damping loops.
    relative_position : float, optional
        Operating point z [m]; default the position setpoint.

    Returns
    -------
    tuple of float
        ``(m, c, k, Kp, Ki, Kd, w_hp)``: mass [kg], viscous damping [N*s/m], MagSpring
        tangent stiffness at the operating point [N/m], PI gains [N/m, N/(m*s)], damping
        gain [N*s/m] and the high-pass corner [rad/s] (0: none).
    """
    z0 = controller.position_setpoint if relative_position is None else relative_position
    return (isolator.mass, isolator.viscous_damping, float(spring_stiffness(z0, isolator)),
            controller.pi_kp, controller.pi_ki, controller.damping_gain,
            2 * np.pi * controller.velocity_highpass)


def linearize(isolator: IsolatorParameters | None = None,
              controller: ControllerParameters | None = None,
              relative_position: float | None = None) -> LinearModel:
    """Linearise the closed-loop isolator at its operating point.

    PI + damping: the closed form of the module's text. With blocks: the plant
    (:func:`plant_system`) and the controller (:func:`controller_system`) closed, ``T`` the
    payload's acceleration over the base's (pole-zero cancellations removed by ``minreal``).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops, and any blocks (a discrete linear controller: use the sampled
        loop's functions); defaults if omitted.
    relative_position : float, optional
        Operating point z [m]; default the position setpoint.

    Returns
    -------
    LinearModel
        ``stiffness`` and ``undamped_natural_frequency`` are the spring's and ``Kp``'s
        alone; the poles are the whole loop's.
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    m, c, k, kp, ki, kd, w_hp = loop_constants(isolator, controller, relative_position)
    if controller.has_blocks:
        transfer = _linearize_blocks(isolator, controller, relative_position)
    else:
        s = control.tf("s")
        highpass = s / (s + w_hp) if w_hp > 0 else 1
        coupling = c * s + k + kp + (ki / s if ki > 0 else 0)
        transfer = control.minreal(coupling / (m * s ** 2 + coupling + kd * s * highpass),
                                   verbose=False)
    state_space = control.ss(transfer)
    poles = np.asarray(transfer.poles())
    oscillatory = poles[np.abs(poles.imag) > 1e-9]
    dominant = oscillatory if oscillatory.size else poles
    dominant = dominant[np.argmin(np.abs(dominant))] if dominant.size else 0j
    wn = abs(dominant)
    zeta = -dominant.real / wn if wn > 0 else 1.0
    # a spring law's negative stiffness beyond Kp: no undamped oscillation (NaN)
    undamped = np.sqrt((k + kp) / m) / (2 * np.pi) if k + kp >= 0 else np.nan
    return LinearModel(transfer, state_space, k + kp, float(undamped), wn / (2 * np.pi),
                       float(zeta), poles)


def linear_transmissibility(frequency, isolator=None, controller=None):
    """Closed-form ``|X/Y|`` [-] of the linearised isolator at ``frequency`` [Hz].

    Parameters
    ----------
    frequency : float or array_like
        Frequency [Hz].
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted.

    Returns
    -------
    float or ndarray
        Amplitude ratio ``|X/Y|`` [-] at the setpoint (see :func:`linearize`).
    """
    return linearize(isolator, controller).transmissibility(frequency)


# ---------------------------------------------------------------- a controller with blocks
#: The plant's states (:func:`plant_system`), in order; the high-pass state only with the
#: charge amplifier's high-pass on, the base's velocity only with the base as an input.
PLANT_STATES = ("relative_position", "relative_velocity", "highpass", "base_velocity")


def _plant_matrices(m, cv, k, w, base=True):
    """``(A, B, C, D)`` of :func:`plant_system`: inputs (base acceleration,) motor force.

    States z, v, (w,) (y-dot); outputs the sensors of :data:`SENSORS` in order.
    """
    n = 2 + (w > 0) + bool(base)
    iw = 2 if w > 0 else None
    iy = n - 1 if base else None
    a, b = np.zeros((n, n)), np.zeros((n, 2))
    c, d = np.zeros((len(SENSORS), n)), np.zeros((len(SENSORS), 2))
    a[0, 1] = 1.0
    a[1, 0], a[1, 1], b[1, 1], b[1, 0] = -k / m, -cv / m, 1.0 / m, -1.0
    c[0, 0] = -1.0                                   # position error z_ref - z
    c[1, 1] = 1.0                                    # measured payload velocity y' + z' - w
    c[2, 0], c[2, 1], d[2, 1] = -k / m, -cv / m, 1.0 / m  # payload acceleration
    d[3, 0] = 1.0                                    # base acceleration
    c[4, 1] = 1.0                                    # relative velocity
    if iw is not None:
        a[iw, 1], a[iw, iw] = w, -w
        c[1, iw] = -1.0
    if iy is not None:
        b[iy, 0] = 1.0
        c[1, iy] = 1.0
        if iw is not None:
            a[iw, iy] = w
    if not base:
        b, d = b[:, 1:], d[:, 1:]
    return a, b, c, d


def plant_matrices(isolator, controller, relative_position=None, *, base=True):
    """``(A, B, C, D)`` of :func:`plant_system` (the same arguments).

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Supplies the setpoint and the high-pass corner.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.
    base : bool
        The base's acceleration is an input (first, before the motor force).

    Returns
    -------
    tuple of ndarray
    """
    m, cv, k, _, _, _, w = loop_constants(isolator, controller, relative_position)
    return _plant_matrices(m, cv, k, w, base)


def plant_system(isolator: IsolatorParameters | None = None,
                 controller: ControllerParameters | None = None,
                 relative_position: float | None = None, *, base: bool = True
                 ) -> "control.StateSpace":
    """The linearised plant at the operating point, every sensor a controller may read out.

    The frictionless-guide limit of eq. (1) (docs/model.md §10): Coulomb and Stribeck terms
    dropped (no linear part at ``v = 0``), the viscous ``Cv``, the spring's tangent stiffness
    ``k`` at the operating point, no stop, motor unsaturated::

        m (z'' + y'') = -k z - Cv z' + F,      w' = w_hp (y' + z' - w)

    Inputs: ``base_acceleration`` y'' [m/s^2] (with ``base``), ``motor_force`` F [N].
    Outputs: the sensors of :data:`qzs.model.controller.SENSORS` in their order (deviations
    from the operating point): position error ``-z`` [m], the charge amplifier's velocity
    ``y' + z' - w`` [m/s] (``y' + z'`` with its high-pass off), payload acceleration
    [m/s^2], base acceleration [m/s^2], relative velocity ``z'`` [m/s]. States
    :data:`PLANT_STATES` (the high-pass's only when on; the base's velocity only with
    ``base``: a pure integrator of its acceleration, which no motor force reaches).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies the setpoint (the operating point) and the high-pass corner.
    relative_position : float, optional
        Operating point z [m]; default the setpoint.
    base : bool
        True: the base's acceleration is an input; False: the base at rest (the loop).

    Returns
    -------
    control.StateSpace
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    w = loop_constants(isolator, controller, relative_position)[6]
    a, b, c_, d = plant_matrices(isolator, controller, relative_position, base=base)
    states = [name for name in PLANT_STATES
              if (name != "highpass" or w > 0) and (name != "base_velocity" or base)]
    inputs = (["base_acceleration"] if base else []) + ["motor_force"]
    return control.ss(a, b, c_, d, inputs=inputs, outputs=list(SENSORS), states=states)


def _on_sensors(a, b, c, d, inputs):
    """A controller's matrices with its inputs spread over all of :data:`SENSORS`."""
    columns = [list(SENSORS).index(name) for name in inputs]
    b_all = np.zeros((a.shape[0], len(SENSORS)))
    d_all = np.zeros((1, len(SENSORS)))
    b_all[:, columns] = b
    d_all[:, columns] = d
    return a, b_all, np.atleast_2d(c), d_all


def _pid_matrices(isolator, controller, period=0.0):
    """PI + damping + the compensation's linear part, on :data:`SENSORS` -> motor force.

    ``F = Kp e + Ki I - Kd v_meas + fraction Cv' z' - r``: the integral ``I`` (``I' = e``;
    sampled ``I <- I + T e``), the compensation's viscous slope ``fraction Cv'`` (its
    Coulomb and Stribeck terms have no linear part at ``z' = 0``) and its observer of the
    friction left, ``r' = w_o (fraction Cv' z' - Cv z' - r)`` (the plant's friction is
    ``-Cv z'`` in this limit; sampled by forward Euler on the friction at the sample and the
    feedforward held until then, a state of its own, the new estimate applied at once).
    ``period`` 0: continuous.
    """
    _, cv, _, kp, ki, kd, _ = loop_constants(isolator, controller, None)
    compensation = controller.compensation
    slope = observer = 0.0
    if compensation is not None:
        slope = compensation.fraction * compensation.law(isolator)[3]
        observer = 2 * np.pi * compensation.observer_bandwidth
    e, vm, vr = (list(SENSORS).index(name) for name in
                 ("position_error", "measured_payload_velocity", "relative_velocity"))
    n = (ki > 0) + (observer > 0) * (2 if period else 1)
    a, b = np.zeros((n, n)), np.zeros((n, len(SENSORS)))
    c, d = np.zeros((1, n)), np.zeros((1, len(SENSORS)))
    d[0, e], d[0, vm], d[0, vr] = kp, -kd, slope
    i = 0
    if ki > 0:
        a[i, i] = 1.0 if period else 0.0
        b[i, e] = period if period else 1.0
        c[0, i] = ki
        i += 1
    if observer > 0:
        c[0, i] = -1.0
        if period:  # r <- r + w_o T (-Cv z' + f_held - r),  f_held <- fraction Cv' z'
            gain = observer * period
            a[i, i], a[i, i + 1], b[i, vr] = 1.0 - gain, gain, -gain * cv
            b[i + 1, vr] = slope
            # the new estimate is applied at once (docs/model.md §5.1): F = ... - r(n+1)
            c[0, i], c[0, i + 1] = -(1.0 - gain), -gain
            d[0, vr] += gain * cv
        else:
            a[i, i], b[i, vr] = -observer, observer * (slope - cv)
    return a, b, c, d


def _parallel(*parts):
    """The sum of controllers' outputs, each ``(A, B, C, D)`` on the same inputs."""
    parts = [p for p in parts if p is not None]
    n = sum(p[0].shape[0] for p in parts)
    a = np.zeros((n, n))
    i = 0
    for p in parts:
        size = p[0].shape[0]
        a[i:i + size, i:i + size] = p[0]
        i += size
    return (a, np.vstack([p[1] for p in parts]), np.hstack([p[2] for p in parts]),
            sum(p[3] for p in parts))


def controller_matrices(isolator, controller, rate=0.0):
    """The controller as matrices, split into its continuous and its sampled part.

    Each part ``(A, B, C, D)`` from :data:`~qzs.model.controller.SENSORS` to the motor
    force (:func:`controller_system`), or None: PI + damping and the compensation's linear
    part are sampled at ``rate`` (0: continuous; forward-Euler integral and observer), a
    linear controller at its own sample time. Sampled together, the linear controller reads
    the payload's acceleration with PI + damping's new force (the simulator's order).

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        The controller.
    rate : float
        Rate of PI + damping [Hz]; 0: continuous.

    Returns
    -------
    continuous, sampled : tuple of ndarray or None
        The two parts.
    period : float
        Sample period of the sampled part [s] (0: none).

    Raises
    ------
    ParameterError
        PI + damping and a discrete linear controller at two different rates.
    """
    linear = controller.linear
    lin = None if linear is None else _on_sensors(*linear.matrices(), linear.inputs)
    period = 1.0 / rate if rate > 0 else 0.0
    pid = _pid_matrices(isolator, controller, period)
    if linear is not None and linear.discrete:
        if period and not math.isclose(period, linear.sample_time, rel_tol=1e-9):
            raise ParameterError(
                f"the controller samples PI + damping at {rate:g} Hz and its linear controller "
                f"every {linear.sample_time:g} s: a loop with two rates is not analysed; give "
                f"them the same (`rate` = {1 / linear.sample_time:g} Hz), or analyse each "
                "with the other continuous.", ("rate",))
        if period:
            return None, _sampled_pair(pid, lin, isolator.mass), period
        return pid, lin, linear.sample_time
    if period:
        return lin, pid, period
    return _parallel(pid, lin), None, 0.0


def _sampled_pair(pid, lin, mass):
    """PI + damping and a linear controller sampled together: the linear one reads the
    payload's acceleration with PI + damping's new force and its own old one (the order in
    which the simulator samples, docs/model.md §5), a one-sample memory of PI + damping's
    force ``p``: ``u_acc <- u_acc + (F_pid - p)/m``.
    """
    acc = list(SENSORS).index("payload_acceleration")
    if not np.any(lin[1][:, acc]) and not lin[3][0, acc]:
        return _parallel(pid, lin)
    a1, b1, c1, d1 = pid
    a2, b2, c2, d2 = lin
    n1, n2 = a1.shape[0], a2.shape[0]
    mix = np.zeros((len(SENSORS), 1))
    mix[acc, 0] = 1.0 / mass
    n = n1 + 1 + n2
    a, b = np.zeros((n, n)), np.zeros((n, len(SENSORS)))
    a[:n1, :n1], b[:n1] = a1, b1
    a[n1, :n1], b[n1] = c1[0], d1[0]                       # p <- F_pid
    through = np.eye(len(SENSORS)) + mix @ d1               # u_lin = through u + mix (c1 x1 - p)
    a[n1 + 1:, :n1] = b2 @ mix @ c1
    a[n1 + 1:, n1] = -(b2 @ mix)[:, 0]
    a[n1 + 1:, n1 + 1:] = a2
    b[n1 + 1:] = b2 @ through
    c = np.hstack([c1 + d2 @ mix @ c1, -(d2 @ mix), c2])
    d = d1 + d2 @ through
    return a, b, c, d


def close_loop(plant, controller):
    """The plant with a controller closed around its motor force (its last input).

    ``F = u + K y`` with ``y`` the plant's outputs (the sensors): the closed loop's inputs
    are the plant's, the last now an external force ``u`` on top of the controller's, its
    outputs the plant's then the motor force ``F``. Continuous or discrete alike (both
    systems the same kind).

    Parameters
    ----------
    plant : tuple of ndarray
        ``(A, B, C, D)`` of the plant, its motor force the last input [SI].
    controller : tuple of ndarray or None
        ``(A, B, C, D)`` of the controller, the plant's outputs in, one force out [SI];
        None: no controller (``F = u``).

    Returns
    -------
    tuple of ndarray
        ``(A, B, C, D)`` of the closed loop.
    """
    a, b, c, d = plant
    if controller is None:
        n_in = b.shape[1]
        return a, b, np.vstack([c, np.zeros((1, a.shape[0]))]), np.vstack(
            [d, np.eye(n_in)[-1:]])
    ak, bk, ck, dk = controller
    b_m, d_m = b[:, -1:], d[:, -1:]
    gain = 1.0 / (1.0 - (dk @ d_m).item())
    u_x, u_k, u_w = gain * dk @ c, gain * ck, gain * dk @ d
    a_cl = np.block([[a + b_m @ u_x, b_m @ u_k],
                     [bk @ (c + d_m @ u_x), ak + bk @ d_m @ u_k]])
    b_cl = np.vstack([b + b_m @ u_w, bk @ (d + d_m @ u_w)])
    c_y = np.hstack([c + d_m @ u_x, d_m @ u_k])
    d_y = d + d_m @ u_w
    external = np.zeros((1, b.shape[1]))
    external[0, -1] = 1.0
    c_f = np.hstack([u_x, u_k])
    d_f = external + u_w
    return a_cl, b_cl, np.vstack([c_y, c_f]), np.vstack([d_y, d_f])


def controller_system(isolator: IsolatorParameters | None = None,
                      controller: ControllerParameters | None = None) -> "control.StateSpace":
    """The whole controller as one linear system: every sensor in, the motor force out.

    ``F = (Kp + Ki/s) e - Kd v_meas + fraction Cv' z' - r + K_user(s) u`` in the
    frictionless-guide limit (docs/model.md §10): PI + damping, the friction compensation's
    linear part (its viscous slope ``fraction Cv'`` on the relative velocity, and its
    observer ``r' = w_o ((fraction Cv' - Cv) z' - r)`` of the friction left; its Coulomb and
    Stribeck terms have no linear part at ``z' = 0``), and the user's
    :class:`~qzs.model.controller.LinearController`. The dither is no feedback: left out.
    A sampled PI + damping enters as its continuous counterpart, as in :func:`linearize`.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters (the compensation's friction law defaults to the plant's); Table 1
        defaults if omitted.
    controller : ControllerParameters, optional
        The controller; defaults if omitted.

    Returns
    -------
    control.StateSpace
        Inputs :data:`~qzs.model.controller.SENSORS` [SI], output ``motor_force`` [N].

    Raises
    ------
    ParameterError
        A discrete linear controller (a sampled loop: ``sampled_loop``).
    """
    import control

    isolator, controller = model_inputs(isolator, controller)
    a, b, c, d = continuous_controller_matrices(isolator, controller)
    return control.ss(a, b, c, d, inputs=list(SENSORS), outputs=["motor_force"])


def continuous_controller_matrices(isolator, controller):
    """The whole controller as matrices ``(A, B, C, D)``, for a continuous loop.

    :func:`controller_matrices` with PI + damping continuous (a sampled one as its
    continuous counterpart).

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        The controller.

    Returns
    -------
    tuple of ndarray
        From :data:`~qzs.model.controller.SENSORS` to the motor force [SI].

    Raises
    ------
    ParameterError
        A discrete linear controller: the loop is sampled.
    """
    linear = controller.linear
    if linear is not None and linear.discrete:
        raise ParameterError(
            f"`controller` has a discrete LinearController (sample time "
            f"{linear.sample_time:g} s): the continuous linearisation cannot hold it; use "
            "qzs.analysis.control_design.sampled_loop, sampled_transmissibility or "
            "loop_margins, which sample it.", ("controller",))
    return controller_matrices(isolator, controller, 0.0)[0]


def _linearize_blocks(isolator, controller, relative_position):
    """:func:`linearize` of a controller with blocks: the plant and the controller closed."""
    import control

    plant = plant_matrices(isolator, controller, relative_position, base=True)
    a, b, c_, d = close_loop(plant, continuous_controller_matrices(isolator, controller))
    acc = list(SENSORS).index("payload_acceleration")
    closed = control.ss(a, b[:, :1], c_[acc:acc + 1], d[acc:acc + 1, :1])
    return control.minreal(control.tf(closed), verbose=False)
