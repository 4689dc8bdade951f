"""The accuracy-driven step (qzs.engine.accuracy, docs/model.md §7 "Accuracy-driven step").

Properties that fail if the step chooser is wrong:

* its error estimate is the Richardson extrapolation ``d r/(r - 1)`` of the difference ``d``
  to the next finer step, ``r`` the observed ratio capped at ``2**order``: on an exact power
  law ``e_j = C dt_j**p`` it equals the error ``e_j`` to round-off, and on a linear plant it
  equals the error measured against a run 512 (state) or 128 (dB) times finer to 1 %
  (relative: a factor wrong by a few percent fails);
* the step chosen is the largest candidate that meets the tolerance: with the tolerance set
  between the measured errors (times ``safety``) of two neighbouring candidates, the finer
  one is chosen, the coarser one fails it.
"""
import math

import numpy as np
import pytest

import qzs.engine.single as simulate_module
from helpers import linear_controller, linear_isolator
from qzs import Chirp, ControllerParameters, IsolatorParameters, Sine, simulate
from qzs.engine import StepChoice, choose_step
from qzs.engine.accuracy import (SAFETY, admissible_step, halving_search, probe_excitation,
                                 step_error)
from qzs.engine.accuracy_batch import choose_batch_step
from qzs.engine.prepare import resolving_step, steps_per_sample
from qzs.engine.stability import largest_stable_step, stability_test
from qzs.errors import ParameterError

CHIRP = Chirp(duration=20.0)
PROBE = 20.0  # s: short probes keep the tests quick


def _check_against_fine(choice, measure, factor=64, isolator=None, controller=None):
    """The chosen step's actual error on the probe, against a step ``factor`` times finer."""
    run = dict(isolator=isolator, controller=controller, duration=choice.probe_duration,
               sample_rate=choice.sample_rate, solver=choice.solver)
    coarse = simulate(choice.probe, dt=choice.dt, **run)
    fine = simulate(choice.probe, dt=choice.dt / factor, **run)
    return step_error(coarse, fine, measure, band=choice.band)


@pytest.mark.parametrize("tolerance", [1e-3, 1e-4])
def test_chosen_step_meets_a_db_tolerance_against_a_much_finer_reference(tolerance):
    choice = choose_step(CHIRP, tolerance=tolerance, band=(1.0, 20.0), probe_duration=PROBE)
    assert isinstance(choice, StepChoice)
    assert choice.measure == "transmissibility_db" and 2 * choice.error <= tolerance
    actual = _check_against_fine(choice, "transmissibility_db")
    assert actual <= tolerance
    # the estimate is an estimate, not a wild bound: within a factor 3 of the actual error
    assert actual / 3 <= choice.error <= 3 * actual
    assert choice.reference_dt == pytest.approx(choice.dt / 4)


def test_chosen_step_meets_a_state_tolerance_and_halves_when_needed():
    choice = choose_step(CHIRP, tolerance_state=1e-6, probe_duration=PROBE, safety=1.0)
    assert choice.dt < 1.0 / choice.sample_rate  # the tolerance forced halvings
    actual = _check_against_fine(choice, "state_m")
    assert actual <= 1e-6
    # the coarser step tried before it really missed the tolerance (the search is not idle)
    assert choice.history[-2][2] > 1e-6
    # a safety factor asks more of the estimate: never a larger step
    assert choose_step(CHIRP, tolerance_state=1e-6, probe_duration=PROBE).dt <= choice.dt


def test_a_tighter_tolerance_never_gives_a_larger_step():
    steps = [choose_step(CHIRP, tolerance_state=tol, probe_duration=PROBE).dt
             for tol in (1e-4, 1e-5, 1e-6, 1e-7)]
    assert all(later <= earlier for earlier, later in zip(steps, steps[1:]))
    assert steps[-1] < steps[0]
    db = [choose_step(CHIRP, tolerance=tol, probe_duration=PROBE).dt
          for tol in (1e-2, 1e-4, 2e-5)]
    assert all(later <= earlier for earlier, later in zip(db, db[1:]))


@pytest.mark.parametrize("sample_rate, controller_rate", [(100.0, 0.0), (1000.0, 300.0),
                                                          (50.0, 0.0)])
def test_the_step_respects_stability_and_divides_the_output_period(sample_rate, controller_rate):
    controller = ControllerParameters(controller_rate=controller_rate)
    choice = choose_step(CHIRP, controller=controller, tolerance=0.5,
                         sample_rate=sample_rate, probe_duration=PROBE)
    limit = largest_stable_step(IsolatorParameters(), controller, "ode3")
    assert choice.stability_limit == pytest.approx(limit)
    assert choice.dt <= limit
    assert stability_test(IsolatorParameters(), controller, "ode3")(choice.dt)
    assert steps_per_sample(sample_rate, choice.dt) == choice.steps_per_sample
    if controller_rate:
        steps_per_sample(controller_rate, choice.dt, "controller_rate")  # raises if not whole
    # stability- or resolution-bound cases start at the largest such multiple of the
    # output period: stable, and 10 steps per period of the probe's highest frequency
    resolving = resolving_step(choice.probe, choice.probe_duration)
    assert choice.history[0][0] <= resolving
    bound = min(limit, resolving)
    if 1.0 / sample_rate > bound:
        k = steps_per_sample(sample_rate, choice.history[0][0])
        assert 1.0 / (sample_rate * (k - 1)) > bound
        which = "stability bounds" if limit <= resolving else "the base motion bounds"
        assert any(which in note for note in choice.notes)


def test_stiff_stops_lower_the_step():
    stiff = IsolatorParameters(stop_stiffness=1e8)
    limit = largest_stable_step(stiff, None, "ode3")
    assert limit < 1e-3
    choice = choose_step(CHIRP, stiff, tolerance=0.5, probe_duration=PROBE)
    assert choice.dt <= limit
    steps_per_sample(1000.0, choice.dt)


def _refuse_to_simulate(*args, **kwargs):
    raise AssertionError("choose_step simulated before validating its arguments")


@pytest.mark.parametrize("kwargs, match", [
    (dict(), "exactly one"),
    (dict(tolerance=0.1, tolerance_state=1e-6), "exactly one"),
    (dict(tolerance=0.0), "positive"),
    (dict(tolerance=-0.1), "positive"),
    (dict(tolerance_state=math.nan), "`tolerance_state` must be finite, got nan"),
    (dict(tolerance=True), "`tolerance` must be a number, got the boolean True"),
    (dict(tolerance=0.1, band=(1.0, 30.0)), "outside the excitation"),
    (dict(tolerance=0.1, band=(5.0, 1.0)), "low <= high"),
    (dict(tolerance=0.1, band=(1.0, 20.0), sample_rate=30.0), "Nyquist"),
    (dict(tolerance=0.1, band="wide"), "two frequencies"),
    (dict(tolerance=0.1, solver="rk45"), "solver"),
    (dict(tolerance=0.1, sample_rate=-1.0), "sample_rate"),
    (dict(tolerance=0.1, probe_duration=0.0), "probe_duration"),
    (dict(tolerance=0.1, fft_length=10 ** 9), "fft_length"),
    (dict(tolerance=0.1, max_halvings=1), "max_halvings"),
    (dict(tolerance=0.1, safety=0.5), "safety"),
])
def test_bad_arguments_raise_before_any_simulation(monkeypatch, kwargs, match):
    monkeypatch.setattr(simulate_module, "integrate", _refuse_to_simulate)
    with pytest.raises(ParameterError, match=match):
        choose_step(CHIRP, **kwargs)


def test_bad_models_and_excitations_are_refused(monkeypatch):
    monkeypatch.setattr(simulate_module, "integrate", _refuse_to_simulate)
    with pytest.raises(ParameterError, match="excitation"):
        choose_step("chirp", tolerance=0.1)
    with pytest.raises(ParameterError, match="isolator"):
        choose_step(CHIRP, ControllerParameters(), tolerance=0.1)
    with pytest.raises(ParameterError, match="band"):  # a sine's band is its frequency
        choose_step(Sine(frequency=3.0), tolerance=0.1, band=(1.0, 20.0))


def test_an_unreachable_tolerance_is_an_error_not_a_silent_step():
    with pytest.raises(ParameterError, match="meets the tolerance"):
        choose_step(CHIRP, tolerance_state=1e-15, probe_duration=5.0, max_halvings=3)


@pytest.mark.parametrize("solver, order", [("euler", 1), ("ode3", 3), ("rk4", 4)])
def test_linear_error_scales_with_the_schemes_order(solver, order, validation):
    # frictionless, linear spring, smooth sine started at full amplitude (a fade-in's
    # raised-cosine slope is not smooth enough for rk4: it caps the observed order at 3)
    excitation = Sine(frequency=2.0, amplitude=0.01, fade_in=0.0)
    tolerance = {"euler": 5e-6, "ode3": 1e-10, "rk4": 1e-11}[solver]
    isolator, controller = linear_isolator(), linear_controller(pi_kp=50.0)
    choice = choose_step(excitation, isolator, controller, tolerance_state=tolerance,
                         solver=solver, sample_rate=100.0, probe_duration=10.0, safety=1.0)
    differences = [d for _, d, _ in choice.history]
    assert len(differences) >= 2
    ratios = [a / b for a, b in zip(differences, differences[1:])]
    assert ratios == pytest.approx([2.0 ** order] * len(ratios), rel=0.1)
    validation(f"{solver}: error ratio between steps h and h/2 (accuracy-driven step)",
               f"2^{order} for a method of order {order}",
               max(abs(ratio / 2.0 ** order - 1) for ratio in ratios), 0.1)
    # the Richardson estimate is the true error: a run 16 times finer is off by 16**-order
    actual = _check_against_fine(choice, "state_m", 16, isolator, controller)
    assert choice.error == pytest.approx(actual / (1 - 16.0 ** -order), rel=0.05)
    validation(f"{solver}: Richardson error estimate of the chosen step",
               "the true error against a run 16 times finer, / (1 - 16^-order)",
               abs(choice.error / (actual / (1 - 16.0 ** -order)) - 1), 0.05)
    assert not any("observed order" in note for note in choice.notes)


def test_the_probe_of_a_chirp_covers_the_band_and_is_short():
    probe, duration = probe_excitation(Chirp(), (1.0, 20.0))
    assert duration == 60.0 and probe.duration == 60.0
    assert probe.f0 == 0.0 and probe.f1 == pytest.approx(22.0)  # past the band's top
    probe, _ = probe_excitation(Chirp(f0=0.0, f1=20.0), (10.0, 15.0), 30.0)
    assert probe.f0 == pytest.approx(8.0) and probe.f1 == pytest.approx(16.5)
    assert probe.fade_in > 0
    falling, _ = probe_excitation(Chirp(f0=20.0, f1=0.0), (1.0, 20.0), 30.0)
    assert falling.f0 == pytest.approx(22.0) and falling.f1 == 0.0
    sine = Sine(frequency=4.0)
    assert probe_excitation(sine, (4.0, 4.0))[0] is sine


def test_summary_names_the_step_and_the_binding_limit():
    choice = choose_step(CHIRP, tolerance=0.1, probe_duration=PROBE, progress=False)
    text = choice.summary()
    assert "dt = 0.001 s" in text and "dB" in text and "output rate bounds" in text
    with pytest.raises(AttributeError):
        choice.dt = 1.0  # frozen
    assert np.isfinite(choice.error)



# ---------------------------------------------------------------- the estimate and the choice
@pytest.mark.parametrize("order", [1, 3, 4])
def test_on_an_exact_power_law_the_estimate_is_the_error(order):
    """``e_j = C dt_j**p``: the differences fall by exactly ``2**p``, and the extrapolation
    ``d_j 2**p/(2**p - 1)`` is ``e_j``. The tolerance lies between ``safety*e_{k-1}`` and
    ``safety*e_k``: candidate k is chosen, every coarser one's estimate fails it."""
    dt0, constant = 1e-3, 5e4

    def error(j):
        return constant * (dt0 / 2 ** j) ** order

    for k in range(0, 5):
        tolerance = SAFETY * error(k) * (2 ** (order / 2) if k else 1.5)
        chosen, history = halving_search(lambda j: error(j) - error(j + 1), order, tolerance,
                                         dt0, 8)
        assert chosen == k
        for j, (dt, difference, estimate) in enumerate(history):
            assert dt == dt0 / 2 ** j
            assert difference == pytest.approx(error(j) - error(j + 1), rel=1e-12)
            assert estimate == pytest.approx(error(j), rel=1e-12)
            assert (SAFETY * estimate <= tolerance) == (j == k)


@pytest.mark.parametrize("ratio, used", [(30.0, 8.0), (8.0, 8.0), (3.0, 3.0), (1.5, 1.5)])
def test_the_observed_ratio_extrapolates_capped_at_the_schemes(ratio, used):
    """Third order: differences falling faster than 8 per halving extrapolate with 8 (the
    asymptotic ratio), slower ones (stick-slip events) with the observed ratio."""
    differences = [ratio ** -j for j in range(10)]
    _, history = halving_search(lambda j: differences[j], 3, 1e-30, 1.0, 5)
    for j, (_, difference, estimate) in enumerate(history):
        assert estimate == pytest.approx(differences[j] * used / (used - 1), rel=1e-12)


def test_no_estimate_where_the_differences_do_not_shrink():
    _, history = halving_search(lambda j: [1.0, 1.0, 0.5, 0.25, 0.1][j], 3, 1e-30, 1.0, 4)
    assert history[0][2] == math.inf  # 1.0 then 1.0: ratio 1
    assert history[1][2] == pytest.approx(1.0 * 2.0 / (2.0 - 1))  # 1.0 then 0.5: ratio 2
    assert halving_search(lambda j: 0.0, 3, 1e-9, 1.0, 4)[0] == 0  # exact: no error


def _candidate_errors(excitation, isolator, controller, measure, run, count, finer, band=None):
    """Errors of the candidates ``dt_0/2**j``, j < count, against a run ``2**finer`` times
    finer than ``dt_0``, measured as :func:`step_error` measures them."""
    dt0 = admissible_step(run["sample_rate"], 0.0,
                          stability_test(isolator, controller, run["solver"]))[0]
    reference = simulate(excitation, isolator, controller, dt=dt0 / 2 ** finer, **run)
    return dt0, [step_error(simulate(excitation, isolator, controller, dt=dt0 / 2 ** j, **run),
                            reference, measure, band=band) for j in range(count)]


@pytest.mark.parametrize("k", [1, 3])
def test_the_chosen_step_is_the_largest_whose_state_error_meets_the_tolerance(k):
    """Linear plant, smooth sine, third order: the candidates' state errors against a run
    512 times finer. With the tolerance between ``safety`` times the errors of candidates
    k-1 and k, candidate k is chosen and its reported error is its measured one."""
    excitation = Sine(frequency=2.0, amplitude=0.01, fade_in=0.0)
    isolator, controller = linear_isolator(), linear_controller(pi_kp=50.0)
    run = dict(duration=10.0, sample_rate=100.0, solver="ode3")
    dt0, errors = _candidate_errors(excitation, isolator, controller, "state_m", run, k + 1, 9)
    tolerance = SAFETY * math.sqrt(errors[k - 1] * errors[k])
    choice = choose_step(excitation, isolator, controller, tolerance_state=tolerance,
                         solver="ode3", sample_rate=100.0, probe_duration=10.0)
    assert choice.probe is excitation
    assert choice.dt == dt0 / 2 ** k
    assert SAFETY * errors[k] <= tolerance < SAFETY * errors[k - 1]  # the next larger fails
    assert choice.error == pytest.approx(errors[k], rel=0.01)
    assert choice.history[-1][2] == choice.error


def test_the_chosen_step_is_the_largest_whose_db_error_meets_the_tolerance():
    """The same for the transmissibility [dB] over 1-20 Hz of a chirp's probe (a linear
    plant: the Welch estimates of two steps differ by a power of the step)."""
    isolator, controller = linear_isolator(), linear_controller(pi_kp=50.0)
    band = (1.0, 20.0)
    probe, duration = probe_excitation(Chirp(duration=20.0), band, 20.0)
    run = dict(duration=duration, sample_rate=1000.0, solver="ode3")
    dt0, errors = _candidate_errors(probe, isolator, controller, "transmissibility_db", run, 2,
                                    7, band)
    tolerance = SAFETY * math.sqrt(errors[0] * errors[1])
    choice = choose_step(Chirp(duration=20.0), isolator, controller, tolerance=tolerance,
                         band=band, probe_duration=20.0)
    assert choice.probe == probe
    assert choice.dt == dt0 / 2
    assert SAFETY * errors[1] <= tolerance < SAFETY * errors[0]
    assert choice.error == pytest.approx(errors[1], rel=0.01)


def test_a_controller_rate_that_shares_no_step_with_the_output_is_refused_at_once():
    """333 Hz against a 1000 Hz output shares a step only at 1/333000 s: refused before any
    probe runs, with rates that would do."""
    from qzs.engine.accuracy import RATE_REFINEMENT_MAX, admissible_step
    from qzs.errors import ControllerRateError

    def stable(dt):
        return dt <= 2.5e-4

    with pytest.raises(ControllerRateError, match=r"`controller_rate` \(333 Hz\)") as caught:
        admissible_step(1000.0, 333.0, stable)
    error = caught.value
    assert error.step == pytest.approx(2.5e-4) and error.refinement == RATE_REFINEMENT_MAX
    for rate in error.suggestions:  # each suggestion is admissible
        dt, _ = admissible_step(1000.0, rate, stable)
        steps_per_sample(rate, dt, "controller_rate")
    assert admissible_step(1000.0, 3000.0, stable) == (pytest.approx(1 / 6000), 6)
    with pytest.raises(ControllerRateError):
        choose_step(CHIRP, controller=ControllerParameters(controller_rate=333.0),
                    tolerance=0.5, probe_duration=PROBE)


def test_a_sine_probe_of_a_fraction_of_an_output_period_is_compared_sample_for_sample():
    """A 300 Hz sine's probe (40 periods, 0.1333 s beyond its fade-in) is no whole number of
    1 ms samples: it is cut to whole samples, so every candidate records the same ones (the
    runs at dt and dt/2 had differed by one sample: a broadcast error)."""
    from qzs import Sine

    choice = choose_step(Sine(frequency=300.0, amplitude=1e-4), tolerance_state=1e-5)
    assert choice.error <= 1e-5
    assert abs(choice.probe_duration * 1000.0 - round(choice.probe_duration * 1000.0)) < 1e-9


def test_an_excitation_no_admissible_step_follows_is_named_before_any_probe():
    """1e9 Hz: no candidate 1/(sample_rate*k), k < 1e6, gives the steps per period a run needs;
    refused with the frequency and the option that sets it, not as a stability failure."""
    from qzs import Sine
    from qzs.errors import UnresolvedExcitationError

    with pytest.raises(UnresolvedExcitationError, match=r"1e\+09 Hz \(`frequency`\)"):
        choose_step(Sine(frequency=1e9), tolerance_state=1e-5)


def test_a_step_choice_loads_scipy_signal_beside_its_first_probe_runs(monkeypatch):
    """scipy.signal (0.9 s of imports) is loaded by the first estimate, not by importing the
    spectral module: the choice starts loading it in a thread before its probes integrate,
    so that the import overlaps them (a first run's choice took 0.2-0.4 s longer without)."""
    import qzs.engine.single as single
    import qzs.engine.step_choice as step_choice

    order = []
    monkeypatch.setattr(step_choice, "import_in_background",
                        lambda *modules: order.append(("import", modules)))
    integrate = single.integrate
    monkeypatch.setattr(single, "integrate",
                        lambda *a, **k: order.append(("probe",)) or integrate(*a, **k))
    choose_step(Chirp(duration=100.0, f1=5.0), tolerance=0.05, probe_duration=12.0)
    assert order[0][0] == "import" and "scipy.signal" in order[0][1]
    assert ("probe",) in order[1:]


def test_a_state_tolerance_on_a_shortened_chirp_says_its_probe_is_shortened():
    """The state error of a probe shorter than the run's chirp understates the run's (its
    phase errors grow with time): the record says so."""
    shortened = choose_step(Chirp(f0=0.0, f1=5.0, duration=10 * PROBE), tolerance_state=1e-2,
                            probe_duration=PROBE, max_halvings=3, fallback=True)
    assert shortened.probe_duration == PROBE
    assert any("shortened chirp" in note for note in shortened.notes)


def test_a_chirp_probed_over_its_whole_length_is_not_called_shortened():
    """A 20 s chirp with a 20 s probe: the probe is as long as the run, so the state error
    is measured over the run's whole time and no shortened-probe caveat applies."""
    whole = choose_step(Chirp(f0=0.0, f1=5.0, duration=PROBE), tolerance_state=1e-2,
                        probe_duration=PROBE, max_halvings=3, fallback=True)
    assert whole.probe_duration == PROBE
    assert not any("shortened chirp" in note for note in whole.notes)
    part = choose_step(Chirp(f0=0.0, f1=5.0, duration=4 * PROBE), tolerance_state=1e-2,
                       probe_duration=PROBE, max_halvings=3, fallback=True)
    assert any("shortened chirp" in note for note in part.notes)  # a quarter of the sweep
    lanes = choose_batch_step([(None, None)], Chirp(f0=0.0, f1=5.0, duration=PROBE),
                              tolerance_state=1e-2, probe_duration=PROBE, max_halvings=3,
                              fallback=True)
    assert not any("shortened chirp" in note for note in lanes.notes)


def test_a_choice_for_another_initial_state_is_not_read_from_the_cache(monkeypatch, tmp_path):
    """The initial state changes every probe run, so a choice made from rest answers no
    run that starts displaced; the displaced one's own choice is then read back."""
    from qzs.model.isolator import InitialState

    monkeypatch.setenv("QZS_CACHE_DIR", str(tmp_path))
    options = dict(tolerance=0.05, probe_duration=PROBE, max_halvings=3, fallback=True,
                   cache=True)
    rest = choose_step(CHIRP, **options)
    displaced = choose_step(CHIRP, initial_state=InitialState(relative_position=1e-3),
                            **options)
    again = choose_step(CHIRP, initial_state=InitialState(relative_position=1e-3), **options)
    assert not rest.cached and not displaced.cached and again.cached


def test_the_step_divides_every_rate_a_controller_samples_at():
    """A 2000 Hz PI beside a discrete linear block sampled at 3000 Hz: the chosen step
    divides both periods (and the 1 ms output period): 1/6000 s or a halving of it."""
    from qzs import LinearController

    block = LinearController(a=[[1.0]], b=[[1.0 / 3000.0]], c=[0.0], d=[0.0],
                             inputs=("position_error",), sample_time=1.0 / 3000.0)
    controller = ControllerParameters(controller_rate=2000.0, linear=block)
    assert sorted(controller.sample_rates) == [2000.0, 3000.0]
    choice = choose_step(CHIRP, controller=controller, tolerance=0.5, probe_duration=PROBE,
                         max_halvings=3, fallback=True)
    for rate in (1000.0, 2000.0, 3000.0):
        steps_per_sample(rate, choice.dt, "rate")  # a whole number of steps per period
    assert choice.dt <= 1.0 / 6000.0 * (1 + 1e-12)


def test_a_step_of_exactly_the_resolving_fraction_of_a_period_is_admissible():
    """10 steps per period (MIN_STEPS_PER_PERIOD) follow the base motion: a 200 Hz sine's
    resolving step, 1/2000 s, is itself the admissible start (k = 2 at 1 kHz), not the next
    finer output fraction."""
    from qzs.engine.accuracy import SingleProbe
    from qzs.engine.prepare import MIN_STEPS_PER_PERIOD

    probe = SingleProbe(excitation=Sine(frequency=200.0, amplitude=1e-5)).build("state_m")
    limit, resolving, dt0, k0 = probe.start()
    assert MIN_STEPS_PER_PERIOD == 10 and resolving == 1.0 / 2000.0 < limit
    assert (dt0, k0) == (resolving, 2)
