"""A six-leg Stewart platform (hexapod) of isolator legs: geometry, kinematics, statics.

Each leg is the single-axis isolator of docs/model.md (MagSpring, motor, guide) between a
joint on the base and a joint on the moving platform; this module holds what the
platform adds: where the joints are, how the leg lengths follow from the platform's pose
and back, the Jacobians, the platform's mass matrix and the static leg forces that carry
its weight. The conventions, frames and signs are those of docs/hexapod.md:

* **base frame** fixed to the base, ``z`` up, gravity along ``-z``;
* **top frame** fixed to the platform; at the home pose it is the base frame translated
  by ``home_position`` [m], not rotated;
* **pose** ``(x, y, z, rx, ry, rz)``: translation of the top frame origin from its home
  position [m] (base-frame components) and rotation angles [rad], the top frame's
  orientation being ``R = Rz(rz) @ Ry(ry) @ Rx(rx)`` (top-frame vectors to base-frame);
* **twist** ``(vx, vy, vz, wx, wy, wz)``: velocity of the top frame origin [m/s] and
  angular velocity [rad/s], both in base-frame components;
* leg ``i`` runs from base joint ``b_i`` to top joint ``a_i = o + R t_i``; its length is
  ``L_i = |a_i - b_i|``, its unit vector ``u_i = (a_i - b_i)/L_i`` points from base to
  platform; a leg force is positive when it pushes the platform away from the base.

Numpy only: no numba, no scipy.
"""
import math
from dataclasses import dataclass, fields

import numpy as np

from qzs._validation import (integer, non_negative_real, parameter, positive_real, real,
                             validate_fields)
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters

__all__ = ["HexapodGeometry", "PlatformParameters", "StrokeCheck", "LEG_COUNT",
           "cubic_geometry", "radial_geometry", "rotation_matrix", "rotation_angles",
           "angular_velocity_matrix", "leg_vectors", "leg_unit_vectors", "inverse_kinematics",
           "forward_kinematics", "jacobian", "base_jacobian", "stroke_check", "leg_positions",
           "mass_matrix", "weight_wrench", "static_leg_forces", "CartesianController",
           "platform_size"]

#: Number of legs of a hexapod [-].
LEG_COUNT = 6
#: Singular values of the home Jacobian (rotations scaled by the platform's size) below this
#: share of the largest make the geometry singular [-].
SINGULAR_TOLERANCE = 1e-9


# ---------------------------------------------------------------- argument checks
def _vector_array(name, value, shape, fix=""):
    """``value`` as a finite float array of ``shape``, or ParameterError naming ``name``."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"`{name}` must be an array of numbers of shape {shape}, got "
                             f"{value!r}.") from None
    if array.shape != shape:
        raise ParameterError(f"`{name}` must have shape {shape}, got shape {array.shape}"
                             f"{'; ' + fix if fix else ''}.")
    bad = ~np.isfinite(array)
    if np.any(bad):
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ParameterError(f"`{name}` must be finite, got {float(array[where])!r} at index "
                             f"{where}.")
    return array


def _read_only(array):
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _pose(pose, name="pose"):
    if pose is None:
        return np.zeros(LEG_COUNT)
    return _vector_array(name, pose, (6,), "a pose is (x, y, z, rx, ry, rz) [m, m, m, rad, rad, "
                                           "rad]")


def _per_leg(name, value):
    """A float or six floats as a (6,) array."""
    array = np.array(value, dtype=float) if np.ndim(value) else None
    if array is None:
        return np.full(LEG_COUNT, real(name, value))
    return _vector_array(name, value, (LEG_COUNT,), "give one number or one per leg")


def _skew(vector):
    """``[v]x``, the matrix of the cross product ``v x .``."""
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


class _ArrayFields:
    """Equality and hash by value for frozen dataclasses that hold numpy arrays."""

    def _values(self):
        return tuple(getattr(self, f.name) for f in fields(self))

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return all(np.array_equal(a, b) for a, b in zip(self._values(), other._values()))

    def __hash__(self):
        return hash(tuple(np.asarray(v, dtype=float).tobytes() for v in self._values()))


# ---------------------------------------------------------------- rotations
def rotation_matrix(angles):
    """Rotation matrix ``R = Rz(rz) @ Ry(ry) @ Rx(rx)`` of the pose angles.

    Parameters
    ----------
    angles : array_like, shape (3,)
        Rotation angles ``(rx, ry, rz)`` [rad] (a pose's last three entries).

    Returns
    -------
    ndarray, shape (3, 3)
        ``R`` [-]: top-frame components to base-frame components.
    """
    rx, ry, rz = _vector_array("angles", angles, (3,))
    cx, sx, cy, sy, cz, sz = (math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry),
                              math.cos(rz), math.sin(rz))
    return np.array([[cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
                     [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
                     [-sy, cy * sx, cy * cx]])


def rotation_angles(matrix):
    """The pose angles ``(rx, ry, rz)`` [rad] of a rotation matrix (inverse of ``rotation_matrix``).

    Parameters
    ----------
    matrix : array_like, shape (3, 3)
        A rotation matrix ``R = Rz(rz) @ Ry(ry) @ Rx(rx)`` [-].

    Returns
    -------
    ndarray, shape (3,)
        ``(rx, ry, rz)`` [rad], with ``ry`` in ``[-pi/2, pi/2]`` and ``rx``, ``rz`` in
        ``[-pi, pi]``; at ``|ry| = pi/2`` (gimbal lock) ``rz`` is set to 0.
    """
    r = _vector_array("matrix", matrix, (3, 3))
    cos_ry = math.hypot(r[0, 0], r[1, 0])
    ry = math.atan2(-r[2, 0], cos_ry)
    if cos_ry > 1e-12:
        return np.array([math.atan2(r[2, 1], r[2, 2]), ry, math.atan2(r[1, 0], r[0, 0])])
    return np.array([math.atan2(-r[1, 2], r[1, 1]), ry, 0.0])


def angular_velocity_matrix(angles):
    """The matrix ``E`` with ``omega = E @ (rx', ry', rz')`` for ``R = Rz Ry Rx``.

    Its columns are the axes of the three elementary rotations in the base frame:
    ``Rz Ry e_x``, ``Rz e_y``, ``e_z``.

    Parameters
    ----------
    angles : array_like, shape (3,)
        Rotation angles ``(rx, ry, rz)`` [rad].

    Returns
    -------
    ndarray, shape (3, 3)
        ``E`` [-]: rates of the angles [rad/s] to angular velocity in the base frame [rad/s].
    """
    _, ry, rz = _vector_array("angles", angles, (3,))
    cy, sy, cz, sz = math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    return np.array([[cz * cy, -sz, 0.0], [sz * cy, cz, 0.0], [-sy, 0.0, 1.0]])


# ---------------------------------------------------------------- geometry
@dataclass(frozen=True, kw_only=True, eq=False)
class HexapodGeometry(_ArrayFields):
    """Joint positions of a six-leg Stewart platform (docs/hexapod.md §1).

    Leg ``i`` joins base joint ``base_joints[i]`` to top joint ``top_joints[i]``.
    Arrays are stored as read-only float arrays.

    Parameters
    ----------
    base_joints : array_like, shape (6, 3)
        Base joint positions ``b_i`` in the base frame [m] (``z`` up).
    top_joints : array_like, shape (6, 3)
        Top joint positions ``t_i`` in the top (platform) frame [m].
    home_position : array_like, shape (3,)
        Position of the top frame origin at the home pose, in the base frame [m]; the
        top frame is not rotated at home.
    stroke_half : float
        Half the stroke of each leg's guide [m]: a leg may lengthen or shorten by this
        much from its home length (default 0.080, as the single axis).

    Raises
    ------
    ParameterError
        On a wrong shape or a non-finite value, a leg of zero length at home, or a
        singular Jacobian at home (legs that cannot hold the platform in all six
        directions).
    """

    base_joints: np.ndarray = parameter(unit="m", doc="base joint positions, base frame")
    top_joints: np.ndarray = parameter(unit="m", doc="top joint positions, top frame")
    home_position: np.ndarray = parameter(unit="m", doc="top frame origin at home, base frame")
    stroke_half: float = parameter(0.080, "m", "half stroke of each leg's guide")

    def __post_init__(self):
        for name, shape in (("base_joints", (LEG_COUNT, 3)), ("top_joints", (LEG_COUNT, 3)),
                            ("home_position", (3,))):
            object.__setattr__(self, name, _read_only(_vector_array(
                name, getattr(self, name), shape,
                "one row (x, y, z) per leg" if shape[0] == LEG_COUNT else "")))
        validate_fields(self, {"stroke_half": positive_real})
        vectors = leg_vectors(self)
        lengths = np.linalg.norm(vectors, axis=1)
        scale = max(float(np.max(np.abs(self.base_joints))),
                    float(np.max(np.abs(self.top_joints))),
                    float(np.max(np.abs(self.home_position))), 1e-300)
        short = np.flatnonzero(lengths <= 1e-12 * scale)
        if short.size:
            i = int(short[0])
            raise ParameterError(
                f"leg {i} has zero length at home: its top joint `top_joints[{i}]` "
                f"{self.top_joints[i].tolist()} placed at `home_position` "
                f"{self.home_position.tolist()} falls on its base joint `base_joints[{i}]` "
                f"{self.base_joints[i].tolist()} [m]; move one of them.")
        object.__setattr__(self, "_home_lengths", _read_only(lengths))
        matrix = jacobian(self)
        length = _platform_size(self)
        scaled = matrix * np.r_[1.0, 1.0, 1.0, 1.0 / length, 1.0 / length, 1.0 / length]
        values = np.linalg.svd(scaled, compute_uv=False)
        if not values[-1] > SINGULAR_TOLERANCE * values[0]:
            raise ParameterError(
                "the hexapod is singular at home: its Jacobian (from `base_joints`, "
                "`top_joints` and `home_position`) has rank below 6 (smallest singular value "
                f"{values[-1] / values[0]:.3g} of the largest, rotations scaled by "
                f"{length:.3g} m), so the legs cannot hold the platform in every direction "
                "(e.g. all legs parallel, or meeting in one point); spread the joints.")

    @property
    def home_lengths(self):
        """Leg lengths ``L_i,home`` at the home pose [m], shape (6,)."""
        return self._home_lengths


def platform_size(geometry):
    """The length [m] that makes a rotation comparable with a translation.

    The top joints' RMS distance from their centroid (what :class:`HexapodGeometry` scales
    its Jacobian's rotation columns by), or the mean leg length if the joints coincide: a
    rotation of ``theta`` [rad] moves the joints by about ``theta * platform_size``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform.

    Returns
    -------
    float
        [m].
    """
    spread = np.sqrt(np.mean(np.sum((geometry.top_joints - geometry.top_joints.mean(axis=0)) ** 2,
                                    axis=1)))
    return float(spread) if spread > 0 else float(np.mean(geometry.home_lengths))


_platform_size = platform_size


def cubic_geometry(*, cube_edge, cube_center_height, base_radius=None, top_radius=None,
                   stroke_half=0.080):
    """Preumont's cubic configuration: six legs on six edges of a cube standing on a vertex.

    The cube's body diagonal is vertical and its centre is at ``(0, 0,
    cube_center_height)`` in the base frame. Its eight vertices are the bottom and top
    vertices on the diagonal, three lower vertices at height ``-a/(2*sqrt(3))`` and
    azimuths 0, 120, 240 [deg] and three upper vertices at ``+a/(2*sqrt(3))`` and
    azimuths 60, 180, 300 [deg] (``a = cube_edge``), all at radius ``a*sqrt(2/3)`` from
    the vertical axis through the centre. The legs are the six edges joining a lower to
    an upper vertex, a zig-zag around the cube: leg ``2k`` runs from the lower vertex at
    ``120k`` [deg] to the upper vertex at ``120k - 60``, leg ``2k + 1`` to the one at
    ``120k + 60``. They point along the three cube axes, each axis carrying two legs on
    opposite sides of the centre, so the legs are mutually orthogonal in pairs; every
    leg rises at ``asin(1/sqrt(3))`` = 35.26 [deg].

    The **top frame origin is the cube's centre** (``home_position = (0, 0,
    cube_center_height)``), where the stiffness matrix of equal legs is diagonal,
    ``k*diag(2, 2, 2, a^2/2, a^2/2, 2*a^2)`` (docs/hexapod.md §5).

    Joints: without radii at the cube's vertices (each vertex shared by two legs). With
    ``base_radius`` the base joint of each leg is the point of the leg's line below the
    cube's centre at that horizontal distance from the vertical axis through the centre;
    likewise the top joint above the centre at ``top_radius``. A leg line passes closest
    to the axis at its edge's midpoint, at distance ``a/sqrt(2)`` and the centre's
    height; at parameter ``s`` along the leg from there it is at distance
    ``sqrt(a^2/2 + 2 s^2/3)`` and height ``s/sqrt(3)``. The leg lines, hence the
    stiffness at the centre, do not depend on the radii.

    Parameters
    ----------
    cube_edge : float
        Edge of the cube, ``a`` [m].
    cube_center_height : float
        Height of the cube's centre (the top frame origin at home) above the base frame
        origin [m].
    base_radius : float, optional
        Horizontal distance of the base joints from the vertical axis through the cube's
        centre [m]; must exceed ``cube_edge/sqrt(2)``. Default: the cube's lower
        vertices, ``cube_edge*sqrt(2/3)``.
    top_radius : float, optional
        The same for the top joints [m]; default the upper vertices.
    stroke_half : float
        Half the stroke of each leg's guide [m].

    Returns
    -------
    HexapodGeometry
    """
    a = positive_real("cube_edge", cube_edge)
    height = real("cube_center_height", cube_center_height)
    # cube frame -> base orientation: the diagonal (1, 1, 1) up, lower vertex (1, -1, -1) at 0 deg
    orientation = np.array([[2.0, -1.0, -1.0], [0.0, 1.0, -1.0], [1.0, 1.0, 1.0]])
    orientation /= np.linalg.norm(orientation, axis=1, keepdims=True)
    lower = [(1, -1, -1), (-1, 1, -1), (-1, -1, 1)]       # azimuths 0, 120, 240 deg
    upper = [(-1, 1, 1), (1, -1, 1), (1, 1, -1)]          # azimuths 180, 300, 60 deg
    pairs = [(0, 1), (0, 2), (1, 2), (1, 0), (2, 0), (2, 1)]  # (lower, upper) per leg
    starts = np.array([orientation @ (0.5 * a * np.array(lower[i], float)) for i, _ in pairs])
    ends = np.array([orientation @ (0.5 * a * np.array(upper[j], float)) for _, j in pairs])
    middles, directions = 0.5 * (starts + ends), (ends - starts) / a

    def joints(radius, name, sign, default):
        if radius is None:
            return default
        r = positive_real(name, radius)
        closest = a / np.sqrt(2.0)
        if r <= closest:
            raise ParameterError(
                f"`{name}` must exceed `cube_edge`/sqrt(2) = {closest!r} m, the distance of "
                f"the leg lines from the cube's vertical axis at their closest, got {r!r} m; "
                f"omit it to put the joints on the cube's vertices (radius "
                f"{a * np.sqrt(2.0 / 3.0)!r} m).")
        s = sign * np.sqrt(1.5 * (r * r - 0.5 * a * a))
        return middles + s * directions

    base = joints(base_radius, "base_radius", -1.0, starts)
    top = joints(top_radius, "top_radius", 1.0, ends)
    center = np.array([0.0, 0.0, height])
    return HexapodGeometry(base_joints=base + center, top_joints=top, home_position=center,
                           stroke_half=stroke_half)


def radial_geometry(*, base_radius, top_radius, base_angle, top_angle, height,
                    stroke_half=0.080):
    """The usual Stewart platform: joints in pairs on two circles, the top rotated by 60 deg.

    Base joints lie in the base frame's ``z = 0`` plane on a circle of ``base_radius``
    about the origin, top joints in the top frame's ``z = 0`` plane on a circle of
    ``top_radius``; the top frame origin is ``height`` above the base origin at home.
    Base joint pairs are centred at azimuths ``phi_k`` = 0, 120, 240 [deg] and top pairs
    at ``phi_k + 60``:

    * leg ``2k`` joins the base joint at ``phi_k - base_angle/2`` to the top joint at
      ``phi_k - 60 + top_angle/2``;
    * leg ``2k + 1`` joins ``phi_k + base_angle/2`` to ``phi_k + 60 - top_angle/2``.

    So each base pair's legs lean apart to the two neighbouring top pairs. Zero angles
    give an octahedral (3-3) platform; negative angles make the legs of a pair cross
    (a cubic configuration with joints off the vertices is of this kind).

    Parameters
    ----------
    base_radius : float
        Radius of the base joints' circle [m].
    top_radius : float
        Radius of the top joints' circle [m].
    base_angle : float
        Angle between the two base joints of a pair, seen from the centre [rad].
    top_angle : float
        Angle between the two top joints of a pair [rad].
    height : float
        Height of the top frame origin (the top joints' plane) above the base joints'
        plane at home [m].
    stroke_half : float
        Half the stroke of each leg's guide [m].

    Returns
    -------
    HexapodGeometry
    """
    rb, rt = positive_real("base_radius", base_radius), positive_real("top_radius", top_radius)
    alpha, beta = real("base_angle", base_angle), real("top_angle", top_angle)
    h = positive_real("height", height)
    base, top = [], []
    for leg in range(LEG_COUNT):
        phi = np.deg2rad(120.0) * (leg // 2)
        sign = 1.0 if leg % 2 else -1.0
        b = phi + sign * alpha / 2
        t = phi + sign * (np.pi / 3 - beta / 2)
        base.append([rb * np.cos(b), rb * np.sin(b), 0.0])
        top.append([rt * np.cos(t), rt * np.sin(t), 0.0])
    return HexapodGeometry(base_joints=base, top_joints=top, home_position=[0.0, 0.0, h],
                           stroke_half=stroke_half)


# ---------------------------------------------------------------- kinematics
def _top_arms(geometry, pose):
    """``R t_i`` (6, 3) [m] and the top joints ``a_i`` in the base frame (6, 3) [m]."""
    arms = geometry.top_joints @ rotation_matrix(pose[3:]).T
    return arms, geometry.home_position + pose[:3] + arms


def leg_vectors(geometry, pose=None):
    """Leg vectors ``a_i - b_i`` from base joint to top joint, in the base frame [m].

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.

    Returns
    -------
    ndarray, shape (6, 3)
        One row per leg [m].
    """
    _, joints = _top_arms(geometry, _pose(pose))
    return joints - geometry.base_joints


def leg_unit_vectors(geometry, pose=None):
    """Unit vectors ``u_i`` of the legs, from base joint to top joint, in the base frame.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.

    Returns
    -------
    ndarray, shape (6, 3)
        One unit row per leg [-].
    """
    vectors = leg_vectors(geometry, pose)
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


def inverse_kinematics(geometry, pose=None):
    """Leg lengths of a pose, in closed form: ``L_i = |o + R t_i - b_i|``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.

    Returns
    -------
    ndarray, shape (6,)
        Leg lengths, joint to joint [m].
    """
    return np.linalg.norm(leg_vectors(geometry, pose), axis=1)


def jacobian(geometry, pose=None, *, point=None):
    """The Jacobian ``J`` from the platform's twist to the leg length rates, ``L' = J @ twist``.

    Row ``i`` is ``[u_i, (R (t_i - p)) x u_i]``: a velocity ``v`` of the platform point
    ``p`` and an angular velocity ``w`` lengthen leg ``i`` at ``u_i . (v + w x R(t_i - p))``.
    By virtual work ``J.T @ f`` is the wrench (force [N], moment about ``p`` [N*m]) that
    leg forces ``f`` [N] (positive pushing the platform away) exert on the platform.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.
    point : array_like, shape (3,), optional
        The platform point ``p`` whose velocity the twist gives, in the top frame [m];
        default the top frame origin (the twist of the pose convention).

    Returns
    -------
    ndarray, shape (6, 6)
        ``J``: columns 0-2 [m/m], columns 3-5 [m/rad].
    """
    pose = _pose(pose)
    point = np.zeros(3) if point is None else _vector_array("point", point, (3,))
    arms, joints = _top_arms(geometry, pose)
    vectors = joints - geometry.base_joints
    units = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    arms = arms - rotation_matrix(pose[3:]) @ point
    return np.hstack([units, np.cross(arms, units)])


def base_jacobian(geometry, pose=None, *, point=None):
    """The Jacobian from the base's own twist to the leg length rates.

    A base moving with velocity ``v`` of the base point ``c`` and angular velocity
    ``w`` moves base joint ``i`` at ``v + w x (b_i - c)``, which shortens leg ``i`` at
    ``u_i`` times that: row ``i`` is ``[-u_i, -((b_i - c) x u_i)]``. When the base and
    the platform move as one rigid body (same twist about the same point) the legs keep
    their lengths: at the home pose ``base_jacobian(g, point=home_position + p) ==
    -jacobian(g, point=p)``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        The platform's pose ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad] relative
        to the base; default the home pose.
    point : array_like, shape (3,), optional
        The base point ``c`` whose velocity the base twist gives, in the base frame [m];
        default the base frame origin.

    Returns
    -------
    ndarray, shape (6, 6)
        Columns 0-2 [m/m], columns 3-5 [m/rad].
    """
    point = np.zeros(3) if point is None else _vector_array("point", point, (3,))
    units = leg_unit_vectors(geometry, pose)
    return -np.hstack([units, np.cross(geometry.base_joints - point, units)])


def forward_kinematics(geometry, lengths, *, guess=None, tolerance=1e-13, max_iterations=50):
    """The pose of given leg lengths, by Newton's method on the inverse kinematics.

    Each step solves ``(J E) d = L(pose) - lengths`` for the pose correction, with
    ``J`` the Jacobian at the current pose and ``E`` mapping angle rates to angular
    velocity (:func:`angular_velocity_matrix`). A hexapod has several poses of the same
    lengths; the one found is the one Newton's method reaches from ``guess``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    lengths : array_like, shape (6,)
        Leg lengths, joint to joint [m].
    guess : array_like, shape (6,), optional
        Starting pose [m, m, m, rad, rad, rad]; default the home pose.
    tolerance : float
        Largest leg length residual accepted [m].
    max_iterations : int
        Newton steps allowed [-].

    Returns
    -------
    ndarray, shape (6,)
        The pose ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad].

    Raises
    ------
    ParameterError
        If the iteration does not reach ``tolerance`` within ``max_iterations``, meets a
        singular Jacobian or diverges: the lengths may be unreachable, or ``guess`` too far.
    """
    target = _vector_array("lengths", lengths, (LEG_COUNT,))
    if np.any(target <= 0):
        raise ParameterError(f"`lengths` must be positive, got {target.tolist()} m.")
    pose = _pose(guess, "guess").copy()
    tolerance = positive_real("tolerance", tolerance)
    max_iterations = integer("max_iterations", max_iterations, 1)
    residual = inverse_kinematics(geometry, pose) - target
    reason = None
    for _ in range(max_iterations):
        if np.max(np.abs(residual)) <= tolerance:
            return pose
        derivative = jacobian(geometry, pose).copy()
        derivative[:, 3:] = derivative[:, 3:] @ angular_velocity_matrix(pose[3:])
        try:
            pose = pose - np.linalg.solve(derivative, residual)
        except np.linalg.LinAlgError:
            reason = f"the Jacobian became singular at pose {pose.tolist()}"
            break
        residual = inverse_kinematics(geometry, pose) - target
        if not np.all(np.isfinite(residual)):
            reason = "the iteration diverged"
            break
    else:
        if np.max(np.abs(residual)) <= tolerance:
            return pose
        reason = (f"after {max_iterations} Newton steps the largest leg length residual is "
                  f"{float(np.max(np.abs(residual))):.3g} m (`tolerance` {tolerance:g} m)")
    raise ParameterError(
        f"forward kinematics did not converge for `lengths` {target.tolist()} m: {reason}. "
        "The lengths may be unreachable (no pose has them), or `guess` too far from the "
        "pose sought; give a nearer `guess`, or raise `max_iterations` or `tolerance`.")


def stroke_check(geometry, pose=None, *, leg_offset=0.0):
    """Which legs a pose drives beyond their guide's stroke.

    Leg ``i``'s stroke is centred at the extension ``leg_offset[i]`` from its home
    length and reaches ``stroke_half`` either side: it is outside when
    ``|L_i - L_i,home - leg_offset[i]| > stroke_half``. With the single axis's
    defaults (stops centred on the setpoint, which the home pose puts each leg at) the
    offset is 0; stops centred at ``stop_center`` give ``stop_center -
    position_setpoint``.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints and ``stroke_half``.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.
    leg_offset : float or array_like, shape (6,)
        Extension at the centre of each leg's stroke [m].

    Returns
    -------
    StrokeCheck
    """
    offset = _per_leg("leg_offset", leg_offset)
    extension = inverse_kinematics(geometry, pose) - geometry.home_lengths
    margin = geometry.stroke_half - np.abs(extension - offset)
    return StrokeCheck(extension=_read_only(extension), margin=_read_only(margin),
                       outside=np.asarray(margin < 0))


@dataclass(frozen=True, kw_only=True, eq=False)
class StrokeCheck:
    """Legs against their stroke at one pose (:func:`stroke_check`).

    Attributes
    ----------
    extension : ndarray, shape (6,)
        ``L_i - L_i,home`` [m]: positive when a leg is longer than at home.
    margin : ndarray, shape (6,)
        Distance from each leg's nearer stop [m]; negative beyond it.
    outside : ndarray of bool, shape (6,)
        True for the legs beyond a stop [-].
    """

    extension: np.ndarray
    margin: np.ndarray
    outside: np.ndarray

    @property
    def within_stroke(self):
        """True if every leg is within its stroke [-]."""
        return not bool(np.any(self.outside))


def leg_positions(geometry, pose=None, setpoint=None):
    """Each leg's relative position ``z_i = (L_i - L_i,home) + z_ref`` [m] (its encoder).

    The home pose puts every leg at the controller's setpoint ``z_ref``; a leg longer
    than at home has its payload side further out, ``z`` larger (docs/hexapod.md §3).

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.
    setpoint : float or array_like, shape (6,), optional
        Each leg's position setpoint ``z_ref`` [m]; default
        ``ControllerParameters().position_setpoint`` (-0.060).

    Returns
    -------
    ndarray, shape (6,)
        Relative positions ``z_i`` [m].
    """
    setpoint = ControllerParameters().position_setpoint if setpoint is None else setpoint
    return inverse_kinematics(geometry, pose) - geometry.home_lengths + _per_leg("setpoint",
                                                                                 setpoint)


# ---------------------------------------------------------------- the platform
@dataclass(frozen=True, kw_only=True, eq=False)
class PlatformParameters(_ArrayFields):
    """The moving platform with its payload: one rigid body.

    Parameters
    ----------
    mass : float
        Mass of the platform, payload and every part moving with them [kg].
    inertia : array_like, shape (3, 3)
        Inertia tensor about the centre of mass, in top-frame components [kg*m^2];
        symmetric positive definite.
    center_of_mass : array_like, shape (3,)
        Centre of mass in the top frame [m]; default the top frame origin.
    gravity : float
        Gravitational acceleration, along ``-z`` of the base frame [m/s^2]; 0 for none.
    """

    mass: float = parameter(unit="kg", doc="mass of platform and payload")
    inertia: np.ndarray = parameter(unit="kg*m^2", doc="inertia about the centre of mass")
    center_of_mass: np.ndarray = parameter((0.0, 0.0, 0.0), "m", "centre of mass, top frame")
    gravity: float = parameter(9.81, "m/s^2", "gravitational acceleration g")

    def __post_init__(self):
        validate_fields(self, {"mass": positive_real, "gravity": non_negative_real})
        inertia = _vector_array("inertia", self.inertia, (3, 3))
        scale = float(np.max(np.abs(inertia)))
        if not np.allclose(inertia, inertia.T, rtol=0.0, atol=1e-12 * scale):
            raise ParameterError(f"`inertia` must be symmetric, got {inertia.tolist()} kg*m^2.")
        inertia = 0.5 * (inertia + inertia.T)
        if scale == 0 or np.linalg.eigvalsh(inertia)[0] <= 1e-12 * scale:
            raise ParameterError(
                f"`inertia` must be positive definite, got {inertia.tolist()} kg*m^2 with "
                f"principal moments {np.linalg.eigvalsh(inertia).tolist()}; a rigid body has "
                "positive moments about every axis.")
        object.__setattr__(self, "inertia", _read_only(inertia))
        object.__setattr__(self, "center_of_mass", _read_only(
            _vector_array("center_of_mass", self.center_of_mass, (3,))))


def mass_matrix(platform, point=None):
    """The 6x6 spatial mass matrix of the platform, expressed at a platform point.

    With the twist taken at point ``p`` and ``r = center_of_mass - p``, the kinetic
    energy is ``0.5 * twist @ M @ twist`` with (home orientation, top = base axes)::

        M = [[ m I,       -m [r]x                  ],
             [ m [r]x,    I_c + m (|r|^2 I - r r^T) ]]

    the lower right block the parallel-axis theorem, ``[r]x`` the cross-product matrix.

    Parameters
    ----------
    platform : PlatformParameters
        Mass, inertia and centre of mass.
    point : array_like, shape (3,), optional
        The reference point ``p`` in the top frame [m]; default the top frame origin.

    Returns
    -------
    ndarray, shape (6, 6)
        Blocks [kg], [kg*m], [kg*m^2].
    """
    point = np.zeros(3) if point is None else _vector_array("point", point, (3,))
    r = platform.center_of_mass - point
    m, cross = platform.mass, _skew(r)
    return np.block([[m * np.eye(3), -m * cross],
                     [m * cross, platform.inertia + m * (r @ r * np.eye(3) - np.outer(r, r))]])


def weight_wrench(platform, pose=None, *, point=None):
    """The wrench the legs must supply to hold the platform's weight, at a platform point.

    ``W = (F, (R (c - p)) x F)``, ``F = (0, 0, m g)``: the force [N] and the moment
    about the point [N*m] that balance gravity acting at the centre of mass ``c``.

    Parameters
    ----------
    platform : PlatformParameters
        Mass, centre of mass and gravity.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.
    point : array_like, shape (3,), optional
        The point ``p`` in the top frame [m]; default the top frame origin.

    Returns
    -------
    ndarray, shape (6,)
        Force [N] and moment [N*m], base-frame components.
    """
    pose = _pose(pose)
    point = np.zeros(3) if point is None else _vector_array("point", point, (3,))
    force = np.array([0.0, 0.0, platform.mass * platform.gravity])
    arm = rotation_matrix(pose[3:]) @ (platform.center_of_mass - point)
    return np.concatenate([force, np.cross(arm, force)])


def static_leg_forces(geometry, platform, pose=None):
    """Axial leg forces [N] that hold the platform's weight: the solution of ``J.T f = W``.

    ``W`` is :func:`weight_wrench` at the top frame origin (the moment of a centre of
    mass off the origin included), ``J`` the Jacobian at the pose. Positive forces push
    the platform away from the base (a strut in compression). In each leg the MagSpring
    supplies ``-a tanh(b z_ref)`` of it and the PI integral the rest.

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform's joints.
    platform : PlatformParameters
        Mass, centre of mass and gravity.
    pose : array_like, shape (6,), optional
        ``(x, y, z, rx, ry, rz)`` [m, m, m, rad, rad, rad]; default the home pose.

    Returns
    -------
    ndarray, shape (6,)
        Leg forces [N].
    """
    pose = _pose(pose)
    return np.linalg.solve(jacobian(geometry, pose).T, weight_wrench(platform, pose))


# ---------------------------------------------------------------- centralised control
_GAIN_UNITS = {"position_gain": "N/m, N*m/rad",
               "integral_gain": "N/(m*s), N*m/(rad*s)",
               "damping_gain": "N*s/m, N*m*s/rad"}


@dataclass(frozen=True, kw_only=True, eq=False)
class CartesianController(_ArrayFields):
    """Centralised control: the legs' PI and damping loops run on the platform's six axes.

    The legs' sensors are mapped to the platform's axes at the home pose,
    ``e = J^-1 (z_ref - z)`` and ``v = J^-1 v_meas`` (``J`` the Jacobian at ``point``, so
    ``e`` is the small displacement of that point [m] and the rotation [rad]); each axis
    ``j`` runs ``F_j = Kp_j e_j + Ki_j I_j - Kd_j v_j`` with ``I_j' = e_j``; the wrench goes
    back to the legs as ``f = J^-T F``, each leg saturated at its motor's limit
    (docs/hexapod.md §9.5). Diagonal gains in the frame of ``point``; with
    ``K = J^T diag(k) J`` diagonal (the cubic configuration at the cube's centre, equal
    legs) it is the decentralised loop exactly.

    Parameters
    ----------
    position_gain : array_like, shape (6,)
        ``Kp`` per axis, x, y, z then rx, ry, rz [N/m, N*m/rad].
    integral_gain : array_like, shape (6,)
        ``Ki`` per axis [N/(m*s), N*m/(rad*s)].
    damping_gain : array_like, shape (6,)
        ``Kd`` per axis, on the absolute velocity the legs' accelerometers measure
        [N*s/m, N*m*s/rad].
    point : {"origin", "center_of_mass"} or array_like, shape (3,)
        Where the axes are: the top frame origin (the cube's centre of a cubic geometry),
        the payload's centre of mass, or a point in the top frame [m].
    """

    position_gain: np.ndarray = parameter(unit=_GAIN_UNITS["position_gain"],
                                          doc="proportional gain per axis")
    integral_gain: np.ndarray = parameter(unit=_GAIN_UNITS["integral_gain"],
                                          doc="integral gain per axis")
    damping_gain: np.ndarray = parameter(unit=_GAIN_UNITS["damping_gain"],
                                         doc="active damping gain per axis")
    point: object = parameter("origin", "m", "the point the axes are taken at (top frame)")

    def __post_init__(self):
        for name in ("position_gain", "integral_gain", "damping_gain"):
            value = _vector_array(name, getattr(self, name), (6,))
            if np.any(value < 0):
                raise ParameterError(
                    f"`{name}` must be non-negative on every axis [{_GAIN_UNITS[name]}], got "
                    f"{value.tolist()}.")
            object.__setattr__(self, name, _read_only(value))
        if isinstance(self.point, str):
            if self.point not in ("origin", "center_of_mass"):
                raise ParameterError(
                    f"`point` must be 'origin', 'center_of_mass' or a point in the top frame "
                    f"[m], got {self.point!r}.")
        else:
            object.__setattr__(self, "point", _read_only(_vector_array("point", self.point,
                                                                       (3,))))

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        if isinstance(self.point, str) or isinstance(other.point, str):
            if not (isinstance(self.point, str) and isinstance(other.point, str)
                    and self.point == other.point):
                return False
        elif not np.array_equal(self.point, other.point):
            return False
        return all(np.array_equal(getattr(self, n), getattr(other, n))
                   for n in ("position_gain", "integral_gain", "damping_gain"))

    def __hash__(self):
        point = self.point if isinstance(self.point, str) else self.point.tobytes()
        return hash((self.position_gain.tobytes(), self.integral_gain.tobytes(),
                     self.damping_gain.tobytes(), point))

    def point_in_top_frame(self, platform):
        """The point the axes are taken at, in the top frame [m].

        Parameters
        ----------
        platform : PlatformParameters
            Gives the centre of mass for ``point="center_of_mass"``.

        Returns
        -------
        ndarray, shape (3,)
        """
        if isinstance(self.point, str):
            return np.zeros(3) if self.point == "origin" else np.array(platform.center_of_mass)
        return np.array(self.point)

    @classmethod
    def from_legs(cls, geometry, controller=None, *, platform=None, point="origin"):
        """The Cartesian loops with the decentralised loops' stiffness on each axis.

        Each gain is the diagonal of ``J^T diag(k) J`` at ``point`` (``k`` the legs' gain):
        what the per-leg loops give the platform's axes when the legs are decoupled there.

        Parameters
        ----------
        geometry : HexapodGeometry
            The platform's joints.
        controller : ControllerParameters or sequence of six, optional
            The legs' loops (``pi_kp``, ``pi_ki``, ``damping_gain``); defaults if omitted.
        platform : PlatformParameters, optional
            Needed for ``point="center_of_mass"``.
        point : {"origin", "center_of_mass"} or array_like, shape (3,)
            As for the class.

        Returns
        -------
        CartesianController
        """
        if not isinstance(geometry, HexapodGeometry):
            raise ParameterError(f"`geometry` must be a HexapodGeometry, got "
                                 f"{type(geometry).__name__}.")
        controllers = ControllerParameters() if controller is None else controller
        if isinstance(controllers, ControllerParameters):
            controllers = (controllers,) * LEG_COUNT
        if not (isinstance(controllers, (list, tuple)) and len(controllers) == LEG_COUNT
                and all(isinstance(c, ControllerParameters) for c in controllers)):
            raise ParameterError(f"`controller` must be a ControllerParameters or a sequence of "
                                 f"six, got {controller!r}.")
        if point == "center_of_mass" and not isinstance(platform, PlatformParameters):
            raise ParameterError("`platform` (a PlatformParameters) is needed for "
                                 "point='center_of_mass'.")
        probe = cls(position_gain=np.zeros(6), integral_gain=np.zeros(6),
                    damping_gain=np.zeros(6), point=point)
        j = jacobian(geometry, point=probe.point_in_top_frame(platform))

        def diagonal(name):
            gains = np.array([getattr(c, name) for c in controllers])
            return np.einsum("ij,i,ij->j", j, gains, j)

        return cls(position_gain=diagonal("pi_kp"), integral_gain=diagonal("pi_ki"),
                   damping_gain=diagonal("damping_gain"), point=point)
