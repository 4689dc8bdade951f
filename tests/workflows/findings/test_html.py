"""The paper's report.html (qzs.workflows.findings.html): its settings and case tables."""
import numpy as np

from qzs.workflows.paper.studies import CaseResult, Study, StudyResult


def study(name, cases):
    """A transmissibility study of ``cases`` (no simulation)."""
    definition = Study(name=name, title=name, kind="transmissibility",
                       cases=tuple({} for _ in cases))
    return StudyResult(definition, list(cases), quick=True)


def case(label, settings):
    """A case with every metric undefined, its statistics and linear model written down."""
    frequency = np.linspace(0.1, 20.0, 50)
    return CaseResult(label, dict(settings), frequency, np.ones(frequency.size),
                      np.ones(frequency.size), frequency > 0,
                      metrics={"resonance_frequency": np.nan},
                      reasons={"resonance_frequency": "no peak on the trusted bins"},
                      stats={"stop_contacts": 0, "locked_fraction": 0.1},
                      linear={"undamped_natural_frequency": 0.2})


def test_the_report_says_why_its_chirp_and_natural_frequency_differ_from_the_papers_text():
    """2015.232 s is what 122 Welch averages of 32768 samples at 1 kHz with 50 % overlap
    need (required_duration); the table's f_n has the PI's Kp as a spring, the paper's
    0.08 Hz is the passive isolator's, which the note computes independently."""
    import math

    from qzs.analysis.spectral import required_duration
    from qzs.model.isolator import IsolatorParameters, passive_natural_frequency
    from qzs.model.controller import ControllerParameters
    from qzs.workflows.findings.html import case_table, settings_table

    needed = required_duration(32768, 122, 1000.0, 0.5)
    assert math.isclose(needed, 2015.232)
    run = dict(solver="ode3", dt=1e-4, sample_rate=1000.0, chirp_amplitude=0.01, chirp_f0=0.0,
               chirp_f1=20.0, chirp_duration=needed, window="hann", fft_length=32768,
               n_averages=122, overlap=0.5, coherence_min=0.9, base_share_min=1e-3)
    result = study("a", [case("Kp 50", {"pi_kp": 50.0})])
    result.cases[0].run = run
    text = settings_table(result)
    assert "not the paper's 2000 s" in text and "122 complete Welch averages of 32768" in text
    result.cases[0].run = dict(run, chirp_duration=2000.0)
    assert "not the paper's" not in settings_table(result)
    table = case_table(result)
    passive = passive_natural_frequency(IsolatorParameters(),
                                        ControllerParameters().position_setpoint)
    assert "f_n with PI [Hz]" in table and "0.08 Hz" in table
    assert f"{passive:.3g} Hz for Kp 50" in table and 0.07 <= passive <= 0.09
    # an undefined metric: a dash with its reason as the table's numbered note
    assert "&mdash;<sup>1</sup>" in table and "<li>no peak on the trusted bins</li>" in table


def test_the_case_table_gives_the_locked_time_in_percent():
    """A locked fraction of 0.1 [-] is 10.0 % in the "locked [%]" column."""
    from qzs.workflows.findings.html import case_table

    table = case_table(study("a", [case("Kp 50", {"pi_kp": 50.0})]))
    assert "locked [%]" in table and ">10.0<" in table and ">0.1<" not in table
