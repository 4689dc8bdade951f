"""The NSGA-II search (qzs.workflows.design_space.optimizer): what it minimises, that it
improves on its first generation, and that an interrupted run resumes bit-identically."""
import copy

import numpy as np
import pytest

from qzs.errors import OutputPathError, ProblemError
from qzs.workflows.design_space import evaluation
from qzs.workflows.design_space.optimizer import fix_step, optimize, probe_designs
from qzs.workflows.design_space.problem import load_problem
from qzs.workflows.design_space.result import objective_matrix, pareto_front

pytest.importorskip("pymoo")

#: Linear metrics only: no simulation, so a search takes a fraction of a second.
LINEAR = {
    "problem": {"name": "linear"},
    "variables": {"damping_gain": {"low": 0.0, "high": 300.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "objectives": [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                   {"metric": "linear_transmissibility_at", "frequency": 12.0}],
    "constraints": [{"metric": "linear_transmissibility_at", "frequency": 5.0, "max": 0.9}],
    "optimizer": {"population": 12, "generations": 5, "seed": 4},
}
#: A simulated problem, short enough for a test.
SIMULATED = {
    "problem": {"name": "simulated"},
    "variables": {"damping_gain": {"low": 0.0, "high": 300.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "uncertain": {"stiction_force": {"distribution": "uniform", "low": 5.0, "high": 15.0}},
    "robust": {"samples": 2},
    "excitation": {"duration": 10.0, "f1": 10.0},
    "simulation": {"dt": 1e-3},
    "analysis": {"fft_length": 2048, "duration": 10.0},
    "objectives": [{"metric": "rms_transmissibility", "band": [1.0, 5.0], "statistic": "worst"},
                   {"metric": "motor_force_rms"}],
    "constraints": [{"metric": "peak_stroke", "max": 0.03, "statistic": "worst"}],
    "optimizer": {"population": 8, "generations": 3, "seed": 2},
}


def test_objectives_are_minimised_and_undefined_goals_make_a_design_infeasible():
    document = copy.deepcopy(LINEAR)
    document["objectives"][1]["sense"] = "maximize"
    document["constraints"].append({"metric": "phase_margin", "min": 30.0})
    problem = load_problem(document)
    values = np.array([[0.5, 0.2, 0.8, 40.0],
                       [0.4, np.nan, 0.95, 20.0]])
    F, G = objective_matrix(problem, values)
    assert F[0].tolist() == [0.5, -0.2]  # maximised: negated
    assert F[1, 1] == -0.2  # undefined: the worst defined value of its column
    assert G[0, :2] == pytest.approx([0.8 - 0.9, 30.0 - 40.0])
    assert G[1, :2] == pytest.approx([0.95 - 0.9, 30.0 - 20.0])
    assert G[:, -1].tolist() == [-1.0, 1.0]


def test_the_pareto_front_is_every_non_dominated_point_once():
    rng = np.random.default_rng(0)
    F = rng.random((300, 2))
    F = np.vstack([F, F[:5]])  # duplicates count once
    front = pareto_front(F)
    brute = [i for i in range(300) if not np.any(np.all(F <= F[i], axis=1)
                                                 & np.any(F < F[i], axis=1))]
    assert front.tolist() == brute


def test_the_search_improves_on_its_first_generation_and_keeps_every_design(tmp_path):
    result = optimize(LINEAR, tmp_path / "linear.zarr", progress=False)
    problem = result.problem
    assert len(result.designs) == 12 * 5
    assert np.all(result.designs[:, 0] >= 0.0) and np.all(result.designs[:, 1] <= 1000.0)
    F, G = objective_matrix(problem, result.goal_values)
    # the Pareto set is non-dominated among every feasible design, and feasible
    feasible = np.flatnonzero(np.all(G <= 0, axis=1))
    for i in result.pareto:
        assert i in feasible
        assert not np.any(np.all(F[feasible] <= F[i], axis=1)
                          & np.any(F[feasible] < F[i], axis=1))

    def hypervolume(rows):  # of the feasible designs of `rows`, to the reference (2, 2)
        from pymoo.indicators.hv import HV

        members = [i for i in rows if i in feasible]
        return HV(ref_point=np.array([2.0, 2.0]))(F[members]) if members else 0.0

    first = np.flatnonzero(result.generation == 0)
    assert hypervolume(range(len(F))) > hypervolume(first)
    chosen = result.chosen
    assert chosen in result.pareto


class Interrupt(Exception):
    """The test's stand-in for Ctrl-C."""


def test_an_interrupted_search_resumes_bit_identically(tmp_path, monkeypatch):
    whole = optimize(LINEAR, tmp_path / "whole.zarr", progress=False)
    calls = []
    evaluate = evaluation.evaluate

    def interrupted(*args, **kwargs):
        calls.append(None)
        if len(calls) == 3:  # during the third generation
            raise Interrupt
        return evaluate(*args, **kwargs)

    from qzs.workflows.design_space import optimizer as optimizer_module

    monkeypatch.setattr(optimizer_module, "evaluate", interrupted)
    store = tmp_path / "cut.zarr"
    with pytest.raises(Interrupt):
        optimize(LINEAR, store, progress=False)
    monkeypatch.setattr(optimizer_module, "evaluate", evaluate)
    from qzs.workflows.design_space.store import stored_generations

    assert stored_generations(store) == 2
    resumed = optimize(LINEAR, store, resume=True, progress=False)
    assert resumed.evaluated == 12 * 3  # generations 2..4 only
    assert np.array_equal(resumed.designs, whole.designs)
    assert np.array_equal(resumed.goal_values, whole.goal_values, equal_nan=True)
    assert resumed.pareto.tolist() == whole.pareto.tolist()
    assert resumed.chosen == whole.chosen


def test_a_half_written_generation_is_cut_off_when_resumed(tmp_path):
    import zarr

    store = tmp_path / "half.zarr"
    optimize(LINEAR, store, generations=2, progress=False)
    group = zarr.open_group(str(store), mode="r+")
    for name in ("search_position", "design_variables"):  # a third generation, half written
        array = group[name]
        array.resize((30, *array.shape[1:]))
        array[24:] = 123.0
    resumed = optimize(LINEAR, store, generations=3, resume=True, progress=False)
    whole = optimize(LINEAR, tmp_path / "whole.zarr", generations=3, progress=False)
    assert np.array_equal(resumed.designs, whole.designs)


def test_a_store_of_another_problem_is_not_resumed(tmp_path):
    store = tmp_path / "s.zarr"
    optimize(LINEAR, store, generations=1, progress=False)
    other = copy.deepcopy(LINEAR)
    other["variables"]["damping_gain"]["high"] = 200.0
    with pytest.raises(OutputPathError, match="another problem"):
        optimize(other, store, resume=True, progress=False)
    with pytest.raises(OutputPathError, match="exists"):
        optimize(LINEAR, store, progress=False)


def test_a_bad_problem_fails_before_any_evaluation(tmp_path, monkeypatch):
    from qzs.workflows.design_space import optimizer as optimizer_module

    monkeypatch.setattr(optimizer_module, "evaluate", pytest.fail)
    document = copy.deepcopy(LINEAR)
    document["objectives"][0]["metric"] = "isolation"
    with pytest.raises(ProblemError) as caught:
        optimize(document, tmp_path / "x.zarr", progress=False)
    assert caught.value.key == "metric" and caught.value.value == "isolation"
    assert not (tmp_path / "x.zarr").exists()


def test_a_simulated_search_runs_each_generation_as_one_task(tmp_path, monkeypatch):
    from qzs.workflows.design_space import evaluation

    batches = []
    task = evaluation.evaluate_batch

    def counted(problem, start, settings, *args, **kwargs):
        batches.append(len(settings))
        return task(problem, start, settings, *args, **kwargs)

    monkeypatch.setattr(evaluation, "evaluate_batch", counted)
    result = optimize(SIMULATED, tmp_path / "sim.zarr", progress=False)
    assert batches == [8 * 2] * 3  # population x draws, once per generation
    assert result.values["motor_force_rms"].shape == (24, 2)
    assert np.isfinite(result.goal_values).all()
    # worst case over the draws: at least the larger of the two draws' values
    column = result.values["rms_transmissibility_from_1_to_5_hz"]
    assert np.array_equal(result.goal_values[:, 0], column.max(axis=1))


def test_the_step_is_chosen_on_the_corners_and_centre_when_the_file_gives_none():
    document = copy.deepcopy(SIMULATED)
    document["simulation"] = {"tolerance": 0.05}
    problem = load_problem(document)
    corners = probe_designs(problem)
    assert corners[:, 1].tolist() == pytest.approx([1.0, 10 ** 1.5, 1000.0])
    fixed = fix_step(problem)
    assert fixed.sweep.simulation["dt"] > 0
    assert "chosen for the transmissibility" in fixed.sweep.simulation["step_note"]


def test_a_dask_cluster_gives_the_local_result(tmp_path):
    distributed = pytest.importorskip("distributed")
    local = optimize(SIMULATED, tmp_path / "local.zarr", generations=2, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster, distributed.Client(cluster) as client:
        remote = optimize(SIMULATED, tmp_path / "dask.zarr", generations=2, scheduler=client,
                          progress=False)
    assert np.array_equal(remote.designs, local.designs)
    for column, values in local.values.items():
        assert np.array_equal(remote.values[column], values, equal_nan=True), column


def test_an_integer_variable_takes_whole_numbers_only(tmp_path):
    document = copy.deepcopy(LINEAR)
    document["variables"]["controller_rate"] = {"low": 200.0, "high": 2000.0, "integer": True}
    document["objectives"] = [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                              {"metric": "phase_margin", "sense": "maximize"}]
    document["constraints"] = []
    result = optimize(document, tmp_path / "int.zarr", generations=2, population=6,
                      progress=False)
    rates = result.designs[:, 2]
    assert np.array_equal(rates, np.round(rates)) and rates.min() >= 200 and rates.max() <= 2000
    # a sampled controller loses phase as its rate falls: the margin is a real objective
    margins = result.goal_values[:, 1]  # NaN where the sampled loop is unstable
    assert np.nanmax(margins) > np.nanmin(margins)


def test_a_log_scale_objective_is_compared_in_ratios_and_must_stay_positive():
    document = copy.deepcopy(LINEAR)
    document["objectives"][0]["scale"] = "log"
    problem = load_problem(document)
    F, G = objective_matrix(problem, np.array([[0.1, 0.5, 0.0], [1e-3, 0.5, 0.0],
                                               [0.0, 0.5, 0.0]]))
    assert F[:2, 0] == pytest.approx([-1.0, -3.0])
    assert G[:, -1].tolist() == [-1.0, -1.0, 1.0]  # log10(0): undefined, so infeasible
    document["objectives"][0] = {"metric": "gain_margin", "scale": "log"}
    with pytest.raises(ProblemError, match="stays positive"):
        load_problem(document)


def test_the_seed_can_be_given_to_the_call_and_changes_the_search(tmp_path):
    one = optimize(LINEAR, tmp_path / "a.zarr", generations=1, progress=False)
    other = optimize(LINEAR, tmp_path / "b.zarr", generations=1, seed=99, progress=False)
    assert other.problem.optimizer["seed"] == 99
    assert not np.array_equal(one.designs, other.designs)
    with pytest.raises(ProblemError, match="must be an integer in"):
        optimize(LINEAR, tmp_path / "c.zarr", seed=1.5, progress=False)


@pytest.mark.parametrize("seed", [-3, 2 ** 63])
def test_a_seed_numpy_or_a_file_cannot_take_is_refused_before_the_store(tmp_path, seed):
    """-3 was a numpy ValueError traceback once the store was made (and it was left behind)."""
    with pytest.raises(ProblemError) as caught:
        optimize(LINEAR, tmp_path / "c.zarr", seed=seed, progress=False)
    assert (caught.value.table, caught.value.key, caught.value.value) == ("optimizer", "seed",
                                                                          seed)
    assert "e.g. 1" in str(caught.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("table", ["optimizer", "robust"])
def test_a_negative_seed_in_the_problem_file_is_refused_by_its_key(table):
    document = copy.deepcopy(SIMULATED)
    document.setdefault(table, {})["seed"] = -3
    with pytest.raises(ProblemError) as caught:
        load_problem(document)
    assert (caught.value.table, caught.value.key, caught.value.value) == (table, "seed", -3)


@pytest.mark.parametrize("option, asked", [("seed", 5), ("population", 16)])
def test_a_resume_with_another_seed_or_population_is_refused_by_name(tmp_path, monkeypatch,
                                                                      option, asked):
    """The optimiser would ask other designs than the stored ones: refused before any
    evaluation, naming the setting, the value the store was started with and the one asked
    for; the stored value given again resumes."""
    from qzs.errors import ResumeMismatchError
    from qzs.workflows.design_space import optimizer as optimizer_module

    store = tmp_path / "s.zarr"
    optimize(LINEAR, store, generations=1, progress=False)
    stored = LINEAR["optimizer"][option]
    evaluate = optimizer_module.evaluate
    monkeypatch.setattr(optimizer_module, "evaluate", pytest.fail)
    with pytest.raises(ResumeMismatchError) as caught:
        optimize(LINEAR, store, resume=True, progress=False, **{option: asked})
    error = caught.value
    assert (error.option, error.stored, error.asked) == (option, stored, asked)
    assert f"--{option}" in str(error) and f"{stored}" in str(error) and f"{asked}" in str(error)
    monkeypatch.setattr(optimizer_module, "evaluate", evaluate)
    resumed = optimize(LINEAR, store, resume=True, generations=2, progress=False,
                       **{option: stored})
    assert resumed.evaluated == LINEAR["optimizer"]["population"]  # the second generation


def test_a_search_started_with_a_seed_resumes_only_with_it(tmp_path):
    """Started with seed 7 (not the file's 4), resumed without it: the file's seed is asked
    for, and refused by name."""
    from qzs.errors import ResumeMismatchError

    store = tmp_path / "s.zarr"
    optimize(LINEAR, store, generations=1, seed=7, progress=False)
    with pytest.raises(ResumeMismatchError) as caught:
        optimize(LINEAR, store, resume=True, generations=2, progress=False)
    assert (caught.value.stored, caught.value.asked) == (7, 4)
    whole = optimize(LINEAR, tmp_path / "whole.zarr", generations=2, seed=7, progress=False)
    resumed = optimize(LINEAR, store, resume=True, generations=2, seed=7, progress=False)
    assert np.array_equal(resumed.designs, whole.designs)


def test_a_store_whose_designs_are_not_asked_for_again_is_refused(tmp_path):
    """Same problem, seed and population, but stored designs the optimiser does not ask for
    (as another qzs or pymoo version would have written them; here one value moved by one
    ulp): the replay refuses it, naming the generation, rather than mixing two searches."""
    import zarr

    store = tmp_path / "s.zarr"
    optimize(LINEAR, store, generations=2, progress=False)
    group = zarr.open_group(str(store), mode="r+")
    position = group["search_position"][:]
    position[13, 1] = np.nextafter(position[13, 1], np.inf)  # generation 1's second design
    group["search_position"][:] = position
    with pytest.raises(OutputPathError, match=r"does not ask for again \(generation 1\)"):
        optimize(LINEAR, store, generations=3, resume=True, progress=False)


@pytest.mark.parametrize("where", ["excitation", "variable"])
def test_designs_of_1e9_s_runs_are_refused_before_any_probe_or_store(tmp_path, monkeypatch,
                                                                     where):
    """What simulate refuses (a run whose samples exceed the memory) is refused before the
    step's probes: a 1e9 s excitation, or an excitation duration searched up to 1e9 s
    (checked at the variables' bounds, not at the file's default duration)."""
    from qzs.errors import ResultTooLargeError
    from qzs.workflows.design_space import optimizer as optimizer_module

    monkeypatch.setattr(optimizer_module, "fix_step", pytest.fail)
    document = copy.deepcopy(SIMULATED)
    document["simulation"] = {}
    if where == "excitation":
        document["excitation"]["duration"] = 1e9
    else:
        del document["excitation"]["duration"]
        document["variables"]["excitation.duration"] = {"low": 10.0, "high": 1e9}
    with pytest.raises(ResultTooLargeError, match="1e[+]09 s run at") as caught:
        optimize(document, tmp_path / "deep" / "x.zarr", progress=False)
    assert "[optimizer] population" in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_a_generations_memory_counts_every_draw_of_every_design(monkeypatch):
    """A generation evaluates population x [robust] samples runs together: with 2 draws per
    design its samples take twice the memory of 1 draw, and 4 designs' half of 8's (the
    bytes the refusal reports, with almost no memory available)."""
    from qzs.engine import driver
    from qzs.errors import ResultTooLargeError
    from qzs.workflows.design_space.optimizer import check_run_length

    monkeypatch.setattr(driver, "available_memory", lambda: 1)

    def needed(population, samples):
        document = copy.deepcopy(SIMULATED)
        document["optimizer"]["population"] = population
        document["robust"]["samples"] = samples
        with pytest.raises(ResultTooLargeError) as caught:
            check_run_length(load_problem(document))
        return caught.value.needed

    assert needed(8, 2) == 2 * needed(8, 1) == 4 * needed(4, 1) > 0


def test_a_search_failing_before_its_first_generation_is_stored_leaves_nothing(tmp_path,
                                                                             monkeypatch):
    from qzs.workflows.design_space import optimizer as optimizer_module

    def refused(*args, **kwargs):
        raise ProblemError("optimizer", "", None, "refused by the generation")

    monkeypatch.setattr(optimizer_module, "_generations", refused)
    with pytest.raises(ProblemError, match="refused by the generation"):
        optimize(LINEAR, tmp_path / "deep" / "x.zarr", progress=False)
    assert list(tmp_path.iterdir()) == []
