"""Each leg of the six-leg platform with its own controller blocks (docs/model.md §5.1,
docs/hexapod.md §9.5a).

Six identical vertical legs under a platform of six masses, base motion in z, are six single
axes: with blocks too (friction compensation with its observer, dither, a continuous linear
controller reading both accelerometers, the sampled PI with its blocks, a discrete linear
controller), each leg's position and block forces equal ``qzs.simulate``'s with the same
controller. Compensation of fraction 0 is no compensation, bit for bit; each leg runs its own
controller; what cannot take blocks refuses them, naming the way out.
"""
import numpy as np
import pytest
from helpers import lead_lag, vertical_legs

from qzs import (Dither, FrictionCompensation, IsolatorParameters, LinearController,
                 ParameterError, PIDamping, Sine, simulate)
from qzs.engine.hexapod import simulate_hexapod
from qzs.engine.hexapod.result import HEXAPOD_BLOCK_CHANNELS
from qzs.model.hexapod import CartesianController, PlatformParameters, cubic_geometry

ISOLATOR = IsolatorParameters(stiction_force=4.0, coulomb_force=2.0)
SINE = Sine(amplitude=0.01, frequency=4.0)
#: Low-passed payload acceleration (20 Hz, -1 kg) and base acceleration (50 Hz, +0.5 kg) and
#: the amplifier's velocity straight through (-20 N*s/m): every sensor the legs read differently
#: from the single axis's code (the accelerometers along the leg).
ACCELEROMETERS = LinearController(
    a=[[-2 * np.pi * 20.0, 0.0], [0.0, -2 * np.pi * 50.0]],
    b=[[2 * np.pi * 20.0, 0.0, 0.0], [0.0, 2 * np.pi * 50.0, 0.0]], c=[-1.0, 0.5],
    d=[0.0, 0.0, -20.0],
    inputs=("payload_acceleration", "base_acceleration", "measured_payload_velocity"))

CONTROLLERS = {
    "compensation-observer-dither": PIDamping() + FrictionCompensation(
        fraction=0.6, observer_bandwidth=5.0) + Dither(amplitude=1.0, frequency=25.0),
    "linear-accelerometers": PIDamping() + ACCELEROMETERS,
    "sampled-pi-with-blocks": PIDamping(controller_rate=1000.0) + FrictionCompensation(
        fraction=0.8, observer_bandwidth=3.0) + Dither(amplitude=1.5, frequency=30.0),
    "discrete-linear": PIDamping() + lead_lag(sample_time=2e-3),
    # sampled at the PI's instants: it reads the acceleration before the PI's new command
    "discrete-accelerometer-with-sampled-pi": PIDamping(controller_rate=500.0) + LinearController(
        a=[[0.5]], b=[[1e-3]], c=[-2.0], d=[-0.5], inputs=("payload_acceleration",),
        sample_time=2e-3),
}


def _platform(isolator=ISOLATOR):
    return PlatformParameters(mass=6 * isolator.mass, inertia=np.diag([1.0, 1.0, 1.5]))


@pytest.mark.parametrize("name", list(CONTROLLERS))
def test_six_vertical_legs_with_blocks_are_six_single_axes(name, validation):
    """Each leg with blocks is the single axis with the same controller, stick-slip included:
    its position to 1e-9 m (the tolerance of the legs without blocks), its motor and block
    forces to 1e-6 N, its locked flags and stick events exactly."""
    controller = CONTROLLERS[name]
    options = dict(duration=4.0, sample_rate=10000.0)
    single = simulate(SINE, ISOLATOR, controller, **options)
    result = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR, controller,
                              excitation={"z": SINE}, **options)
    assert single.run["stick_events"] >= 1
    difference = np.max(np.abs(result["relative_position"]
                               - single["relative_position"][:, None]))
    assert difference < 1e-9
    forces = ["motor_force"] + [n for n in HEXAPOD_BLOCK_CHANNELS if n in single.channels]
    for channel in forces:
        assert np.ptp(single[channel]) > 0 or channel == "friction_estimate"
        assert np.max(np.abs(result[channel] - single[channel][:, None])) < 1e-6, channel
    assert np.all(result["locked"] == single["locked"][:, None])
    assert result.run["stick_events"] == [single.run["stick_events"]] * 6
    validation(f"Six vertical legs with the controller blocks {name} under a platform of six "
               "masses", "the single axis with the same controller (qzs.simulate), stick-slip "
               "events included", difference, 1e-9, measure="largest leg position difference [m]")



#: A base moving at t = 0 (y' = 0.19 m/s) and one accelerating (y'' = -3.55 m/s^2): no fade-in.
MOVING = Sine(amplitude=0.01, frequency=3.0, fade_in=0.0)
ACCELERATING = Sine(amplitude=0.01, frequency=3.0, phase=np.pi / 2, fade_in=0.0)
#: What each leg's controller puts out at t = 0 besides the PI's integral: nothing (a
#: feedthrough on the measured velocity, the amplifier settled), a feedthrough on the base's
#: acceleration (+7.1 N), a discrete controller's states at equilibrium with the payload's
#: acceleration (C x0 + D u0 = -2.3 N).
STARTS = {
    "measured velocity, moving base": (
        MOVING, PIDamping() + LinearController.from_transfer_function(
            [-40.0], [1.0], "measured_payload_velocity")),
    "base acceleration, accelerating base": (
        ACCELERATING, PIDamping() + LinearController.from_transfer_function(
            [-2.0], [1.0], "base_acceleration")),
    "discrete on the payload's acceleration": (ACCELERATING, PIDamping() + LinearController(
        a=[[0.9, 0.05], [0.0, 0.8]], b=[[1e-3, 0.0], [0.0, 0.01]], c=[30.0, -2.0],
        d=[10.0, 0.0], inputs=("position_error", "payload_acceleration"), sample_time=1e-3)),
}


@pytest.mark.parametrize("name", list(STARTS))
def test_six_vertical_legs_start_their_motors_where_the_single_axis_does(name):
    """docs/model.md §5.1, initial state: each leg's PI preload nets what its blocks put out at
    t = 0, as the single axis's does, so each of the six motors starts at the single axis's
    motor force, the static load the spring does not carry, on a base already moving or
    accelerating at t = 0. The legs used to leave their blocks' output out (the base at rest)."""
    excitation, controller = STARTS[name]
    options = dict(duration=0.01, sample_rate=10000.0)
    single = simulate(excitation, ISOLATOR, controller, **options)
    result = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR, controller,
                              excitation={"z": excitation}, **options)
    static = ISOLATOR.mass * ISOLATOR.gravity - ISOLATOR.spring_force * np.tanh(
        -ISOLATOR.spring_shape * controller.position_setpoint)
    assert single["motor_force"][0] == pytest.approx(static, rel=1e-12)
    np.testing.assert_allclose(result["motor_force"][0], single["motor_force"][0], rtol=0,
                               atol=1e-9)

@pytest.mark.parametrize("rate", [0.0, 1000.0], ids=["continuous", "sampled"])
def test_compensation_of_fraction_zero_is_no_compensation_bit_for_bit(rate):
    """On the cubic platform (nothing decouples), a compensation of fraction 0 on every leg
    changes no bit of any channel, and its force channel is 0 throughout."""
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    base = PIDamping(pi_kp=2000.0, pi_ki=800.0, controller_rate=rate)
    options = dict(excitation={"z": SINE, "rx": Sine(amplitude=0.02, frequency=3.0)},
                   duration=3.0)
    plain = simulate_hexapod(geometry, platform, controller=base, **options)
    zero = simulate_hexapod(geometry, platform, controller=base + FrictionCompensation(
        fraction=0.0), **options)
    assert not plain.has_blocks and zero.has_blocks
    assert sum(plain.run["stick_events"]) >= 1
    width = plain._data.shape[1]
    np.testing.assert_array_equal(zero._data[:, :width], plain._data)
    np.testing.assert_array_equal(zero._flags, plain._flags)
    assert not np.any(zero["compensation_force"])


def test_each_leg_runs_its_own_controller():
    """A sequence of six: each leg's dither is its own sine, 0 on the legs without one; the
    legs without blocks record no other block force."""
    amplitudes = [0.0, 1.0, 0.0, 2.0, 0.5, 0.0]
    controllers = [PIDamping() + Dither(amplitude=a, frequency=20.0 + i) if a else PIDamping()
                   for i, a in enumerate(amplitudes)]
    result = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR, controllers,
                              excitation={"z": SINE}, duration=1.0)
    time = result["time"][:, None]
    expected = np.array(amplitudes) * np.sin(2 * np.pi * (20.0 + np.arange(6)) * time)
    np.testing.assert_allclose(result["dither_force"], expected, rtol=0, atol=1e-12)
    for channel in ("compensation_force", "friction_estimate", "linear_force"):
        assert not np.any(result[channel])
    # legs without a dither are not the legs with one: each leg moves under its own force
    assert np.max(np.abs(result["relative_position"][:, 3] - result["relative_position"][:, 0])
                  ) > 1e-6


def test_block_channels_exist_only_with_blocks_and_reach_the_dataset(tmp_path):
    """Without blocks the rows keep their columns and asking for a block force says why it is
    absent; with blocks the dataset and the file carry each leg's block forces with their
    units."""
    options = dict(excitation={"z": SINE}, duration=0.2)
    plain = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR, **options)
    with pytest.raises(KeyError, match="only when a leg's controller has blocks"):
        plain["dither_force"]
    assert "dither_force" not in plain.to_xarray()
    result = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR,
                              PIDamping() + Dither(amplitude=1.0, frequency=20.0), **options)
    dataset = result.to_xarray()
    assert dataset["dither_force"].dims == ("time", "leg")
    assert dataset["dither_force"].attrs["units"] == "N"
    np.testing.assert_array_equal(dataset["dither_force"].values, result["dither_force"])
    assert result.metadata()["controller.dither.amplitude"] == (1.0, "N")
    import xarray as xr

    with xr.open_dataset(result.save(tmp_path / "run.nc")) as stored:
        np.testing.assert_array_equal(stored["dither_force"].values, result["dither_force"])


def test_blocks_are_refused_with_centralised_control_and_a_bad_period_names_the_leg():
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    controller = PIDamping(pi_kp=2000.0, pi_ki=800.0)
    cartesian = CartesianController.from_legs(geometry, controller)
    with pytest.raises(ParameterError, match=r"centralised control \(`cartesian`\) models PI "
                                             r"\+ damping alone; `controller` has blocks"):
        simulate_hexapod(geometry, platform, controller=controller + Dither(),
                         cartesian=cartesian, duration=0.1)
    legs = [controller] * 5 + [controller + lead_lag(sample_time=1.5e-4)]
    with pytest.raises(ParameterError, match=r"leg 6: `sample_time` of the LinearController"
                                             ) as error:
        simulate_hexapod(geometry, platform, controller=legs, duration=0.1)
    assert error.value.options == ("sample_time",)


def test_a_legs_discrete_controller_samples_at_its_period_whatever_leg_0_runs():
    """Leg 0 without a linear controller, legs 1-5 with a discrete one of period 2 ms: each of
    those holds its output between its samples and changes at them (the base moves the
    payload, the amplifier's velocity with it), once every period throughout."""
    period, duration = 2e-3, 0.1
    controllers = [PIDamping()] + [PIDamping() + lead_lag(sample_time=period)] * 5
    result = simulate_hexapod(vertical_legs(), _platform(), ISOLATOR, controllers,
                              excitation={"z": SINE}, duration=duration, sample_rate=10000.0)
    time = result["time"]
    for leg in range(1, 6):
        linear = result["linear_force"][:, leg]
        changes = time[np.flatnonzero(np.diff(linear) != 0.0) + 1]
        assert len(changes) >= duration / period - 1  # it samples all along
        # once a period: held in between
        np.testing.assert_allclose(np.diff(changes), period, rtol=0, atol=1e-9)
    assert not np.any(result["linear_force"][:, 0])
