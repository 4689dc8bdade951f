"""The one step search (qzs.engine.step_search): its choice against a closed form, its memo,
its one fallback and its one record.

The runs here are synthetic: a "run" at step ``dt`` is the number ``C * dt**p``, the error of
a scheme of order ``p`` against the exact answer 0, so that the differences, the Richardson
estimate and the chosen step all have closed forms:

* the estimate of ``dt_j`` is exact when the observed ratio is the scheme's ``2**p``, and the
  chosen step is the coarsest ``dt_j`` with ``safety * C * dt_j**p <= tolerance``;
* each candidate is integrated once per case, however often it is compared;
* several cases share the finest of their chosen steps; a case no step meets is listed and
  does not hold the others back; where none meets the tolerance the fallback is the caller's
  finest step (default the paper's), with no estimate and a note saying why;
* the record reads the same from the choice and from its file attributes read back.
"""
import math

import pytest

from qzs import defaults
from engine.search_probe import search
from qzs.engine.step_search import (MAX_HALVINGS, SAFETY, StepChoice, halving_search,
                                    record_line)
from qzs.errors import ParameterError, ToleranceNotMetError

ORDER = 3
DT0 = 1e-3


def _search(constants, tolerance, **options):
    """``search_step`` over cases whose run at ``dt`` is ``C * dt**ORDER``."""
    calls = []

    def run(dt, cases):
        calls.extend((dt, c) for c in cases)
        return [constants[c] * dt ** ORDER for c in cases]

    choice = search(run=run, compare=lambda coarse, fine: abs(coarse - fine),
                         cases=len(constants), dt0=DT0, order=ORDER,
                         measure="transmissibility_db", tolerance=tolerance, sample_rate=1000.0,
                         solver="ode3", probe=None, probe_duration=10.0, band=(1.0, 20.0),
                         stability_limit=0.005, **options)
    return choice, calls


def _expected_step(constant, tolerance, max_halvings=8):
    """The coarsest dt_j whose exact error, times the safety factor, meets the tolerance."""
    for j in range(max_halvings - 1):
        dt = DT0 / 2 ** j
        if SAFETY * constant * dt ** ORDER <= tolerance * (1 + 1e-12):
            return dt
    return None


@pytest.mark.parametrize("constant", [1e3, 1e6, 1e8])
def test_the_chosen_step_is_the_coarsest_whose_exact_error_meets_the_tolerance(constant):
    tolerance = 1e-3
    choice, calls = _search([constant], tolerance)
    assert choice.dt == _expected_step(constant, tolerance)
    # the Richardson estimate of an exact order-p error is the error itself
    assert choice.error == pytest.approx(constant * choice.dt ** ORDER, rel=1e-9)
    assert choice.met and choice.chosen and choice.reference_dt == choice.dt / 4
    # each candidate integrated once, though all but the first are compared twice
    assert len(calls) == len(set(calls))


def test_several_cases_share_the_finest_of_their_steps_and_an_unmet_case_is_named():
    tolerance = 1e-3
    choice, _ = _search([1e3, 1e6], tolerance, labels=["soft", "stiff"])
    assert choice.dt == min(_expected_step(1e3, tolerance), _expected_step(1e6, tolerance))
    assert choice.case_steps == (_expected_step(1e3, tolerance), _expected_step(1e6, tolerance))
    assert choice.unmet == ()
    # a case whose differences never shrink (constant error: no convergence) is unmet
    stuck = [0.0]

    def run(dt, cases):
        return [1e3 * dt ** ORDER if c == 0 else (stuck.__setitem__(0, stuck[0] + 1) or stuck[0])
                for c in cases]

    mixed = search(run=run, compare=lambda a, b: abs(a - b), cases=2, dt0=DT0,
                        order=ORDER, measure="transmissibility_db", tolerance=tolerance,
                        sample_rate=1000.0, solver="ode3", probe=None, probe_duration=10.0,
                        band=(1.0, 20.0), stability_limit=0.005, labels=["ok", "stuck"])
    assert mixed.dt == _expected_step(1e3, tolerance) and mixed.unmet == (1,)
    assert math.isinf(mixed.case_errors[1]) and any("stuck" in note for note in mixed.notes)


def test_the_one_fallback_runs_at_the_finest_allowed_step_and_says_why():
    with pytest.raises(ToleranceNotMetError):
        _search([1e12], 1e-12)
    choice, _ = _search([1e12], 1e-12, fallback=True)
    assert choice.dt == defaults.SIMULATION["dt"] and not choice.met
    assert math.isnan(choice.error) and "no step down to" in choice.notes[-1]
    finer, _ = _search([1e12], 1e-12, fallback=True, finest=DT0 / 4)
    assert finer.dt == DT0 / 4 and not finer.met
    assert all(h[0] >= DT0 / 4 for h in finer.history)  # no candidate finer than `finest`


@pytest.mark.parametrize("floor", [DT0 / 4, DT0 / 5, DT0 / 2 ** 5, DT0 / 48, DT0 / 2 ** 10])
@pytest.mark.parametrize("reach", ["never", "one_below", "at_the_floor"])
def test_no_step_below_the_finest_allowed_is_integrated_or_returned(floor, reach):
    """``finest`` is a floor: the candidates are ``dt_0/2**j`` down to the last one at or
    above it, ``n = floor(log2(dt_0/finest))`` halvings (at most ``max_halvings``), and no
    further, whether the tolerance is never met, met only one halving below the floor (where
    the search must not go: the fallback), or met at the finest candidate that can still be
    estimated (``dt_{n-2}``, compared with ``dt_{n-1}`` and ``dt_n``)."""
    deepest = min(math.floor(math.log2(DT0 / floor) + 1e-9), MAX_HALVINGS)
    tolerance = 1e-6
    # the error C*dt**p just meets the tolerance at dt_level, and at no coarser candidate
    level = {"never": None, "one_below": deepest - 1, "at_the_floor": deepest - 2}[reach]
    constant = 1e30 if level is None else 0.999 * tolerance / (SAFETY * (DT0 / 2 ** level)
                                                               ** ORDER)
    choice, calls = _search([constant], tolerance, fallback=True, finest=floor)
    integrated = sorted({dt for dt, _ in calls})
    assert integrated[0] >= floor and integrated[0] == DT0 / 2 ** deepest
    assert integrated == [DT0 / 2 ** j for j in range(deepest, -1, -1)]
    assert choice.dt >= floor and all(h[0] >= floor for h in choice.history)
    # the record's reference is the finest step integrated, met or not
    assert choice.reference_dt == integrated[0]
    if reach == "at_the_floor":
        assert choice.met and choice.dt == DT0 / 2 ** level
    else:
        # the fallback names the finest candidate whose error was estimated, dt_{n-2}
        assert not choice.met and choice.dt == floor
        assert f"no step down to {DT0 / 2 ** (deepest - 2):.3g} s" in choice.notes[-1]


def test_no_trusted_bin_is_an_error_or_the_fallback():
    def run(dt, cases):
        return [0.0 for _ in cases]

    options = dict(run=run, compare=lambda a, b: math.nan, dt0=DT0, order=ORDER,
                   measure="transmissibility_db", tolerance=0.01, sample_rate=1000.0,
                   solver="ode3", probe=None, probe_duration=10.0, band=(1.0, 20.0),
                   stability_limit=0.005)
    with pytest.raises(ParameterError, match="no bin of the band"):
        search(**options)
    choice = search(**options, fallback=True)
    assert not choice.met and "no bin of the band" in choice.notes[-1]


def test_halving_search_is_the_one_loop_on_given_differences():
    differences = {j: 1e6 * (DT0 / 2 ** j) ** ORDER * (1 - 2.0 ** -ORDER) for j in range(9)}
    chosen, history = halving_search(lambda j: differences[j], ORDER, 1e-3, DT0, 8)
    assert DT0 / 2 ** chosen == _expected_step(1e6, 1e-3)
    assert [h[0] for h in history] == [DT0 / 2 ** j for j in range(chosen + 1)]


def test_the_record_reads_the_same_from_the_choice_and_from_its_attributes():
    choice, _ = _search([1e6], 1e-3)
    attributes = choice.attributes()
    assert attributes["step"] == "accuracy-driven"
    assert attributes["step_error_db"] == choice.error
    assert record_line({"dt": choice.dt, **attributes}) == choice.line()
    assert "accuracy-driven" in choice.line() and "dB" in choice.line()
    record = choice.to_dict()
    assert record["chosen"] and record["met"] and record["unit"] == "dB"
    literal = StepChoice.literal(2e-4)
    assert literal.attributes() == {"step": "given"} and "given" in literal.line()
    fallback, _ = _search([1e12], 1e-12, fallback=True)
    assert fallback.attributes()["step"] == "fallback"
    assert fallback.attributes()["step_reason"] == fallback.notes[-1]
    assert "fallback" in fallback.line()


def test_a_hopeless_case_leaves_the_search_at_once_and_a_reachable_one_does_not():
    """``give_up_early``: a case whose estimate, brought down at the scheme's order to the
    finest candidate compared (``dt_{max_halvings-2}``), still exceeds the tolerance is
    integrated only for the first comparison (dt_0, dt_1, dt_2), not at every candidate as
    without the early exit; a case that meets the tolerance just at that finest candidate is
    not given up."""
    tolerance, halvings = 1e-3, 8
    finest = DT0 / 2 ** (halvings - 2)
    ok, hopeless = 1e3, 1e12
    assert SAFETY * hopeless * finest ** ORDER > tolerance  # no candidate can meet it

    def integrations(calls, case):
        return sorted((dt for dt, c in calls if c == case), reverse=True)

    choice, calls = _search([ok, hopeless], tolerance, give_up_early=True,
                            max_halvings=halvings)
    assert integrations(calls, 1) == [DT0, DT0 / 2, DT0 / 4]
    assert choice.unmet == (1,) and choice.dt == _expected_step(ok, tolerance, halvings)
    patient, calls = _search([ok, hopeless], tolerance, give_up_early=False,
                             max_halvings=halvings)
    assert integrations(calls, 1) == [DT0 / 2 ** j for j in range(halvings + 1)]
    assert patient.unmet == (1,) and patient.dt == choice.dt
    # meets the tolerance at the finest candidate compared, and at no coarser one
    reachable = 0.999 * tolerance / (SAFETY * finest ** ORDER)
    late, calls = _search([ok, reachable], tolerance, give_up_early=True,
                          max_halvings=halvings)
    assert late.dt == finest == _expected_step(reachable, tolerance, halvings)
    assert late.unmet == ()


def test_an_unmet_case_s_note_names_the_finest_candidate_estimated_as_the_fallback_does():
    """A case whose differences never shrink is searched to the end: its note names the
    finest candidate whose error was estimated (the last in the history, the one compared
    with two finer runs), the step the one-case fallback sentence names too."""
    stuck = [0.0]

    def run(dt, cases):
        return [1e3 * dt ** ORDER if c == 0 else (stuck.__setitem__(0, stuck[0] + 1) or stuck[0])
                for c in cases]

    mixed = search(run=run, compare=lambda a, b: abs(a - b), cases=2, dt0=DT0,
                   order=ORDER, measure="transmissibility_db", tolerance=1e-3,
                   sample_rate=1000.0, solver="ode3", probe=None, probe_duration=10.0,
                   band=(1.0, 20.0), stability_limit=0.005, labels=["ok", "stuck"])
    finest = min(dt for dt, _, _ in mixed.history)
    note, = [note for note in mixed.notes if note.startswith("stuck:")]
    assert f"no step down to {finest:.3g} s meets" in note
    alone, _ = _search([1e12], 1e-12, fallback=True)
    assert f"no step down to {min(dt for dt, _, _ in alone.history):.3g} s met" in alone.notes[-1]
