"""One step for many cases (qzs.engine.accuracy_batch.choose_batch_step, docs/model.md §7).

The batch search probes every case at once through the lockstep kernel, which gives each
case :func:`qzs.simulate`'s numbers to the last bit; so each case's step and estimate must
be exactly what :func:`~qzs.engine.accuracy.choose_step` finds for it alone, and the
batch's step the finest of them. A case no step meets (the payload without PI rides on the
hard stops) is reported and does not hold the others back.
"""
import math

import pytest

from qzs import defaults
from qzs import Chirp, ControllerParameters, IsolatorParameters
from qzs.engine.accuracy import choose_step
from qzs.engine.accuracy_batch import BatchStepChoice, choose_batch_step
from qzs.errors import ParameterError, ToleranceNotMetError

CHIRP = Chirp(duration=20.0)
PROBE = 20.0  # s: short probes keep the tests quick
NO_PI = (IsolatorParameters(), ControllerParameters(pi_kp=0.0, pi_ki=0.0))
CASES = [(IsolatorParameters(), ControllerParameters()),
         (IsolatorParameters(viscous_damping=400.0), ControllerParameters()),
         (IsolatorParameters(stiction_force=15.0), ControllerParameters()),
         NO_PI]


def test_each_case_gets_its_own_choice_and_the_batch_the_finest_step():
    tolerance = 1e-3
    batch = choose_batch_step(CASES, CHIRP, tolerance=tolerance, probe_duration=PROBE,
                              labels=["table 1", "Cv = 400", "Fs = 15", "no PI"])
    assert isinstance(batch, BatchStepChoice)
    alone = [choose_step(CHIRP, *case, tolerance=tolerance, probe_duration=PROBE)
             for case in CASES[:3]]
    # the lockstep probe is the one-case probe, bit for bit: the same steps and estimates
    assert list(batch.case_steps[:3]) == [choice.dt for choice in alone]
    assert list(batch.case_errors[:3]) == [choice.error for choice in alone]
    assert len({choice.dt for choice in alone}) > 1  # the cases disagree: the test decides
    assert batch.dt == min(choice.dt for choice in alone)
    assert batch.error == max(choice.error for choice in alone)
    assert batch.reference_dt == batch.dt / 4
    # the case without PI: no step meets it, alone an error, in the batch a note
    with pytest.raises(ToleranceNotMetError):
        choose_step(CHIRP, *NO_PI, tolerance=tolerance, probe_duration=PROBE)
    assert batch.unmet == (3,)
    assert math.isinf(batch.case_errors[3]) and math.isnan(batch.case_steps[3])
    assert any(note.startswith("no PI: no step down to") for note in batch.notes)
    assert "no PI" in batch.summary()


def test_no_case_meeting_the_tolerance_is_an_error_and_a_hopeless_case_is_probed_once(
        monkeypatch):
    """The case without PI is hopeless at the first comparison (its estimate, brought down
    at the scheme's order ``2**order`` per halving to the finest candidate, still exceeds the
    tolerance: read from the error's data), so the search gives it up after the probes of
    that comparison (dt_0, dt_0/2, dt_0/4) instead of probing every candidate."""
    from qzs.engine import batch as batch_module
    from qzs.engine.accuracy_batch import BATCH_MAX_HALVINGS
    from qzs.engine.stability import SOLVERS

    probed = []
    simulate_batch = batch_module.simulate_batch

    def counted(cases, *args, **kwargs):
        probed.append(kwargs["dt"])
        return simulate_batch(cases, *args, **kwargs)

    monkeypatch.setattr(batch_module, "simulate_batch", counted)
    with pytest.raises(ToleranceNotMetError, match="no step down to") as caught:
        choose_batch_step([NO_PI], CHIRP, tolerance=1e-3, probe_duration=PROBE)
    error, order = caught.value, SOLVERS[defaults.SIMULATION["solver"]][1]
    assert error.safety * error.smallest_error > error.tolerance * 2.0 ** (
        order * (BATCH_MAX_HALVINGS - 2))
    assert probed == [probed[0], probed[0] / 2, probed[0] / 4]


@pytest.mark.parametrize("cases, options, match", [
    ([], {"tolerance": 0.01}, "at least one"),
    (CASES[:1], {}, "exactly one of"),
    (CASES[:1], {"tolerance": 0.01, "tolerance_state": 1e-6}, "exactly one of"),
    (CASES[:1], {"tolerance": -1.0}, "tolerance"),
    (CASES[:1], {"tolerance": 0.01, "labels": ["a", "b"]}, "labels"),
    (CASES[:1], {"tolerance": 0.01, "band": (1.0, 50.0)}, "band"),
])
def test_bad_arguments_raise_before_any_simulation(monkeypatch, cases, options, match):
    import qzs.engine.batch

    def refuse(*args, **kwargs):
        raise AssertionError("simulated before the arguments were checked")

    monkeypatch.setattr(qzs.engine.batch, "simulate_batch", refuse)
    with pytest.raises(ParameterError, match=match):
        choose_batch_step(cases, CHIRP, probe_duration=PROBE, **options)


def test_the_batch_records_the_stability_limit_of_its_stiffest_case():
    """Every case shares the step, so the batch's stability limit is the smallest of its
    cases' (a stiff spring's), the one the record and the notes quote."""
    from qzs.engine.stability import largest_stable_step

    soft = (IsolatorParameters(), ControllerParameters())
    stiff = (IsolatorParameters(), ControllerParameters(pi_kp=2e6, damping_gain=2e3))
    limits = [largest_stable_step(*case, defaults.SIMULATION["solver"]) for case in (soft, stiff)]
    assert limits[1] < limits[0]
    batch = choose_batch_step([soft, stiff], CHIRP, tolerance=0.5, probe_duration=PROBE,
                              max_halvings=3, fallback=True)
    assert batch.stability_limit == min(limits)


def test_the_batch_step_divides_every_case_s_controller_period():
    """Cases sampled at 2000 Hz and 3000 Hz in one batch: the shared step divides both
    periods (and the 1 ms output period): 1/6000 s or a halving of it."""
    from qzs.engine.prepare import steps_per_sample

    cases = [(IsolatorParameters(), ControllerParameters(controller_rate=rate))
             for rate in (2000.0, 3000.0)]
    batch = choose_batch_step(cases, CHIRP, tolerance=0.5, probe_duration=PROBE,
                              max_halvings=3, fallback=True)
    for rate in (1000.0, 2000.0, 3000.0):
        steps_per_sample(rate, batch.dt, "rate")  # a whole number of steps per period
    assert batch.dt <= 1.0 / 6000.0 * (1 + 1e-12)


def test_a_batch_choice_at_another_welch_length_is_not_read_from_the_cache(monkeypatch,
                                                                          tmp_path):
    """The Welch segment length changes the measured transmissibility, so the choice made
    with one answers no batch asking with another; its own is then read back."""
    monkeypatch.setenv("QZS_CACHE_DIR", str(tmp_path))
    options = dict(tolerance=0.5, probe_duration=PROBE, max_halvings=3, fallback=True,
                   cache=True)
    first = choose_batch_step([NO_PI], CHIRP, fft_length=4096, **options)
    other = choose_batch_step([NO_PI], CHIRP, fft_length=2048, **options)
    again = choose_batch_step([NO_PI], CHIRP, fft_length=2048, **options)
    assert not first.cached and not other.cached and again.cached


def test_a_batch_halves_its_start_at_most_its_own_default_times():
    """A batch tries BATCH_MAX_HALVINGS halvings by default (fewer than one axis: every
    candidate runs every case): an unreachable tolerance is given up at the finest candidate
    estimated, dt_0 / 2**(BATCH_MAX_HALVINGS - 2), the one the fallback names."""
    from qzs.engine.accuracy_batch import BATCH_MAX_HALVINGS, BatchProbe
    from qzs.engine.step_choice import StepRequest, choose

    choice = choose(StepRequest(tolerance=1e-9), BatchProbe(cases=[NO_PI], excitation=CHIRP,
                                                            probe_duration=PROBE),
                    fallback=True)
    finest = choice.history[0][0] / 2 ** (BATCH_MAX_HALVINGS - 2)
    assert not choice.met
    assert choice.unmet_note.startswith(f"no step down to {finest:.3g} s met")
