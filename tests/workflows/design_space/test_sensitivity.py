"""Global sensitivity: Ishigami's analytic Sobol indices and the linearised isolator's
derivative-based ranking, through the pipeline qzs sensitivity runs."""
import math

import numpy as np
import pytest

from qzs.errors import CountLimitError, ParameterError, ProblemError
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters, spring_stiffness
from qzs.workflows.design_space.problem import load_problem
from qzs.workflows.design_space.sensitivity import sensitivity

from workflows.design_space.ishigami import (ISHIGAMI_COLUMN, ISHIGAMI_NAMES, ishigami,
                                             ishigami_indices, ishigami_problem)

# ---------------------------------------------------------------- Ishigami
def test_ishigami_analytic_indices_lie_in_the_reported_intervals(ishigami_sobol, validation):
    result = ishigami_sobol
    first, total = ishigami_indices()
    assert np.allclose(first, [0.3139, 0.4424, 0.0], atol=1e-4)  # the published values
    assert np.allclose(total, [0.5576, 0.4424, 0.2437], atol=1e-4)
    assert result.method == "sobol" and result.parameters == ISHIGAMI_NAMES
    assert result.samples == 2 ** 12 and result.evaluations == 2 ** 12 * (3 + 2)
    for name, exact in (("first_order", first), ("total_order", total)):
        interval = np.stack(result.intervals[name], axis=-1)[0]
        assert np.all(interval[:, 0] <= exact) and np.all(exact <= interval[:, 1]), (
            name, exact, interval)
        width = interval[:, 1] - interval[:, 0]
        assert np.all(width < 0.15), width  # intervals that say something
        error = np.max(np.abs(getattr(result, name)[0] - exact))
        validation(f"Sobol {name.replace('_', ' ')} indices of the Ishigami function "
                   "(a = 7, b = 0.1), N = 4096, through qzs sensitivity's pipeline",
                   "Ishigami & Homma (1990); Sobol' (1999), analytic", error,
                   float(np.max(width) / 2), measure="largest absolute error [-]")
    assert result.ranking() == ("pi_kp", "pi_ki", "damping_gain")
    assert result.reasons == ("",) and result.failed == 0


def test_morris_sees_ishigami_x3_act_only_through_interaction(ishigami_sobol):
    """x3 has no first-order effect but its elementary effects are large and spread."""
    result = sensitivity(ishigami_problem(method="morris", trajectories=40), evaluate=ishigami,
                         progress=False)
    assert result.method == "morris" and result.evaluations == 40 * (3 + 1)
    assert result.first_order is None and result.mu_star.shape == (1, 3)
    mu_star, sigma = result.mu_star[0], result.sigma[0]
    low = result.intervals["mu_star"][0][0]
    assert np.all(low > 0)  # each parameter matters: x3 too, though S1(x3) = 0
    assert abs(ishigami_sobol.first_order[0, 2]) < 0.05
    assert sigma[2] > mu_star[2] / 2  # x3 acts through its interaction with x1
    assert set(result.ranking()) == set(ISHIGAMI_NAMES)


def test_the_same_seed_gives_the_same_indices():
    one = sensitivity(ishigami_problem(samples=64, seed=3), evaluate=ishigami, progress=False)
    two = sensitivity(ishigami_problem(samples=64), seed=3, evaluate=ishigami, progress=False)
    assert np.array_equal(one.total_order, two.total_order)
    assert np.array_equal(one.intervals["first_order"], two.intervals["first_order"])


# ---------------------------------------------------------------- linearised isolator
#: Influences on |T(3 Hz)| well apart: the order of this table is not the ranking.
LINEAR_BOUNDS = {"pi_kp": (1.0, 100.0), "mass": (5.0, 8.0),
                 "viscous_damping": (50.0, 150.0), "damping_gain": (0.0, 300.0)}
FREQUENCY = 3.0


def linear_transmissibility(x):
    """``|T(j*2*pi*f)|`` of docs/model.md's linearised loop, in plain numpy (x: kp, m, c, Kd)."""
    isolator, controller = IsolatorParameters(), ControllerParameters()
    k = float(spring_stiffness(controller.position_setpoint, isolator))
    w_hp = 2 * np.pi * controller.velocity_highpass
    kp, m, c, kd = np.asarray(x, dtype=float).T
    s = 2j * np.pi * FREQUENCY
    coupling = c * s + k + kp + controller.pi_ki / s
    return np.abs(coupling / (m * s ** 2 + coupling + kd * s * s / (s + w_hp)))


def derivative_based_bounds():
    """DGSM upper bounds of the total indices, ``E[(df/dx_i)^2] (b_i - a_i)^2 / (pi^2 V)``
    (Sobol' & Kucherenko 2009, uniform inputs), by central differences of the closed form."""
    low = np.array([b[0] for b in LINEAR_BOUNDS.values()])
    high = np.array([b[1] for b in LINEAR_BOUNDS.values()])
    x = low + (high - low) * np.random.default_rng(0).random((40_000, low.size))
    variance = linear_transmissibility(x).var()
    bounds = []
    for i in range(low.size):
        step = np.zeros(low.size)
        step[i] = 1e-6 * (high[i] - low[i])
        slope = (linear_transmissibility(x + step) - linear_transmissibility(x - step)) \
            / (2 * step[i])
        bounds.append(np.mean(slope ** 2) * (high[i] - low[i]) ** 2 / (math.pi ** 2 * variance))
    return dict(zip(LINEAR_BOUNDS, bounds))


def linear_problem(**sensitivity_table):
    return {"problem": {"name": "linear", "title": "Linearised isolator at 3 Hz"},
            "variables": {n: {"low": a, "high": b} for n, (a, b) in LINEAR_BOUNDS.items()},
            "objectives": [{"metric": "linear_transmissibility_at", "frequency": FREQUENCY}],
            "sensitivity": sensitivity_table}


@pytest.fixture(scope="module")
def linear_sobol():
    return sensitivity(linear_problem(samples=64), progress=False)


def test_linear_isolator_ranking_agrees_with_the_derivative_based_one(linear_sobol, validation):
    result = linear_sobol
    bounds = derivative_based_bounds()
    expected = tuple(sorted(bounds, key=bounds.get, reverse=True))
    assert expected != tuple(LINEAR_BOUNDS)  # not the input order: the test can fail
    assert result.ranking() == expected == ("damping_gain", "viscous_damping", "mass",
                                            "pi_kp")
    # the bound holds: every total index's interval starts below its DGSM bound
    lower = result.intervals["total_order"][0][0]
    for j, name in enumerate(result.parameters):
        assert lower[j] <= bounds[name] + 1e-9, (name, lower[j], bounds[name])
    # and the qzs path evaluates exactly the closed form (no simulation)
    assert result.settings["dt"] is None and result.settings["evaluator"] == "qzs"
    order = [expected.index(n) for n in result.ranking()]
    validation("rank of the Sobol total indices of |T(3 Hz)| of the linearised isolator "
               "(mass, viscous damping, Kp, Kd) against the DGSM ranking",
               "derivative-based global sensitivity bounds of the closed-form T(s) "
               "(Sobol' & Kucherenko 2009)", sum(o != k for k, o in enumerate(order)), 0,
               measure="parameters out of rank")


def test_a_failed_case_leaves_the_indices_undefined_with_the_reason():
    """Coulomb friction above the stiction is an invalid case: NaN, no crash."""
    problem = linear_problem(samples=4)
    problem["variables"]["coulomb_force"] = {"low": 0.5, "high": 15.0}  # stiction 10 N
    result = sensitivity(problem, progress=False)
    assert result.failed > 0
    assert np.isnan(result.total_order).all() and np.isnan(result.intervals["first_order"]).all()
    assert "cases gave NaN" in result.reasons[0] and "coulomb" in result.reasons[0].lower()
    with pytest.raises(ParameterError, match="undefined"):
        result.ranking()
    assert "undefined:" in result.summary()


def test_a_nan_from_the_evaluator_is_reported_too():
    def sometimes_nan(settings):
        y = ishigami(settings)[ISHIGAMI_COLUMN]
        y[3] = np.nan
        return {ISHIGAMI_COLUMN: y}

    result = sensitivity(ishigami_problem(samples=8), evaluate=sometimes_nan, progress=False)
    assert result.reasons[0].startswith("1 of 40 cases gave NaN")
    assert np.isnan(result.first_order).all()


def test_uncertain_parameters_are_sampled_from_their_distributions():
    """An uncertain parameter's values follow its distribution (the inverse CDF of SALib's
    probabilities): uniform draws of a uniform, the stated list's values only."""
    seen = []

    def record(settings):
        seen.extend(settings)
        return ishigami([{**c, "pi_kp": c["pi_kp"], "pi_ki": 0.0,
                          "damping_gain": c["stiction_force"] / 10} for c in settings])

    document = ishigami_problem(samples=64)
    del document["variables"]["pi_ki"], document["variables"]["damping_gain"]
    document["uncertain"] = {"stiction_force": {"distribution": "uniform", "low": 5.0,
                                                "high": 15.0},
                             "mass": {"values": [6.2, 6.4, 6.6]}}
    result = sensitivity(document, evaluate=record, progress=False)
    assert result.parameters == ("pi_kp", "stiction_force", "mass")
    assert result.parameter_kinds == ("variable", "uncertain", "uncertain")
    assert result.parameter_units == ("N/m", "N", "kg")
    stiction = np.array([c["stiction_force"] for c in seen])
    assert len(seen) == 64 * 5 and 5.0 < stiction.min() and stiction.max() < 15.0
    assert abs(stiction.mean() - 10.0) < 0.3
    assert {c["mass"] for c in seen} == {6.2, 6.4, 6.6}
    assert abs(result.total_order[0, 2]) < 0.05  # mass is not used by the evaluator

    morris = []
    sensitivity(document, method="morris", samples=4, progress=False,
                evaluate=lambda s: (morris.extend(s), record(s))[1])
    levels = sorted({round(c["stiction_force"], 9) for c in morris})
    assert levels == [6.25, 8.75, 11.25, 13.75]  # medians of 4 equally likely strata


def test_a_simulated_metric_runs_end_to_end():
    """Morris, two variables and an uncertain stiction, 4 trajectories of a 20 s chirp."""
    document = {
        "problem": {"name": "simulated"},
        "variables": {"damping_gain": {"low": 0.0, "high": 200.0},
                      "pi_kp": {"low": 10.0, "high": 100.0, "scale": "log"}},
        "uncertain": {"stiction_force": {"distribution": "normal", "mean": 10.0, "std": 2.0,
                                         "low": 2.0}},
        "excitation": {"kind": "chirp", "f0": 1.0, "f1": 20.0, "duration": 20.0,
                       "amplitude": 0.002},
        "simulation": {"dt": 1e-3},
        "objectives": [{"metric": "transmissibility_at", "frequency": 5.0},
                       {"metric": "peak_stroke"}],
        "sensitivity": {"method": "morris", "trajectories": 4}}
    result = sensitivity(document, progress=False)
    assert result.evaluations == 4 * (3 + 1) and result.failed == 0
    assert result.metrics == ("transmissibility_at_5_hz", "peak_stroke")
    assert result.metric_units == ("1", "m")
    assert np.all(np.isfinite(result.mu_star)) and np.all(result.mu_star >= 0)
    assert result.settings["dt"] == 1e-3
    # more damping lowers the transmissibility at 5 Hz, above the resonance... its effect
    # is the largest of the three and its mean effect negative
    assert result.ranking("transmissibility_at_5_hz")[0] == "damping_gain"
    assert result.mu[0, 0] < 0


# ---------------------------------------------------------------- refused before any case
def test_designs_of_1e9_s_runs_are_refused_before_any_probe_or_folder(tmp_path, monkeypatch):
    """As qzs.optimize: what a simulation refuses (samples beyond the memory) is refused
    before the step's probes, and run_sensitivity makes no folder."""
    from qzs.errors import ResultTooLargeError
    from qzs.workflows.design_space import optimizer
    from qzs.workflows.design_space.sensitivity import run_sensitivity

    monkeypatch.setattr(optimizer, "fix_step", pytest.fail)
    document = {"problem": {"name": "long"},
                "variables": {"pi_kp": {"low": 10.0, "high": 100.0, "scale": "log"}},
                "excitation": {"f1": 10.0, "duration": 1e9},
                "analysis": {"sample_rate": 100.0, "fft_length": 512},
                "objectives": [{"metric": "transmissibility_at", "frequency": 5.0}],
                "sensitivity": {"method": "morris", "trajectories": 4}}
    with pytest.raises(ResultTooLargeError, match="a 1e[+]09 s run at 100 Hz"):
        run_sensitivity(document, tmp_path / "out", progress=False)
    assert list(tmp_path.iterdir()) == []


def refused(evaluations):
    def evaluate(settings):
        evaluations.append(len(settings))
        return ishigami(settings)
    return evaluate


@pytest.mark.parametrize("arguments, error, message", [
    ({"samples": 100}, ParameterError, r"`samples` must be a power of two .* use 64 or 128"),
    ({"samples": 1}, ParameterError, "power of two >= 2"),
    ({"samples": 2.5}, ParameterError, "`samples` must be a whole number"),
    ({"method": "fast"}, ParameterError, r"`method` must be one of \('sobol', 'morris'\)"),
    ({"method": "morris", "samples": 1}, ParameterError, "at least 2 trajectories"),
    ({"metrics": ["peak_stroke"]}, ParameterError,
     r"`metrics` must name metric columns .*linear_transmissibility_at_3_hz"),
    ({"seed": -1}, ParameterError, r"`seed` must be an integer in \[0, 9223372036854775807\]"),
    ({"seed": 2 ** 64}, ParameterError, "`seed` must be an integer in"),  # failed in the files
    ({"samples": 2 ** 19}, CountLimitError, "asks for 2,621,440 evaluations"),
])
def test_bad_arguments_are_refused_before_any_case(arguments, error, message):
    evaluations = []
    with pytest.raises(error, match=message):
        sensitivity(ishigami_problem(), evaluate=refused(evaluations), progress=False,
                    **arguments)
    assert evaluations == []


@pytest.mark.parametrize("table, key, message", [
    ({"samples": 100}, "samples", "power of two"),
    ({"method": "morris", "levels": 5}, "levels", "even number of levels"),
])
def test_bad_sensitivity_tables_name_the_key(table, key, message):
    evaluations = []
    with pytest.raises(ProblemError, match=message) as caught:
        sensitivity(ishigami_problem(**table), evaluate=refused(evaluations), progress=False)
    assert caught.value.table == "sensitivity" and caught.value.key == key
    assert evaluations == []


def test_problem_files_refuse_unknown_methods_and_metrics():
    with pytest.raises(ProblemError, match=r"\[sensitivity\] method = 'fast'"):
        load_problem(ishigami_problem(method="fast"))
    with pytest.raises(ProblemError, match=r"\[sensitivity\] metrics"):
        load_problem(ishigami_problem(metrics=["peak_stroke"]))


def test_an_evaluator_must_return_every_metric_per_case():
    with pytest.raises(ParameterError, match="returned no 'linear_transmissibility_at_3_hz'"):
        sensitivity(ishigami_problem(samples=4), evaluate=lambda s: {}, progress=False)
    with pytest.raises(ParameterError, match=r"one value per case .* shape \(20,\)"):
        sensitivity(ishigami_problem(samples=4), progress=False,
                    evaluate=lambda s: {ISHIGAMI_COLUMN: np.zeros(3)})
    with pytest.raises(ParameterError, match="`evaluate` must be a callable"):
        sensitivity(ishigami_problem(samples=4), evaluate=3, progress=False)


@pytest.mark.parametrize("confidence", [0.9, 0.5])
def test_each_interval_is_the_index_plus_minus_salib_s_bootstrap_half_width(confidence):
    """The interval of an index is the index -/+ SALib's ``<index>_conf`` at the asked
    ``confidence`` (the bootstrap's quantile half-width), recomputed here by SALib on the
    metric's values the analysis was given, with its seed and resamples."""
    from SALib.analyze import sobol

    from qzs.workflows.design_space.sensitivity import NUM_RESAMPLES

    seen = []

    def evaluate(settings):
        out = ishigami(settings)
        seen.append(np.asarray(out[ISHIGAMI_COLUMN], dtype=float))
        return out

    result = sensitivity(ishigami_problem(samples=2 ** 8, confidence=confidence),
                         evaluate=evaluate, progress=False)
    assert result.confidence == confidence
    found = sobol.analyze({"num_vars": 3, "names": list(ISHIGAMI_NAMES),
                           "bounds": [[0.0, 1.0]] * 3}, np.concatenate(seen),
                          calc_second_order=False, num_resamples=NUM_RESAMPLES,
                          conf_level=confidence, seed=result.seed)
    for name, key in (("first_order", "S1"), ("total_order", "ST")):
        low, high = result.intervals[name]
        np.testing.assert_allclose(getattr(result, name)[0], found[key], rtol=1e-12)
        np.testing.assert_allclose(high[0] - low[0], 2 * found[f"{key}_conf"], rtol=1e-9)
        np.testing.assert_allclose(low[0] + high[0], 2 * found[key], rtol=1e-9, atol=1e-12)
