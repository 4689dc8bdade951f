"""One frequency of the stepped sine (qzs.workflows.response.frequency) against closed forms
no one here wrote.

* Den Hartog (1931): the exact steady state of a linear oscillator with Coulomb (and viscous)
  friction under a harmonic force, here the base's inertial force on the relative motion;
* the ideal zero-stiffness isolator with Coulomb friction under base motion: held while the
  stiction exceeds the base's inertial force, sliding without stops below a friction ratio
  c* = 1/sqrt(1 + pi^2/4), with fundamental transmissibility 4c/pi (docs/response.md §6);
* the linearised closed loop (python-control) for a frictionless guide;
* sub-harmonic responses of an impact oscillator, confirmed on one uncut simulation;
* a response that does not settle: NaN with its reason;
* the decision that a response is periodic (docs/response.md §3), on sequences of changes
  whose answer is known, and on a linear plant whose decay is known in closed form.

Property that fails if the periodicity rule is loosened or tightened: a geometric approach
of known ratio rho is accepted exactly when its last 3 changes are within the tolerance and
its extrapolated remainder ``d rho^m/(1 - rho^m)`` is (on either side of the boundary, to 1
part in 1e9); 2 periods of 3 within the tolerance are not enough; the ratio used is the
largest of the changes'; a period-m answer needs every shorter period's change above 1000
tolerances; and an overdamped linear plant started from rest settles in the number of periods
after which its closed-form transient ``expm(A T)^k e_0`` is within the tolerance, to one.
"""
import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import root

import qzs
from qzs import ControllerParameters, IsolatorParameters, Sine
from helpers import linear_controller, linear_isolator
from qzs.workflows.response import SAMPLES_PER_PERIOD, steady_state_response, steps_for
from qzs.workflows.response.frequency import _period_multiple

MASS = 6.4
PASSIVE = ControllerParameters(pi_kp=0.0, pi_ki=0.0, position_setpoint=0.0)


def run(frequencies, amplitude, isolator, controller, **options):
    options = {"direction": "up", "dt": 1e-3, "harmonic_balance": False, "workers": 1,
               **options}
    return steady_state_response(frequencies, amplitude, isolator, controller, **options)


@pytest.mark.parametrize("frequency, dt, steps", [
    (20.0, 5e-4, 256), (2.0, 1e-3, 512), (3.0, 1e-3, 512), (0.5, 1e-3, 2048)])
def test_a_period_is_a_whole_number_of_output_samples(frequency, dt, steps):
    """The fewest multiple of 256 steps per period whose step is at most ``dt``."""
    assert steps_for(frequency, dt) == steps
    assert 1 / (frequency * steps) <= dt
    fewer = steps - SAMPLES_PER_PERIOD
    assert fewer == 0 or 1 / (frequency * fewer) > dt


# ---------------------------------------------------------------- Den Hartog (1931)
def den_hartog_amplitude(force_ratio, beta, static):
    """Den Hartog's closed form: the peak amplitude of ``m z'' + k z + F sgn(z') =
    P cos(w t)`` moving without stops (J. P. Den Hartog, Forced vibrations with combined
    Coulomb and viscous friction, Trans. ASME 53, APM-53-9, 107-115, 1931):
    ``X = (P/k) sqrt(V^2 - (F/P)^2 U^2)``,
    ``V = 1/(1 - beta^2)``, ``U = sin(pi/beta) / (beta (1 + cos(pi/beta)))``."""
    v = 1.0 / (1.0 - beta ** 2)
    u = math.sin(math.pi / beta) / (beta * (1.0 + math.cos(math.pi / beta)))
    return static * math.sqrt(v ** 2 - force_ratio ** 2 * u ** 2)


def exact_coulomb_oscillator(m, k, c, friction, force, omega):
    """Den Hartog's construction, solved here: the symmetric steady state of
    ``m z'' + c z' + k z + F sgn(z') = P cos(w t + phi)`` without stops.

    Over the half period ``0 <= t <= pi/w`` the mass moves up from ``-X`` to ``+X``
    (``z' > 0``), so the equation is linear there: the free solution of the damped
    oscillator plus the forced one, shifted by ``-F/k``. The four conditions ``z(0) = -X``,
    ``z'(0) = 0``, ``z(pi/w) = X``, ``z'(pi/w) = 0`` fix ``C1, C2, X, phi``; the other half is
    the mirror image. Returns ``(X, |Z_1|)``: the peak and the fundamental amplitude.
    """
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd, decay = wn * math.sqrt(1 - zeta ** 2), zeta * wn
    receptance = 1.0 / (k - m * omega ** 2 + 1j * c * omega)
    half = math.pi / omega

    def motion(c1, c2, phi, t):
        e = np.exp(-decay * t)
        free = e * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
        free_rate = e * ((-decay * c1 + wd * c2) * np.cos(wd * t)
                         - (decay * c2 + wd * c1) * np.sin(wd * t))
        forced = force * receptance * np.exp(1j * (omega * t + phi))
        return -friction / k + free + forced.real, free_rate + (1j * omega * forced).real

    def conditions(u):
        c1, c2, x, phi = u
        z0, v0 = motion(c1, c2, phi, 0.0)
        z1, v1 = motion(c1, c2, phi, half)
        return [z0 + x, v0, z1 - x, v1]

    guess = abs(force * receptance)
    for phi in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        solution = root(conditions, [0.0, 0.0, guess, phi], tol=1e-14)
        if not solution.success or solution.x[2] <= 0:
            continue
        c1, c2, x, phi = solution.x
        inside = np.linspace(0, half, 4001)[1:-1]
        z, v = motion(c1, c2, phi, inside)
        if np.all(v > 0):  # moving without stops: the construction holds
            break
    else:
        raise AssertionError("no motion without stops for this case")
    n = 8192
    t = np.arange(n) * 2 * half / n
    first = t < half
    z = np.where(first, motion(c1, c2, phi, np.where(first, t, 0.0))[0],
                 -motion(c1, c2, phi, np.where(first, 0.0, t - half))[0])
    # turning point: the spring and the force must overcome friction, or the mass would stick
    assert abs(-k * x + force * math.cos(math.pi + phi)) > friction
    return x, abs(2.0 / n * np.sum(z * np.exp(-1j * omega * t)))


@pytest.mark.parametrize("beta, force_ratio, viscous", [
    (0.6, 0.3, 0.0), (1.6, 0.3, 0.0), (2.5, 0.5, 0.0), (1.6, 0.3, 5.0)])
def test_den_hartog_coulomb_oscillator(beta, force_ratio, viscous, validation):
    """A linear spring (tanh with a tiny shape: bz ~ 1e-5), Coulomb friction F (Fs = Fc) and
    viscous friction, no controller, no gravity: the relative motion is Den Hartog's
    oscillator forced by ``-m y''`` = ``m A w^2 cos(w t)``."""
    natural, amplitude, shape = 2.0, 0.005, 1e-3
    k = MASS * (2 * math.pi * natural) ** 2
    frequency = beta * natural
    omega = 2 * math.pi * frequency
    force = MASS * amplitude * omega ** 2
    friction = force_ratio * force
    peak, fundamental = exact_coulomb_oscillator(MASS, k, viscous, friction, force, omega)
    if viscous == 0.0:  # the construction reproduces the printed closed form
        assert peak == pytest.approx(den_hartog_amplitude(force_ratio, beta, force / k),
                                     rel=1e-9)
    isolator = IsolatorParameters(mass=MASS, gravity=0.0, spring_force=k / shape,
                                  spring_shape=shape, stiction_force=friction,
                                  coulomb_force=friction, viscous_damping=viscous,
                                  stroke_half=1.0)
    point = run([frequency], amplitude, isolator, PASSIVE).points[0]
    assert point.converged and point.period_multiple == 1, point.reason
    assert point.relative_amplitude == pytest.approx(fundamental, rel=1e-5)
    # the sampled peak: 256 samples a period miss the crest by at most 1 - cos(pi/256)
    assert point.relative_peak == pytest.approx(peak, rel=2e-4)
    assert point.locked_fraction == 0.0 and point.stop_contacts == 0.0
    case = f"beta = {beta}, F/P = {force_ratio}, c = {viscous} N s/m"
    if viscous == 0.0:
        validation(f"Den Hartog's construction against his closed form ({case})",
                   "X = (P/k) sqrt(V^2 - (F/P)^2 U^2) (Den Hartog 1931)",
                   abs(peak / den_hartog_amplitude(force_ratio, beta, force / k) - 1), 1e-9)
    validation(f"Stepped sine, fundamental of the relative motion ({case})",
               "Den Hartog's exact steady state (1931), Coulomb + viscous friction",
               abs(point.relative_amplitude / fundamental - 1), 1e-5)
    validation(f"Stepped sine, peak of the relative motion ({case})",
               "Den Hartog's exact steady state (1931), sampled at 256 points a period",
               abs(point.relative_peak / peak - 1), 2e-4)


# ---------------------------------------------------------------- zero stiffness + Coulomb
CRITICAL_RATIO = 1.0 / math.sqrt(1.0 + math.pi ** 2 / 4.0)  # docs/response.md §6


def zero_stiffness(ratio, amplitude, frequency):
    friction = ratio * MASS * amplitude * (2 * math.pi * frequency) ** 2
    return IsolatorParameters(mass=MASS, gravity=0.0, spring_force=0.0,
                              stiction_force=friction, coulomb_force=friction,
                              viscous_damping=0.0, stroke_half=1.0)


@pytest.mark.parametrize("ratio", [0.2, 0.5, 0.53])
def test_zero_stiffness_isolator_slides_with_four_c_over_pi(ratio, validation):
    """Below c* the payload slides all the time: its acceleration is a square wave of
    height F/m, whose fundamental is 4F/(pi m), i.e. T = 4c/pi; odd harmonics 4c/(k pi)."""
    amplitude, frequency = 0.005, 3.0
    point = run([frequency], amplitude, zero_stiffness(ratio, amplitude, frequency),
                PASSIVE).points[0]
    assert point.converged, point.reason
    assert point.transmissibility == pytest.approx(4 * ratio / math.pi, rel=1e-5)
    assert point.harmonics[1] == pytest.approx(4 * ratio / (3 * math.pi), rel=1e-4)
    assert point.harmonics[3] == pytest.approx(4 * ratio / (5 * math.pi), rel=1e-3)
    validation(f"Zero-stiffness Coulomb isolator, c = {ratio}: fundamental T",
               "4c/pi (square-wave acceleration, docs/response.md §6)",
               abs(point.transmissibility / (4 * ratio / math.pi) - 1), 1e-5)
    validation(f"Zero-stiffness Coulomb isolator, c = {ratio}: third harmonic",
               "4c/(3 pi)", abs(point.harmonics[1] / (4 * ratio / (3 * math.pi)) - 1), 1e-4)
    assert point.harmonics[0] < 1e-6 and point.harmonics[2] < 1e-6  # no even harmonics
    assert point.locked_fraction == 0.0


def test_zero_stiffness_isolator_sticks_above_the_critical_ratio():
    """Just above c* the payload sticks at each reversal (the stick rule |F_hold| <= Fs
    decides it) and the square-wave result no longer holds; at c >= 1 it never slips."""
    amplitude, frequency = 0.005, 3.0
    above = run([frequency], amplitude, zero_stiffness(1.02 * CRITICAL_RATIO, amplitude,
                                                       frequency), PASSIVE).points[0]
    below = run([frequency], amplitude, zero_stiffness(0.98 * CRITICAL_RATIO, amplitude,
                                                       frequency), PASSIVE).points[0]
    assert below.locked_fraction == 0.0
    assert above.locked_fraction > 0.0
    assert abs(above.transmissibility / (4 * 1.02 * CRITICAL_RATIO / math.pi) - 1) > 1e-5
    held = run([frequency], amplitude, zero_stiffness(1.2, amplitude, frequency),
               PASSIVE).points[0]
    assert held.locked_fraction == 1.0
    assert held.transmissibility == pytest.approx(1.0, abs=1e-12)


# ---------------------------------------------------------------- linear closed loop
def test_frictionless_steady_state_is_the_linear_closed_loop(validation):
    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    controller = ControllerParameters(damping_gain=30.0)
    frequencies = [0.3, 1.0, 3.0, 10.0]
    response = run(frequencies, 0.001, isolator, controller)
    model = qzs.linearize(isolator, controller)
    expected = model.transfer_function(2j * np.pi * np.array(frequencies))
    up = response.branch("up")
    assert np.all(up["converged"] == 1)
    np.testing.assert_allclose(up["transmissibility"], np.abs(expected), rtol=1e-4)
    np.testing.assert_allclose(up["phase"], np.angle(expected), atol=1e-4)
    validation("Frictionless stepped sine, 0.3-10 Hz, |T|", "the linearised closed loop "
               "(python-control)", np.abs(up["transmissibility"] / np.abs(expected) - 1).max(),
               1e-4)
    validation("Frictionless stepped sine, 0.3-10 Hz, phase", "the linearised closed loop "
               "(python-control)", np.abs(up["phase"] - np.angle(expected)).max(), 1e-4,
               measure="absolute error [rad]")
    # and the record's linear value is the same model's
    records = response.to_records()
    np.testing.assert_allclose([r["linear_transmissibility"] for r in records],
                               np.abs(expected), rtol=1e-12)


def test_a_frequency_run_is_the_sweep_s_point_and_carries_its_state_to_the_next():
    """A sweep's frequency is the frozen plan at that frequency: run alone from rest it gives
    the sweep's own point, bit for bit (the plan carries every setting down); started from
    its final state it is continued, settles sooner, and agrees within the periodicity
    tolerance."""
    import dataclasses

    from qzs.workflows.response.frequency import FrequencyRun, SweepPlan, _run_frequency

    isolator = IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
    controller = ControllerParameters(damping_gain=30.0)
    sweep = run([1.0], 0.001, isolator, controller)
    plan = SweepPlan(amplitude=0.001, isolator=isolator, controller=controller, dt=1e-3,
                     solver="ode3", periodic_tolerance=sweep.settings["periodic_tolerance"],
                     max_periods=sweep.settings["max_periods"],
                     max_time=sweep.settings["max_time"], fade_in=sweep.settings["fade_in"],
                     harmonics=sweep.settings["harmonics"])
    first = plan.at("up", 1.0)
    assert first == FrequencyRun(plan=plan, direction="up", frequency=1.0, carried=None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        first.frequency = 2.0
    point, carried = _run_frequency(first)
    expected = dataclasses.replace(sweep.points[0], seconds=point.seconds)
    assert point == expected and point.start == "rest"
    again, _ = _run_frequency(plan.at("up", 1.0, carried))
    assert again.start == "continued" and again.periods < point.periods
    assert again.transmissibility == pytest.approx(point.transmissibility,
                                                   rel=plan.periodic_tolerance)


# ---------------------------------------------------------------- sub-harmonics
def impact_oscillator():
    k, shape = MASS * (2 * math.pi * 2.0) ** 2, 1e-3
    return IsolatorParameters(mass=MASS, gravity=0.0, spring_force=k / shape,
                              spring_shape=shape, stiction_force=0.0, coulomb_force=0.0,
                              viscous_damping=2.0, stroke_half=0.003, stop_stiffness=2e4,
                              stop_damping=500.0)


@pytest.mark.parametrize("frequency, multiple", [(2.2, 2), (3.2, 3)])
def test_subharmonic_responses_are_found_and_confirmed_by_one_uncut_run(frequency, multiple):
    """A payload bouncing between close compliant stops settles on period-2 and period-3
    orbits. An uncut qzs.simulate of the same sine repeats every ``multiple`` periods and
    not sooner, and gives the very same transmissibility: cutting a run into periods
    (whole multiples of the kernels' 256-step exact-sine period) changes no bit."""
    amplitude, isolator = 0.005, impact_oscillator()
    point = run([frequency], amplitude, isolator, PASSIVE).points[0]
    assert point.converged and point.period_multiple == multiple
    assert point.subharmonic > 1e-3 and point.stop_contacts > 0
    period = 1.0 / frequency
    steps = steps_for(frequency, 1e-3)
    fade = math.ceil(2.0 * frequency) / frequency
    result = qzs.simulate(Sine(amplitude=amplitude, frequency=frequency, phase=math.pi / 2,
                               fade_in=fade), isolator, PASSIVE,
                          duration=point.periods * period, dt=period / steps,
                          sample_rate=frequency * SAMPLES_PER_PERIOD)
    z = result.relative_position[::SAMPLES_PER_PERIOD][-4:]
    assert abs(z[-1] - z[-1 - multiple]) < 1e-8 * amplitude * 1e3
    assert all(abs(z[-1] - z[-1 - j]) > 1e-6 for j in range(1, multiple))
    x = result.to_xarray()
    n = multiple * SAMPLES_PER_PERIOD
    # the last whole periods, their closing sample (phase 0 again) moved to the front
    payload, base = (np.roll(x[name].values[-n:], 1)
                     for name in ("payload_displacement", "base_displacement"))
    kernel = np.exp(-2j * np.pi * multiple * np.arange(n) / n)
    ratio = np.sum(payload * kernel) / np.sum(base * kernel)
    assert abs(ratio) == pytest.approx(point.transmissibility, rel=1e-14)



# ---------------------------------------------------------------- honesty
def test_a_response_that_does_not_settle_is_nan_with_its_reason():
    # the default isolator coming down into the locked band hunts: the PI integral ramps
    # while stiction holds the payload off the setpoint, on a cycle much longer than the
    # excitation's period
    response = steady_state_response([1.0, 2.5], direction="down", dt=1e-3,
                                     harmonic_balance=False, workers=1, max_time=300.0)
    points = {p.frequency: p for p in response.points}
    assert points[2.5].converged
    held = points[1.0]
    assert not held.converged and held.period_multiple == 0
    assert math.isnan(held.transmissibility) and math.isnan(held.locked_fraction)
    assert "not periodic after 300 periods" in held.reason and "PI integral" in held.reason
    assert any("NaN" in note for note in response.notes)


# ---------------------------------------------------------------- when is it periodic?
TOLERANCE = 1e-6


def decide(history, multiple=1, shorter=1.0):
    """The rule's answer for the m-period changes ``history`` (oldest first); every shorter
    period's changes are ``shorter`` (default: far from settling)."""
    changes = {m: [] for m in (1, 2, 3)}
    for j in range(1, multiple):
        changes[j] = [shorter] * len(history)
    changes[multiple] = list(history)
    return _period_multiple(changes, TOLERANCE)


def geometric(rho, multiple, count=6):
    """Changes of a geometric approach of per-period ratio ``rho`` scaled so that it sits on
    the rule's boundary: its binding quantity (the largest of the last 3 changes, or the
    extrapolated remainder ``d rho^m/(1 - rho^m)``) equals the tolerance."""
    d = rho ** np.arange(count)
    remainder = d[-1] * rho ** multiple / (1 - rho ** multiple)
    return d * TOLERANCE / max(d[-3:].max(), remainder)


@pytest.mark.parametrize("multiple", [1, 2, 3])
@pytest.mark.parametrize("rho", [0.3, 0.5, 0.8, 0.95, 0.999])
def test_a_geometric_approach_settles_exactly_when_its_remainder_is_within_tolerance(rho,
                                                                                   multiple):
    history = geometric(rho, multiple)
    assert decide(history * (1 - 1e-9), multiple) == multiple
    assert decide(history * (1 + 1e-9), multiple) == 0
    remainder = history[-1] * rho ** multiple / (1 - rho ** multiple)
    if remainder > history[-3:].max():  # the remainder binds: changes within it are not enough
        assert remainder == pytest.approx(TOLERANCE, rel=1e-12)
        assert history[-3:].max() * (1 + 1e-9) < TOLERANCE


def test_two_periods_of_three_within_the_tolerance_are_not_enough():
    """Changes falling a thousandfold a period: the remainder is tiny at once, but the
    change three periods back is above the tolerance; one more period settles it."""
    history = [10.0, 2 * TOLERANCE, 1e-3 * TOLERANCE, 1e-6 * TOLERANCE]
    assert decide(history) == 0
    assert decide(history[1:]) == 0  # no matter how long the history
    assert decide(history + [1e-9 * TOLERANCE]) == 1
    assert decide(history[2:]) == 0  # two periods only: not yet three


def test_the_remainder_uses_the_largest_ratio_of_the_last_changes():
    """Ratios 0.9 then 0.5: the approach may be as slow as 0.9, remainder ``d 0.9/0.1``
    (not ``d 0.5/0.5`` from the last ratio alone)."""
    d = np.array([1.0, 0.9, 0.45])
    scale = TOLERANCE / (d[-1] * 0.9 / 0.1)
    assert decide(d * scale * (1 - 1e-9)) == 1
    assert decide(d * scale * (1 + 1e-9)) == 0
    # and only the last three periods count: an early slow stretch is forgotten
    assert decide(np.concatenate([[10.0, 9.99], 0.1 ** np.arange(3) * TOLERANCE])) == 1


def test_round_off_changes_are_exact_repetition_and_growth_never_settles():
    assert decide([0.0, 0.0, 0.0]) == 1  # a locked payload repeats bit for bit
    assert decide([1e-12, 1e-13, 0.0]) == 1  # below round-off (1e-11): zero
    assert decide([0.0, 0.5 * TOLERANCE, 0.4 * TOLERANCE]) == 0  # from zero to non-zero
    assert decide([0.1, 0.1, 0.1] * np.array(TOLERANCE)) == 0  # not shrinking: inf
    assert decide([0.2, 0.3, 0.1] * np.array(TOLERANCE)) == 0  # a ratio above one


@pytest.mark.parametrize("multiple", [2, 3])
def test_a_subharmonic_needs_every_shorter_period_far_from_settling(multiple):
    """A period-1 response approached slowly meets the 2-period test a little before the
    1-period one: period m is taken only with the shorter changes above 1000 tolerances."""
    settled = [0.0, 0.0, 0.0]
    assert decide(settled, multiple, shorter=1001 * TOLERANCE) == multiple
    assert decide(settled, multiple, shorter=999 * TOLERANCE) == 0
    # and period 1 is tried first: settled in both, the answer is 1
    assert _period_multiple({1: settled, 2: settled, 3: settled}, TOLERANCE) == 1


def closed_form_settling(mass, stiffness, damping, amplitude, frequency, tolerance):
    """Periods after which the transient of ``m z'' + c z' + k z = m A w^2 cos(w t)`` from
    rest (z = z' = 0) is within ``tolerance`` of the periodic orbit, in the rule's scaled
    state (z / A, z' / (A w)): ``e_k = expm(M T)^k e_0``, ``e_0`` minus the orbit at t = 0."""
    omega = 2 * np.pi * frequency
    orbit = mass * amplitude * omega ** 2 / (stiffness - mass * omega ** 2 + 1j * damping * omega)
    error = -np.array([orbit.real, (1j * omega * orbit).real])
    monodromy = expm(np.array([[0.0, 1.0], [-stiffness / mass, -damping / mass]]) / frequency)
    scale = np.array([amplitude, amplitude * omega])
    for periods in range(1, 10_000):
        error = monodromy @ error
        if np.max(np.abs(error) / scale) <= tolerance:
            return periods, float(np.max(np.abs(np.linalg.eigvals(monodromy))))
    raise AssertionError("no settling")


@pytest.mark.parametrize("stiffness, damping, frequency", [
    (100.0, 100.0, 5.0), (100.0, 200.0, 5.0), (100.0, 100.0, 2.0)])
def test_a_linear_plant_settles_when_its_closed_form_transient_is_within_tolerance(
        stiffness, damping, frequency):
    """Overdamped (one slow real pole): the approach is geometric, ratio 0.58-0.90 per
    period, and the rule's remainder is the distance to the orbit. Without the remainder
    (changes alone within the tolerance) the run would stop 8-40 periods too soon."""
    amplitude = 0.005
    isolator = linear_isolator(stiffness=stiffness, damping=damping)
    expected, rho = closed_form_settling(MASS, stiffness, damping, amplitude, frequency,
                                         TOLERANCE)
    point = run([frequency], amplitude, isolator, linear_controller(), fade_in=0.0,
                periodic_tolerance=TOLERANCE).points[0]
    assert point.converged and point.period_multiple == 1, point.reason
    assert abs(point.periods - expected) <= 1, (point.periods, expected, rho)
    assert point.residual <= TOLERANCE



def test_a_run_keeps_the_direction_of_its_sweep():
    """``plan.at(direction, ...)`` is a run of that direction: a downward sweep's points are
    recorded as such."""
    from qzs.workflows.response.frequency import FrequencyRun, SweepPlan

    plan = SweepPlan(amplitude=0.001, isolator=None, controller=None, dt=1e-3, solver="ode3",
                     periodic_tolerance=1e-3, max_periods=10, max_time=10.0, fade_in=1.0,
                     harmonics=3)
    for direction in ("up", "down"):
        assert plan.at(direction, 2.0) == FrequencyRun(plan=plan, direction=direction,
                                                       frequency=2.0)
