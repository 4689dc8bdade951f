"""Design problem files (qzs.workflows.design_space.problem): what they resolve to, and every
mistake refused with its table, key, value and fix before anything runs."""
import copy

import numpy as np
import pytest

from qzs.errors import CountLimitError, ProblemError
from qzs.workflows.design_space.problem import load_problem, plan_text

BASE = {
    "problem": {"name": "base", "title": "a small problem"},
    "variables": {"damping_gain": {"low": 0.0, "high": 300.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "uncertain": {"stiction_force": {"distribution": "uniform", "low": 5.0, "high": 15.0}},
    "robust": {"samples": 4, "seed": 3},
    "excitation": {"duration": 20.0},
    "simulation": {"dt": 1e-3},
    "analysis": {"fft_length": 4096, "duration": 20.0},
    "objectives": [{"metric": "transmissibility_at", "frequency": 12.0, "statistic": "worst"},
                   {"metric": "motor_force_rms"}],
    "constraints": [{"metric": "peak_stroke", "max": 0.02, "statistic": "worst"},
                    {"metric": "hunting_amplitude", "max": 0.001}],
}


def changed(**tables):
    document = copy.deepcopy(BASE)
    for name, value in tables.items():
        if value is None:
            document.pop(name, None)
        else:
            document[name] = value
    return document


def test_a_problem_resolves_its_goals_and_the_sweep_that_evaluates_them():
    problem = load_problem(BASE)
    assert [v.name for v in problem.variables] == ["damping_gain", "pi_kp"]
    assert problem.variables[1].search_bounds == (0.0, 3.0)  # log10 of 1 .. 1000 N/m
    assert problem.variables[0].units == "N*s/m"
    assert problem.columns == ("transmissibility_at_12_hz", "motor_force_rms", "peak_stroke",
                               "hunting_amplitude")
    outputs = problem.sweep.outputs
    assert outputs["stats"] == ["motor_force_rms", "peak_stroke"]
    assert outputs["metrics"] == ["transmissibility_at_12_hz"]
    assert problem.sweep.analysis["at_frequencies"] == [12.0]
    assert not outputs["transmissibility"]  # no curve kept: metrics only
    assert problem.objectives[0].label == "transmissibility_at_12_hz_worst"
    assert problem.constraints[0].describe() == "peak_stroke (worst case) <= 0.02 m"
    assert problem.hash == load_problem(copy.deepcopy(BASE)).hash
    assert problem.hash != load_problem(changed(robust={"samples": 5, "seed": 3})).hash


def test_the_draws_are_common_random_numbers_stratified_by_the_latin_hypercube():
    problem = load_problem(changed(robust={"samples": 8, "seed": 3}))
    first, again = problem.draws(), problem.draws()
    assert np.array_equal(first["stiction_force"], again["stiction_force"])
    # one draw in each eighth of 5..15 N
    strata = np.floor((first["stiction_force"] - 5.0) / 10.0 * 8).astype(int)
    assert sorted(strata) == list(range(8))


def test_a_list_of_values_is_drawn_in_equal_shares():
    problem = load_problem(changed(uncertain={"mass": {"values": [6.0, 6.4, 6.8]}},
                                   robust={"samples": 9}))
    values, counts = np.unique(problem.draws()["mass"], return_counts=True)
    assert values.tolist() == [6.0, 6.4, 6.8] and counts.tolist() == [3, 3, 3]


BAD = [
    ("unknown parameter", {"variables": {"pi_kpp": {"low": 1.0, "high": 2.0}}},
     "variables", "pi_kpp", "not a parameter"),
    ("empty bounds", {"variables": {"pi_kp": {"low": 5.0, "high": 5.0}}},
     "variables", "pi_kp", "empty bounds"),
    ("reversed bounds", {"variables": {"pi_kp": {"low": 50.0, "high": 5.0}}},
     "variables", "pi_kp", "empty bounds"),
    ("log scale through zero", {"variables": {"pi_kp": {"low": 0.0, "high": 5.0,
                                                        "scale": "log"}}},
     "variables.pi_kp", "low", "log scale needs `low` > 0"),
    ("no variables", {"variables": {}}, "variables", "", "at least one decision variable"),
    ("an objective that is not a metric", {"objectives": [{"metric": "transmissibilty"}]},
     "objectives[0]", "metric", "not a metric"),
    ("no objective", {"objectives": None}, "objectives", "", "at least one objective"),
    ("a frequency missing", {"objectives": [{"metric": "transmissibility_at"}]},
     "objectives[0]", "frequency", "needs `frequency`"),
    ("a frequency outside the band",
     {"objectives": [{"metric": "transmissibility_at", "frequency": 80.0}]},
     "objectives[0]", "frequency", "analysis band"),
    ("a bad statistic", {"objectives": [{"metric": "peak_stroke", "statistic": "median"}]},
     "objectives[0]", "statistic", "must be one of"),
    ("a constraint without a bound", {"constraints": [{"metric": "peak_stroke"}]},
     "constraints[0]", "max", "exactly one of `max`"),
    ("an infeasible constraint set",
     {"constraints": [{"metric": "peak_stroke", "max": 0.01},
                      {"metric": "peak_stroke", "min": 0.02}]},
     "constraints", "peak_stroke", "infeasible"),
    ("a bound the metric never meets",
     {"constraints": [{"metric": "saturated_fraction", "max": -0.1}]},
     "constraints", "saturated_fraction", "never below 0"),
    ("a share above one", {"constraints": [{"metric": "locked_fraction", "min": 1.5}]},
     "constraints", "locked_fraction", "never above 1"),
    ("searched and uncertain",
     {"uncertain": {"pi_kp": {"distribution": "uniform", "low": 1.0, "high": 2.0}}},
     "uncertain", "pi_kp", "also a decision variable"),
    ("a bad distribution",
     {"uncertain": {"stiction_force": {"distribution": "triangular", "low": 1.0}}},
     "uncertain", "stiction_force", "unknown distribution"),
    ("a statistic without uncertainty",
     {"uncertain": None, "robust": None}, "objectives", "transmissibility_at_12_hz",
     "needs [uncertain]"),
    ("an unknown table", {"optimiser": {"population": 10}}, "top level", "optimiser",
     "unknown key"),
    ("a goal key misspelt", {"objectives": [{"metric": "peak_stroke", "sens": "minimize"}]},
     "objectives[0]", "sens", "unknown key"),
    ("a tiny population", {"optimizer": {"population": 2}}, "optimizer", "population",
     "at least 4"),
    ("a bad sensitivity method", {"sensitivity": {"method": "fast"}}, "sensitivity",
     "method", "must be one of"),
    ("an excitation key it does not know", {"excitation": {"frequenz": 3.0}},
     "parameters, excitation, simulation or analysis", "", "frequenz"),
    # the shared checks of qzs._validation, with the table: text is not a number there either
    ("a bound given as text", {"variables": {"pi_kp": {"low": "1", "high": 10.0}}},
     "variables.pi_kp", "low", "must be a number"),
    ("an infinite bound", {"variables": {"pi_kp": {"low": 1.0, "high": float("inf")}}},
     "variables.pi_kp", "high", "must be finite"),
    ("a fractional count of draws", {"robust": {"samples": 2.5}}, "robust", "samples",
     "must be an integer >= 1"),
]


@pytest.mark.parametrize("what, tables, table, key, fix", BAD, ids=[b[0] for b in BAD])
def test_a_bad_problem_is_refused_naming_table_key_value_and_fix(what, tables, table, key, fix):
    with pytest.raises(ProblemError) as caught:
        load_problem(changed(**tables))
    error = caught.value
    assert (error.table, error.key) == (table, key)
    assert fix in error.fix
    assert error.source == "problem definition"
    shown = table if "[" in table else f"[{table}]"
    assert str(error).startswith(f"problem definition: {shown}")


def test_too_many_draws_are_refused_before_any_draw():
    with pytest.raises(CountLimitError):
        load_problem(changed(robust={"samples": 10 ** 7}))


def test_a_problem_file_names_itself_in_the_error(tmp_path):
    import tomli_w

    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(changed(variables={"pi_kp": {"low": 2.0, "high": 1.0}})))
    with pytest.raises(ProblemError, match="bad.toml") as caught:
        load_problem(path)
    assert caught.value.value == [2.0, 1.0]


def test_a_missing_file_is_a_problem_error(tmp_path):
    with pytest.raises(ProblemError, match="no_such"):
        load_problem(tmp_path / "no_such.toml")


def test_the_plan_counts_the_cases_and_steps():
    text = plan_text(load_problem(BASE))
    # 64 designs x 4 draws per generation, 20 generations, 20 s at 1 ms
    assert "256 cases per generation" in text
    assert f"about {20 * 256 * 20 / 1e-3:.3g} integration steps" in text


def test_a_block_s_parameter_is_a_design_variable_by_its_dotted_name():
    """``compensation.fraction`` (an unquoted dotted key in a problem file reads the same)
    is a variable with its unit; its cases are the default loop plus that compensation; a
    bound outside the block's range is refused naming it."""
    import tomllib

    import qzs
    from qzs.workflows.design_space.evaluation import case_settings
    from qzs.workflows.sweeps.cases import build_model

    variables = tomllib.loads("compensation.fraction = { low = 0.0, high = 1.2 }\n"
                              "pi_kp = { low = 20.0, high = 80.0 }\n")
    problem = load_problem(changed(variables=variables))
    assert [v.name for v in problem.variables] == ["compensation.fraction", "pi_kp"]
    assert problem.variables[0].units == "-"
    (case, *_) = case_settings(problem, np.array([[0.6, 40.0]]))
    _, controller = build_model(problem.sweep, case)
    assert controller == qzs.PIDamping(pi_kp=40.0) + qzs.FrictionCompensation(fraction=0.6)
    with pytest.raises(ProblemError) as error:
        load_problem(changed(variables={"compensation.fraction": {"low": 0.0, "high": 2.0}}))
    assert "compensation.fraction" in str(error.value) and "1.5" in str(error.value)


def test_a_spring_law_s_parameter_is_a_design_variable_of_the_problem_s_law(tmp_path):
    """A problem file with a [spring] table (a polynomial, docs/model.md §3.1) searches its
    ``spring.c1`` (an unquoted dotted key): a case's isolator carries that law with the
    design's coefficient, and the linear metric follows it: the loop's linear
    transmissibility equals the scalar linearisation of that law (python-level
    ``qzs.linearize``), and a stiffer spring moves it."""
    import qzs
    from qzs.workflows.design_space.evaluation import case_settings, evaluate_batch
    from qzs.workflows.sweeps.cases import build_model

    path = tmp_path / "duffing.toml"
    path.write_text(
        '[problem]\nname = "duffing"\n'
        '[spring]\nlaw = "polynomial"\ncoefficients = [62.78, -100.0, 0.0, -5e4]\n'
        'center = -0.06\n'
        '[variables]\nspring.c1 = { low = -400.0, high = -10.0 }\n'
        'pi_kp = { low = 20.0, high = 80.0 }\n'
        '[[objectives]]\nmetric = "linear_transmissibility_at"\nfrequency = 3.0\n')
    problem = load_problem(path)
    assert [v.name for v in problem.variables] == ["spring.c1", "pi_kp"]
    assert problem.variables[0].units == "N/m"
    settings = case_settings(problem, np.array([[-300.0, 40.0], [-20.0, 40.0]]))
    isolator, controller = build_model(problem.sweep, settings[0])
    assert isolator.spring == qzs.PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -5e4),
                                                   center=-0.06)
    got = evaluate_batch(problem, 0, settings, problem.columns, threads=1)
    column = problem.columns[0]
    for case, values in zip(settings, got["values"][column]):
        iso, con = build_model(problem.sweep, case)
        assert values == pytest.approx(qzs.linearize(iso, con).transmissibility(3.0),
                                       rel=1e-9)
    assert abs(got["values"][column][0] - got["values"][column][1]) > 0.01


@pytest.mark.parametrize("spring, variables, fix", [
    (None, {"spring.preload": {"low": 50.0, "high": 70.0}}, "MagSpring's tanh"),
    ({"law": "oblique"}, {"spring.c3": {"low": 0.0, "high": 1.0}},
     "no parameter of this 'oblique' spring law"),
    ({"law": "oblique"}, {"spring.free_length": {"low": -1.0, "high": 0.2}}, "must be positive"),
    ({"law": "cubic"}, {"pi_kp": {"low": 1.0, "high": 2.0}}, "law = one of"),
])
def test_a_spring_variable_the_law_cannot_take_is_refused_naming_it(spring, variables, fix):
    document = changed(variables=variables, spring=spring)
    with pytest.raises(ProblemError, match=fix) as error:
        load_problem(document)
    assert error.value.table in ("variables", "spring")


def test_an_uncertain_spring_parameter_the_law_lacks_is_refused_in_its_table():
    """[uncertain] names ``spring.*`` as [variables] does (docs/model.md §3.1): the MagSpring's
    tanh has none, so an uncertain ``spring.preload`` is refused in [uncertain], naming it."""
    document = changed(uncertain={"spring.preload": {"distribution": "uniform",
                                                     "low": 55.0, "high": 65.0}})
    with pytest.raises(ProblemError, match="MagSpring's tanh") as error:
        load_problem(document)
    assert (error.value.table, error.value.key) == ("uncertain", "spring.preload")


def test_a_table_law_s_csv_is_read_beside_the_problem_file(tmp_path, monkeypatch):
    """A [spring] table law's ``csv`` is relative to the problem file wherever it is read
    from; the problem's sweep carries that law."""
    import qzs

    folder = tmp_path / "design"
    folder.mkdir()
    (folder / "curve.csv").write_text("position [m],force [N]\n-0.1,40.0\n-0.05,62.0\n0.0,80.0\n")
    path = folder / "table.toml"
    path.write_text('[problem]\nname = "table"\n'
                    '[spring]\nlaw = "table"\ncsv = "curve.csv"\noutside = "extend"\n'
                    '[variables]\npi_kp = { low = 20.0, high = 80.0 }\n'
                    '[[objectives]]\nmetric = "motor_force_rms"\n')
    monkeypatch.chdir(tmp_path)
    problem = load_problem(path)
    assert problem.sweep.spring == qzs.TabulatedSpring(positions=(-0.1, -0.05, 0.0),
                                                       forces=(40.0, 62.0, 80.0),
                                                       outside="extend")
