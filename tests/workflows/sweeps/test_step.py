"""A sweep's integration step (qzs.workflows.sweeps.step): without ``dt``, the smallest of
the steps chosen on the first, middle and last cases, deterministic; a case no step settles
is named and the others set the step."""
import pytest

from qzs.workflows.sweeps.definition import load_sweep, plan_text, sample_cases

QUICK = {"fft_length": 1024, "n_averages": 4}


def definition(**tables):
    document = {"sweep": {"name": "t"}, "analysis": dict(QUICK)}
    for key, value in tables.items():
        document[key] = {**document.get(key, {}), **value}
    return document


def test_without_dt_the_step_is_chosen_for_the_tolerance_before_any_case_runs():
    """No `dt`: the sweep's step is the smallest of the steps choose_step picks on the first,
    middle and last cases; deterministic; a fixed `dt` is kept as given."""
    from qzs.engine.accuracy import choose_step
    from qzs.workflows.sweeps.cases import build_case, case_settings
    from qzs.workflows.sweeps.step import choose_sweep_step

    document = definition(grid={"stiction_force": [2.0, 15.0]},
                          analysis={"fft_length": 2048, "n_averages": 6},
                          simulation={"tolerance": 0.05})
    sweep = load_sweep(document)
    assert sweep.simulation["dt"] is None and "chosen at run time" in plan_text(sweep)
    settings = case_settings(sweep, sample_cases(sweep))
    chosen, choices = choose_sweep_step(sweep, settings)
    assert [i for i, _ in choices] == [0, 1]
    isolator, controller, (excitation, _), _ = build_case(sweep, settings[1])
    direct = choose_step(excitation, isolator, controller, tolerance=0.05)
    assert chosen.simulation["dt"] == min(c.dt for _, c in choices) <= direct.dt
    from qzs.engine.accuracy import SAFETY

    assert all(c.error * SAFETY <= 0.05 for _, c in choices)
    assert "0.05 dB" in chosen.simulation["step_note"]
    assert choose_sweep_step(sweep, settings)[0].simulation["dt"] == chosen.simulation["dt"]
    fixed = load_sweep(definition(grid={"stiction_force": [2.0]}, simulation={"dt": 2e-4}))
    assert choose_sweep_step(fixed, case_settings(fixed, sample_cases(fixed)))[0] is fixed


def test_a_case_no_step_can_settle_is_named_and_the_others_set_the_step():
    """Without the PI loop the payload falls onto the stop and every refinement redraws its
    bounces: no step meets the tolerance there. The sweep warns, names the case in its note,
    and takes the step of the cases that converge."""
    from qzs import DataWarning
    from qzs.workflows.sweeps.cases import case_settings
    from qzs.workflows.sweeps.step import choose_sweep_step

    sweep = load_sweep(definition(grid={"pi_kp": [0.0, 50.0]}, parameters={"pi_ki": 0.0},
                                  analysis={"fft_length": 2048, "n_averages": 6}))
    settings = case_settings(sweep, sample_cases(sweep))
    with pytest.warns(DataWarning, match="case 0: no step"):
        chosen, choices = choose_sweep_step(sweep, settings)
    assert [i for i, _ in choices] == [1]
    assert chosen.simulation["dt"] == choices[0][1].dt
    assert "case 0: no step" in chosen.simulation["step_note"]


def test_the_sweep_takes_the_finest_of_its_probed_cases_steps():
    """A soft and a stiff PI loop: the stiff one needs a finer step for the same tolerance;
    every case of the sweep runs at the step of the one that needs it most."""
    from qzs.workflows.sweeps.cases import case_settings
    from qzs.workflows.sweeps.step import choose_sweep_step

    sweep = load_sweep(definition(grid={"pi_kp": [2000.0, 2e5]},
                                  simulation={"tolerance": 0.01}))
    chosen, choices = choose_sweep_step(sweep, case_settings(sweep, sample_cases(sweep)))
    steps = [c.dt for _, c in choices]
    assert len(set(steps)) == 2  # the two cases' own steps differ
    assert chosen.simulation["dt"] == min(steps)
