"""Linear analysis of a hexapod of isolator legs about its home pose (python-control).

The six-axis generalisation of :mod:`qzs.analysis.linear` (docs/hexapod.md §5-6). Each
leg is the single-axis closed loop along its axis, slipping (Coulomb and Stribeck terms
left out), its motor unsaturated; its force on the platform, positive pushing away,
changes by

    df_i = -(k_i + c_i s + Ki_i/s) dL_i - Kd_i HP_i(s) s dx_i,

``k_i`` the MagSpring's tangent stiffness at the setpoint plus ``Kp_i``, ``dL_i`` the leg's
length change (relative motion of its joints), ``dx_i`` the absolute displacement of its
top joint along the leg (what a per-leg accelerometer integrates). With ``q`` the
platform's and ``q_b`` the base's small displacement (translation of the frame point [m],
rotation [rad]) at the chosen frame point, ``dL = J (q - q_b)`` and ``dx = J q``, so

    M s^2 q = -(K + C s + J^T Kd HP s J + J^T Ki J/s) q - (K_b - C s - J^T Ki J/s) q_b + w,

``K = J^T diag(k) J + K_g``, ``K_b = -J^T diag(k) J + K_gb``, ``C = J^T diag(c) J``; ``K_g``
and ``K_gb`` are the geometric (preload) stiffness of the static leg forces turning with
their legs and of the weight turning with the platform, ``w`` an external wrench.
"""
from dataclasses import dataclass

import numpy as np

from qzs._validation import choice, real
from qzs.defaults import AXES, AXIS_UNITS
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters, refuse_blocks
from qzs.model.hexapod import (LEG_COUNT, CartesianController, HexapodGeometry,
                               PlatformParameters, jacobian, mass_matrix, static_leg_forces)
from qzs.model.isolator import IsolatorParameters, spring_stiffness

__all__ = ["HexapodLinearModel", "hexapod_linearize", "geometric_stiffness",
           "off_diagonal_coupling", "entry_unit", "FRAMES"]

#: Named frame points of :func:`hexapod_linearize` (or give a point in the top frame).
FRAMES = ("center_of_mass", "origin")
#: |omega^2| below this share of the largest counts as zero (a neutral mode) [-].
_NEUTRAL = 1e-12


def _skew(vector):
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _rotation_hessian(direction, arm):
    """``A`` with ``direction . (theta x (theta x arm)) = theta @ A @ theta`` (symmetric)."""
    outer = np.outer(direction, arm)
    return 0.5 * (outer + outer.T) - float(direction @ arm) * np.eye(3)


def off_diagonal_coupling(matrix):
    """How far a symmetric matrix is from diagonal: ``max |A_ij| / sqrt(|A_ii A_jj|)``, i != j.

    Normalising by the diagonal makes the measure free of the units of mixed blocks
    (N/m, N, N*m/rad): 0 for a diagonal matrix, 1 for two coordinates as coupled as a
    rank-one pair, above 1 for a matrix that is not positive definite in that pair.

    Parameters
    ----------
    matrix : array_like, shape (n, n)
        Stiffness, damping or mass matrix (any consistent units).

    Returns
    -------
    float
        The measure [-]; ``inf`` if a diagonal entry is 0 while its row is not.
    """
    a = np.asarray(matrix, dtype=float)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ParameterError(f"`matrix` must be square, got shape {a.shape}.")
    scale = np.sqrt(np.abs(np.outer(np.diag(a), np.diag(a))))
    off = np.abs(a - np.diag(np.diag(a)))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(off > 0, off / scale, 0.0)
    return float(np.max(ratio)) if ratio.size else 0.0


def geometric_stiffness(geometry, platform, *, point=None, leg_forces=None):
    """Geometric (preload) stiffness of loaded legs and of the weight, at the home pose.

    Second derivatives of the legs' and the weight's potential: a leg pushing with
    ``f_i`` turns with its line, a weight off the point swings with the platform.
    With ``r_i = t_i - p`` (top joint from the point), ``beta_i = b_i - (o_home + p)``,
    ``P_i = (I - u_i u_i^T)/L_i``, ``G_q = [I, -[r_i]x]``, ``G_b = [-I, [beta_i]x]``::

        K_g  = -sum f_i (G_q^T P_i G_q + diag(0, A(u_i, r_i))) + diag(0, m g A(e_z, c - p))
        K_gb = -sum f_i  G_q^T P_i G_b

    ``A(u, r) = sym(u r^T) - (u . r) I`` is the second-order term of a small rotation.
    In translation ``K_g`` is ``-sum f_i P_i``: compressed legs (``f_i > 0``) make it
    negative, of order ``f/L``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass, centre of mass and gravity.
    point : array_like, shape (3,), optional
        Frame point ``p`` in the top frame [m]; default the top frame origin.
    leg_forces : array_like, shape (6,), optional
        Static leg forces [N]; default :func:`~qzs.model.hexapod.static_leg_forces`,
        which hold the weight. Other forces leave the platform out of equilibrium and
        ``K_g`` then depends on how rotations are parametrised.

    Returns
    -------
    platform_stiffness : ndarray, shape (6, 6)
        ``K_g``: to add to the stiffness on the platform's displacement [N/m, N, N*m/rad].
    base_stiffness : ndarray, shape (6, 6)
        ``K_gb``: to add to the stiffness on the base's displacement [N/m, N, N*m/rad].
    """
    point = np.zeros(3) if point is None else np.asarray(point, dtype=float)
    forces = (static_leg_forces(geometry, platform) if leg_forces is None
              else np.asarray(leg_forces, dtype=float))
    center = geometry.home_position + point
    platform_stiffness = np.zeros((6, 6))
    base_stiffness = np.zeros((6, 6))
    for b, t, f in zip(geometry.base_joints, geometry.top_joints, forces):
        arm, base_arm = t - point, b - center
        vector = arm - base_arm
        length = float(np.linalg.norm(vector))
        unit = vector / length
        normal = (np.eye(3) - np.outer(unit, unit)) / length
        g_q = np.hstack([np.eye(3), -_skew(arm)])
        g_b = np.hstack([-np.eye(3), _skew(base_arm)])
        platform_stiffness -= f * (g_q.T @ normal @ g_q)
        platform_stiffness[3:, 3:] -= f * _rotation_hessian(unit, arm)
        base_stiffness -= f * (g_q.T @ normal @ g_b)
    weight = platform.mass * platform.gravity
    platform_stiffness[3:, 3:] += weight * _rotation_hessian(np.array([0.0, 0.0, 1.0]),
                                                             platform.center_of_mass - point)
    return platform_stiffness, base_stiffness



def entry_unit(output, input, dimensionless="1"):
    """Unit of the entry platform axis ``output`` per base axis ``input`` (indices 0-5).

    Parameters
    ----------
    output, input : int
        Axis indices (0-2 translations, 3-5 rotations).
    dimensionless : str
        What to say for an entry without unit (translation per translation, rotation
        per rotation).

    Returns
    -------
    str
        ``dimensionless``, ``"m/rad"`` or ``"rad/m"``.
    """
    row, column = AXIS_UNITS[output], AXIS_UNITS[input]
    return dimensionless if row == column else f"{row}/{column}"

@dataclass(frozen=True, kw_only=True, eq=False)
class HexapodLinearModel:
    """The hexapod's closed loop linearised at the home pose (:func:`hexapod_linearize`).

    Coordinates ``q``: translation [m] of the frame point and rotation angles [rad] of
    the platform; the base's ``q_b`` likewise, at the same point. Matrices are in SI,
    blocks [N/m, N; N, N*m/rad] for stiffness, [N*s/m, N*s; N*s, N*m*s/rad] for damping.

    Attributes
    ----------
    frame_point : ndarray, shape (3,)
        The point the matrices are expressed at, in the top frame [m].
    stiffness_matrix : ndarray, shape (6, 6)
        ``K = J^T diag(k) J + K_g`` [N/m, N, N*m/rad]: legs plus geometric stiffness.
    leg_stiffness_matrix : ndarray, shape (6, 6)
        ``J^T diag(k) J`` [N/m, N, N*m/rad]: the legs' axial stiffness alone (with
        centralised control, the springs' plus the loops' ``T^T diag(Kp) T``).
    geometric_stiffness_matrix : ndarray, shape (6, 6)
        ``K_g`` [N/m, N, N*m/rad]: preload of the legs and weight (0 without preload).
    base_stiffness_matrix : ndarray, shape (6, 6)
        ``K_b``: the platform's wrench is ``-K_b q_b`` for a static base displacement
        ``q_b`` [N/m, N, N*m/rad].
    damping_matrix : ndarray, shape (6, 6)
        ``C = J^T diag(c) J`` [N*s/m, N*s, N*m*s/rad]: viscous friction on the legs'
        relative velocity.
    active_damping_matrix : ndarray, shape (6, 6)
        ``J^T diag(Kd) J`` [N*s/m, N*s, N*m*s/rad]: active damping on the absolute
        velocity, before the high-pass.
    integral_matrix : ndarray, shape (6, 6)
        ``J^T diag(Ki) J`` [N/(m*s), N/s, N*m/(rad*s)]: the PI integral, acting as ``/s``.
    mass_matrix : ndarray, shape (6, 6)
        Spatial mass matrix at the frame point [kg, kg*m, kg*m^2].
    jacobian : ndarray, shape (6, 6)
        ``J`` at the frame point and home pose [m/m, m/rad].
    leg_forces : ndarray, shape (6,)
        Static leg forces holding the weight [N], positive pushing the platform away.
    leg_stiffness : ndarray, shape (6,)
        Axial stiffness ``k_i`` of each leg [N/m].
    leg_damping : ndarray, shape (6,)
        Viscous friction ``c_i`` of each leg [N*s/m].
    leg_integral_gain : ndarray, shape (6,)
        ``Ki`` of each loop [N/(m*s)]: a leg's, or with centralised control an axis's
        ([N/(m*s)] or [N*m/(rad*s)]; see ``control``).
    leg_damping_gain : ndarray, shape (6,)
        ``Kd`` of each loop [N*s/m] (an axis's [N*s/m] or [N*m*s/rad] when centralised).
    leg_highpass : ndarray, shape (6,)
        Corner of each loop's velocity high-pass [Hz]; 0 for none.
    loop_matrix : ndarray, shape (6, 6)
        From the coordinates ``q`` to the loops' coordinates: ``J`` (leg lengths) for
        per-leg loops, ``T = J_c^-1 J`` (the controller's axes) when centralised.
    control : {"per leg", "centralised"}
        Where the loops act (docs/hexapod.md §9.5).
    include_preload : bool
        Whether ``K_g`` and ``K_gb`` are included [-].
    eigenvalues : ndarray, shape (6,)
        ``omega^2`` of ``K v = omega^2 M v`` [rad^2/s^2], ascending; negative for an
        unstable direction.
    natural_frequencies : ndarray, shape (6,)
        Undamped natural frequencies ``sqrt(omega^2)/(2 pi)`` [Hz]; NaN where
        ``omega^2 < 0`` (see ``notes``).
    mode_shapes : ndarray, shape (6, 6)
        Columns: the modes ``v`` [m, rad], normalised ``v^T M v = 1``, largest entry positive.
    poles : ndarray
        Poles of the whole closed loop (legs' integrals and high-passes included) [rad/s].
    stable : bool
        True if every pole has a negative real part [-].
    notes : tuple of str
        Why a frequency is NaN, and what the loop's stability is.
    transmissibility_system : control.StateSpace
        Base displacement ``q_b`` (6 inputs) to platform displacement ``q`` (6 outputs),
        both at the frame point.
    compliance_system : control.StateSpace
        External wrench on the platform at the frame point (6 inputs, [N, N*m]) to ``q``.
    """

    frame_point: np.ndarray
    stiffness_matrix: np.ndarray
    leg_stiffness_matrix: np.ndarray
    geometric_stiffness_matrix: np.ndarray
    base_stiffness_matrix: np.ndarray
    damping_matrix: np.ndarray
    active_damping_matrix: np.ndarray
    integral_matrix: np.ndarray
    mass_matrix: np.ndarray
    jacobian: np.ndarray
    leg_forces: np.ndarray
    leg_stiffness: np.ndarray
    leg_damping: np.ndarray
    leg_integral_gain: np.ndarray
    leg_damping_gain: np.ndarray
    leg_highpass: np.ndarray
    include_preload: bool
    eigenvalues: np.ndarray
    natural_frequencies: np.ndarray
    mode_shapes: np.ndarray
    poles: np.ndarray
    stable: bool
    notes: tuple
    transmissibility_system: object
    compliance_system: object
    loop_matrix: np.ndarray | None = None
    control: str = "per leg"

    # ------------------------------------------------------------ responses
    def _solve(self, frequency, wrench):
        """``T(s)`` (``wrench`` False) or ``G(s)`` per frequency, shaped ``frequency + (6, 6)``.

        With a PI integral both sides of ``D(s) q = N(s) q_b + w`` are multiplied by ``s``
        so that 0 Hz stays finite (``D s -> J^T Ki J``).
        """
        f = np.asarray(frequency, dtype=float)
        if not np.all(np.isfinite(f)) or np.any(f < 0):
            raise ParameterError(f"`frequency` must be finite and non-negative [Hz], got {f!r}.")
        s = (2j * np.pi * f.reshape(-1))[:, None, None]
        corner = 2 * np.pi * self.leg_highpass
        with np.errstate(divide="ignore", invalid="ignore"):
            highpass = np.where(corner > 0, s[:, :, 0] / (s[:, :, 0] + corner), 1.0)
        j = self.jacobian if self.loop_matrix is None else self.loop_matrix
        active = np.einsum("li,kl,lj->kij", j, self.leg_damping_gain * highpass, j)
        scale = s if np.any(self.leg_integral_gain > 0) else np.ones_like(s)
        denominator = scale * (self.mass_matrix * s ** 2 + self.stiffness_matrix
                               + (self.damping_matrix + active) * s) + self.integral_matrix
        if wrench:
            right = scale * np.eye(6)
        else:
            right = scale * (self.damping_matrix * s - self.base_stiffness_matrix) \
                + self.integral_matrix
        try:
            response = np.linalg.solve(denominator, np.broadcast_to(right, denominator.shape))
        except np.linalg.LinAlgError:
            raise ParameterError(
                "the response is singular at a `frequency` of the request (0 Hz without a "
                "PI integral on every leg, or a platform with zero static stiffness); leave "
                "0 Hz out.") from None
        return response.reshape(f.shape + (6, 6))

    def transmissibility(self, frequency, magnitude=False):
        """The 6x6 transmissibility ``q = T q_b`` at ``frequency``.

        Entry ``[..., i, j]`` is platform coordinate ``i`` per base coordinate ``j`` at the
        frame point (``x, y, z, rx, ry, rz``): [m/m] and [rad/rad] on the diagonal
        blocks, [m/rad] and [rad/m] off them. At 0 Hz with every leg's PI integral it is
        the identity (the platform follows the base rigidly).

        Parameters
        ----------
        frequency : float or array_like
            Frequency [Hz], non-negative.
        magnitude : bool
            Return ``|T|`` [-] instead of the complex values.

        Returns
        -------
        ndarray, shape ``frequency.shape + (6, 6)``
            Complex ``T`` or its magnitude.
        """
        response = self._solve(frequency, wrench=False)
        return np.abs(response) if magnitude else response

    def compliance(self, frequency):
        """The 6x6 compliance ``q = G w`` for an external wrench ``w`` on the platform.

        Parameters
        ----------
        frequency : float or array_like
            Frequency [Hz], non-negative.

        Returns
        -------
        ndarray, shape ``frequency.shape + (6, 6)``
            Complex ``G`` [m/N, m/(N*m), rad/N, rad/(N*m)].
        """
        return self._solve(frequency, wrench=True)

    # ------------------------------------------------------------ decoupling views
    @property
    def stiffness_in_leg_frame(self):
        """``J^-T K J^-1`` [N/m]: the stiffness seen in leg length coordinates (6x6).

        Without preload it is ``diag(k)``; the geometric stiffness couples the legs.
        """
        inverse = np.linalg.inv(self.jacobian)
        return inverse.T @ self.stiffness_matrix @ inverse

    @property
    def mass_in_leg_frame(self):
        """``J^-T M J^-1`` [kg]: the platform's mass seen in leg length coordinates (6x6).

        Diagonal when the legs are dynamically decoupled (each leg moves its own mass).
        """
        inverse = np.linalg.inv(self.jacobian)
        return inverse.T @ self.mass_matrix @ inverse

    @property
    def damping_in_leg_frame(self):
        """``J^-T C J^-1`` [N*s/m]: the viscous damping in leg coordinates, ``diag(c)``."""
        inverse = np.linalg.inv(self.jacobian)
        return inverse.T @ self.damping_matrix @ inverse

    def decoupling(self):
        """:func:`off_diagonal_coupling` of each matrix, in pose and in leg coordinates.

        Returns
        -------
        dict
            ``{"stiffness", "mass", "damping", "stiffness_in_leg_frame",
            "mass_in_leg_frame"}`` -> measure [-]; 0 means diagonal (decoupled).
        """
        return {"stiffness": off_diagonal_coupling(self.stiffness_matrix),
                "mass": off_diagonal_coupling(self.mass_matrix),
                "damping": off_diagonal_coupling(self.damping_matrix),
                "stiffness_in_leg_frame": off_diagonal_coupling(self.stiffness_in_leg_frame),
                "mass_in_leg_frame": off_diagonal_coupling(self.mass_in_leg_frame)}


def _per_leg(name, value, kind):
    """One parameter object or a sequence of six, as a list of six."""
    if isinstance(value, kind):
        return [value] * LEG_COUNT
    try:
        items = list(value)
    except TypeError:
        items = None
    if items is None or len(items) != LEG_COUNT or not all(isinstance(v, kind) for v in items):
        raise ParameterError(f"`{name}` must be one {kind.__name__} or a sequence of six, one "
                             f"per leg, got {value!r}.")
    return items


def _frame_point(frame, platform):
    if isinstance(frame, str):
        choice("frame", frame, FRAMES)
        return (np.array(platform.center_of_mass) if frame == "center_of_mass"
                else np.zeros(3))
    try:
        point = np.array(frame, dtype=float)
    except (TypeError, ValueError):
        point = None
    if point is None or point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ParameterError(f"`frame` must be 'center_of_mass', 'origin' or a finite point "
                             f"(x, y, z) in the top frame [m], got {frame!r}.")
    return point


def hexapod_linearize(geometry, platform, isolator=None, controller=None, *, leg_stiffness=None,
                      frame="center_of_mass", include_preload=True, cartesian=None):
    """Linearise the hexapod of isolator legs at its home pose.

    Each leg is the single-axis loop of :func:`qzs.analysis.linear.linearize` along its
    axis (docs/hexapod.md §5-6): axial stiffness ``k`` = MagSpring tangent stiffness at
    the setpoint + ``Kp``, viscous friction ``c`` on the relative velocity, the integral
    ``Ki/s``, and active damping ``Kd HP(s) s`` on the absolute velocity of the leg's top
    joint along the leg. The legs are massless; ``isolator.mass`` and
    ``isolator.gravity`` are not used (the platform's are), nor are stiction, Coulomb
    friction, stops and saturation.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass, inertia, centre of mass and gravity of the moving platform.
    isolator : IsolatorParameters or sequence of six, optional
        Each leg's plant (spring and viscous friction); Table 1 defaults if omitted.
    controller : ControllerParameters or sequence of six, optional
        Each leg's loop (setpoint, gains, high-pass); defaults if omitted.
    leg_stiffness : float or array_like, shape (6,), optional
        Axial stiffness of every leg [N/m], replacing spring + ``Kp`` (damping and the
        integral still come from ``isolator`` and ``controller``).
    frame : {"center_of_mass", "origin"} or array_like, shape (3,)
        The point the coordinates and matrices refer to: the centre of mass (default),
        the top frame origin (the cube's centre for :func:`cubic_geometry`) or a point in
        the top frame [m].
    include_preload : bool
        Include the geometric stiffness of the static leg forces and of the weight
        (nothing changes where ``platform.gravity`` is 0) [-].
    cartesian : CartesianController, optional
        Centralised control (docs/hexapod.md §9.5): the loops act on the platform's axes at
        the controller's point, ``T = J_c^-1 J`` from these coordinates to those axes, so
        they add ``T^T Kp T`` to the stiffness, ``T^T Kd HP(s) T s`` of damping and an
        integral per axis; the legs keep their springs and viscous friction
        (``leg_stiffness``, if given, replaces the springs only) and the legs' gains are not
        used. The legs' high-pass corners must then be equal (one filter per axis).

    Returns
    -------
    HexapodLinearModel
    """
    import control

    if not isinstance(geometry, HexapodGeometry):
        raise ParameterError(f"`geometry` must be a HexapodGeometry, got {geometry!r}.")
    if not isinstance(platform, PlatformParameters):
        raise ParameterError(f"`platform` must be a PlatformParameters, got {platform!r}.")
    if not isinstance(include_preload, (bool, np.bool_)):
        raise ParameterError(f"`include_preload` must be True or False, got {include_preload!r}.")
    isolators = _per_leg("isolator", IsolatorParameters() if isolator is None else isolator,
                         IsolatorParameters)
    controllers = _per_leg("controller",
                           ControllerParameters() if controller is None else controller,
                           ControllerParameters)
    refuse_blocks(controllers, "the six-axis linear model",
                  "simulate the platform instead (qzs.simulate_hexapod)")
    if cartesian is not None and not isinstance(cartesian, CartesianController):
        raise ParameterError(f"`cartesian` must be a CartesianController or None, got "
                             f"{type(cartesian).__name__}.")
    if leg_stiffness is None:
        loop = 0.0 if cartesian is not None else np.array([c.pi_kp for c in controllers])
        stiffness = np.array([float(spring_stiffness(c.position_setpoint, i))
                              for i, c in zip(isolators, controllers)]) + loop
    elif np.ndim(leg_stiffness) == 0:
        stiffness = np.full(LEG_COUNT, real("leg_stiffness", leg_stiffness))
    else:
        stiffness = np.array(leg_stiffness, dtype=float)
        if stiffness.shape != (LEG_COUNT,) or not np.all(np.isfinite(stiffness)):
            raise ParameterError(f"`leg_stiffness` must be a finite number or six of them "
                                 f"[N/m], got {leg_stiffness!r}.")
    damping = np.array([i.viscous_damping for i in isolators])
    integral = np.array([c.pi_ki for c in controllers])
    active = np.array([c.damping_gain for c in controllers])
    highpass = np.array([c.velocity_highpass for c in controllers])
    point = _frame_point(frame, platform)

    j = jacobian(geometry, point=point)
    mass = mass_matrix(platform, point)
    forces = static_leg_forces(geometry, platform)
    legs = j.T @ np.diag(stiffness) @ j
    loops = j  # from these coordinates to the loops' coordinates: leg lengths, or axes
    if cartesian is not None:
        if np.ptp(highpass) != 0:
            raise ParameterError(
                f"with `cartesian`, every leg's `velocity_highpass` must be the same (one "
                f"filter per axis), got {highpass.tolist()} Hz.")
        loops = np.linalg.solve(jacobian(geometry, point=cartesian.point_in_top_frame(platform)),
                                j)
        integral = np.array(cartesian.integral_gain)
        active = np.array(cartesian.damping_gain)
        highpass = np.full(LEG_COUNT, highpass[0])
        legs = legs + loops.T @ np.diag(cartesian.position_gain) @ loops
    if include_preload:
        geometric, geometric_base = geometric_stiffness(geometry, platform, point=point,
                                                        leg_forces=forces)
    else:
        geometric, geometric_base = np.zeros((6, 6)), np.zeros((6, 6))
    stiffness_matrix = legs + geometric
    base_matrix = -legs + geometric_base
    damping_matrix = j.T @ np.diag(damping) @ j
    active_matrix = loops.T @ np.diag(active) @ loops
    integral_matrix = loops.T @ np.diag(integral) @ loops

    eigenvalues, modes, frequencies, notes = _modes(stiffness_matrix, mass)
    system, compliance_system = _state_space(control, loops, mass, stiffness_matrix,
                                             base_matrix, damping_matrix, integral, active,
                                             highpass)
    poles = np.linalg.eigvals(system.A) if system.nstates else np.zeros(0)
    stable = bool(np.all(poles.real < 0))
    if not stable:
        worst = poles[np.argmax(poles.real)]
        notes += (f"the closed loop is not asymptotically stable: its pole {worst:.4g} rad/s "
                  "has a real part >= 0",)
    return HexapodLinearModel(
        frame_point=point, stiffness_matrix=stiffness_matrix, leg_stiffness_matrix=legs,
        geometric_stiffness_matrix=geometric, base_stiffness_matrix=base_matrix,
        damping_matrix=damping_matrix, active_damping_matrix=active_matrix,
        integral_matrix=integral_matrix, mass_matrix=mass, jacobian=j, leg_forces=forces,
        leg_stiffness=stiffness, leg_damping=damping, leg_integral_gain=integral,
        leg_damping_gain=active, leg_highpass=highpass, include_preload=bool(include_preload),
        eigenvalues=eigenvalues, natural_frequencies=frequencies, mode_shapes=modes,
        poles=poles, stable=stable, notes=notes, transmissibility_system=system,
        compliance_system=compliance_system, loop_matrix=loops,
        control="per leg" if cartesian is None else "centralised")


def _modes(stiffness, mass):
    """Undamped modes of ``K v = omega^2 M v``: eigenvalues, M-normalised shapes, [Hz], notes."""
    lower = np.linalg.cholesky(mass)
    inverse = np.linalg.inv(lower)
    reduced = inverse @ stiffness @ inverse.T
    eigenvalues, vectors = np.linalg.eigh(0.5 * (reduced + reduced.T))
    modes = inverse.T @ vectors
    for k in range(6):
        if modes[np.argmax(np.abs(modes[:, k])), k] < 0:
            modes[:, k] = -modes[:, k]
    threshold = _NEUTRAL * max(float(np.max(np.abs(eigenvalues))), 1e-300)
    frequencies = np.full(6, np.nan)
    notes = []
    for k, value in enumerate(eigenvalues):
        if value < -threshold:
            shape = ", ".join(f"{AXES[i]} {modes[i, k]:+.3g}" for i in range(6)
                              if abs(modes[i, k]) >= 0.1 * np.max(np.abs(modes[:, k])))
            notes.append(f"mode {k + 1} (of 6, lowest omega^2 first) is statically unstable: "
                         f"omega^2 = {value:.4g} rad^2/s^2 < 0 (negative stiffness along "
                         f"{shape}); its natural frequency is NaN")
        else:
            frequencies[k] = np.sqrt(max(value, 0.0)) / (2 * np.pi)
    return eigenvalues, modes, frequencies, tuple(notes)


def _state_space(control, j, mass, stiffness, base, damping, integral, active, highpass):
    """Transmissibility and compliance as state-space systems.

    States: ``q`` (6), ``p = M q' - C q_b`` (6), the integral ``I_i`` of each leg with
    ``Ki > 0`` and the high-pass state ``w_i`` of each leg with ``Kd > 0`` and a corner.
    """
    inverse_mass = np.linalg.inv(mass)
    with_integral = np.flatnonzero(integral > 0)
    with_highpass = np.flatnonzero((active > 0) & (highpass > 0))
    n_i, n_w = with_integral.size, with_highpass.size
    n = 12 + n_i + n_w
    select_i = np.eye(6)[with_integral]
    select_w = np.eye(6)[with_highpass]
    corner = np.diag(2 * np.pi * highpass[with_highpass])
    active_matrix = j.T @ np.diag(active) @ j
    a = np.zeros((n, n))
    b_base = np.zeros((n, 6))
    b_wrench = np.zeros((n, 6))
    q, p = slice(0, 6), slice(6, 12)
    i_s, w_s = slice(12, 12 + n_i), slice(12 + n_i, n)
    # q' = M^-1 p + M^-1 C q_b
    a[q, p] = inverse_mass
    b_base[q] = inverse_mass @ damping
    # p' = -K q - K_b q_b - (C + J^T Kd J) q' + J^T Kd S_w^T w + J^T Ki S_i^T I + wrench
    drag = damping + active_matrix
    a[p, q] = -stiffness
    a[p, p] = -drag @ inverse_mass
    b_base[p] = -base - drag @ inverse_mass @ damping
    a[p, i_s] = j.T @ np.diag(integral) @ select_i.T
    a[p, w_s] = j.T @ np.diag(active) @ select_w.T
    b_wrench[p] = np.eye(6)
    # I' = -S_i J (q - q_b)
    a[i_s, q] = -select_i @ j
    b_base[i_s] = select_i @ j
    # w' = W (S_w J q' - w)
    a[w_s, p] = corner @ select_w @ j @ inverse_mass
    a[w_s, w_s] = -corner
    b_base[w_s] = corner @ select_w @ j @ inverse_mass @ damping
    c = np.zeros((6, n))
    c[:, q] = np.eye(6)
    outputs = [f"platform_{axis}" for axis in AXES]
    states = ([f"q_{axis}" for axis in AXES] + [f"p_{axis}" for axis in AXES]
              + [f"integral_{i}" for i in with_integral] + [f"highpass_{i}" for i in with_highpass])
    transmissibility = control.ss(a, b_base, c, np.zeros((6, 6)), states=states, outputs=outputs,
                                  inputs=[f"base_{axis}" for axis in AXES])
    compliance = control.ss(a, b_wrench, c, np.zeros((6, 6)), states=states, outputs=outputs,
                            inputs=["force_x", "force_y", "force_z", "moment_x", "moment_y",
                                    "moment_z"])
    return transmissibility, compliance
