"""Linear analysis of the hexapod (qzs.analysis.hexapod_linear, docs/hexapod.md §5-6).

Closed forms and independent references: the cubic configuration's published stiffness
diagonal, its change of reference point, the geometric stiffness against finite
differences of the exact nonlinear wrench, the rigid-body limits of the base coupling,
the single-axis :func:`qzs.analysis.linear.linearize` where the modes decouple, the
state-space systems against the direct frequency response.
"""
import numpy as np
import pytest

from qzs.analysis.hexapod_linear import (geometric_stiffness, hexapod_linearize,
                                         off_diagonal_coupling)
from qzs.analysis.linear import linearize
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.hexapod import (PlatformParameters, cubic_geometry, mass_matrix, radial_geometry,
                               rotation_matrix)
from qzs.model.isolator import IsolatorParameters, spring_force, spring_stiffness

EDGE = 0.15
CUBE = cubic_geometry(cube_edge=EDGE, cube_center_height=0.2, base_radius=0.16, top_radius=0.13)
RADIAL = radial_geometry(base_radius=0.20, top_radius=0.12, base_angle=np.deg2rad(20),
                         top_angle=np.deg2rad(30), height=0.25)
OFFSET = PlatformParameters(mass=21.0, inertia=[[0.30, 0.01, 0.0], [0.01, 0.35, 0.02],
                                                [0.0, 0.02, 0.5]],
                            center_of_mass=[0.01, -0.02, 0.05])
STIFF = 3000.0  # [N/m]: legs stiff enough to carry the preload's negative stiffness


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def shift(point):
    """``X`` with ``q_P = X q_O``: pose coordinates at ``point`` from those at the origin."""
    x = np.eye(6)
    x[:3, 3:] = -skew(point)
    return x


# ---------------------------------------------------------------- stiffness
@pytest.mark.parametrize("radii", [(None, None), (0.16, 0.13), (0.2, 0.11)])
def test_cubic_stiffness_at_the_cube_centre_is_the_published_diagonal(radii, validation):
    geometry = cubic_geometry(cube_edge=EDGE, cube_center_height=0.2, base_radius=radii[0],
                              top_radius=radii[1])
    k, a = 1234.5, EDGE
    model = hexapod_linearize(geometry, OFFSET, leg_stiffness=k, frame="origin",
                              include_preload=False)
    expected = k * np.diag([2, 2, 2, a ** 2 / 2, a ** 2 / 2, 2 * a ** 2])
    np.testing.assert_allclose(model.stiffness_matrix, expected, rtol=0, atol=1e-12 * k)
    np.testing.assert_allclose(model.geometric_stiffness_matrix, 0)
    np.testing.assert_allclose(model.base_stiffness_matrix, -expected, atol=1e-12 * k)
    validation(f"Cubic hexapod stiffness at the cube's centre, joint radii {radii}",
               "k diag(2, 2, 2, a^2/2, a^2/2, 2 a^2) (cubic configuration, Preumont)",
               np.max(np.abs(model.stiffness_matrix - expected)) / k, 1e-12,
               measure="largest |K - closed form| / k")


def test_cubic_stiffness_off_the_centre_couples_translation_and_rotation():
    k, a, h = 800.0, EDGE, 0.07
    model = hexapod_linearize(CUBE, OFFSET, leg_stiffness=k, frame=[0, 0, h],
                              include_preload=False)
    # K_P = X^-T K_centre X^-1 with X = shift(p), p = (0, 0, h)
    expected = k * np.array([
        [2, 0, 0, 0, -2 * h, 0],
        [0, 2, 0, 2 * h, 0, 0],
        [0, 0, 2, 0, 0, 0],
        [0, 2 * h, 0, a ** 2 / 2 + 2 * h ** 2, 0, 0],
        [-2 * h, 0, 0, 0, a ** 2 / 2 + 2 * h ** 2, 0],
        [0, 0, 0, 0, 0, 2 * a ** 2]])
    np.testing.assert_allclose(model.stiffness_matrix, expected, rtol=0, atol=1e-12 * k)
    assert off_diagonal_coupling(model.stiffness_matrix) > 0.1


@pytest.mark.parametrize("geometry", [CUBE, RADIAL], ids=["cubic", "radial"])
def test_leg_frame_stiffness_without_preload_is_the_legs_own(geometry):
    k = np.array([100.0, 200.0, 300.0, 400.0, 500.0, 600.0])
    model = hexapod_linearize(geometry, OFFSET, leg_stiffness=k, include_preload=False)
    np.testing.assert_allclose(model.stiffness_in_leg_frame, np.diag(k), atol=1e-9)
    np.testing.assert_allclose(model.damping_in_leg_frame,
                               np.diag(model.leg_damping), atol=1e-9)
    assert model.decoupling()["stiffness_in_leg_frame"] < 1e-12


def nonlinear_wrench(geometry, platform, point, forces, stiffness, q, q_base):
    """Exact wrench on the platform (force, moment about the displaced point) [N, N*m].

    ``q``: the platform's displacement at ``point`` (translation, ZYX angles); ``q_base``:
    the base's, rotating about the same point's home position. Legs: linear springs of
    stiffness ``stiffness`` preloaded with ``forces`` at their home lengths.
    """
    home = geometry.home_position + point
    rotation, base_rotation = rotation_matrix(q[3:]), rotation_matrix(q_base[3:])
    moved = home + q[:3]
    top = moved + (geometry.top_joints - point) @ rotation.T
    base = home + q_base[:3] + (geometry.base_joints - home) @ base_rotation.T
    vectors = top - base
    lengths = np.linalg.norm(vectors, axis=1)
    units = vectors / lengths[:, None]
    leg = forces - stiffness * (lengths - geometry.home_lengths)
    weight = np.array([0, 0, -platform.mass * platform.gravity])
    force = leg @ units + weight
    moment = (np.sum(np.cross(top - moved, leg[:, None] * units), axis=0)
              + np.cross(rotation @ (platform.center_of_mass - point), weight))
    return np.r_[force, moment]


@pytest.mark.parametrize("geometry, frame", [(CUBE, "center_of_mass"), (RADIAL, "origin"),
                                             (RADIAL, (0.03, 0.02, -0.04))],
                         ids=["cubic-com", "radial-origin", "radial-point"])
def test_stiffness_with_preload_against_the_exact_nonlinear_wrench(geometry, frame, validation):
    """Both the platform and the base stiffness, geometric terms included."""
    k = np.array([900.0, 1100.0, 1000.0, 1200.0, 950.0, 1050.0])
    model = hexapod_linearize(geometry, OFFSET, leg_stiffness=k, frame=frame)
    point, forces = model.frame_point, model.leg_forces
    zero = np.zeros(6)
    np.testing.assert_allclose(
        nonlinear_wrench(geometry, OFFSET, point, forces, k, zero, zero), 0, atol=1e-12)
    h = 1e-6

    def wrench(q, q_base):
        return nonlinear_wrench(geometry, OFFSET, point, forces, k, q, q_base)

    platform_fd, base_fd = np.zeros((6, 6)), np.zeros((6, 6))
    for i in range(6):
        e = np.zeros(6)
        e[i] = h
        platform_fd[:, i] = -(wrench(e, zero) - wrench(-e, zero)) / (2 * h)
        base_fd[:, i] = -(wrench(zero, e) - wrench(zero, -e)) / (2 * h)
    scale = np.max(np.abs(model.stiffness_matrix))
    np.testing.assert_allclose(model.stiffness_matrix, platform_fd, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(model.base_stiffness_matrix, base_fd, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(model.stiffness_matrix, model.stiffness_matrix.T,
                               atol=1e-12 * scale)
    assert np.max(np.abs(model.geometric_stiffness_matrix)) > 1e-3 * scale  # not vacuous
    validation(f"Hexapod stiffness with preload ({'cubic' if geometry is CUBE else 'radial'}, "
               f"frame {frame})", "central differences of the exact nonlinear wrench",
               np.max(np.abs(model.stiffness_matrix - platform_fd)) / scale, 1e-8,
               measure="largest |K - finite differences| / largest |K|")


def test_base_coupling_in_the_rigid_body_limits():
    """Base and platform displaced together: a translation changes nothing; a tilt turns
    the leg forces with the base while the weight stays vertical."""
    model = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF)
    together = model.stiffness_matrix + model.base_stiffness_matrix
    np.testing.assert_allclose(together[:, :3], 0, atol=1e-9)
    weight = np.array([0, 0, OFFSET.mass * OFFSET.gravity])
    arm = OFFSET.center_of_mass - model.frame_point
    np.testing.assert_allclose(together[:3, 3:], skew(weight), atol=1e-9)
    np.testing.assert_allclose(together[3:, 3:], skew(arm) @ skew(weight), atol=1e-9)


def test_preload_of_compressed_legs_is_a_negative_stiffness_of_order_f_over_l():
    """Cubic legs at the vertices with equal forces f: K_g = -(4 f/a) I in translation.

    A leg pushing with f turns with its line at -f/L per unit of lateral motion of its
    top joint; summed, ``-(f/a) (6 I - sum u u^T) = -(f/a)(6 - 2) I``. Unlike the legs'
    axial stiffness, the preload couples translation and tilt at the cube's centre (its
    rotational terms depend on where the joints sit on the lines), but not the vertical.
    """
    geometry = cubic_geometry(cube_edge=EDGE, cube_center_height=0.2)
    platform = PlatformParameters(mass=20.0, inertia=0.3 * np.eye(3))
    model = hexapod_linearize(geometry, platform, leg_stiffness=STIFF, frame="origin")
    f = platform.mass * platform.gravity * np.sqrt(3) / 6
    np.testing.assert_allclose(model.leg_forces, f, rtol=1e-13)
    geometric = model.geometric_stiffness_matrix
    np.testing.assert_allclose(geometric[:3, :3], -4 * f / EDGE * np.eye(3), atol=1e-9)
    np.testing.assert_allclose(geometric[2, 3:], 0, atol=1e-9)
    # the vertical is a mode with omega^2 = (2 k - 4 f/a)/m
    vertical = (2 * STIFF - 4 * f / EDGE) / platform.mass
    index = np.flatnonzero(np.isclose(model.eigenvalues, vertical, rtol=1e-10))
    assert index.size == 1
    shape = model.mode_shapes[:, index[0]]
    np.testing.assert_allclose(np.abs(shape) / np.max(np.abs(shape)), np.eye(6)[2], atol=1e-9)
    # zero gravity: no preload, nothing to add
    weightless = PlatformParameters(mass=20.0, inertia=0.3 * np.eye(3), gravity=0.0)
    np.testing.assert_allclose(geometric_stiffness(geometry, weightless)[0], 0)


def test_cubic_static_stability_threshold_is_three_f_over_a(validation):
    """Joints at the vertices, centre of mass at the cube's centre, equal legs: the
    horizontal translation couples with the tilt through the preload, ``K_g[x, ry] =
    -m g/2 = -sqrt(3) f`` (no preload term in tilt itself), and
    ``det [[2 k - 4 f/a, -sqrt(3) f], [-sqrt(3) f, k a^2/2]] = (k a - 3 f)(k a + f)``
    vanishes at ``k = 3 f/a``, whatever the inertia."""
    geometry = cubic_geometry(cube_edge=EDGE, cube_center_height=0.2)
    platform = PlatformParameters(mass=20.0, inertia=np.diag([0.2, 0.3, 0.4]))
    f = platform.mass * platform.gravity * np.sqrt(3) / 6
    coupling = hexapod_linearize(geometry, platform, leg_stiffness=1.0,
                                 frame="origin").geometric_stiffness_matrix[0, 4]
    np.testing.assert_allclose(coupling, -np.sqrt(3) * f, rtol=1e-12)
    validation("Preload coupling of translation and tilt, cubic hexapod",
               "K_g[x, ry] = -sqrt(3) f (stability threshold k = 3 f/a)",
               abs(coupling / (-np.sqrt(3) * f) - 1), 1e-12)
    np.testing.assert_allclose(geometric_stiffness(geometry, platform)[0][3:, 3:], 0,
                               atol=1e-12)
    for factor, stable in ((1 - 1e-6, False), (1 + 1e-6, True)):
        model = hexapod_linearize(geometry, platform, leg_stiffness=factor * 3 * f / EDGE)
        assert bool(model.eigenvalues.min() > 0) is stable
        assert bool(np.all(np.isfinite(model.natural_frequencies))) is stable


def test_paper_legs_carrying_their_spring_load_are_unstable_and_say_so():
    """Six paper legs (1.6 N/m + Kp) holding the payload their MagSprings carry."""
    geometry = cubic_geometry(cube_edge=EDGE, cube_center_height=0.2)
    isolator, controller = IsolatorParameters(), ControllerParameters()
    f = float(spring_force(controller.position_setpoint, isolator))
    platform = PlatformParameters(mass=6 * f / (np.sqrt(3) * 9.81), inertia=0.3 * np.eye(3))
    model = hexapod_linearize(geometry, platform, isolator, controller, frame="origin")
    np.testing.assert_allclose(model.leg_forces, f, rtol=1e-12)
    k = float(spring_stiffness(controller.position_setpoint, isolator)) + controller.pi_kp
    np.testing.assert_allclose(model.leg_stiffness, k)
    assert np.all(np.diag(model.stiffness_matrix)[:3] < 0)
    assert np.all(np.isnan(model.natural_frequencies[:3])) and not model.stable
    assert sum("statically unstable" in note for note in model.notes) >= 3
    assert any("not asymptotically stable" in note for note in model.notes)
    # without the preload the same legs are stable
    plain = hexapod_linearize(geometry, platform, isolator, controller, include_preload=False)
    assert plain.stable and np.all(np.isfinite(plain.natural_frequencies))


# ---------------------------------------------------------------- frames and modes
def test_the_frame_changes_coordinates_not_physics():
    at_origin = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF, frame="origin")
    at_com = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF)
    np.testing.assert_allclose(at_com.natural_frequencies, at_origin.natural_frequencies,
                               rtol=1e-10)
    x = shift(OFFSET.center_of_mass)
    inverse = np.linalg.inv(x)
    for name in ("stiffness_matrix", "base_stiffness_matrix", "damping_matrix", "mass_matrix"):
        np.testing.assert_allclose(getattr(at_com, name),
                                   inverse.T @ getattr(at_origin, name) @ inverse,
                                   atol=1e-10 * np.max(np.abs(getattr(at_origin, name))))
    np.testing.assert_allclose(at_com.mass_matrix, mass_matrix(OFFSET, OFFSET.center_of_mass))
    f = np.array([0.3, 2.0, 15.0])
    np.testing.assert_allclose(at_com.transmissibility(f),
                               x @ at_origin.transmissibility(f) @ inverse, atol=1e-10)
    # the mass at the centre of mass is block diagonal
    np.testing.assert_allclose(at_com.mass_matrix[:3, 3:], 0, atol=1e-15)


def test_modes_solve_the_generalised_eigenproblem():
    model = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF)
    k, m, v = model.stiffness_matrix, model.mass_matrix, model.mode_shapes
    np.testing.assert_allclose(v.T @ m @ v, np.eye(6), atol=1e-10)
    np.testing.assert_allclose(v.T @ k @ v, np.diag(model.eigenvalues),
                               atol=1e-9 * np.max(np.abs(model.eigenvalues)))
    np.testing.assert_allclose(model.natural_frequencies,
                               np.sqrt(model.eigenvalues) / (2 * np.pi), rtol=1e-14)
    assert model.stable and model.notes == ()


# ---------------------------------------------------------------- dynamic responses
def test_state_space_systems_match_the_direct_responses():
    import control

    controller = ControllerParameters(damping_gain=40.0, pi_ki=15.0)
    model = hexapod_linearize(CUBE, OFFSET, controller=controller, leg_stiffness=STIFF)
    f = np.logspace(-2, 2, 9)
    for system, direct in ((model.transmissibility_system, model.transmissibility(f)),
                           (model.compliance_system, model.compliance(f))):
        response = control.frequency_response(system, 2 * np.pi * f)
        np.testing.assert_allclose(np.moveaxis(response.frdata, -1, 0), direct,
                                   rtol=1e-9, atol=1e-12 * np.max(np.abs(direct)))
    assert model.transmissibility_system.nstates == 12 + 6 + 6  # q, p, integrals, high-passes
    np.testing.assert_allclose(np.sort(model.poles.real)[-1] < 0, True)


def test_transmissibility_tends_to_identity_at_low_frequency_with_the_integral():
    model = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF)
    np.testing.assert_allclose(model.transmissibility(0.0), np.eye(6), atol=1e-12)
    # T - I vanishes in proportion to the frequency
    errors = [np.max(np.abs(model.transmissibility(f) - np.eye(6))) for f in (1e-6, 1e-7)]
    assert errors[1] < 1e-4 and errors[0] / errors[1] == pytest.approx(10, rel=1e-3)
    # compliance: the integral holds the pose against a static wrench
    np.testing.assert_allclose(model.compliance(0.0), 0, atol=1e-15)


def test_static_response_without_the_integral():
    controller = ControllerParameters(pi_ki=0.0)
    model = hexapod_linearize(RADIAL, OFFSET, controller=controller, leg_stiffness=STIFF)
    static = -np.linalg.solve(model.stiffness_matrix, model.base_stiffness_matrix)
    np.testing.assert_allclose(model.transmissibility(0.0), static, atol=1e-12)
    np.testing.assert_allclose(static[:, :3], np.eye(6)[:, :3], atol=1e-12)  # base translation
    assert np.max(np.abs(static[:, 3:] - np.eye(6)[:, 3:])) > 1e-3  # a tilt moves the load
    np.testing.assert_allclose(model.compliance(0.0), np.linalg.inv(model.stiffness_matrix),
                               rtol=1e-10)
    plain = hexapod_linearize(RADIAL, OFFSET, controller=controller, leg_stiffness=STIFF,
                              include_preload=False)
    np.testing.assert_allclose(plain.transmissibility(0.0), np.eye(6), atol=1e-12)


def test_high_frequency_roll_off_is_the_viscous_one():
    """Far above the modes ``T -> M^-1 C / s``: -20 dB/decade as the single axis."""
    model = hexapod_linearize(RADIAL, OFFSET, leg_stiffness=STIFF)
    f = 1e4
    s = 2j * np.pi * f
    np.testing.assert_allclose(s * model.transmissibility(f),
                               np.linalg.solve(model.mass_matrix, model.damping_matrix),
                               rtol=0, atol=2e-3 * np.max(np.abs(np.linalg.solve(
                                   model.mass_matrix, model.damping_matrix))))
    ratio = model.transmissibility(10 * f, magnitude=True) / model.transmissibility(
        f, magnitude=True)
    big = model.transmissibility(f, magnitude=True) > 1e-3 * np.max(
        model.transmissibility(f, magnitude=True))
    np.testing.assert_allclose(ratio[big], 0.1, rtol=2e-3)


@pytest.mark.parametrize("controller", [
    ControllerParameters(),
    ControllerParameters(pi_kp=10.0, pi_ki=0.0, damping_gain=30.0),
    ControllerParameters(pi_kp=80.0, pi_ki=5.0, damping_gain=60.0, velocity_highpass=0.0),
], ids=["default", "damping", "no-highpass"])
def test_decoupled_axes_are_single_axis_isolators(controller, validation):
    """Cubic, centre of mass at the cube centre, isotropic inertia, no preload: every
    matrix is ``kappa_j * (per-leg value)`` on the diagonal with ``kappa = (2, 2, 2,
    a^2/2, a^2/2, 2 a^2)``, so axis ``j`` is the single-axis isolator of mass
    ``M_jj/kappa_j``: ``m/2`` in translation, ``2 I/a^2`` in tilt, ``I/(2 a^2)`` about z."""
    mass, inertia, a = 20.0, 0.25, EDGE
    platform = PlatformParameters(mass=mass, inertia=inertia * np.eye(3))
    isolator = IsolatorParameters(viscous_damping=60.0)
    model = hexapod_linearize(CUBE, platform, isolator, controller, include_preload=False)
    assert max(model.decoupling()[name] for name in ("stiffness", "mass", "damping")) < 1e-12
    f = np.logspace(-2, 1.5, 25)
    response = model.transmissibility(f)
    kappa = np.array([2, 2, 2, a ** 2 / 2, a ** 2 / 2, 2 * a ** 2])
    worst = 0.0
    for j in range(6):
        equivalent = IsolatorParameters(mass=model.mass_matrix[j, j] / kappa[j],
                                        viscous_damping=60.0)
        single = linearize(equivalent, controller)
        expected = single.transfer_function(2j * np.pi * f)
        np.testing.assert_allclose(response[:, j, j], expected, rtol=1e-9)
        worst = max(worst, float(np.max(np.abs(response[:, j, j] / expected - 1))))
        off = np.delete(response[:, j, :], j, axis=1)
        assert np.max(np.abs(off)) < 1e-12
    assert model.mass_matrix[2, 2] / kappa[2] == mass / 2
    # and the undamped frequencies are the single axis's
    expected = [linearize(IsolatorParameters(mass=model.mass_matrix[j, j] / kappa[j]),
                          controller).undamped_natural_frequency for j in range(6)]
    np.testing.assert_allclose(model.natural_frequencies, np.sort(expected), rtol=1e-12)
    validation(f"Decoupled cubic hexapod axes as single-axis isolators ({controller})",
               "the single axis's linearize with mass M_jj/kappa_j", worst, 1e-9)


# ---------------------------------------------------------------- inputs and helpers
def test_each_leg_s_stiffness_is_its_own_spring_law_s_slope():
    """Legs with their own laws (docs/model.md §3.1): each leg's axial stiffness is its law's
    ``-dF/dz`` at the setpoint (a central difference of the law's force, an independent
    reference) plus its ``Kp``; the stiffness matrix is ``J^T diag(k) J``."""
    from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring

    laws = [None, ObliqueSpringQZS(), PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -2e5),
                                                       center=-0.05),
            TabulatedSpring.from_law(ObliqueSpringQZS(vertical_stiffness=500.0),
                                     np.linspace(-0.15, 0.03, 38)), None,  # z_ref mid-piece
            ObliqueSpringQZS.quasi_zero()]
    isolators = [IsolatorParameters(spring=law) for law in laws]
    controller = ControllerParameters(pi_kp=40.0)
    model = hexapod_linearize(CUBE, OFFSET, isolators, controller, include_preload=False)
    z, h = controller.position_setpoint, 1e-6
    slopes = np.array([-(spring_force(z + h, i) - spring_force(z - h, i)) / (2 * h)
                       for i in isolators])
    assert np.ptp(slopes) > 100.0  # N/m: the legs differ
    np.testing.assert_allclose(model.leg_stiffness, slopes + 40.0, rtol=1e-7, atol=1e-6)
    np.testing.assert_allclose(model.leg_stiffness_matrix,
                               model.jacobian.T @ np.diag(slopes + 40.0) @ model.jacobian,
                               rtol=1e-6, atol=1e-6)


def test_per_leg_parameters_and_override():
    isolators = [IsolatorParameters(viscous_damping=10.0 * (i + 1)) for i in range(6)]
    controllers = [ControllerParameters(pi_kp=5.0 * i) for i in range(6)]
    model = hexapod_linearize(CUBE, OFFSET, isolators, controllers, include_preload=False)
    spring = float(spring_stiffness(-0.060, IsolatorParameters()))
    np.testing.assert_allclose(model.leg_stiffness, spring + 5.0 * np.arange(6))
    np.testing.assert_allclose(model.leg_damping, 10.0 * np.arange(1, 7))
    np.testing.assert_allclose(model.damping_in_leg_frame, np.diag(model.leg_damping),
                               atol=1e-10)
    override = hexapod_linearize(CUBE, OFFSET, isolators, controllers, leg_stiffness=77.0)
    np.testing.assert_allclose(override.leg_stiffness, 77.0)


def test_off_diagonal_coupling():
    assert off_diagonal_coupling(np.diag([1.0, 4.0, 9.0])) == 0.0
    assert off_diagonal_coupling([[4.0, 1.0], [1.0, 1.0]]) == pytest.approx(0.5)
    assert off_diagonal_coupling([[1.0, 1.0], [1.0, 1.0]]) == pytest.approx(1.0)
    # free of units: scaling a coordinate changes nothing
    scale = np.diag([1.0, 1e3])
    assert off_diagonal_coupling(scale @ [[4.0, 1.0], [1.0, 1.0]] @ scale) == pytest.approx(0.5)


@pytest.mark.parametrize("keywords, argument", [
    (dict(frame="top"), "`frame`"),
    (dict(frame=[0.0, 0.0]), "`frame`"),
    (dict(isolator=[IsolatorParameters()] * 5), "`isolator`"),
    (dict(controller="fast"), "`controller`"),
    (dict(leg_stiffness=[1.0, 2.0]), "`leg_stiffness`"),
    (dict(leg_stiffness=np.nan), "`leg_stiffness`"),
    (dict(include_preload="yes"), "`include_preload`"),
    (dict(platform=IsolatorParameters()), "`platform`"),
    (dict(geometry="cube"), "`geometry`"),
])
def test_bad_inputs_name_the_argument(keywords, argument):
    arguments = {"geometry": CUBE, "platform": OFFSET, **keywords}
    with pytest.raises(ParameterError, match=argument):
        hexapod_linearize(**arguments)


def test_bad_frequency_names_the_argument():
    model = hexapod_linearize(CUBE, OFFSET, leg_stiffness=STIFF)
    with pytest.raises(ParameterError, match="`frequency`"):
        model.transmissibility(-1.0)
