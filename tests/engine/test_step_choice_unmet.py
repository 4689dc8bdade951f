"""The one meaning of an unmet tolerance: the sweeps, the design, the paper's studies and the
page all show the same sentence (StepChoice.unmet_note, made by
qzs.engine.step_choice.unmet_sentence) for the same unmet choice."""
import warnings

import pytest

from qzs import Chirp
from engine.search_probe import search
from qzs.errors import DataWarning


@pytest.fixture()
def unmet(monkeypatch):
    """A genuine fallback record of the one search over two cases (differences that never
    shrink), returned by every call of ``choose``."""
    import qzs.engine.step_choice as step_choice

    choice = search(run=lambda dt, cases: [dt] * len(cases),
                         compare=lambda coarse, fine: 1.0, cases=2, dt0=1e-3, order=3,
                         measure="transmissibility_db", tolerance=0.01, sample_rate=1000.0,
                         solver="ode3", probe=Chirp(f1=5.0, duration=20.0), probe_duration=20.0,
                         band=(1.0, 5.0), stability_limit=2e-3, fallback=True, per_case=True,
                         labels=["a", "b"])
    assert not choice.met and choice.unmet_note
    monkeypatch.setattr(step_choice, "choose", lambda request, probe, **kw: choice)
    return choice


def _sweeps():
    from qzs.workflows.sweeps.cases import case_settings
    from qzs.workflows.sweeps.definition import load_sweep, sample_cases
    from qzs.workflows.sweeps.step import choose_sweep_step

    sweep = load_sweep({"sweep": {"name": "t"}, "grid": {"stiction_force": [2.0, 15.0]},
                        "analysis": {"fft_length": 1024, "n_averages": 4},
                        "simulation": {"tolerance": 0.01}})
    with pytest.warns(DataWarning):
        chosen, _ = choose_sweep_step(sweep, case_settings(sweep, sample_cases(sweep)))
    return chosen.simulation["step_note"]


def _design():
    from qzs.workflows.design.inputs import _design_settings
    from qzs.workflows.design.integration_step import choose_dt

    settings = _design_settings(
        None, None, excitation=Chirp(duration=60.0), stiction_range=(8.0, 12.0),
        mass_range=(6.4, 6.4), force_steps=(2.0,), band=(1.0, 20.0), cost="rms",
        controller_rate=None, delay=0.0, quick=True, dt=1e-3, damping_gain_max=300.0,
        gain_margin_min=6.0, phase_margin_min=30.0, workers=1, progress=False)
    return choose_dt(settings, settings.controller.pi_kp)[1]


def _paper():
    from qzs.engine.step_choice import StepRequest
    from qzs.workflows.paper.studies import _choose_steps, _study_cases, load_study

    cases = _study_cases(load_study("stiction"), True)
    _, (record,) = _choose_steps([cases], StepRequest(), 1, False)
    assert record["source"] == "fallback"
    return "; ".join(record["notes"])


def _page(choice):
    from qzs.app.compute import _step_note

    return _step_note(choice)


def test_every_caller_shows_the_one_sentence_for_an_unmet_tolerance(unmet):
    sentence = unmet.unmet_note
    shown = {"sweeps": _sweeps(), "design": _design(), "paper": _paper(), "page": _page(unmet)}
    assert all(sentence in text for text in shown.values()), shown
    assert shown["page"] == shown["paper"] == sentence


def test_a_met_or_literal_step_shows_no_unmet_sentence():
    from qzs.app.compute import _step_note
    from qzs.engine.step_search import StepChoice

    assert _step_note(StepChoice.literal(1e-3)) == ""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        met = search(run=lambda dt, cases: [dt] * len(cases),
                          compare=lambda coarse, fine: 1e-3 * coarse, dt0=1e-3, order=3,
                          measure="state_m", tolerance=1.0, sample_rate=1000.0, solver="ode3",
                          probe=None, probe_duration=1.0, band=None, stability_limit=2e-3)
    assert met.met and met.unmet_note == "" and _step_note(met) == ""
