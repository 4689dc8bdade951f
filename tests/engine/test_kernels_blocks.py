"""The kernels with the controller's blocks (qzs.engine.kernels, docs/model.md §5).

A user's linear controller built as today's PI + high-passed damping runs as the PI + damping
does; compensation of fraction 0 is no compensation, bit for bit; the dither is its sine; the
friction observer is its first-order filter; a batch runs blocks as single runs do; the
energy ledger still closes; an unstable controller diverges with a clear message.
"""
import numpy as np
import pytest
import scipy.signal

from qzs import (Chirp, Dither, FrictionCompensation, IsolatorParameters, LinearController,
                 ParameterError, PIDamping, SimulationError, Sine, simulate, simulate_batch)
from qzs.engine.channels import CHANNELS

SINE = Sine(amplitude=0.010, frequency=3.0)  # stick-slip at the paper's defaults
BASE = PIDamping(damping_gain=20.0)
NO_LOOPS = PIDamping(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0)


def _as_linear(controller, sample_time=0.0):
    """The PI + damping of ``controller`` as a LinearController on (error, measured velocity).

    Continuous: ``x' = e``, ``F = Ki x + Kp e - Kd v``; discrete: ``x <- x + T e`` (the
    forward-Euler integral of the sampled PI).
    """
    a = [[1.0]] if sample_time else [[0.0]]
    b = [[sample_time if sample_time else 1.0, 0.0]]
    return LinearController(a=a, b=b, c=[controller.pi_ki],
                            d=[controller.pi_kp, -controller.damping_gain],
                            inputs=("position_error", "measured_payload_velocity"),
                            sample_time=sample_time)


def _run(controller, excitation=SINE, duration=12.0, isolator=None, **options):
    options.setdefault("dt", 1e-4)
    options.setdefault("sample_rate", 1e3)
    return simulate(excitation, isolator, controller=controller, duration=duration, **options)


@pytest.fixture(scope="module")
def pi_sine_run():
    return _run(BASE)


#: The channels of the whole run: the PI's and the damping's own force are the linear
#: controller's output there (checked on its own).
SHARED = [name for name in CHANNELS if name not in ("pi_force", "damping_force")]


def _relative_difference(a, b, name, other=None):
    span = np.ptp(a[name])
    other = b[name] if other is None else other
    return np.max(np.abs(a[name] - other)) / (span if span > 0 else 1.0)


@pytest.mark.parametrize("excitation, duration", [(Chirp(), 60.0), (SINE, 12.0)],
                         ids=["paper-chirp-60s", "sine-3Hz"])
def test_pi_and_damping_as_a_linear_controller_is_the_same_run(excitation, duration,
                                                                pi_sine_run, validation):
    reference = pi_sine_run if excitation is SINE else _run(BASE, excitation, duration)
    run = _run(NO_LOOPS + _as_linear(BASE), excitation, duration)
    assert run.run["stick_events"] == reference.run["stick_events"]
    worst = max(_relative_difference(reference, run, name) for name in SHARED)
    commands = reference["pi_force"] + reference["damping_force"]
    assert np.max(np.abs(run["linear_force"] - commands)) <= 1e-9 * np.ptp(commands)
    assert worst <= 1e-9
    np.testing.assert_array_equal(run["locked"], reference["locked"])
    validation("A LinearController built as the PI + high-passed damping against PIDamping "
               f"({excitation.__class__.__name__}, {duration:g} s)",
               "the same closed loop, operation for operation but the order of the sums",
               worst, 1e-9, measure="largest difference over every channel / its range")


def test_a_discrete_linear_controller_is_the_sampled_pi_and_damping():
    sampled = PIDamping(damping_gain=20.0, controller_rate=1000.0)
    reference = _run(sampled)
    run = _run(NO_LOOPS + _as_linear(sampled, sample_time=1e-3))
    assert run.run["stick_events"] == reference.run["stick_events"]
    assert max(_relative_difference(reference, run, n) for n in SHARED) <= 1e-9
    fine = _run(NO_LOOPS + _as_linear(sampled, sample_time=1e-3), duration=0.05, sample_rate=1e4)
    held = fine["linear_force"][1:].reshape(-1, 10)  # ten samples per period: one value each
    assert np.all(held == held[:, :1])


def test_compensation_of_fraction_zero_is_no_compensation_bit_for_bit(pi_sine_run):
    run = _run(BASE + FrictionCompensation(fraction=0.0))
    for name in CHANNELS:
        np.testing.assert_array_equal(run[name], pi_sine_run[name], err_msg=name)
    assert not np.any(run["compensation_force"])


def test_compensation_pushes_along_the_slip_with_a_fraction_of_the_friction_law():
    fraction = 0.7
    run = _run(BASE + FrictionCompensation(fraction=fraction, viscous_damping=None))
    plant = IsolatorParameters()
    v = run["relative_velocity"]
    slipping = ~run["locked"] & (np.abs(v) > 1e-6)
    level = (plant.coulomb_force + (plant.stiction_force - plant.coulomb_force)
             * np.exp(-plant.stribeck_decay * np.abs(v)))
    expected = fraction * (level * np.sign(v) + plant.viscous_damping * v)
    np.testing.assert_allclose(run["compensation_force"][slipping], expected[slipping],
                               rtol=1e-12, atol=1e-12)
    assert not np.any(run["compensation_force"][run["locked"]])  # nothing while stuck


def test_a_deadband_leaves_slow_slip_uncompensated():
    deadband = 5e-3
    run = _run(BASE + FrictionCompensation(fraction=1.0, deadband=deadband))
    slow = np.abs(run["relative_velocity"]) <= deadband
    assert slow.any() and (~slow).any()
    assert not np.any(run["compensation_force"][slow])
    assert np.all(run["compensation_force"][~slow] != 0.0)


def test_the_dither_is_its_sine_at_every_sample():
    dither = Dither(amplitude=3.0, frequency=37.0)
    run = _run(BASE + dither, duration=2.0)
    t = run["time"]
    np.testing.assert_allclose(run["dither_force"], 3.0 * np.sin(2 * np.pi * 37.0 * t),
                               rtol=0, atol=1e-12)


def test_the_friction_observer_is_a_first_order_filter_of_the_friction_left():
    bandwidth = 8.0
    block = FrictionCompensation(fraction=0.5, observer_bandwidth=bandwidth)
    run = _run(BASE + block, duration=4.0, sample_rate=1e4)
    estimate = run["friction_estimate"]
    feedforward = run["compensation_force"] + estimate
    left = run["friction_force"] + run["stop_force"] + feedforward
    omega = 2 * np.pi * bandwidth
    filtered = scipy.signal.lsim(([omega], [1.0, omega]), left, run["time"])[1]
    # lsim holds its input linearly between samples; the kernels integrate the filter with
    # the plant at 1e-4 s: they agree to the sampling of the friction's jumps
    assert np.max(np.abs(filtered - estimate)) <= 0.02 * np.ptp(left)
    assert np.ptp(estimate) > 0.2 * np.ptp(left)


def test_a_batch_runs_every_block_as_a_single_run_does():
    controllers = [BASE + FrictionCompensation(fraction=f) for f in (0.0, 0.5, 1.2)]
    controllers += [BASE + Dither(amplitude=2.0, frequency=30.0), BASE,
                    NO_LOOPS + _as_linear(BASE)]
    plant = IsolatorParameters()
    batch = simulate_batch([(plant, c) for c in controllers], SINE, duration=4.0, dt=1e-4,
                           sample_rate=1e3, channels=("relative_position", "motor_force"))
    for index, controller in enumerate(controllers):
        single = _run(controller, duration=4.0)
        for name in ("relative_position", "motor_force"):
            np.testing.assert_array_equal(batch.channels[name][index], single[name],
                                          err_msg=f"case {index} {name}")


@pytest.mark.parametrize("block", [FrictionCompensation(fraction=1.3, observer_bandwidth=5.0,
                                                        viscous_damping=None),
                                   Dither(amplitude=4.0, frequency=25.0)],
                         ids=["compensation", "dither"])
def test_the_energy_ledger_closes_with_blocks(block, pi_sine_run):
    run = _run(BASE + block)
    scale = np.max(np.abs(run["base_work"])) + np.max(np.abs(run["motor_work"]))
    reference = np.max(np.abs(pi_sine_run.energy_residual()))
    assert np.max(np.abs(run.energy_residual())) <= max(10 * reference, 1e-9 * scale)


def test_an_unstable_controller_runs_saturated_until_its_state_overflows_then_says_so():
    # accepted (the loop analysis flags it); the motor saturates, the state grows e^(a t)
    slow = LinearController(a=[[20.0]], b=[[1.0]], c=[1.0], d=[0.0], inputs=("position_error",))
    run = _run(NO_LOOPS + slow, duration=2.0)
    assert np.max(np.abs(run["motor_force"])) == IsolatorParameters().motor_force_max
    runaway = LinearController(a=[[500.0]], b=[[1.0]], c=[1.0], d=[0.0],
                               inputs=("position_error",))
    with pytest.raises(SimulationError, match=r"diverged at t = .* controller blocks' largest "
                                              r"state .* unstable in the loop"):
        _run(NO_LOOPS + runaway, duration=5.0)


def test_a_discrete_sample_time_off_the_step_grid_is_refused_before_the_run():
    off = LinearController(a=[[0.5]], b=[[1.0]], c=[1.0], d=[0.0],
                           inputs=("position_error",), sample_time=1.5e-4)
    with pytest.raises(ParameterError, match=r"`sample_time` .* whole number of integration "
                                             r"steps .* use sample_time=0.0001 s"):
        _run(BASE + off, duration=1.0)


def test_the_dithers_cost_is_the_payloads_mobility_at_its_frequency(validation):
    # frictionless guide, no PI: the payload answers the dither force as m s^2 + Cv s + k
    plant = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    dither = Dither(amplitude=2.0, frequency=40.0)
    run = simulate(Sine(amplitude=0.0, frequency=1.0), plant, PIDamping() + dither,
                   duration=3.0, dt=1e-4, sample_rate=1e4)
    omega = 2 * np.pi * dither.frequency
    k = plant.spring_force * plant.spring_shape / np.cosh(plant.spring_shape * -0.06) ** 2
    k += PIDamping().pi_kp
    mobility = omega ** 2 / abs(-plant.mass * omega ** 2 + 1j * omega * plant.viscous_damping + k)
    expected = dither.amplitude * mobility
    measured = run.statistics["dither_payload_acceleration"]
    assert measured == pytest.approx(expected, rel=2e-2)
    validation("The dither's cost: payload acceleration at the dither frequency",
               "F/|m - j Cv/w - k/w^2| of the frictionless payload", abs(measured / expected - 1),
               2e-2, measure="relative error")
    assert run.statistics["dither_force_rms"] == pytest.approx(2.0 / np.sqrt(2), rel=1e-3)


def test_the_summary_names_the_blocks_and_their_cost():
    run = _run(BASE + FrictionCompensation(fraction=0.5) + Dither(amplitude=1.0, frequency=50.0),
               duration=2.0)
    text = run.summary()
    assert "friction compensation (fraction 0.5)" in text and "dither (1 N at 50 Hz)" in text
    assert "payload acceleration" in text and "at 50 Hz" in text
    assert "controller" not in _run(BASE, duration=1.0).summary().split("note")[0].split(
        "motor force")[1]  # PI + damping alone: as before


@pytest.mark.parametrize("controller_rate", [0.0, 500.0])
def test_a_discrete_accelerometer_loop_reads_the_acceleration_in_the_documented_order(
        controller_rate):
    """A discrete static gain on the payload's acceleration holds, over its next period, the
    gain times the acceleration it read at its sample: with the PI continuous, the one recorded
    at that instant (an output row there is recorded before the samples); with the PI sampled at
    the same instant, that acceleration under the PI's new command (the PI and its blocks sample
    first, docs/model.md §5.1: the order the sampled loop's analysis models)."""
    gain = -0.5  # [N/(m/s^2)]
    period = 2e-3  # [s]
    loop = LinearController(a=np.zeros((0, 0)), b=np.zeros((0, 1)), c=np.zeros(0), d=[gain],
                            inputs=("payload_acceleration",), sample_time=period)
    controller = PIDamping(damping_gain=20.0, controller_rate=controller_rate) + loop
    slipping = IsolatorParameters(stiction_force=0.2, coulomb_force=0.1)  # stuck, the payload
    # would move with the base whatever the motor's force
    run = _run(controller, duration=0.4, sample_rate=1.0 / period, isolator=slipping)
    slip = ~run["locked"][:-1]
    assert slip.mean() > 0.3
    read = run["payload_acceleration"][:-1].copy()
    if controller_rate:  # the PI's new command (held from the next row) already acts
        pid = run["pi_force"] + run["damping_force"]
        read[slip] += (pid[1:] - pid[:-1])[slip] / slipping.mass
    expected = gain * read[slip]
    np.testing.assert_allclose(run["linear_force"][1:][slip], expected, rtol=0,
                               atol=1e-9 * np.ptp(expected))


#: A payload held by a stiction no motor force breaks (stuck all run), 5 mm above the setpoint:
#: the position error is a constant, and a linear controller on it runs alone.
HELD_PLANT = IsolatorParameters(stiction_force=200.0, coulomb_force=100.0)
HELD_ERROR = -0.005
#: A 2-state controller with a non-symmetric A (its rows packed as rows), whose equilibrium
#: command (-70 N) is beyond the motor's 44 N.
WINDUP = LinearController(a=[[-1.0, 2.0], [0.0, -3.0]], b=[[0.0], [3.0]], c=[4000.0, 6000.0],
                          d=[0.0], inputs=("position_error",), tracking_time=0.1)


def saturated_command(linear, plant, error):
    """The command a saturated linear controller settles at under back-calculation [N].

    ``x' = A x + B e + L (F_motor - C x) = 0`` with ``F_motor = -F_max`` (the command below
    the limit): ``x = -(A - L C)^-1 (B e - L F_max)`` (docs/model.md §5.1).
    """
    a, b, c, _ = linear.matrices()
    gain = linear.antiwindup_gain()[:, None]
    x = -np.linalg.solve(a - gain @ c, b * error - gain * plant.motor_force_max)
    return (c @ x).item(), (c @ -np.linalg.solve(a, b * error)).item()


def test_a_saturated_linear_controller_settles_where_back_calculation_puts_it():
    from qzs.model.isolator import InitialState

    settled, unsaturated = saturated_command(WINDUP, HELD_PLANT, HELD_ERROR)
    # a real windup: beyond the limit, held back from the unsaturated equilibrium
    assert unsaturated < settled < -HELD_PLANT.motor_force_max
    run = simulate(Sine(amplitude=0.0, frequency=1.0), HELD_PLANT, NO_LOOPS + WINDUP,
                   duration=6.0, dt=1e-4, sample_rate=100.0,
                   initial_state=InitialState(relative_position=NO_LOOPS.position_setpoint
                                              - HELD_ERROR))
    assert run["locked"].all()
    # it starts in equilibrium with its sensors, then the excess pulls it to the limit
    assert run["linear_force"][0] == pytest.approx(unsaturated, rel=1e-9)
    assert run["linear_force"][-1] == pytest.approx(settled, rel=1e-5)
    assert np.all(run["motor_force"][1:] == -HELD_PLANT.motor_force_max)
