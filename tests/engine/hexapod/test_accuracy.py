"""The six-axis accuracy-driven step (qzs.engine.hexapod.accuracy): the chosen step meets
its tolerance against runs 8 times finer, it is the largest candidate that does, bad
tolerances are refused before any run, and a tolerance no step meets is said."""
import math

import numpy as np
import pytest

from qzs import Chirp, ControllerParameters, RandomExcitation, Sine
from qzs.engine.accuracy import SAFETY
from qzs.engine.hexapod import simulate_hexapod
from qzs.engine.hexapod.accuracy import choose_hexapod_step, hexapod_probe, hexapod_step_error
from qzs.errors import ParameterError, ToleranceNotMetError
from qzs.model.hexapod import PlatformParameters, cubic_geometry, platform_size

STABLE = ControllerParameters(pi_kp=2000.0, pi_ki=800.0)
RATE = 500.0  # the coarsest candidate is then 2 ms: short probes


@pytest.fixture(scope="module")
def setup():
    return (cubic_geometry(cube_edge=0.3, cube_center_height=0.3),
            PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5])))


def _probe_run(setup, choice, dt):
    geometry, platform = setup
    return simulate_hexapod(geometry, platform, controller=STABLE, excitation=choice.probe,
                            duration=choice.probe_duration, dt=dt, sample_rate=RATE)


@pytest.mark.parametrize("excitation, measure", [
    ({"x": Chirp(amplitude=0.002, f0=0.0, f1=8.0, duration=20.0)}, "tolerance"),
    ({"x": RandomExcitation(amplitude=0.002, f_low=0.5, f_high=8.0, duration=5.0, seed=1)},
     "tolerance_state")])
def test_the_chosen_step_is_the_largest_meeting_the_tolerance_against_a_finer_run(
        setup, excitation, measure):
    """A tolerance between the coarsest candidate's estimate and the next one's: the
    coarsest is refused, the next chosen, and its actual error against a run 8 times finer
    (in the same measure) is within the tolerance."""
    geometry, platform = setup
    options = dict(excitation=excitation, sample_rate=RATE, max_halvings=4)
    loose = choose_hexapod_step(geometry, platform, controller=STABLE, **{measure: 1.0},
                                **options)
    first = loose.history[0][2]
    assert loose.dt == loose.history[0][0] and 0 < first < math.inf
    tolerance = 0.5 * SAFETY * first  # the coarsest candidate's estimate misses it by 2
    choice = choose_hexapod_step(geometry, platform, controller=STABLE,
                                 **{measure: tolerance}, **options)
    assert choice.dt < loose.dt  # the coarsest was refused
    assert choice.dt == choice.history[-1][0]
    assert all(SAFETY * estimate > tolerance for _, _, estimate in choice.history[:-1])
    assert SAFETY * choice.error <= tolerance
    kind = "transmissibility_db" if measure == "tolerance" else "state_m"
    assert choice.measure == kind and choice.tolerance == tolerance
    chosen, finer = (_probe_run(setup, choice, dt) for dt in (choice.dt, choice.dt / 8))
    actual = hexapod_step_error(chosen, finer, kind, axis="x", band=choice.band)
    assert actual <= tolerance
    assert actual == pytest.approx(choice.error, rel=0.5)  # the estimate is an estimate of it


def test_the_state_measure_counts_a_rotation_as_the_arc_at_the_platforms_size(setup):
    geometry, platform = setup
    run = simulate_hexapod(geometry, platform, controller=STABLE,
                           excitation={"rx": Sine(amplitude=0.01, frequency=2.0)},
                           duration=0.05, dt=1e-3, sample_rate=RATE)

    class Shifted:
        def __init__(self, axis, by):
            self.geometry, self.pose = geometry, run["platform_pose"].copy()
            self.pose[:, axis] += by

        def __getitem__(self, name):
            return self.pose

    size = platform_size(geometry)
    assert hexapod_step_error(Shifted(3, 1e-4), run, "state_m") == pytest.approx(1e-4 * size)
    assert hexapod_step_error(Shifted(1, 1e-4), run, "state_m") == pytest.approx(1e-4)


@pytest.mark.parametrize("options, match", [
    (dict(tolerance=0.0), "`tolerance`.*0"),
    (dict(tolerance=-0.01), "`tolerance`.*-0.01"),
    (dict(tolerance=float("nan")), "`tolerance`.*nan"),
    (dict(tolerance_state="small"), "`tolerance_state`.*small"),
    (dict(), "exactly one of `tolerance`.*neither"),
    (dict(tolerance=0.01, tolerance_state=1e-5), "tolerance and tolerance_state"),
    (dict(tolerance=0.01, excitation={"x": Chirp(duration=20.0), "z": Chirp(duration=20.0)}),
     "one axis.*Give `tolerance_state`"),
    (dict(tolerance=0.01, excitation={}), "moves no base axis"),
    (dict(tolerance=0.01, band=(1.0, 50.0)), "`band`.*outside"),
])
def test_bad_tolerances_are_refused_before_any_run(setup, monkeypatch, options, match):
    import qzs.engine.hexapod.simulate as simulate

    def no_run(*args, **kwargs):
        raise AssertionError("a probe ran")

    monkeypatch.setattr(simulate, "simulate_hexapod", no_run)
    geometry, platform = setup
    arguments = dict(excitation={"x": Chirp(amplitude=0.002, f1=8.0, duration=20.0)},
                     sample_rate=RATE)
    arguments.update(options)
    with pytest.raises(ParameterError, match=match):
        choose_hexapod_step(geometry, platform, controller=STABLE, **arguments)


def test_a_tolerance_no_step_meets_is_an_error_or_the_fallback_with_the_reason(setup):
    """A tolerance below rounding: no step meets it; without a fallback that is a
    ToleranceNotMetError, with one the fallback step, no estimate and a note saying why."""
    geometry, platform = setup
    options = dict(excitation={"x": Sine(amplitude=0.002, frequency=3.0)}, sample_rate=RATE,
                   duration=1.0, tolerance_state=1e-30, finest=2.5e-4)
    with pytest.raises(ToleranceNotMetError, match="1e-30 m"):
        choose_hexapod_step(geometry, platform, controller=STABLE, **options)
    choice = choose_hexapod_step(geometry, platform, controller=STABLE, fallback=True,
                                 **options)
    assert choice.dt == 2.5e-4 and math.isnan(choice.error) and not choice.met
    assert "running at dt = 0.00025 s" in choice.notes[-1]
    assert [h[0] for h in choice.history] == [2e-3, 1e-3]  # down to the finest, 2.5e-4 s


def test_the_probe_of_a_chirp_sweeps_the_band_and_a_sine_stops_with_the_run():
    chirp = Chirp(amplitude=0.002, f0=0.0, f1=20.0, duration=400.0)
    probe, length = hexapod_probe({"z": chirp}, band=(1.0, 20.0), duration=5.0)
    assert length == 60.0 and probe["z"].duration == 60.0  # a chirp ignores the run's end
    assert probe["z"].f1 == pytest.approx(22.0) and probe["z"].amplitude == 0.002
    sine = Sine(amplitude=0.002, frequency=3.0)
    probe, length = hexapod_probe({"x": sine}, duration=100.0)
    assert probe["x"] is sine and length == pytest.approx(sine.fade_in + 40 / 3.0)
    # a run shorter than a probe is its own probe (the state measure: no band)
    probe, length = hexapod_probe({"x": sine, "z": chirp}, duration=5.0)
    assert probe == {"x": sine, "z": chirp} and length == 5.0


@pytest.mark.parametrize("halvings", [1, 0])
def test_too_few_halvings_to_estimate_an_error_are_refused_before_any_run(setup, monkeypatch,
                                                                         halvings):
    """An estimate compares a candidate with two finer ones: fewer than two halvings
    estimate nothing, so they are refused naming `max_halvings`."""
    import qzs.engine.hexapod.simulate as simulate

    def no_run(*args, **kwargs):
        raise AssertionError("a probe ran")

    monkeypatch.setattr(simulate, "simulate_hexapod", no_run)
    geometry, platform = setup
    with pytest.raises(ParameterError, match="`max_halvings` must be an integer >= 2") as info:
        choose_hexapod_step(geometry, platform, controller=STABLE, tolerance=0.01,
                            excitation={"x": Chirp(amplitude=0.002, f1=8.0, duration=20.0)},
                            sample_rate=RATE, max_halvings=halvings)
    assert not isinstance(info.value, ToleranceNotMetError)


@pytest.mark.parametrize("excitation, measure", [
    ({"z": Chirp(duration=20.0)}, "transmissibility_db"),
    ({"z": Chirp(duration=20.0), "x": Chirp(duration=20.0)}, "state_m"),
    ({"z": Sine(frequency=2.0)}, "state_m"),
    ({}, "state_m"),
])
def test_the_default_request_measures_one_chirping_axis_s_transmissibility_else_the_pose(
        setup, excitation, measure):
    """Without a tolerance: one chirping base axis is judged by its transmissibility; two
    axes (no one driven axis) or a sine (no band) by the pose."""
    from qzs.engine.hexapod.accuracy import HexapodProbe

    geometry, platform = setup
    probe = HexapodProbe(geometry=geometry, platform=platform, excitation=excitation)
    assert probe.default_measure == measure
