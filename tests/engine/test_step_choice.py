"""Step choice as one call (qzs.engine.step_choice): the request checked once, a literal step
probes nothing, the probes of one axis and of a batch agree, the cache answers as the search
did, and the deprecated ``tolerance_db`` warns with the new name."""
import dataclasses
import math
import warnings

import pytest

from qzs import Chirp, Sine
from qzs.defaults import ACCURACY, SIMULATION
from qzs.engine.accuracy import SingleProbe, choose_step
from qzs.engine.accuracy_batch import BatchProbe, choose_batch_step
from qzs.engine.step_choice import (StepRequest, choose, fallback_step, step_request,
                                    unmet_sentence)
from engine.search_probe import search
from qzs.engine.step_search import StepChoice
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters

#: A short probe: 20 s of a 0-5 Hz chirp (its probe is itself).
CHIRP = Chirp(f0=0.0, f1=5.0, duration=20.0)


# ---------------------------------------------------------------- the request
@pytest.mark.parametrize("options, names, shown", [
    (dict(dt=1e-3, tolerance=0.01), ("dt", "tolerance"), "0.001"),
    (dict(dt=1e-3, measure="state_m"), ("dt", "tolerance"), "state_m"),
    (dict(dt=0.0), ("dt",), "0.0"),
    (dict(dt=-1e-3), ("dt",), "-0.001"),
    (dict(dt=math.inf), ("dt",), "inf"),
    (dict(tolerance=0.0), ("tolerance",), "0.0"),
    (dict(tolerance=math.nan), ("tolerance",), "nan"),
    (dict(tolerance=-1e-5, measure="state_m"), ("tolerance_state",), "-1e-05"),
    (dict(tolerance=0.01, measure="db"), ("measure",), "'db'"),
])
def test_a_bad_request_is_refused_on_construction_naming_the_argument_and_value(
        options, names, shown):
    with pytest.raises(ParameterError) as caught:
        StepRequest(**options)
    message = str(caught.value)
    assert all(f"`{name}`" in message for name in names) and shown in message
    assert set(names) <= set(caught.value.options)


def test_the_request_is_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        StepRequest(1e-3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        StepRequest(dt=1e-3).dt = 2e-3


def test_the_default_request_is_the_defaults_accuracy_in_the_probes_measure():
    """No dt and no tolerance: ACCURACY's value of the probe's measure; a tolerance alone is
    on the transmissibility; a measure alone takes its default value."""
    default = StepRequest()
    assert not default.literal
    assert default.resolved("transmissibility_db") == ("transmissibility_db",
                                                       ACCURACY["tolerance_db"])
    assert default.resolved("state_m") == ("state_m", ACCURACY["tolerance_state"])
    assert StepRequest(tolerance=0.2).resolved("state_m") == ("transmissibility_db", 0.2)
    assert StepRequest(measure="state_m").resolved("transmissibility_db") == (
        "state_m", ACCURACY["tolerance_state"])
    # the probes' default measures: a sine has no band, so its state; a chirp its dB
    assert SingleProbe(excitation=Sine(frequency=2.0)).default_measure == "state_m"
    assert SingleProbe(excitation=CHIRP).default_measure == "transmissibility_db"
    assert BatchProbe(cases=[], excitation=Sine(frequency=2.0)).default_measure == "state_m"


def test_the_api_keywords_make_one_request():
    assert step_request(tolerance=0.02) == StepRequest(tolerance=0.02,
                                                       measure="transmissibility_db")
    assert step_request(tolerance_state=1e-6) == StepRequest(tolerance=1e-6, measure="state_m")
    assert step_request(dt=1e-3) == StepRequest(dt=1e-3)
    assert step_request() == StepRequest()
    with pytest.raises(ParameterError, match="exactly one of `tolerance`.*got tolerance and "
                                             "tolerance_state"):
        step_request(tolerance=0.01, tolerance_state=1e-6)
    with pytest.raises(ParameterError, match="got neither"):
        step_request(required=True)


# ---------------------------------------------------------------- the deprecated name
@pytest.mark.parametrize("call", [
    lambda **kw: choose_step(CHIRP, **kw),
    lambda **kw: choose_batch_step([(None, None)], CHIRP, **kw),
])
def test_tolerance_db_still_works_for_one_release_and_warns_with_the_new_name(monkeypatch, call):
    import qzs.engine.step_choice as step_choice

    asked = []
    monkeypatch.setattr(step_choice, "choose", lambda request, probe, **kw: asked.append(request))
    with pytest.warns(DeprecationWarning, match="`tolerance_db` is deprecated.*use `tolerance`"):
        call(tolerance_db=0.03)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        call(tolerance=0.03)  # the new name: no warning
    assert asked[0] == asked[1] == StepRequest(tolerance=0.03, measure="transmissibility_db")
    with pytest.raises(ParameterError, match="give `tolerance` only"):
        call(tolerance=0.03, tolerance_db=0.03)


def test_resolve_hexapod_takes_tolerance_and_warns_on_tolerance_db(monkeypatch):
    import qzs.engine.step_choice as step_choice
    from qzs.engine.run_spec import resolve_hexapod

    def stop(request, probe, **kw):
        raise RuntimeError(request)

    monkeypatch.setattr(step_choice, "choose", stop)
    monkeypatch.setattr("qzs.engine.hexapod.prepare.check_hexapod_run", lambda *a, **k: None)
    with pytest.warns(DeprecationWarning, match="use `tolerance`"), \
            pytest.raises(RuntimeError) as caught:
        resolve_hexapod(None, None, excitation={"x": CHIRP}, tolerance_db=0.04)
    assert caught.value.args[0] == StepRequest(tolerance=0.04, measure="transmissibility_db")


# ---------------------------------------------------------------- literal: no probe work
@dataclasses.dataclass(frozen=True)
class _Untouchable:
    """A probe builder that fails on any probe work (a literal request must do none)."""

    sample_rate: float = 500.0
    solver: str = "rk4"

    @property
    def default_measure(self):
        raise AssertionError("a literal request asked for a measure")

    def build(self, measure):
        raise AssertionError("a literal request built its probe")


def test_a_literal_request_runs_no_probe_and_records_a_given_step():
    choice = choose(StepRequest(dt=2e-3), _Untouchable(), fallback=True, cache=True)
    assert choice == StepChoice.literal(2e-3, sample_rate=500.0, solver="rk4")
    assert not choice.chosen and choice.unmet_note == ""


# ---------------------------------------------------------------- the probes agree
def test_a_batch_probe_of_one_case_chooses_what_the_single_axis_probe_chooses():
    """The lockstep kernel integrates a lane bit for bit as the single-axis kernel does, so a
    batch of one case meets the same candidates with the same differences: the same step,
    estimate, history and notes (the batch adds only its per-case entries)."""
    pair = (IsolatorParameters(), ControllerParameters())
    request = StepRequest(tolerance=0.05)
    single = choose(request, SingleProbe(excitation=CHIRP, isolator=pair[0], controller=pair[1],
                                             max_halvings=5))
    batch = choose(request, BatchProbe(cases=[pair], excitation=CHIRP, max_halvings=5))
    assert single.met and batch.met
    assert (batch.dt, batch.error, batch.history, batch.notes) == (
        single.dt, single.error, single.history, single.notes)
    assert batch.case_steps == (single.dt,) and batch.case_errors == (single.error,)


def test_a_cache_hit_is_the_choice_the_search_made(monkeypatch, tmp_path):
    """The second identical question is answered from the cache without a probe run, with
    the same record (only ``cached`` differs)."""
    import qzs.engine.single as single_module

    monkeypatch.setenv("QZS_CACHE_DIR", str(tmp_path))
    probe = SingleProbe(excitation=CHIRP, max_halvings=5)
    fresh = choose(StepRequest(tolerance=0.05), probe, fallback=True, cache=True)

    def no_run(*args, **kwargs):
        raise AssertionError("the probe ran again")

    monkeypatch.setattr(single_module, "integrate", no_run)
    hit = choose(StepRequest(tolerance=0.05), probe, fallback=True, cache=True)
    assert hit.cached and not fresh.cached
    assert hit.to_dict() == {**fresh.to_dict(), "cached": True}
    assert dataclasses.replace(hit, cached=False) == dataclasses.replace(fresh, probe=hit.probe)


# ---------------------------------------------------------------- the one unmet meaning
def test_an_unmet_tolerance_falls_back_with_the_one_sentence():
    """Differences that never shrink: no candidate meets the tolerance; the record runs at
    the one fallback step and its last note is the one sentence."""
    choice = search(run=lambda dt, cases: [dt] * len(cases),
                         compare=lambda coarse, fine: 1.0, dt0=1e-3, order=3,
                         measure="transmissibility_db", tolerance=0.01, sample_rate=1000.0,
                         solver="ode3", probe=None, probe_duration=10.0, band=(1.0, 5.0),
                         stability_limit=2e-3, fallback=True)
    assert not choice.met and choice.dt == fallback_step() == SIMULATION["dt"]
    assert choice.unmet_note == choice.notes[-1]
    assert choice.unmet_note.startswith("no step down to ")
    assert choice.unmet_note.endswith(unmet_sentence("", choice.dt))
    assert choice.attributes()["step_reason"] == choice.unmet_note
    assert fallback_step(5e-4) == 5e-4


# ---------------------------------------------------------------- the admissible start
def test_a_sampled_controller_whose_period_the_stable_start_divides_starts_there():
    """Stable up to 0.25 ms, 1000 Hz output: the stable start is k = 4 (0.25 ms), and a
    4000 Hz controller's period is that very step, so the start is k = 4, not a finer one;
    a 2000 Hz controller (two such steps) too; 3000 Hz first at k = 6 (1/6000 s)."""
    from qzs.engine.step_choice import admissible_step

    def stable(dt):
        return dt <= 2.5e-4

    assert admissible_step(1000.0, 0.0, stable) == (pytest.approx(2.5e-4), 4)
    for rate in (4000.0, 2000.0, 1000.0):
        assert admissible_step(1000.0, rate, stable) == (pytest.approx(2.5e-4), 4)
    assert admissible_step(1000.0, 3000.0, stable) == (pytest.approx(1 / 6000), 6)


@pytest.mark.parametrize("k0, limit, resolving, bound", [
    (1, 2e-3, 1e-2, "the output rate bounds the step"),
    (2, 6e-4, 1e-2, "stability bounds the step"),
    (2, 1e-2, 6e-4, "the base motion bounds the step"),
    (3, 4e-4, 1e-2, "stability bounds the step"),
])
def test_the_note_names_what_bounds_the_coarsest_candidate(k0, limit, resolving, bound):
    """dt_0 = 1/(sample_rate*k0): at k0 = 1 the output period bounds it (a coarser step
    would be stable); any finer start is bound by the smaller of stability and the base
    motion's resolution."""
    from qzs.engine.step_choice import bound_notes

    notes = bound_notes(1e-3 / k0, k0, 1000.0, limit, resolving, "transmissibility_db", False)
    assert len(notes) == 1 and notes[0].startswith(bound)


def test_the_cache_answers_only_the_question_it_was_asked(monkeypatch, tmp_path):
    """A tolerance no candidate meets: the fallback is the ``finest`` step asked for, so a
    cached fallback at one ``finest`` is no answer at another; nor to a caller without
    ``fallback``, who gets the error instead."""
    from qzs.errors import ToleranceNotMetError

    monkeypatch.setenv("QZS_CACHE_DIR", str(tmp_path))
    probe = SingleProbe(excitation=CHIRP, max_halvings=3)
    request = StepRequest(tolerance=1e-9)
    first = choose(request, probe, fallback=True, finest=1e-4, cache=True)
    assert not first.met and first.dt == 1e-4 and not first.cached
    other = choose(request, probe, fallback=True, finest=5e-5, cache=True)
    assert not other.met and other.dt == 5e-5 and not other.cached
    again = choose(request, probe, fallback=True, finest=1e-4, cache=True)
    assert again.cached and again.dt == 1e-4
    with pytest.raises(ToleranceNotMetError):
        choose(request, probe, finest=1e-4, cache=True)


def test_a_probe_s_default_safety_is_the_search_s():
    """Without ``safety`` a probe keeps the documented factor (SAFETY = 2): a tolerance of
    1.5 times the coarsest candidate's estimate refuses that candidate (2 x > 1.5 x)."""
    from qzs.engine.step_search import SAFETY

    loose = choose(StepRequest(tolerance=1.0), SingleProbe(excitation=CHIRP, max_halvings=4))
    first = loose.history[0][2]
    assert loose.dt == loose.history[0][0] and 0 < first < math.inf
    choice = choose(StepRequest(tolerance=1.5 * first),
                    SingleProbe(excitation=CHIRP, max_halvings=4), fallback=True)
    assert SAFETY == 2.0 and choice.dt < loose.dt
