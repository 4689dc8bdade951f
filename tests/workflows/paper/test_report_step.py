"""The paper at its chosen step against the paper's own dt = 1e-4 s (docs/workflows/paper.md,
"The integration step"): the shortened paper (``--quick``) is run at both steps, and every
claim's verdict must be equal and every tabulated number agree within its criterion.

The criteria, per kind of number, for a tolerance ``tol`` on the transmissibility [dB]:

* a transmissibility (T at the reported frequencies, T at the peak): within ``tol`` dB;
* a frequency (peak, isolation onset, -3 dB point, the trusted range): within one Welch bin,
  ``sample_rate / fft_length`` (a crossing read between two bins may move by one);
* the roll-off slope [dB/decade]: within ``4 tol``, what an error of ``tol`` in every bin
  can change a least-squares slope over half a decade or more;
* a count (hard-stop contacts): equal;
* a share (the time locked, overall and below 0.5 Hz): within ``10**(tol/20) - 1``, the
  relative change of an amplitude the tolerance allows (0.0012 at 0.01 dB);
* a number that does not depend on the step (the linearised natural frequency, the spring
  fit): equal;
* whether a number is defined on the trusted bins: the same at both steps.

The numbers of a case no step meets the tolerance for (the paper's case without PI: its
payload rides on the hard stops, its stop contacts differ between any two steps, the
paper's own and half of it included) are left out; its verdict is compared like every other.
"""
import math

import numpy as np
import pytest

from qzs.defaults import ACCURACY, SIMULATION
from qzs.workflows.paper.report import decide_claims
from qzs.workflows.paper.report_step import AGREEMENT_TEST, step_record
from qzs.workflows.paper.studies import load_study, run_studies, shipped_studies

TRANSMISSIBILITY = ("resonance_peak",)
FREQUENCY = ("resonance_frequency", "isolation_onset", "minus_3db_frequency", "trusted_from",
             "trusted_to", "untrusted_below")
SLOPE = ("rolloff_db_per_decade",)
SHARES = ("locked_fraction", "locked_fraction_below_half_hz")
COUNTS = ("stop_contacts",)


def kind(name):
    """The criterion a metric falls under (every metric has one)."""
    if name in TRANSMISSIBILITY or name.startswith("transmissibility_at_"):
        return "transmissibility"
    if name in FREQUENCY:
        return "frequency"
    if name in SLOPE:
        return "slope"
    if name in ("spring_force", "spring_shape"):
        return "exact"
    raise AssertionError(f"no criterion for the metric {name!r}: add it to this test and to "
                         "docs/workflows/paper.md")


def disagreement(name, chosen, paper, tolerance, bin_width):
    """Why ``chosen`` and ``paper`` (the values of metric ``name``) disagree, or None."""
    if not (np.isfinite(chosen) and np.isfinite(paper)):
        return None if np.isfinite(chosen) == np.isfinite(paper) else "defined at one step only"
    how = kind(name)
    if how == "transmissibility":
        off = abs(20 * math.log10(chosen / paper))
        return None if off <= tolerance else f"{off:.3g} dB > {tolerance:g} dB"
    if how == "frequency":
        off = abs(chosen - paper)
        return None if off <= bin_width * (1 + 1e-9) else f"{off:.3g} Hz > one bin {bin_width:.3g} Hz"
    if how == "slope":
        off = abs(chosen - paper)
        return None if off <= 4 * tolerance else f"{off:.3g} dB/decade > {4 * tolerance:g}"
    return None if chosen == paper else f"{chosen!r} != {paper!r}"


@pytest.fixture(scope="module")
def both():
    """The quick paper at the chosen step and at the paper's own: (chosen, paper) results."""
    studies = [load_study(path) for path in shipped_studies()]
    chosen = run_studies(studies, quick=True, progress=False)
    paper = run_studies(studies, quick=True, progress=False, dt=SIMULATION["dt"])
    return chosen, paper


def test_the_criteria_catch_a_disagreement():
    """Each criterion fails just beyond its bound (the test can fail)."""
    tol = ACCURACY["tolerance_db"]
    assert disagreement("transmissibility_at_12_hz", 0.2 * 10 ** (1.01 * tol / 20), 0.2, tol, 0.06)
    assert not disagreement("transmissibility_at_12_hz", 0.2 * 10 ** (0.99 * tol / 20), 0.2, tol,
                            0.06)
    assert disagreement("isolation_onset", 1.0 + 0.07, 1.0, tol, 0.06)
    assert not disagreement("isolation_onset", 1.0 + 0.06, 1.0, tol, 0.06)
    assert disagreement("rolloff_db_per_decade", -20.0 + 4.1 * tol, -20.0, tol, 0.06)
    assert disagreement("resonance_frequency", 1.0, float("nan"), tol, 0.06)
    assert not disagreement("resonance_frequency", float("nan"), float("nan"), tol, 0.06)
    with pytest.raises(AssertionError, match="no criterion"):
        kind("a_new_metric")


@pytest.mark.slow
def test_the_chosen_step_is_coarser_than_the_papers_and_says_so(both):
    chosen, _ = both
    record = step_record(chosen)
    assert AGREEMENT_TEST.endswith("test_report_step.py")
    assert record["steps"] and all(step["source"] == "chosen" for step in record["steps"])
    for step in record["steps"]:
        assert step["dt"] > SIMULATION["dt"]  # else this test compares nothing
        assert 0 <= step["estimated_error_db"] <= ACCURACY["tolerance_db"]
    assert [d["case"] for d in record["step_dependent"]] == ["no PI (Kp = 0, Ki = 0)"]
    assert "agrees with the paper's own step" in record["statement"]


@pytest.mark.slow
def test_every_verdict_is_the_papers_own_steps(both):
    chosen, paper = both
    a, b = decide_claims(chosen), decide_claims(paper)
    assert [(v.claim, v.study) for v in a] == [(v.claim, v.study) for v in b]
    assert [v.label for v in a] == [v.label for v in b]


@pytest.mark.slow
def test_every_tabulated_number_agrees_within_its_criterion(both):
    chosen, paper = both
    tol = ACCURACY["tolerance_db"]
    share = 10 ** (tol / 20) - 1
    problems, compared = [], 0
    for mine, theirs in zip(chosen, paper):
        dependent = set(mine.step.get("unmet", ()))
        for case, reference in zip(mine.cases, theirs.cases):
            assert case.label == reference.label
            if case.label in dependent:
                continue
            bin_width = (case.run["sample_rate"] / case.run["fft_length"]) if case.run else 0.0
            pairs = [(name, case.metrics[name], reference.metrics[name])
                     for name in case.metrics]
            if "metrics" in case.extra:
                pairs += [(name, case.extra["metrics"][name], reference.extra["metrics"][name])
                          for name in case.extra["metrics"]]
            for name, a, b in pairs:
                why = disagreement(name, a, b, tol, bin_width)
                compared += 1
                if why:
                    problems.append(f"{mine.study.name}/{case.label} {name}: {a!r} against "
                                    f"{b!r}: {why}")
            for name in COUNTS + SHARES:
                if name not in case.stats:
                    continue
                a, b = case.stats[name], reference.stats[name]
                compared += 1
                bound = 0 if name in COUNTS else share
                if not (abs(a - b) <= bound or (np.isnan(a) and np.isnan(b))):
                    problems.append(f"{mine.study.name}/{case.label} {name}: {a!r} against "
                                    f"{b!r} (allowed {bound:g})")
            if case.linear:
                compared += 1
                if (case.linear["undamped_natural_frequency"]
                        != reference.linear["undamped_natural_frequency"]):
                    problems.append(f"{case.label}: linear natural frequency differs")
    assert compared > 200
    assert not problems, "\n".join(problems)


def _result(name, **step):
    """A StudyResult of no case, with the step record ``step``."""
    from qzs.workflows.paper.studies import Study, StudyResult

    return StudyResult(Study(name=name, title=name, kind="transmissibility", cases=()), [],
                       quick=True, step=step)


def chosen_step(tolerance, unmet=(), seconds=1.0, group=0):
    return dict(dt=1e-3, source="chosen", tolerance_db=tolerance, estimated_error_db=0.002,
                reference_dt=2.5e-4, probe_duration=60.0, unmet=list(unmet), notes=[],
                seconds=seconds, group=group)


def test_the_statement_claims_agreement_only_where_the_test_checks_it():
    """At the default tolerance the statement claims the agreement the test checks; at
    another it says the check is at the default only; a given step claims nothing."""
    tol = ACCURACY["tolerance_db"]
    default = step_record([_result("a", **chosen_step(tol, unmet=["no PI"])),
                           _result("b", **chosen_step(tol, seconds=2.0, group=1))])
    assert len(default["steps"]) == 1 and default["steps"][0]["studies"] == ["a", "b"]
    assert default["steps"][0]["seconds"] == 3.0  # two choices, one per group
    assert default["step_dependent"] == [{"study": "a", "case": "no PI"}]
    assert "agrees with the paper's own step" in default["statement"]
    assert "no PI (a)" in default["statement"]
    other = step_record([_result("a", **chosen_step(10 * tol))])["statement"]
    assert "agrees" not in other and f"at the default {tol:g} dB only" in other
    given = step_record([_result("a", dt=SIMULATION["dt"], source="given")])["statement"]
    assert "the paper's own" in given and "as given" in given and "agrees" not in given


def test_a_step_read_from_the_step_cache_says_so_and_only_when_every_group_was():
    tol = ACCURACY["tolerance_db"]
    both = step_record([_result("a", **chosen_step(tol), cached=True),
                        _result("b", **chosen_step(tol, group=1), cached=True)])
    assert both["steps"][0]["cached"] and "read from the step cache" in both["statement"]
    assert "to choose" not in both["statement"]
    one = step_record([_result("a", **chosen_step(tol), cached=True),
                       _result("b", **chosen_step(tol, seconds=2.0, group=1), cached=False)])
    assert not one["steps"][0]["cached"] and "3.0 s to choose" in one["statement"]
