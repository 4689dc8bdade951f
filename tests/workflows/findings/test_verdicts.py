"""Each of the paper's claims decided on synthetic cases: built to be reproduced, then flipped.

No simulation: every case is a :class:`CaseResult` whose curve, trusted bins, metrics and
statistics are written down, so each test knows the verdict the data must give. Each
reproduced variant also carries untrusted bins whose values would flip the verdict if
they were used.
"""
import random
import types

import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.model.excitation import Chirp
from qzs.workflows.findings.verdicts import CLAIMS, TREND_CLAIMS, decide_claims
from qzs.workflows.paper.studies import CLAIMS as STATEMENTS
from qzs.workflows.paper.studies import CaseResult, Study, StudyResult, load_study

FREQUENCY = np.round(np.arange(0.0, 20.0 + 1e-9, 0.05), 10)  # [Hz]


def curve(level_low, level_high=None, corner=3.0, slope=-1.0):
    """T = level_low up to ``corner`` [Hz], then ``level_high * (f/corner)**slope``."""
    level_high = level_low if level_high is None else level_high
    f = np.maximum(FREQUENCY, 1e-9)
    return np.where(f <= corner, level_low, level_high * (f / corner) ** slope)


def case(label, settings, magnitude=None, *, trusted=None, metrics=None, stats=None, linear=None,
         extra=None):
    magnitude = curve(0.8) if magnitude is None else magnitude
    trusted = FREQUENCY > 0 if trusted is None else trusted
    return CaseResult(label, dict(settings), FREQUENCY, np.asarray(magnitude, float),
                      np.where(trusted, 1.0, 0.1), trusted,
                      metrics={"resonance_frequency": np.nan, "isolation_onset": 1.0,
                               **(metrics or {})},
                      stats={"stop_contacts": 0, "z_min": -0.07, "z_max": -0.05,
                             "locked_fraction": 0.1, "locked_fraction_below_half_hz": 1.0,
                             "n_averages": 12, **(stats or {})},
                      linear={"undamped_natural_frequency": 0.2,
                              "magnitude": np.ones(FREQUENCY.size), **(linear or {})},
                      extra=extra or {})


def study(name, claims, cases, kind="transmissibility"):
    definition = Study(name=name, title=name, kind=kind, cases=tuple({} for _ in cases),
                       claims=tuple(claims))
    return StudyResult(definition, list(cases), quick=True)


def verdict(result, claim):
    found = [v for v in decide_claims([result]) if v.claim == claim]
    assert len(found) == 1
    return found[0]


def untrusted_at(frequencies):
    """Every bin above 0 Hz trusted, except those nearest ``frequencies`` [Hz]."""
    trusted = FREQUENCY > 0
    for f in frequencies:
        trusted[np.argmin(np.abs(FREQUENCY - f))] = False
    return trusted


def with_spike(magnitude, frequency, value):
    out = np.array(magnitude, dtype=float)
    out[np.argmin(np.abs(FREQUENCY - frequency))] = value
    return out


# ---------------------------------------------------------------- resonance_masked
def masked_cases(locked=(0.3, 0.95, 1.0, 1.0), resonance=(np.nan,) * 4):
    return [case(f"Fs = {fs:g} N", {"stiction_force": fs},
                 stats={"locked_fraction_below_half_hz": lf},
                 metrics={"resonance_frequency": r, "isolation_onset": 1.0 + fs / 10})
            for fs, lf, r in zip((2.0, 5.0, 10.0, 15.0), locked, resonance)]


def test_resonance_masked_follows_the_locked_fraction():
    assert verdict(study("s", ["resonance_masked"], masked_cases()), "resonance_masked").label \
        == "reproduced"
    # a case with Fs >= 5 N that is not locked at low frequency: not masked
    flipped = study("s", ["resonance_masked"], masked_cases(locked=(0.3, 0.95, 0.5, 1.0)))
    assert verdict(flipped, "resonance_masked").label == "not reproduced"
    # Fs = 2 N is below the masking threshold: its locked fraction does not matter
    weak = study("s", ["resonance_masked"], masked_cases(locked=(0.0, 0.95, 1.0, 1.0)))
    assert verdict(weak, "resonance_masked").label == "reproduced"


def test_resonance_masked_flips_on_a_trusted_low_frequency_peak():
    peaked = study("s", ["resonance_masked"],
                   masked_cases(resonance=(np.nan, np.nan, 0.3, np.nan)))
    assert verdict(peaked, "resonance_masked").label == "not reproduced"
    # a peak at the break-away, above 1 Hz, is not the passive resonance
    breakaway = study("s", ["resonance_masked"],
                      masked_cases(resonance=(np.nan, np.nan, np.nan, 2.4)))
    assert verdict(breakaway, "resonance_masked").label == "reproduced"


def test_resonance_masked_is_not_decidable_without_strong_stiction():
    weak = study("s", ["resonance_masked"], masked_cases()[:1])
    assert verdict(weak, "resonance_masked").label == "not decidable"


# ---------------------------------------------------------------- pi_resonance_range
def pi_cases(fns=(0.12, 0.21, 0.45, 2.0), low=(0.80, 0.80, 0.81, 0.95),
             high=(0.20, 0.20, 0.20, 0.21), contacts=(0, 0, 0, 0), spike=None):
    cases = []
    for i, (kp, ki) in enumerate(((2.0, 1.0), (10.0, 4.0), (50.0, 20.0), (1000.0, 400.0))):
        magnitude = curve(low[i], high[i], corner=4.0, slope=0.0)
        magnitude = np.where(FREQUENCY > 8.0, high[i], magnitude)
        trusted = FREQUENCY > 0
        if spike is not None and i == spike:
            magnitude = with_spike(magnitude, 2.0, 30.0)
            trusted = untrusted_at([2.0])
        cases.append(case(f"Kp = {kp:g} N/m", {"pi_kp": kp, "pi_ki": ki}, magnitude,
                          trusted=trusted, linear={"undamped_natural_frequency": fns[i]},
                          stats={"stop_contacts": contacts[i]}))
    return cases


def test_pi_resonance_range_follows_the_linear_natural_frequencies():
    result = study("p", ["pi_resonance_range"], pi_cases())
    assert verdict(result, "pi_resonance_range").label == "reproduced"
    out = study("p", ["pi_resonance_range"], pi_cases(fns=(0.12, 0.6, 0.45, 2.0)))
    assert verdict(out, "pi_resonance_range").label == "not reproduced"
    # the excessive Kp = 1000 N/m is outside the claim's range of gains
    assert verdict(study("p", ["pi_resonance_range"], pi_cases(fns=(0.12, 0.21, 0.45, 9.0))),
                   "pi_resonance_range").label == "reproduced"
    # one gain set cannot show the resonance moving
    one = study("p", ["pi_resonance_range"], pi_cases()[:1])
    assert verdict(one, "pi_resonance_range").label == "not decidable"


# ---------------------------------------------------------------- pi_low_frequency
def test_pi_low_frequency_reproduced_and_flipped():
    # the lowest gains carry an untrusted spike in 0.5-4 Hz that would spoil them if used
    assert verdict(study("p", ["pi_low_frequency"], pi_cases(spike=0)),
                   "pi_low_frequency").label == "reproduced"
    not_spoiled = pi_cases(low=(0.80, 0.80, 0.81, 0.82))
    assert verdict(study("p", ["pi_low_frequency"], not_spoiled), "pi_low_frequency").label \
        == "not reproduced"
    # a low gain set that already spoils it: "barely affected by low gains" fails
    middle = pi_cases(low=(0.80, 0.90, 0.81, 0.95))
    assert verdict(study("p", ["pi_low_frequency"], middle), "pi_low_frequency").label \
        == "not reproduced"
    unheld = pi_cases(contacts=(5, 0, 0, 0))
    assert verdict(study("p", ["pi_low_frequency"], unheld), "pi_low_frequency").label \
        == "not reproduced"
    spread = pi_cases(high=(0.20, 0.20, 0.20, 0.30))
    assert verdict(study("p", ["pi_low_frequency"], spread), "pi_low_frequency").label \
        == "not reproduced"


# ---------------------------------------------------------------- stiction_low_frequency
def stiction_cases(levels=(0.80, 0.82, 0.85, 0.90), onsets=(0.9, 1.4, 1.9, 2.4), spike=True):
    cases = []
    for i, (fs, level, onset) in enumerate(zip((2.0, 5.0, 10.0, 15.0), levels, onsets)):
        magnitude, trusted = curve(level, corner=3.0), FREQUENCY > 0
        if spike and i == 0:  # an untrusted bin that would make Fs = 2 N the highest
            magnitude, trusted = with_spike(magnitude, 2.0, 50.0), untrusted_at([2.0])
        cases.append(case(f"Fs = {fs:g} N", {"stiction_force": fs}, magnitude, trusted=trusted,
                          metrics={"isolation_onset": onset}))
    return cases


def test_stiction_low_frequency_reproduced_from_trusted_bins_only():
    result = study("s", ["stiction_low_frequency"], stiction_cases())
    assert verdict(result, "stiction_low_frequency").label == "reproduced"


def test_stiction_low_frequency_flips_when_the_trend_reverses():
    falling = stiction_cases(levels=(0.90, 0.85, 0.82, 0.80))
    assert verdict(study("s", ["stiction_low_frequency"], falling),
                   "stiction_low_frequency").label == "not reproduced"
    narrower = stiction_cases(onsets=(2.4, 1.9, 1.4, 0.9))
    assert verdict(study("s", ["stiction_low_frequency"], narrower),
                   "stiction_low_frequency").label == "not reproduced"


def test_stiction_trend_is_decided_over_every_case_not_the_ends():
    """First < last, but a middle case breaks the rise: not reproduced."""
    middle = stiction_cases(levels=(0.80, 0.95, 0.85, 0.90))
    assert verdict(study("s", ["stiction_low_frequency"], middle),
                   "stiction_low_frequency").label == "not reproduced"
    onset = stiction_cases(onsets=(0.9, 2.6, 1.9, 2.7))
    assert verdict(study("s", ["stiction_low_frequency"], onset),
                   "stiction_low_frequency").label == "not reproduced"


def test_stiction_trend_follows_the_parameter_not_the_file_order():
    cases = stiction_cases()
    random.Random(3).shuffle(cases)
    assert [c.settings["stiction_force"] for c in cases] != [2.0, 5.0, 10.0, 15.0]
    assert verdict(study("s", ["stiction_low_frequency"], cases),
                   "stiction_low_frequency").label == "reproduced"


# ---------------------------------------------------------------- viscous_high_frequency
def viscous_cases(levels=(0.10, 0.20, 0.40), spike=True):
    cases = []
    for i, (cv, level) in enumerate(zip((50.0, 100.0, 200.0), levels)):
        magnitude = np.where(FREQUENCY < 5.0, 1.0, level)
        trusted = FREQUENCY > 0
        if spike and i == 0:  # untrusted bins around 12 Hz that would make Cv = 50 the highest
            magnitude = np.where(np.abs(FREQUENCY - 12.0) < 0.06, 5.0, magnitude)
            trusted = untrusted_at([11.95, 12.0, 12.05])
        cases.append(case(f"Cv = {cv:g} N s/m", {"viscous_damping": cv}, magnitude,
                          trusted=trusted))
    return cases


def test_viscous_high_frequency_reproduced_and_flipped():
    result = study("v", ["viscous_high_frequency"], viscous_cases(spike=False))
    assert verdict(result, "viscous_high_frequency").label == "reproduced"
    falling = study("v", ["viscous_high_frequency"], viscous_cases(levels=(0.4, 0.2, 0.1),
                                                                    spike=False))
    assert verdict(falling, "viscous_high_frequency").label == "not reproduced"
    middle = study("v", ["viscous_high_frequency"], viscous_cases(levels=(0.1, 0.5, 0.4),
                                                                   spike=False))
    assert verdict(middle, "viscous_high_frequency").label == "not reproduced"


def test_viscous_claim_never_reads_an_untrusted_bin():
    """T(12 Hz) of the first case lies only in untrusted bins: not decidable, never a number."""
    result = study("v", ["viscous_high_frequency"], viscous_cases())
    found = verdict(result, "viscous_high_frequency")
    assert found.label == "not decidable" and "T(12 Hz)" in found.evidence


# ---------------------------------------------------------------- trends need three cases
@pytest.mark.parametrize("claim, builder", [
    ("stiction_low_frequency", stiction_cases),
    ("viscous_high_frequency", lambda: viscous_cases(spike=False)),
    ("pi_low_frequency", pi_cases),
])
def test_a_trend_from_two_cases_is_not_decidable(claim, builder):
    cases = builder()
    two = [cases[0], cases[-1]]
    found = verdict(study("t", [claim], two), claim)
    assert found.label == "not decidable" and found.decidable is False
    assert found.reproduced is not True
    assert "at least 3 cases" in found.evidence
    # three cases with the same parameter value are no trend either
    same = [case(c.label, {**c.settings, TREND_CLAIMS[claim]: 7.0}) for c in cases]
    assert verdict(study("t", [claim], same), claim).label == "not decidable"


# ---------------------------------------------------------------- no_pi_stops
def no_pi_cases(without=120, with_pi=0):
    return [case("no PI", {"pi_kp": 0.0, "pi_ki": 0.0}, stats={"stop_contacts": without}),
            case("PI", {"pi_kp": 5.0, "pi_ki": 2.0}, stats={"stop_contacts": with_pi})]


def test_no_pi_stops_reproduced_and_flipped():
    assert verdict(study("n", ["no_pi_stops"], no_pi_cases()), "no_pi_stops").label \
        == "reproduced"
    assert verdict(study("n", ["no_pi_stops"], no_pi_cases(without=0)), "no_pi_stops").label \
        == "not reproduced"
    assert verdict(study("n", ["no_pi_stops"], no_pi_cases(with_pi=3)), "no_pi_stops").label \
        == "not reproduced"
    # the order of the cases does not matter, a missing side makes it undecidable
    assert verdict(study("n", ["no_pi_stops"], no_pi_cases()[::-1]), "no_pi_stops").label \
        == "reproduced"
    assert verdict(study("n", ["no_pi_stops"], no_pi_cases()[:1]), "no_pi_stops").label \
        == "not decidable"


# ---------------------------------------------------------------- damping_small_effect
def damping_cases(reductions_db=(1.0, 2.0), spike=True):
    reference = curve(1.0, 0.6, corner=2.0)
    cases = [case("Kd = 0 N s/m", {"damping_gain": 0.0}, reference)]
    for kd, db in zip((20.0, 50.0), reductions_db):
        magnitude, trusted = reference * 10 ** (-db / 20), FREQUENCY > 0
        if spike and kd == 50.0:  # an untrusted bin reduced by 30 dB
            magnitude = with_spike(magnitude, 6.0, reference[120] * 10 ** (-30 / 20))
            trusted = untrusted_at([6.0])
        cases.append(case(f"Kd = {kd:g} N s/m", {"damping_gain": kd}, magnitude, trusted=trusted))
    return cases


def test_damping_small_effect_reproduced_and_flipped():
    assert verdict(study("d", ["damping_small_effect"], damping_cases()),
                   "damping_small_effect").label == "reproduced"
    assert verdict(study("d", ["damping_small_effect"], damping_cases((1.0, 4.0))),
                   "damping_small_effect").label == "not reproduced"
    assert verdict(study("d", ["damping_small_effect"], damping_cases()[1:]),
                   "damping_small_effect").label == "not decidable"


def test_damping_verdict_shows_both_metrics_and_is_partly_when_they_disagree():
    """A 6 dB dip in one bin: a large per-bin reduction, a small band-RMS change."""
    cases = damping_cases((0.0, 0.0), spike=False)
    cases[2].magnitude = with_spike(cases[2].magnitude, 6.0,
                                    cases[0].magnitude[120] * 10 ** (-6 / 20))
    found = verdict(study("d", ["damping_small_effect"], cases), "damping_small_effect")
    assert found.label == "partly reproduced"
    assert "largest per-bin reduction of T 0, 6 dB" in found.evidence
    assert "change of the band RMS" in found.evidence and "docs/design.md" in found.evidence
    assert "per bin not small, over the band small" in found.evidence


# ---------------------------------------------------------------- experiment_shape
def processing_case(peak=2.0, t12=0.3, rising=False, spike=True):
    f = np.maximum(FREQUENCY, 1e-9)
    bump = 1.0 + 0.5 * np.exp(-((f - peak) / 0.3) ** 2)
    slope = 1.0 if rising else -1.0
    tail = np.where(f > 4.0, t12 * (f / 12.0) ** slope, t12 * (4.0 / 12.0) ** slope)
    magnitude = np.maximum(bump * (f < 4.0), tail)
    trusted = FREQUENCY >= 1.5
    if spike:  # untrusted: a tall peak at 5 Hz and a high value at 12 Hz
        magnitude = with_spike(with_spike(magnitude, 5.0, 40.0), 12.0, 3.0)
        trusted = trusted & untrusted_at([5.0, 12.0])
    extra = {"frequency": FREQUENCY, "magnitude": magnitude, "trusted": trusted,
             "highpass": 1.0, "n_averages": 29}
    return case("Kp = 50 N/m", {"pi_kp": 50.0}, extra=extra)


def test_experiment_shape_reproduced_partly_and_not():
    result = study("p", ["experiment_shape"], [processing_case(spike=False)], kind="processing")
    assert verdict(result, "experiment_shape").label == "reproduced"
    one_off = study("p", ["experiment_shape"], [processing_case(t12=0.6, spike=False)],
                    kind="processing")
    assert verdict(one_off, "experiment_shape").label == "partly reproduced"
    all_off = study("p", ["experiment_shape"],
                    [processing_case(peak=3.8, t12=0.05, rising=True, spike=False)],
                    kind="processing")
    assert verdict(all_off, "experiment_shape").label == "not reproduced"


def test_experiment_shape_ignores_untrusted_bins():
    """An untrusted peak at 5 Hz and an untrusted bin at 12 Hz: T(12 Hz) is undecidable."""
    result = study("p", ["experiment_shape"], [processing_case()], kind="processing")
    found = verdict(result, "experiment_shape")
    assert found.label == "not decidable" and "12 Hz" in found.evidence
    shifted = processing_case(spike=False)
    shifted.extra["magnitude"] = with_spike(shifted.extra["magnitude"], 5.0, 40.0)
    shifted.extra["trusted"] = shifted.extra["trusted"] & untrusted_at([5.0])
    found = verdict(study("p", ["experiment_shape"], [shifted], kind="processing"),
                    "experiment_shape")
    assert found.label == "reproduced", found.evidence


# ---------------------------------------------------------------- ids and the table
def test_every_claim_has_a_statement_and_a_decision():
    assert set(CLAIMS) == set(STATEMENTS)
    assert set(TREND_CLAIMS) <= set(CLAIMS)


def test_a_claim_is_decided_by_each_study_that_names_it_only():
    named = study("mine", ["no_pi_stops"], no_pi_cases())
    silent = study("other", [], no_pi_cases())
    verdicts = decide_claims([named, silent])
    assert [(v.claim, v.study) for v in verdicts] == [("no_pi_stops", "mine")]


def test_unknown_claim_id_names_the_file_the_id_and_the_known_ids(tmp_path):
    path = tmp_path / "typo.toml"
    path.write_text("[study]\nname='x'\nkind='transmissibility'\n"
                    "claims=['no_pi_stop']\n[[case]]\nlabel='a'\n")
    with pytest.raises(ParameterError) as error:
        load_study(path)
    message = str(error.value)
    assert str(path) in message and "'no_pi_stop'" in message
    assert all(claim in message for claim in CLAIMS)
    path.write_text("[study]\nname='x'\nkind='transmissibility'\nclaims='no_pi_stops'\n"
                    "[[case]]\nlabel='a'\n")
    with pytest.raises(ParameterError, match="must be a list of claim ids"):
        load_study(path)


def test_a_stiction_trend_that_levels_off_does_not_fall():
    """"Must not fall": two cases with the same low-frequency level, or the same onset,
    keep the trend reproduced."""
    flat = stiction_cases(levels=(0.80, 0.85, 0.85, 0.90), onsets=(0.9, 1.4, 1.4, 2.4))
    assert verdict(study("s", ["stiction_low_frequency"], flat),
                   "stiction_low_frequency").label == "reproduced"


def test_a_case_with_an_integral_gain_alone_has_pi():
    """"Without PI" is Kp = Ki = 0: an integral-only loop (Kp = 0, Ki > 0) is a PI case,
    so its holding the payload off the stops reproduces the claim."""
    cases = [*no_pi_cases(), case("I only", {"pi_kp": 0.0, "pi_ki": 2.0},
                                  stats={"stop_contacts": 0})]
    assert verdict(study("n", ["no_pi_stops"], cases), "no_pi_stops").label == "reproduced"
