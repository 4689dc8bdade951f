"""Hexapod geometry, kinematics and statics (qzs.model.hexapod, docs/hexapod.md §1-4).

Checks against closed forms and independent constructions: rotations against the
elementary matrices, forward kinematics as the inverse of the inverse kinematics, the
Jacobians against finite differences of exactly composed motions, the cubic
configuration against the cube it is built from, the statics against a force balance
written from the leg vectors, the mass matrix against a cloud of point masses.
"""
import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.model.hexapod import (HexapodGeometry, PlatformParameters, angular_velocity_matrix,
                               base_jacobian, cubic_geometry, forward_kinematics,
                               inverse_kinematics, jacobian, leg_positions, leg_unit_vectors,
                               leg_vectors, mass_matrix, radial_geometry, rotation_angles,
                               rotation_matrix, static_leg_forces, stroke_check, weight_wrench)

EDGE = 0.15
GEOMETRIES = {
    "cubic_vertices": cubic_geometry(cube_edge=EDGE, cube_center_height=0.2),
    "cubic_radii": cubic_geometry(cube_edge=EDGE, cube_center_height=0.2, base_radius=0.16,
                                  top_radius=0.13),
    "radial": radial_geometry(base_radius=0.20, top_radius=0.12, base_angle=np.deg2rad(20),
                              top_angle=np.deg2rad(30), height=0.25),
}


def elementary(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    matrix = np.eye(3)
    matrix[i, i] = matrix[j, j] = c
    matrix[i, j], matrix[j, i] = -s, s
    return matrix


def rodrigues(rotation_vector):
    """exp([w]x) of a rotation vector [rad]."""
    angle = np.linalg.norm(rotation_vector)
    if angle == 0:
        return np.eye(3)
    k = rotation_vector / angle
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


def random_poses(seed, count=6, translation=0.02, angle=np.deg2rad(4)):
    rng = np.random.default_rng(seed)
    return [np.r_[rng.uniform(-translation, translation, 3), rng.uniform(-angle, angle, 3)]
            for _ in range(count)]


# ---------------------------------------------------------------- rotations
def test_rotation_matrix_is_rz_ry_rx_and_angles_invert_it():
    for angles in ([0.1, -0.2, 0.3], [-1.2, 0.7, 2.9], [0.0, 0.0, -3.0]):
        expected = elementary(2, angles[2]) @ elementary(1, angles[1]) @ elementary(0, angles[0])
        np.testing.assert_allclose(rotation_matrix(angles), expected, atol=1e-15)
        np.testing.assert_allclose(rotation_angles(expected), angles, atol=1e-14)


def test_angular_velocity_matrix_gives_the_base_frame_angular_velocity():
    angles, h = np.array([0.3, -0.4, 1.1]), 1e-6
    matrix = angular_velocity_matrix(angles)
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        rate = (rotation_matrix(angles + step) - rotation_matrix(angles - step)) / (2 * h)
        skew = rate @ rotation_matrix(angles).T  # dR/dt R^T = [w]x
        omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
        np.testing.assert_allclose(omega, matrix[:, k], atol=1e-9)


# ---------------------------------------------------------------- kinematics
@pytest.mark.parametrize("name", GEOMETRIES)
def test_forward_kinematics_inverts_inverse_kinematics(name, validation):
    geometry = GEOMETRIES[name]
    worst = 0.0
    for pose in random_poses(1):
        found = forward_kinematics(geometry, inverse_kinematics(geometry, pose))
        np.testing.assert_allclose(found, pose, rtol=0, atol=1e-12)
        worst = max(worst, float(np.max(np.abs(found - pose))))
    validation(f"Forward kinematics (Newton) after inverse kinematics, {name} geometry",
               "the pose itself (round trip)", worst, 1e-12,
               measure="largest pose error [m, rad]")


def test_inverse_kinematics_is_the_joint_distance():
    geometry = GEOMETRIES["radial"]
    pose = np.array([0.01, -0.02, 0.015, 0.05, -0.03, 0.08])
    top = geometry.home_position + pose[:3] + geometry.top_joints @ rotation_matrix(pose[3:]).T
    lengths = [np.sqrt(np.sum((t - b) ** 2)) for t, b in zip(top, geometry.base_joints)]
    np.testing.assert_allclose(inverse_kinematics(geometry, pose), lengths, rtol=1e-15)
    np.testing.assert_allclose(leg_vectors(geometry, pose), top - geometry.base_joints,
                               atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(leg_unit_vectors(geometry, pose), axis=1), 1.0)


def moved_pose(pose, twist, time):
    """The pose after moving with a constant twist for ``time`` [s], composed exactly."""
    rotation = rodrigues(np.asarray(twist[3:]) * time) @ rotation_matrix(pose[3:])
    return np.r_[pose[:3] + np.asarray(twist[:3]) * time, rotation_angles(rotation)]


@pytest.mark.parametrize("name", GEOMETRIES)
def test_jacobian_against_finite_differences(name):
    geometry, h = GEOMETRIES[name], 1e-6
    rng = np.random.default_rng(2)
    for pose in random_poses(3, count=4):
        twist = rng.normal(size=6) * np.r_[0.1, 0.1, 0.1, 1.0, 1.0, 1.0]
        rate = (inverse_kinematics(geometry, moved_pose(pose, twist, h))
                - inverse_kinematics(geometry, moved_pose(pose, twist, -h))) / (2 * h)
        np.testing.assert_allclose(jacobian(geometry, pose) @ twist, rate, rtol=0, atol=1e-8)
        # the twist of another platform point p: the origin moves at v_p - w x (R p)
        point = np.array([0.02, -0.05, 0.1])
        at_point = twist.copy()
        at_point[:3] = twist[:3] + np.cross(twist[3:], rotation_matrix(pose[3:]) @ point)
        np.testing.assert_allclose(jacobian(geometry, pose, point=point) @ at_point,
                                   jacobian(geometry, pose) @ twist, atol=1e-14)


@pytest.mark.parametrize("name", GEOMETRIES)
def test_base_jacobian_against_finite_differences(name):
    geometry, h = GEOMETRIES[name], 1e-6
    pose = np.array([0.01, 0.005, -0.01, 0.02, -0.03, 0.04])
    point = np.array([0.03, -0.01, 0.05])
    twist = np.array([0.05, -0.1, 0.08, 0.7, -0.4, 0.9])  # of the base point `point`

    def lengths(time):
        moved = (point + twist[:3] * time
                 + (geometry.base_joints - point) @ rodrigues(twist[3:] * time).T)
        base = HexapodGeometry(base_joints=moved, top_joints=geometry.top_joints,
                               home_position=geometry.home_position)
        return inverse_kinematics(base, pose)

    rate = (lengths(h) - lengths(-h)) / (2 * h)
    np.testing.assert_allclose(base_jacobian(geometry, pose, point=point) @ twist, rate,
                               rtol=0, atol=1e-8)


@pytest.mark.parametrize("name", GEOMETRIES)
def test_moving_base_and_platform_together_keeps_the_legs(name):
    geometry = GEOMETRIES[name]
    point = np.array([0.01, 0.02, -0.03])
    np.testing.assert_allclose(base_jacobian(geometry, point=geometry.home_position + point),
                               -jacobian(geometry, point=point), atol=1e-15)


# ---------------------------------------------------------------- generators
@pytest.mark.parametrize("name", ["cubic_vertices", "cubic_radii"])
def test_cubic_legs_lie_on_the_edges_of_a_cube(name):
    geometry = GEOMETRIES[name]
    units = leg_unit_vectors(geometry)
    # every leg rises at asin(1/sqrt(3)); the legs are orthogonal or parallel in pairs
    np.testing.assert_allclose(units[:, 2], 1 / np.sqrt(3), rtol=1e-14)
    products = np.abs(units @ units.T)
    assert np.all((np.abs(products) < 1e-14) | (np.abs(products - 1) < 1e-14))
    assert np.allclose(np.sum(products > 0.5, axis=1), 2)  # each axis carries two legs
    # each leg line is an edge line of the cube centred at the top frame origin: it passes
    # a/sqrt(2) from the centre, and its closest point is an edge midpoint m, a point of
    # the cube's frame (+-a/2 on two cube axes, 0 on the third)
    center = geometry.home_position
    cube_axes = np.unique(np.round(np.vstack([units, -units]), 12), axis=0)
    assert len(cube_axes) == 6
    for base, unit in zip(geometry.base_joints, units):
        offset = base - center
        middle = offset - (offset @ unit) * unit
        assert np.linalg.norm(middle) == pytest.approx(EDGE / np.sqrt(2), rel=1e-13)
        along = np.abs(units @ middle)
        assert np.allclose(np.unique(np.round(along, 12)), [0, EDGE / 2], atol=1e-12)


def test_cubic_joints_at_vertices_and_at_given_radii():
    vertices = GEOMETRIES["cubic_vertices"]
    np.testing.assert_allclose(vertices.home_lengths, EDGE, rtol=1e-14)
    radius = EDGE * np.sqrt(2 / 3)
    np.testing.assert_allclose(np.hypot(*vertices.base_joints[:, :2].T), radius, rtol=1e-14)
    np.testing.assert_allclose(vertices.top_joints[:, 2], EDGE / (2 * np.sqrt(3)), rtol=1e-14)
    azimuths = np.rad2deg(np.arctan2(vertices.base_joints[:, 1], vertices.base_joints[:, 0]))
    np.testing.assert_allclose(np.round(azimuths), [0, 0, 120, 120, -120, -120], atol=1e-9)
    radii = GEOMETRIES["cubic_radii"]
    np.testing.assert_allclose(np.hypot(*radii.base_joints[:, :2].T), 0.16, rtol=1e-14)
    np.testing.assert_allclose(np.hypot(*radii.top_joints[:, :2].T), 0.13, rtol=1e-14)
    # the same leg lines: moving joints along them keeps the unit vectors
    np.testing.assert_allclose(leg_unit_vectors(radii), leg_unit_vectors(vertices), atol=1e-14)
    # base joints below the centre, top joints above
    assert np.all(radii.base_joints[:, 2] < radii.home_position[2])
    assert np.all(radii.top_joints[:, 2] > 0)


def test_radial_geometry_places_joint_pairs_as_documented():
    alpha, beta = np.deg2rad(20), np.deg2rad(30)
    geometry = GEOMETRIES["radial"]
    base = np.rad2deg(np.arctan2(geometry.base_joints[:, 1], geometry.base_joints[:, 0]))
    top = np.rad2deg(np.arctan2(geometry.top_joints[:, 1], geometry.top_joints[:, 0]))
    a, b = np.rad2deg(alpha) / 2, np.rad2deg(beta) / 2
    expected_base = [-a, a, 120 - a, 120 + a, -120 - a, -120 + a]
    expected_top = [-60 + b, 60 - b, 60 + b, 180 - b, 180 + b, 300 - b]
    np.testing.assert_allclose(base, expected_base, atol=1e-12)
    np.testing.assert_allclose(np.mod(top, 360), np.mod(expected_top, 360), atol=1e-12)
    np.testing.assert_allclose(geometry.base_joints[:, 2], 0)
    np.testing.assert_allclose(geometry.home_position, [0, 0, 0.25])
    np.testing.assert_allclose(geometry.home_lengths, geometry.home_lengths[0], rtol=1e-14)


# ---------------------------------------------------------------- statics, mass, stroke
@pytest.mark.parametrize("name", GEOMETRIES)
def test_static_leg_forces_balance_the_weight(name):
    geometry = GEOMETRIES[name]
    platform = PlatformParameters(mass=12.0, inertia=np.diag([0.2, 0.3, 0.4]),
                                  center_of_mass=[0.02, -0.01, 0.06])
    pose = np.array([0.005, -0.01, 0.01, 0.03, -0.02, 0.05])
    forces = static_leg_forces(geometry, platform, pose)
    np.testing.assert_allclose(jacobian(geometry, pose).T @ forces,
                               weight_wrench(platform, pose), rtol=1e-12, atol=1e-12)
    # the same balance from the leg vectors: force, and moment about the centre of mass
    rotation = rotation_matrix(pose[3:])
    top = geometry.home_position + pose[:3] + geometry.top_joints @ rotation.T
    com = geometry.home_position + pose[:3] + rotation @ platform.center_of_mass
    units = leg_unit_vectors(geometry, pose)
    weight = np.array([0, 0, -platform.mass * platform.gravity])
    np.testing.assert_allclose(forces @ units + weight, 0, atol=1e-11)
    np.testing.assert_allclose(np.sum(np.cross(top - com, forces[:, None] * units), axis=0), 0,
                               atol=1e-12)


@pytest.mark.parametrize("name", GEOMETRIES)
def test_a_symmetric_platform_loads_every_leg_equally(name):
    geometry = GEOMETRIES[name]
    platform = PlatformParameters(mass=20.0, inertia=np.eye(3), center_of_mass=[0, 0, 0.07])
    forces = static_leg_forces(geometry, platform)
    rise = leg_unit_vectors(geometry)[0, 2]
    np.testing.assert_allclose(forces, platform.mass * platform.gravity / (6 * rise), rtol=1e-12)
    assert np.all(forces > 0)  # struts in compression push the platform up


def test_mass_matrix_is_that_of_a_cloud_of_point_masses():
    rng = np.random.default_rng(4)
    masses, points = rng.uniform(0.5, 2.0, 9), rng.normal(scale=0.1, size=(9, 3))
    total = masses.sum()
    center = masses @ points / total
    offsets = points - center
    inertia = sum(m * (r @ r * np.eye(3) - np.outer(r, r)) for m, r in zip(masses, offsets))
    platform = PlatformParameters(mass=total, inertia=inertia, center_of_mass=center)
    for point in (np.zeros(3), center, np.array([0.1, -0.2, 0.3])):
        expected = np.zeros((6, 6))
        for m, x in zip(masses, points):
            r = x - point  # particle velocity v + w x r = G @ twist
            g = np.hstack([np.eye(3), -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]],
                                                 [-r[1], r[0], 0]])])
            expected += m * g.T @ g
        np.testing.assert_allclose(mass_matrix(platform, point), expected, atol=1e-12)
    # parallel-axis terms explicitly: at a point r below the centre of mass
    r = center - np.array([0.1, -0.2, 0.3])
    lower = mass_matrix(platform, [0.1, -0.2, 0.3])[3:, 3:]
    assert lower[0, 0] == pytest.approx(inertia[0, 0] + total * (r[1] ** 2 + r[2] ** 2), rel=1e-12)
    assert lower[0, 1] == pytest.approx(inertia[0, 1] - total * r[0] * r[1], rel=1e-12)


def test_stroke_check_and_leg_positions_of_a_vertical_lift():
    geometry = GEOMETRIES["cubic_vertices"]  # legs of length a rising a/sqrt(3)
    horizontal, rise = EDGE * np.sqrt(2 / 3), EDGE / np.sqrt(3)
    limit = np.sqrt((EDGE + geometry.stroke_half) ** 2 - horizontal ** 2) - rise  # lift [m]
    for lift, outside in ((limit * (1 - 1e-9), False), (limit * (1 + 1e-9), True)):
        check = stroke_check(geometry, [0, 0, lift, 0, 0, 0])
        extension = np.sqrt(horizontal ** 2 + (rise + lift) ** 2) - EDGE
        np.testing.assert_allclose(check.extension, extension, rtol=1e-12)
        np.testing.assert_allclose(check.margin, geometry.stroke_half - extension, atol=1e-15)
        assert np.all(check.outside == outside) and check.within_stroke is not outside
        np.testing.assert_allclose(leg_positions(geometry, [0, 0, lift, 0, 0, 0], -0.06),
                                   extension - 0.06, rtol=1e-12)
    # stops centred 10 mm out: the lift that reaches the centred stops leaves 10 mm
    check = stroke_check(geometry, [0, 0, limit, 0, 0, 0], leg_offset=0.01)
    np.testing.assert_allclose(check.margin, 0.01, rtol=1e-9)
    np.testing.assert_allclose(leg_positions(geometry), -0.060)


# ---------------------------------------------------------------- bad inputs
def cube():
    return cubic_geometry(cube_edge=EDGE, cube_center_height=0.2)


@pytest.mark.parametrize("change, argument", [
    (dict(base_joints=np.zeros((5, 3))), "`base_joints`"),
    (dict(top_joints=[[0, 0, np.nan]] * 6), "`top_joints`"),
    (dict(home_position=[0, 0]), "`home_position`"),
    (dict(stroke_half=-0.01), "`stroke_half`"),
    (dict(base_joints="here"), "`base_joints`"),
])
def test_bad_geometry_names_the_argument(change, argument):
    g = cube()
    fields = {"base_joints": g.base_joints, "top_joints": g.top_joints,
              "home_position": g.home_position, **change}
    with pytest.raises(ParameterError, match=argument):
        HexapodGeometry(**fields)


def test_zero_length_and_singular_geometries_are_refused():
    g = cube()
    top = np.array(g.top_joints)
    top[3] = g.base_joints[3] - g.home_position
    with pytest.raises(ParameterError, match=r"leg 3 has zero length.*`top_joints\[3\]`"):
        HexapodGeometry(base_joints=g.base_joints, top_joints=top, home_position=g.home_position)
    base = np.array(g.top_joints) + [0, 0, 0.05]  # every leg vertical: no lateral stiffness
    with pytest.raises(ParameterError, match="singular"):
        HexapodGeometry(base_joints=base - [0, 0, 0.2], top_joints=g.top_joints,
                        home_position=[0, 0, 0.05])


@pytest.mark.parametrize("change, argument", [
    (dict(mass=-1.0), "`mass`"),
    (dict(inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "`inertia` must be symmetric"),
    (dict(inertia=np.diag([1.0, -1.0, 1.0])), "`inertia` must be positive definite"),
    (dict(inertia=np.eye(2)), "`inertia`"),
    (dict(center_of_mass=[0, 0, np.inf]), "`center_of_mass`"),
    (dict(gravity=-9.81), "`gravity`"),
])
def test_bad_platform_names_the_argument(change, argument):
    with pytest.raises(ParameterError, match=argument):
        PlatformParameters(**{"mass": 10.0, "inertia": np.eye(3), **change})


def test_bad_generator_and_kinematics_inputs_name_the_argument():
    with pytest.raises(ParameterError, match="`base_radius` must exceed"):
        cubic_geometry(cube_edge=0.1, cube_center_height=0.1, base_radius=0.05)
    with pytest.raises(ParameterError, match="`cube_edge`"):
        cubic_geometry(cube_edge=0.0, cube_center_height=0.1)
    with pytest.raises(ParameterError, match="`height`"):
        radial_geometry(base_radius=0.1, top_radius=0.1, base_angle=0.1, top_angle=0.1,
                        height=-0.1)
    g = cube()
    with pytest.raises(ParameterError, match="`pose`"):
        inverse_kinematics(g, [0, 0, 0])
    with pytest.raises(ParameterError, match="did not converge for `lengths`"):
        forward_kinematics(g, [0.1, 0.1, 0.1, 0.1, 0.1, 3.0])
    with pytest.raises(ParameterError, match="`lengths` must be positive"):
        forward_kinematics(g, [0.1, 0.1, 0.1, 0.1, 0.1, -0.1])
    with pytest.raises(ParameterError, match="`leg_offset`"):
        stroke_check(g, leg_offset=[0.0, 0.0])


def test_geometry_is_frozen_read_only_and_compares_by_value():
    g = cube()
    with pytest.raises(ValueError):
        g.base_joints[0, 0] = 1.0
    with pytest.raises(AttributeError):
        g.stroke_half = 0.1
    assert g == cube() and hash(g) == hash(cube())
    assert g != cubic_geometry(cube_edge=EDGE, cube_center_height=0.21)
