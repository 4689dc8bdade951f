"""Sweep definitions: validation messages, grids, random and Latin-hypercube sampling.

No simulation runs here (see test_init.py).
"""
import math

import numpy as np
import pytest
from scipy import stats

from qzs import ParameterError
from qzs.workflows.sweeps.definition import (
    DISTRIBUTIONS,
    METHODS,
    draw_samples,
    load_sweep,
    plan_text,
    sample_cases,
    shipped_sweeps,
)

QUICK = {"fft_length": 1024, "n_averages": 4}


def definition(**tables):
    document = {"sweep": {"name": "t"}, "analysis": dict(QUICK)}
    for key, value in tables.items():
        document[key] = {**document.get(key, {}), **value}
    return document


def raises(document, *patterns):
    with pytest.raises(ParameterError) as info:
        load_sweep(document)
    message = str(info.value)
    for pattern in patterns:
        assert pattern in message, message
    assert isinstance(info.value, ValueError)
    return message


# ---------------------------------------------------------------- malformed files
def test_unknown_parameter_lists_the_valid_names():
    message = raises(definition(grid={"pi_kpp": [1.0, 2.0]}), "unknown parameter 'pi_kpp'",
                     "pi_kp", "stiction_force", "excitation.amplitude", "excitation.f1")
    assert "excitation.frequency" not in message  # a chirp has no `frequency`


def test_unknown_fixed_parameter_and_unknown_table_and_key():
    raises(definition(parameters={"stiffness": 1.0}), "unknown key(s) ['stiffness']",
           "[parameters]", "stiction_force")
    raises({**definition(grid={"pi_kp": [1.0]}), "grids": {}}, "unknown key(s) ['grids']")
    raises(definition(grid={"pi_kp": [1.0]}, analysis={"fft": 8}), "[analysis]",
           "fft_length")
    raises(definition(grid={"pi_kp": [1.0]}, outputs={"stats": ["peak"]}),
           "unknown stats ['peak']", "peak_stroke")


@pytest.mark.parametrize("spec", [[], {"start": 1.0, "stop": 2.0, "num": 0},
                                  {"start": 2.0, "stop": 1.0, "step": 0.5}])
def test_empty_range_is_an_error(spec):
    raises(definition(grid={"pi_kp": spec}), "empty range for 'pi_kp'")


def test_a_number_given_as_text_is_refused_as_the_api_and_problem_files_refuse_it():
    """One check of a real number everywhere (qzs._validation.real): text is not a number."""
    raises(definition(grid={"pi_kp": {"start": "1", "stop": 2.0, "num": 3}}),
           "`pi_kp.start` must be a number, got '1'")
    raises(definition(grid={"pi_kp": [1.0]}, simulation={"dt": "1e-4"}),
           "`dt` must be a number, got '1e-4'")
    raises(definition(grid={"pi_kp": [1.0]}, simulation={"dt": 0.0}), "`dt` must be positive")


def test_malformed_range():
    raises(definition(grid={"pi_kp": {"start": 1.0, "stop": 2.0}}), "one of `num` or `step`")
    raises(definition(grid={"pi_kp": {"start": 0.0, "stop": 2.0, "num": 3, "scale": "log"}}),
           "log range", "`start` > 0")
    raises(definition(grid={"pi_kp": 3.0}), "list of values or a table")


def test_bad_distribution_names_the_allowed_ones_and_their_keys():
    sample = {"sweep": {"name": "t", "method": "lhs", "samples": 8}}
    message = raises({**definition(distributions={"mass": {"distribution": "gamma", "a": 2}}),
                      **sample}, "unknown distribution 'gamma'", "uniform", "normal",
                     "lognormal", "loguniform")
    assert "median" in message and "std" in message
    raises({**definition(distributions={"mass": {"distribution": "normal", "mean": 6.4}}),
            **sample}, "required are ['mean', 'std']", "missing key(s) ['std']")
    raises({**definition(distributions={"mass": {"distribution": "uniform", "low": 7.0,
                                                 "high": 6.0}}), **sample}, "`low` < `high`")
    raises({**definition(distributions={"mass": {"distribution": "lognormal", "median": 6.4,
                                                 "sigma": -1.0}}), **sample},
           "`mass.sigma` must be positive")
    raises({**definition(distributions={"mass": 6.4}), **sample}, "`distribution` key")


def test_bad_sampling_method_and_method_mismatches():
    raises(definition(sweep={"method": "sobol"}, grid={"pi_kp": [1.0]}), "`method` must be one",
           *[repr(m) for m in METHODS])
    raises(definition(distributions={"mass": {"distribution": "uniform", "low": 6.0,
                                              "high": 7.0}}), "[distributions] needs")
    raises(definition(sweep={"method": "random"}, grid={"pi_kp": [1.0]}),
           "needs a [distributions] table")
    raises(definition(sweep={"method": "lhs"},
                      distributions={"mass": {"distribution": "uniform", "low": 6.0,
                                              "high": 7.0}}), "`samples` must be an integer")
    raises(definition(), "nothing varies")


def test_fixed_and_varied_conflicts_and_invalid_fixed_values():
    raises(definition(parameters={"pi_kp": 5.0}, grid={"pi_kp": [1.0]}), "both fixed and varied")
    raises(definition(parameters={"mass": -1.0}, grid={"pi_kp": [1.0]}), "mass")
    raises(definition(excitation={"kind": "square"}, grid={"pi_kp": [1.0]}), "`kind` must be")
    raises(definition(excitation={"frequency": 2.0}, grid={"pi_kp": [1.0]}), "[excitation]")


def test_the_tolerance_key_and_its_deprecated_name_tolerance_db():
    """[simulation] writes `tolerance` [dB]; `tolerance_db` is read one release more, with a
    DeprecationWarning naming `tolerance`; the store keeps its `tolerance_db` (the schema)."""
    import warnings

    grid = {"pi_kp": [1.0]}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        new = load_sweep(definition(grid=grid, simulation={"tolerance": 0.2}))
    with pytest.warns(DeprecationWarning, match="`tolerance_db` is deprecated.*use `tolerance`"):
        old = load_sweep(definition(grid=grid, simulation={"tolerance_db": 0.2}))
    assert new.simulation["tolerance_db"] == old.simulation["tolerance_db"] == 0.2
    assert new.simulation["dt"] is old.simulation["dt"] is None
    raises(definition(grid=grid, simulation={"tolerance": 0.2, "tolerance_db": 0.2}),
           "give `tolerance` only")
    for path in shipped_sweeps():  # the shipped files say `tolerance`
        assert "tolerance_db" not in path.read_text(encoding="utf-8"), path


def test_analysis_and_simulation_checks():
    raises(definition(grid={"pi_kp": [1.0]}, analysis={"sample_rate": 3000.0},
                      simulation={"dt": 1e-4}), "`sample_rate` (3000.0 Hz) must divide")
    raises(definition(grid={"pi_kp": [1.0]}, simulation={"dt": 1e-4, "tolerance": 0.1}),
           "either `dt`", "`tolerance`")
    raises(definition(grid={"pi_kp": [1.0]}, simulation={"tolerance": -1.0}),
           "`tolerance`")
    raises(definition(grid={"pi_kp": [1.0]}, simulation={"solver": "rk45"}), "`solver`")
    raises(definition(grid={"pi_kp": [1.0]}, analysis={"duration": 10.0}),
           "either `n_averages` or `duration`")
    raises(definition(grid={"pi_kp": [1.0]}, outputs={"bands": {"low": [0.01, 0.02]}}),
           "holds no frequency bin")


def test_missing_file_lists_the_shipped_sweeps(tmp_path):
    with pytest.raises(ParameterError, match="shipped sweeps are .*pi_vs_stiction"):
        load_sweep(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[sweep\n")
    with pytest.raises(ParameterError, match="not valid TOML"):
        load_sweep(bad)
    wrong = tmp_path / "wrong.toml"
    wrong.write_text("[grid]\npi_kpp = [1.0]\n")
    with pytest.raises(ParameterError, match=r"wrong\.toml.*unknown parameter 'pi_kpp'"):
        load_sweep(wrong)


def test_the_shipped_example_loads():
    assert [p.stem for p in shipped_sweeps()] == ["pi_vs_stiction"]
    sweep = load_sweep("pi_vs_stiction")
    assert sweep.n_cases == 8 * 3 * 5
    assert sweep.analysis["duration"] == pytest.approx(131.072)
    assert "120 cases" in plan_text(sweep)


# ---------------------------------------------------------------- grids
def test_grid_is_the_full_product_in_order_with_excitation_axes_slowest():
    sweep = load_sweep(definition(grid={
        "pi_kp": [1.0, 2.0, 3.0], "stiction_force": {"start": 5.0, "stop": 15.0, "num": 3},
        "excitation.amplitude": [0.005, 0.010], "pi_ki": {"start": 1.0, "stop": 100.0,
                                                          "num": 3, "scale": "log"}}))
    cases = sample_cases(sweep)
    assert sweep.n_cases == 3 * 3 * 2 * 3 == cases["pi_kp"].size
    assert list(cases) == ["excitation.amplitude", "pi_kp", "stiction_force", "pi_ki"]
    np.testing.assert_allclose(cases["pi_ki"][:3], [1.0, 10.0, 100.0])
    np.testing.assert_array_equal(cases["excitation.amplitude"][:27], 0.005)
    points = set(zip(*(cases[k].tolist() for k in cases)))
    assert len(points) == sweep.n_cases


def test_step_range_includes_its_end():
    sweep = load_sweep(definition(grid={"pi_kp": {"start": 0.0, "stop": 1.0, "step": 0.25}}))
    np.testing.assert_allclose(sample_cases(sweep)["pi_kp"], [0, 0.25, 0.5, 0.75, 1.0])


def test_string_values_on_a_grid():
    sweep = load_sweep(definition(grid={"stop_model": ["compliant", "plastic"]}))
    assert sample_cases(sweep)["stop_model"].tolist() == ["compliant", "plastic"]


# ---------------------------------------------------------------- sampling
UNIFORM = {"x": ("uniform", {"low": 2.0, "high": 6.0})}


@pytest.mark.parametrize("n", [7, 50])
def test_latin_hypercube_puts_one_sample_in_each_stratum(n):
    two = {**UNIFORM, "y": ("loguniform", {"low": 1.0, "high": 100.0})}
    draws = draw_samples(two, n, "lhs", seed=3)
    x_strata = np.floor((draws["x"] - 2.0) / 4.0 * n).astype(int)
    y_strata = np.floor(np.log10(draws["y"]) / 2.0 * n).astype(int)
    for strata in (x_strata, y_strata):
        np.testing.assert_array_equal(np.sort(strata), np.arange(n))


def test_random_sampling_is_not_stratified_but_in_range():
    draws = draw_samples(UNIFORM, 200, "random", seed=3)["x"]
    assert 2.0 <= draws.min() and draws.max() <= 6.0
    assert np.unique(np.floor((draws - 2.0) / 4.0 * 200)).size < 200


@pytest.mark.parametrize("method", ["random", "lhs"])
def test_seeds_reproduce_and_differ(method):
    a = draw_samples(UNIFORM, 20, method, seed=1)["x"]
    np.testing.assert_array_equal(a, draw_samples(UNIFORM, 20, method, seed=1)["x"])
    assert not np.allclose(a, draw_samples(UNIFORM, 20, method, seed=2)["x"])


@pytest.mark.parametrize("method", ["random", "lhs"])
def test_distribution_moments(method):
    spec = {"u": ("uniform", {"low": 5.0, "high": 15.0}),
            "n": ("normal", {"mean": 100.0, "std": 10.0}),
            "l": ("lognormal", {"median": 6.4, "sigma": 0.1}),
            "t": ("normal", {"mean": 0.0, "std": 1.0, "low": -1.0, "high": 2.0}),
            "g": ("loguniform", {"low": 1.0, "high": 1000.0})}
    d = draw_samples(spec, 4000, method, seed=11)
    tolerance = 0.05  # relative, loose enough for 4000 independent draws
    assert d["u"].mean() == pytest.approx(10.0, rel=tolerance / 5)
    assert d["u"].std() == pytest.approx(10.0 / math.sqrt(12), rel=tolerance)
    assert d["n"].mean() == pytest.approx(100.0, rel=tolerance / 5)
    assert d["n"].std() == pytest.approx(10.0, rel=tolerance)
    assert np.median(d["l"]) == pytest.approx(6.4, rel=tolerance / 5)
    assert np.log(d["l"]).std() == pytest.approx(0.1, rel=tolerance)
    assert -1.0 <= d["t"].min() and d["t"].max() <= 2.0
    assert d["t"].mean() == pytest.approx(stats.truncnorm(-1.0, 2.0).mean(), abs=0.03)
    assert np.log10(d["g"]).mean() == pytest.approx(1.5, rel=tolerance)
    assert set(DISTRIBUTIONS) == {"uniform", "normal", "lognormal", "loguniform"}


def test_samples_are_crossed_with_the_grid_as_common_random_numbers():
    sweep = load_sweep(definition(
        sweep={"method": "lhs", "samples": 5, "seed": 4}, grid={"pi_kp": [1.0, 2.0, 3.0]},
        distributions={"stiction_force": {"distribution": "uniform", "low": 5.0,
                                          "high": 15.0}}))
    cases = sample_cases(sweep)
    assert sweep.n_cases == 15
    np.testing.assert_array_equal(cases["pi_kp"], np.repeat([1.0, 2.0, 3.0], 5))
    np.testing.assert_array_equal(cases["sample"], np.tile(np.arange(5), 3))
    stiction = cases["stiction_force"].reshape(3, 5)
    np.testing.assert_array_equal(stiction[0], stiction[2])
    assert sweep.hash == load_sweep(dict(sweep.document)).hash


# ---------------------------------------------------------------- too many cases, at once
@pytest.mark.parametrize("tables, name", [
    (dict(grid={"pi_kp": {"start": 1.0, "stop": 100.0, "num": 10 ** 8}}), "[grid] pi_kp.num"),
    (dict(grid={"pi_kp": {"start": 0.0, "stop": 1e8, "step": 1.0}}), "[grid] pi_kp.step"),
    (dict(grid={"pi_kp": {"start": 1.0, "stop": 100.0, "num": 10 ** 4},
                "stiction_force": {"start": 5.0, "stop": 15.0, "num": 10 ** 4}}), "[grid]"),
    (dict(sweep={"method": "random", "samples": 10 ** 8},
          distributions={"pi_kp": {"distribution": "uniform", "low": 1.0, "high": 2.0}}),
     "[sweep] samples"),
])
def test_a_sweep_of_1e8_cases_fails_before_building_any(tables, name):
    """The count is known from the file: nothing is built, so the error comes at once."""
    import time

    from qzs.errors import CountLimitError
    from qzs.workflows.sweeps.definition import MAX_CASES

    began = time.perf_counter()
    with pytest.raises(CountLimitError) as caught:
        load_sweep(definition(**tables))
    assert time.perf_counter() - began < 1.0
    error = caught.value
    assert (error.name, error.limit, error.items) == (name, MAX_CASES, "cases")
    assert error.count >= 10 ** 8 and f"`{name}`" in str(error) and "split" in str(error)


@pytest.mark.parametrize("spring, grid, message", [
    (None, {"spring.preload": [60.0, 62.0]}, "MagSpring's tanh"),
    ({"law": "polynomial", "coefficients": [62.78, -100.0]}, {"spring.preload": [60.0, 62.0]},
     "no parameter of this 'polynomial' spring law"),
])
def test_a_varied_spring_parameter_the_law_lacks_is_refused_before_any_run(spring, grid,
                                                                            message):
    """``spring.*`` names a parameter of the sweep's [spring] law (docs/model.md §3.1): one
    the law has not is refused when the file is read, naming it and the fix."""
    from qzs.workflows.sweeps import load_sweep

    document = {"sweep": {"name": "s"}, "grid": grid,
                **({"spring": spring} if spring else {})}
    with pytest.raises(ParameterError, match=message):
        load_sweep(document)



def test_a_fixed_spring_parameter_applies_to_the_sweep_s_law_and_is_checked_on_reading():
    """[parameters] may fix a ``spring.*`` of the [spring] law (docs/model.md §3.1): the file
    reads, a case's isolator has the law with that value, and a value the law refuses is
    refused on reading, naming it."""
    import dataclasses

    import qzs
    from qzs.workflows.sweeps.cases import build_model

    spring = {"law": "oblique", "vertical_stiffness": "quasi-zero"}
    sweep = load_sweep(definition(spring=spring, parameters={"spring.preload": 61.0},
                                  grid={"mass": [6.0, 7.0]}))
    isolator, _ = build_model(sweep, {"mass": 7.0})
    assert isolator.mass == 7.0
    assert isolator.spring == dataclasses.replace(qzs.ObliqueSpringQZS.quasi_zero(),
                                                  preload=61.0)
    raises(definition(spring=spring, parameters={"spring.free_length": -1.0},
                      grid={"mass": [6.0, 7.0]}), "`spring.free_length` must be positive")


def test_a_spring_parameter_drawn_from_a_distribution_the_law_lacks_is_refused_on_reading():
    """[distributions] names ``spring.*`` as [grid] does: the MagSpring's tanh has none, so a
    random sweep over ``spring.preload`` without a [spring] law is refused on reading."""
    document = definition(sweep={"method": "random", "samples": 4, "seed": 1},
                          distributions={"spring.preload": {"distribution": "uniform",
                                                            "low": 55.0, "high": 65.0}})
    raises(document, "`spring.preload`", "MagSpring's tanh")


def test_a_table_law_s_csv_is_read_beside_the_sweep_file(tmp_path, monkeypatch):
    """A [spring] table law's ``csv`` is relative to the sweep file, wherever the sweep is
    read from (docs/model.md §3.1)."""
    import qzs

    folder = tmp_path / "study"
    folder.mkdir()
    (folder / "curve.csv").write_text("position [m],force [N]\n-0.1,40.0\n-0.05,62.0\n0.0,80.0\n")
    path = folder / "sweep.toml"
    path.write_text('[sweep]\nname = "t"\n[spring]\nlaw = "table"\ncsv = "curve.csv"\n'
                    '[grid]\nmass = [6.0, 7.0]\n')
    monkeypatch.chdir(tmp_path)
    sweep = load_sweep(path)
    assert sweep.spring == qzs.TabulatedSpring(positions=(-0.1, -0.05, 0.0),
                                               forces=(40.0, 62.0, 80.0))


def test_a_sweep_spelled_with_the_deprecated_tolerance_db_is_the_same_sweep():
    """`tolerance` and `tolerance_db` give the same [simulation] settings, key for key (what
    the store and a resume compare), the value under the records' key alone."""
    grid = {"pi_kp": [1.0]}
    new = load_sweep(definition(grid=grid, simulation={"tolerance": 0.2}))
    with pytest.warns(DeprecationWarning):
        old = load_sweep(definition(grid=grid, simulation={"tolerance_db": 0.2}))
    assert new.simulation == old.simulation
