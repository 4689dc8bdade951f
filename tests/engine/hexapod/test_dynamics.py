"""The six-leg platform's dynamics (qzs.engine.hexapod, docs/hexapod.md "Dynamics").

Reference checks, each able to fail: a platform locked by huge stiction moves with the base to
rounding; a symmetric platform under vertical base motion neither tilts nor drifts sideways;
small-signal motion matches the linear 6x6 transmissibility of ``hexapod_linearize``; the
energy ledger closes at the integrator's order; legs stay within their stops' contact bound;
six vertical legs reduce exactly to the single axis, stick-slip events included; bad inputs
are refused before any integration. Runs are a few seconds long.

The legs are the paper's (Table 1) except where a test says otherwise. Six QZS legs carrying
their preload on spherical joints are statically unstable with the paper's ``Kp`` of 50 N/m
(docs/hexapod.md §6), so the platforms here run ``Kp`` = 2000 N/m, ``Ki`` = 800 N/(m*s), a
stable loop for the cubic geometry below (natural frequencies 1.8 to 4.3 Hz).
"""
import re

import numpy as np
import pytest
from helpers import vertical_legs

from qzs import (Chirp, ControllerParameters, DisplacementRecord, IsolatorParameters,
                 ParameterError, Sine, StabilityError, simulate)
from qzs.analysis.hexapod_linear import hexapod_linearize
from qzs.engine.hexapod import AXES, HEXAPOD_CHANNELS, HexapodResult, simulate_hexapod
from qzs.model.hexapod import (CartesianController, PlatformParameters,
                               cubic_geometry, jacobian, static_leg_forces)

STABLE = ControllerParameters(pi_kp=2000.0, pi_ki=800.0)
#: Every leg carries about the single axis's load: 22.17 kg on six cubic legs (62.8 N each).
MASS = 22.17


@pytest.fixture(scope="module")
def cubic():
    """The cube of edge 0.3 m standing on a vertex, its centre 0.3 m up (legs 0.3 m long)."""
    return cubic_geometry(cube_edge=0.3, cube_center_height=0.3)


def symmetric_platform():
    """Centre of mass on the vertical axis (at the cube's centre), diagonal inertia."""
    return PlatformParameters(mass=MASS, inertia=np.diag([0.3, 0.3, 0.5]))


def skewed_platform():
    """Centre of mass off the axis, a full inertia tensor: nothing decouples."""
    return PlatformParameters(mass=MASS, inertia=[[0.3, 0.01, 0.0], [0.01, 0.35, 0.02],
                                                  [0.0, 0.02, 0.5]],
                              center_of_mass=[0.01, -0.02, 0.05])


def base_motion(axis, fade_in=0.2):
    """A sine in one axis: 10 mm in translation, 0.05 rad in rotation."""
    i = AXES.index(axis)
    return Sine(amplitude=0.01 if i < 3 else 0.05, frequency=2.0 + 0.7 * i, fade_in=fade_in)


# ---------------------------------------------------------------- locked by stiction
@pytest.mark.parametrize("axes", [(axis,) for axis in AXES] + [AXES])
def test_huge_stiction_carries_the_platform_with_the_base(cubic, axes):
    """Fs = 1e6 N: every leg stays locked, the platform's pose is the base's to rounding.

    The base pose is the displacement of the base point under the top frame origin at home
    and the base's rotation, so a platform carried rigidly has exactly the base's pose; each
    leg's position stays at the setpoint exactly (its slip velocity is held at 0).
    """
    isolator = IsolatorParameters(stiction_force=1e6)
    result = simulate_hexapod(cubic, skewed_platform(), isolator, STABLE,
                              excitation={axis: base_motion(axis) for axis in axes},
                              duration=1.0)
    assert result["locked"].all()
    assert result.run["events"] == 0
    assert np.max(np.abs(result["base_pose"])) > 4e-3  # the base did move
    assert np.max(np.abs(result["platform_pose"] - result["base_pose"])) < 1e-15
    assert np.max(np.abs(result["platform_acceleration"] - result["base_acceleration"])) < 1e-12
    assert np.all(result["relative_position"] == STABLE.position_setpoint)


# ---------------------------------------------------------------- symmetry
@pytest.mark.parametrize("isolator, bound", [
    (IsolatorParameters(stiction_force=5.0, coulomb_force=5.0), 1e-12),
    (IsolatorParameters(), 1e-9),
])
def test_vertical_base_motion_of_a_symmetric_platform_stays_vertical(cubic, isolator, bound):
    """A 120-degree symmetric platform under a z chirp: no tilt, no sideways motion.

    Stick-slip included: legs that act alike lock, break away and re-lock together (whatever
    the rounding decides first), so with Coulomb friction the six legs stay identical and the
    horizontal and rotational motion stays at the rounding level (relative to the vertical).
    The paper's Stribeck friction falls with speed: while the legs break away it is a negative
    damping that amplifies the rounding differences between legs (4e-14 N in their PI
    preloads) about a thousandfold, a physical instability of the symmetric motion, so there
    the bound is 1e-9.
    """
    result = simulate_hexapod(cubic, symmetric_platform(), isolator, STABLE,
                              excitation={"z": Chirp(duration=20.0)}, duration=5.0)
    pose = result["platform_pose"]
    vertical = np.max(np.abs(pose[:, 2]))
    assert vertical > 5e-3
    assert np.max(np.abs(pose[:, [0, 1, 3, 4, 5]])) < bound * vertical
    locked = result["locked"]
    assert locked.any() and not locked.all()  # stuck, then slipping
    if isolator.stiction_force == isolator.coulomb_force:
        z = result["relative_position"]
        assert np.max(np.abs(z - z[:, :1])) < 1e-12 * np.ptp(z)
        assert np.all(locked == locked[:, :1])
        assert len(set(result.run["stick_events"])) == 1


# ---------------------------------------------------------------- small signals
def small_sine_ratio(geometry, platform, isolator, controller, axis, frequency, **options):
    """|platform / base| in ``axis`` at ``frequency`` [Hz] of a 0.1 mm (1 mrad) base sine: the
    single-frequency DFT of the last whole periods of a 14 s run (the slowest pole, the
    integral's, has decayed to 1e-3 by then)."""
    a = AXES.index(axis)
    duration = 14.0
    result = simulate_hexapod(geometry, platform, isolator, controller,
                              excitation={axis: Sine(amplitude=1e-4 if a < 3 else 1e-3,
                                                     frequency=frequency, fade_in=1.0)},
                              duration=duration, **options)
    t = result["time"]
    window = t >= duration - int(6 * frequency) / frequency

    def amplitude_of(x):
        x = x[window] - x[window].mean()
        return 2 * np.abs(np.mean(x * np.exp(-2j * np.pi * frequency * t[window])))

    return amplitude_of(result["platform_pose"][:, a]) / amplitude_of(result["base_pose"][:, a])


@pytest.mark.parametrize("axis, frequency", [("z", 1.0), ("z", 3.0), ("rx", 3.0)])
def test_frictionless_small_motion_matches_the_linear_transmissibility(cubic, axis, frequency,
                                                                       validation):
    """Fs = Fc = 0 (viscous friction kept), 0.1 mm or 1 mrad sine: |T| of the nonlinear run
    equals the diagonal entry of ``hexapod_linearize``'s 6x6 transmissibility (preload
    included) within 1e-3.

    Both at the top frame origin (``frame="origin"``), the base pose described at the same
    point. The amplitude ratio is the single-frequency DFT of the last whole periods of a 14 s
    run (the slowest pole, the integral's, has decayed to 1e-3). What is left is the legs'
    geometric nonlinearity, of order amplitude/leg length = 3e-4.
    """
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
    a = AXES.index(axis)
    ratio = small_sine_ratio(cubic, symmetric_platform(), isolator, controller, axis, frequency)
    model = hexapod_linearize(cubic, symmetric_platform(), isolator, controller, frame="origin")
    expected = model.transmissibility(frequency, magnitude=True)[a, a]
    assert abs(ratio / expected - 1) < 1e-3
    assert abs(expected - 1) > 0.1  # a response, not the platform following the base
    validation(f"Frictionless small sine on the hexapod, {axis} at {frequency:g} Hz",
               "the linear 6x6 transmissibility (hexapod_linearize)", abs(ratio / expected - 1),
               1e-3)


# ---------------------------------------------------------------- energy
def _relative_residual(result):
    return np.max(np.abs(result.energy_residual())) / np.max(np.abs(result["base_work"]))


@pytest.mark.parametrize("case", ["chirp_z", "all_axes"])
def test_energy_ledger_closes_at_the_integrators_order(cubic, case, validation):
    """Base work + motor work = change of kinetic, spring, gravity, stop energy + dissipation.

    With stick-slip (and, for ``all_axes``, a base translating and rotating in six axes,
    which exercises the moving frame's fictitious forces, an off-axis centre of mass, a full
    inertia tensor and active damping) the residual is below 1e-7 of the largest |base work|
    and falls about 8 times when ``dt`` halves (ode3): it is truncation error, not a missing
    term.
    """
    if case == "chirp_z":
        platform, excitation = symmetric_platform(), {"z": Chirp(duration=20.0)}
        controller = STABLE
    else:
        platform = skewed_platform()
        excitation = {axis: base_motion(axis, fade_in=0.5) for axis in AXES}
        excitation["z"] = Chirp(duration=20.0)
        controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=30.0)
    residuals = []
    for dt in (1e-4, 5e-5):
        result = simulate_hexapod(cubic, platform, None, controller, excitation=excitation,
                                  duration=3.0, dt=dt)
        assert result["locked"].any() and not result["locked"].all()
        residuals.append(_relative_residual(result))
    assert residuals[0] < 1e-7
    assert residuals[0] / residuals[1] > 4
    validation(f"Hexapod energy ledger ({case})", "energy balance: base + motor work = "
               "mechanical energy change + dissipation", residuals[0], 1e-7,
               measure="largest residual / largest |base work|")


# ---------------------------------------------------------------- stops
def test_legs_stay_within_their_stops_contact_bound():
    """A 5 mm stroke against a 10 mm, 6 Hz base motion: every leg hits its stops, never
    further than its contact allows, and the ledger still closes.

    Bound per leg, from energy: a leg reaching a stop at most at the run's largest slip speed
    ``v`` with at most ``F`` = static load + Fs + F_max + a pressing it on (everything a leg
    can push with) penetrates at most ``(F + sqrt(F^2 + k_s m v^2))/k_s``, ``m`` the platform's
    mass (more than any leg moves). A stop that did not act would let the legs run on by
    centimetres.
    """
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3, stroke_half=0.005)
    isolator = IsolatorParameters(stroke_half=0.005)
    platform = PlatformParameters(mass=MASS, inertia=np.diag([0.3, 0.3, 0.5]),
                                  center_of_mass=[0.01, 0.0, 0.03])
    result = simulate_hexapod(geometry, platform, isolator, STABLE,
                              excitation={"z": Sine(amplitude=0.01, frequency=6.0, fade_in=0.5)},
                              duration=3.0, sample_rate=10000.0)
    z = result["relative_position"]
    low, high = np.asarray(result.run["stops"]).T
    penetration = np.max(np.maximum(low - z, 0.0) + np.maximum(z - high, 0.0), axis=0)
    assert min(result.run["stop_contacts"]) >= 10
    assert np.all(result["stop_contact"].any(axis=0))
    force = (np.abs(static_leg_forces(geometry, platform)) + isolator.stiction_force
             + isolator.motor_force_max + isolator.spring_force)
    speed = np.max(np.abs(result["relative_velocity"]), axis=0)
    k = isolator.stop_stiffness
    bound = (force + np.sqrt(force ** 2 + k * platform.mass * speed ** 2)) / k
    assert np.all(penetration > 0) and np.all(penetration <= bound)
    assert result["stop_dissipation"][-1] > 0
    assert _relative_residual(result) < 1e-4


# ---------------------------------------------------------------- the single axis
@pytest.mark.parametrize("excitation, duration, isolator", [
    (Chirp(duration=20.0), 8.0, IsolatorParameters()),
    (Sine(amplitude=0.01, frequency=4.0), 6.0, IsolatorParameters(stiction_force=4.0,
                                                                  coulomb_force=2.0)),
])
def test_six_vertical_legs_are_six_single_axes(excitation, duration, isolator, validation):
    """Six identical vertical legs under a platform of 6 m, base motion in z: each leg is
    the single-axis isolator of mass m (docs/model.md), stick-slip events included.

    The platform's vertical equation is the single axis's with the whole mass and six times
    the forces; each leg's z(t) equals ``qzs.simulate``'s with the same leg (to 1e-9 m; in
    fact to rounding), its locked flags and stick events too.
    """
    platform = PlatformParameters(mass=6 * isolator.mass, inertia=np.diag([1.0, 1.0, 1.5]))
    single = simulate(excitation, isolator, duration=duration)
    result = simulate_hexapod(vertical_legs(), platform, isolator,
                              excitation={"z": excitation}, duration=duration)
    assert single.run["stick_events"] >= 1
    difference = np.max(np.abs(result["relative_position"]
                               - single["relative_position"][:, None]))
    assert difference < 1e-9
    assert np.all(result["locked"] == single["locked"][:, None])
    assert result.run["stick_events"] == [single.run["stick_events"]] * 6
    validation(f"Six vertical legs under a platform of six masses, {type(excitation).__name__}",
               "the single axis (qzs.simulate), stick-slip events included", difference, 1e-9,
               measure="largest leg position difference [m]")
    assert np.max(np.abs(result["platform_pose"][:, [0, 1, 3, 4, 5]])) < 1e-12


@pytest.mark.parametrize("rate, excitation, duration, isolator", [
    (1000.0, Chirp(duration=20.0), 8.0, IsolatorParameters()),
    (250.0, Sine(amplitude=0.01, frequency=4.0), 6.0,
     IsolatorParameters(stiction_force=4.0, coulomb_force=2.0)),
])
def test_sampled_leg_controllers_are_the_single_axis_sampled_controller(rate, excitation,
                                                                        duration, isolator):
    """A controller sampled with zero-order hold (``controller_rate``): six vertical legs are
    still six single axes, the single axis's sampled controller included (its forward-Euler
    integral, the held outputs, breakaway at a sample), to 1e-9 m; and the held motor force
    is a staircase of the controller's period."""
    controller = ControllerParameters(controller_rate=rate)
    platform = PlatformParameters(mass=6 * isolator.mass, inertia=np.diag([1.0, 1.0, 1.5]))
    single = simulate(excitation, isolator, controller, duration=duration, sample_rate=10000.0)
    result = simulate_hexapod(vertical_legs(), platform, isolator, controller,
                              excitation={"z": excitation}, duration=duration,
                              sample_rate=10000.0)
    assert single.run["stick_events"] >= 1
    assert np.max(np.abs(result["relative_position"]
                         - single["relative_position"][:, None])) < 1e-9
    assert np.max(np.abs(result["motor_force"] - single["motor_force"][:, None])) < 1e-6
    assert np.all(result["locked"] == single["locked"][:, None])
    period = int(round(10000.0 / rate))
    force = result["motor_force"][:, 0]
    changes = np.flatnonzero(np.diff(force) != 0) + 1
    # the sample at t_k = k N dt is taken at the start of that step: the output at t_k (the
    # previous step's end) still shows the value held before it
    assert changes.size > 10 and np.all((changes - 1) % period == 0)


def test_a_sampled_controller_changes_the_hexapod(cubic):
    """The hold is not a no-op: a 50 Hz controller's run differs from the continuous one by
    more than rounding, and less than the response (the loop is slow against 50 Hz)."""
    runs = [simulate_hexapod(cubic, symmetric_platform(), None,
                             ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=30.0,
                                                  controller_rate=rate),
                             excitation={"z": Chirp(duration=20.0)}, duration=3.0)
            for rate in (0.0, 50.0)]
    difference = np.max(np.abs(runs[0]["platform_pose"] - runs[1]["platform_pose"]))
    motion = np.max(np.abs(runs[0]["platform_pose"][:, 2]))
    assert 1e-4 * motion < difference < 0.2 * motion
    assert runs[1].run["controller_rate"] == 50.0


# ---------------------------------------------------------------- centralised control
def test_cartesian_loops_with_the_legs_stiffness_at_the_cube_centre_are_the_per_leg_loops(
        cubic):
    """At the cube's centre ``J^T J = diag(2, 2, 2, a^2/2, a^2/2, 2a^2)``, so Cartesian gains
    ``k * diag(J^T J)`` are ``J^-T K J^-1 = k I``: the centralised loops act on each leg as
    its own loop. Stick-slip and a base moving in three axes give the same run to 1e-9 m
    (rounding of the mappings through ``J``), as long as no motor saturates: the anti-windup
    is per leg in one and per axis in the other (docs/hexapod.md §9.5)."""
    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=30.0)
    cartesian = CartesianController.from_legs(cubic, controller, point="origin")
    a = 0.3
    assert np.allclose(cartesian.position_gain, 2000.0 * np.array([2, 2, 2, a * a / 2,
                                                                   a * a / 2, 2 * a * a]))
    excitation = {"z": Chirp(duration=20.0), "x": base_motion("x"), "ry": base_motion("ry")}
    runs = [simulate_hexapod(cubic, symmetric_platform(), None, controller,
                             excitation=excitation, duration=3.0, cartesian=c)
            for c in (None, cartesian)]
    assert runs[0]["locked"].any() and not runs[0]["locked"].all()  # stuck, then slipping
    limit = IsolatorParameters().motor_force_max
    assert 0.5 * limit < np.max(np.abs(runs[0]["pi_force"] + runs[0]["damping_force"])) < limit
    assert np.max(np.abs(runs[0]["relative_position"] - runs[1]["relative_position"])) < 1e-9
    assert np.all(runs[0]["locked"] == runs[1]["locked"])
    assert runs[1].run["control"] == "centralised" and runs[0].run["control"] == "per leg"


def test_a_stiff_cartesian_axis_holds_that_axis_only(cubic):
    """Centralised control can do what per-leg loops cannot: stiffen one axis alone. With a
    soft loop on every axis but a 20x stiffer one on x, a lateral base sine moves the
    platform in x about 20x less than in y under the same sine in y (per-leg loops: 1x).
    Frictionless legs, the axes at the centre of mass (on the cube's centre: decoupled)."""
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    soft = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=30.0)
    base = CartesianController.from_legs(cubic, soft, point="center_of_mass",
                                         platform=symmetric_platform())
    gain = np.array(base.position_gain)
    gain[0] *= 20
    cartesian = CartesianController(position_gain=gain, integral_gain=base.integral_gain,
                                    damping_gain=base.damping_gain, point="center_of_mass")
    amplitude = {}
    for axis in ("x", "y"):
        result = simulate_hexapod(cubic, symmetric_platform(), isolator, soft,
                                  excitation={axis: Sine(amplitude=1e-3, frequency=0.3)},
                                  duration=6.0, cartesian=cartesian)
        i = AXES.index(axis)
        amplitude[axis] = np.ptp((result["platform_pose"] - result["base_pose"])[-2000:, i])
    assert 8 < amplitude["y"] / amplitude["x"] < 40


@pytest.mark.parametrize("axis, frequency", [("x", 1.5), ("ry", 2.5), ("z", 3.0)])
def test_frictionless_small_motion_under_cartesian_loops_matches_their_linearisation(
        cubic, axis, frequency):
    """The linearisation with ``cartesian`` (loops ``T^T Kp T``, per-axis integrals and
    damping through ``T = J_c^-1 J``) against the nonlinear run, as the per-leg test above:
    a skewed platform (nothing decouples), the axes at the cube's centre while the model's
    coordinates are at the centre of mass, a 10x stiffer x loop; |T| within 1e-3."""
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    legs = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
    base = CartesianController.from_legs(cubic, legs)
    gain = np.array(base.position_gain)
    gain[0] *= 10
    cartesian = CartesianController(position_gain=gain, integral_gain=base.integral_gain,
                                    damping_gain=base.damping_gain)
    a = AXES.index(axis)
    ratio = small_sine_ratio(cubic, skewed_platform(), isolator, legs, axis, frequency,
                             cartesian=cartesian)
    model = hexapod_linearize(cubic, skewed_platform(), isolator, legs, frame="origin",
                              cartesian=cartesian)
    per_leg = hexapod_linearize(cubic, skewed_platform(), isolator, legs, frame="origin")
    expected = model.transmissibility(frequency, magnitude=True)[a, a]
    assert model.stable
    assert abs(ratio / expected - 1) < 1e-3
    other = per_leg.transmissibility(frequency, magnitude=True)[a, a]
    assert abs(other / expected - 1) > 0.01 or axis != "x"  # the stiffer x loop shows


def test_cartesian_linearisation_with_the_legs_stiffness_is_the_per_leg_one(cubic):
    """At the cube's centre, ``from_legs`` gains: the same 6x6 matrices and transmissibility
    as the per-leg loops (``T^T diag(k J^T J) T = J^T k J``)."""
    legs = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
    cartesian = CartesianController.from_legs(cubic, legs)
    one = hexapod_linearize(cubic, skewed_platform(), None, legs, cartesian=cartesian)
    two = hexapod_linearize(cubic, skewed_platform(), None, legs)
    for name in ("stiffness_matrix", "integral_matrix", "active_damping_matrix"):
        assert np.allclose(getattr(one, name), getattr(two, name), rtol=1e-12, atol=1e-9)
    frequencies = np.array([0.3, 1.0, 3.0, 10.0])
    assert np.allclose(one.transmissibility(frequencies), two.transmissibility(frequencies),
                       rtol=1e-9, atol=1e-12)


def test_cartesian_controller_checks_its_arguments(cubic):
    with pytest.raises(ParameterError, match="position_gain"):
        CartesianController(position_gain=[1.0] * 5, integral_gain=[0.0] * 6,
                            damping_gain=[0.0] * 6)
    with pytest.raises(ParameterError, match="integral_gain"):
        CartesianController(position_gain=[1.0] * 6, integral_gain=[-1.0] * 6,
                            damping_gain=[0.0] * 6)
    with pytest.raises(ParameterError, match="point"):
        CartesianController(position_gain=[1.0] * 6, integral_gain=[0.0] * 6,
                            damping_gain=[0.0] * 6, point="centre")
    with pytest.raises(ParameterError, match="platform"):
        CartesianController.from_legs(cubic, STABLE, point="center_of_mass")
    one = CartesianController.from_legs(cubic, STABLE)
    assert one == CartesianController.from_legs(cubic, STABLE) and hash(one) == hash(
        CartesianController.from_legs(cubic, STABLE))
    j = jacobian(cubic)
    assert np.allclose(one.position_gain, np.diag(j.T @ j) * 2000.0)


# ---------------------------------------------------------------- the result
def test_the_result_repackages_with_units_and_delegates(cubic, tmp_path):
    """``to_xarray`` (dims time, dof, leg; units on every variable), ``summary``, ``plot``."""
    result = simulate_hexapod(cubic, symmetric_platform(), None, STABLE,
                              excitation={"z": Chirp(duration=20.0)}, duration=0.5,
                              solver="rk4", progress=True)
    assert isinstance(result, HexapodResult) and len(result) == 501
    dataset = result.to_xarray()
    assert dict(dataset.sizes) == {"time": 501, "dof": 6, "leg": 6}
    assert list(dataset["dof"].values) == list(AXES)
    assert list(dataset["leg"].values) == [1, 2, 3, 4, 5, 6]
    for name, variable in dataset.variables.items():
        assert variable.attrs.get("units"), name
    assert dataset["platform_pose"].attrs["units"] == "m, m, m, rad, rad, rad"
    assert dataset.attrs["Conventions"] == "CF-1.10"
    assert set(HEXAPOD_CHANNELS) - {"time"} <= set(dataset.data_vars)
    text = result.summary()
    assert "stroke used [mm]" in text and "motor RMS [N]" in text and len(text.splitlines()) > 10
    # which part of the 20 s chirp ran (was "z: Chirp" beside "0.5 s")
    assert "Base excitation: z: Chirp 0-20 Hz over 20 s: first 0.5 s run (0-0.5 Hz)" in text
    figure = result.plot(path=tmp_path / "hexapod.png")
    assert len(figure.axes) == 4 and (tmp_path / "hexapod.png").stat().st_size > 0
    assert all(ax.get_ylabel().endswith("]") for ax in figure.axes)


# ---------------------------------------------------------------- bad inputs
@pytest.mark.parametrize("change, argument", [
    (dict(geometry="cube"), "geometry"),
    (dict(platform=22.0), "platform"),
    (dict(isolator=[IsolatorParameters()] * 5), "isolator"),
    (dict(controller=IsolatorParameters()), "controller"),
    (dict(excitation=Chirp()), "excitation"),
    (dict(excitation={"zz": Chirp()}), "zz"),
    (dict(excitation={"z": 0.01}), "excitation['z']"),
    (dict(excitation={"z": Sine(amplitude=0.01, frequency=2.0)}, duration=None), "duration"),
    (dict(excitation=None, duration=None), "duration"),
    (dict(excitation={"z": Chirp(duration=2.0)}, duration=3.0), "duration"),
    (dict(dt=-1e-4), "dt"),
    (dict(dt=3e-4), "sample_rate"),
    (dict(duration=0.0), "duration"),
    (dict(solver="rk45"), "solver"),
    (dict(progress="yes"), "progress"),
    (dict(isolator=IsolatorParameters(stop_model="plastic")), "stop_model"),
    (dict(isolator=IsolatorParameters(stroke_half=0.05)), "stroke_half"),
    (dict(controller=[ControllerParameters(pi_kp=2000.0, pi_ki=800.0, controller_rate=1000.0)]
          + [STABLE] * 5), "controller_rate"),
    (dict(controller=ControllerParameters(controller_rate=3000.0)), "controller_rate"),
    (dict(cartesian=STABLE), "cartesian"),
    (dict(isolator=IsolatorParameters(stop_center=0.1)), "position_setpoint"),
])
def test_bad_inputs_raise_parameter_errors_naming_the_argument(cubic, change, argument):
    arguments = dict(geometry=cubic, platform=symmetric_platform(), isolator=None,
                     controller=STABLE, excitation={"z": Chirp(duration=20.0)}, duration=1.0)
    arguments.update(change)
    with pytest.raises(ParameterError, match=re.escape(argument)):
        simulate_hexapod(arguments.pop("geometry"), arguments.pop("platform"), **arguments)


def test_a_step_beyond_the_stable_limit_is_refused(cubic):
    with pytest.raises(StabilityError, match="`dt`"):
        simulate_hexapod(cubic, symmetric_platform(), controller=STABLE, duration=1.0,
                         dt=0.02, sample_rate=50.0)


def test_a_recorded_base_motion_replays_through_its_spline(cubic):
    """A DisplacementRecord drives an axis like any excitation (its own length by default)."""
    time = np.linspace(0.0, 1.0, 201)
    record = DisplacementRecord(time=time, displacement=0.002 * np.sin(2 * np.pi * 3 * time),
                                fade_in=0.0)
    result = simulate_hexapod(cubic, symmetric_platform(), IsolatorParameters(stiction_force=1e6),
                              STABLE, excitation={"y": record})
    assert result["time"][-1] == pytest.approx(1.0)
    assert np.max(np.abs(result["platform_pose"][:, 1] - result["base_pose"][:, 1])) < 1e-15
    assert np.max(np.abs(result["base_pose"][:, 1])) == pytest.approx(0.002, rel=1e-2)


def test_regularised_friction_is_refused_by_the_hexapod():
    import qzs
    from qzs.workflows.hexapod.setups import hexapod_setup

    setup = hexapod_setup(settings={"pi_kp": 2000.0, "pi_ki": 800.0})
    with pytest.raises(qzs.ParameterError, match="friction_regularisation"):
        qzs.simulate_hexapod(setup.geometry, setup.platform,
                             qzs.IsolatorParameters(friction_regularisation=1e-3),
                             setup.controller, excitation={"z": qzs.Sine(frequency=2.0)},
                             duration=0.1)


# ---------------------------------------------------------------- batches of platforms
def test_a_batch_of_platforms_gives_each_its_own_run(cubic):
    """``simulate_hexapods`` runs platforms in threads: each result is bit for bit the one
    ``simulate_hexapod`` gives it alone, whatever the number of threads."""
    from qzs.engine.hexapod import simulate_hexapods

    runs = [dict(geometry=cubic, platform=platform, controller=STABLE,
                 excitation={"z": Chirp(duration=20.0)}, duration=1.0)
            for platform in (symmetric_platform(), skewed_platform(), symmetric_platform())]
    runs[2]["isolator"] = IsolatorParameters(stiction_force=2.0, coulomb_force=1.0)
    alone = [simulate_hexapod(**arguments) for arguments in runs]
    for workers in (1, 2):
        batch = simulate_hexapods(runs, workers=workers)
        for one, other in zip(alone, batch):
            assert np.array_equal(one._data, other._data)
            assert np.array_equal(one._flags, other._flags)


def test_a_bad_run_of_a_batch_is_named_before_any_integration(cubic):
    from qzs.engine.hexapod import simulate_hexapods
    from qzs.errors import CaseError

    good = dict(geometry=cubic, platform=symmetric_platform(), controller=STABLE,
                excitation={"z": Chirp(duration=20.0)}, duration=1.0)
    with pytest.raises(CaseError, match="dt") as caught:
        simulate_hexapods([good, {**good, "dt": -1.0}])
    assert caught.value.index == 1
    with pytest.raises(ParameterError, match="geometry"):
        simulate_hexapods([{"platform": symmetric_platform()}])
    with pytest.raises(ParameterError, match="workers"):
        simulate_hexapods([good], workers=0)
