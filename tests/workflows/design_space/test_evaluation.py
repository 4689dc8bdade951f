"""The task of a design evaluation (qzs.workflows.design_space.evaluation): a batch's runs,
estimates and linear metrics in one task, whose numbers do not depend on how the cases are
shared over threads, batches or processes."""
import copy

import numpy as np
import pytest

from qzs.workflows.design_space import evaluation
from qzs.workflows.design_space.evaluation import evaluate_batch, evaluate_cases, shares
from qzs.workflows.design_space.problem import load_problem

#: Simulated and linear goals together, short runs.
MIXED = {
    "problem": {"name": "mixed"},
    "variables": {"damping_gain": {"low": 0.0, "high": 300.0},
                  "pi_kp": {"low": 1.0, "high": 1e9, "scale": "log"}},
    "uncertain": {"stiction_force": {"distribution": "uniform", "low": 5.0, "high": 15.0}},
    "robust": {"samples": 2},
    "excitation": {"duration": 6.0, "f1": 10.0},
    "simulation": {"dt": 1e-3},
    "analysis": {"fft_length": 1024, "duration": 6.0},
    "objectives": [{"metric": "transmissibility_at", "frequency": 3.0},
                   {"metric": "motor_force_rms"}],
    "constraints": [{"metric": "peak_stroke", "max": 0.03},
                    {"metric": "hunting_amplitude", "max": 0.005},
                    {"metric": "phase_margin", "min": 30.0}],
}


@pytest.fixture(scope="module")
def problem():
    return load_problem(MIXED)


@pytest.fixture(scope="module")
def settings():
    rng = np.random.default_rng(34)
    cases = [{"damping_gain": float(kd), "pi_kp": float(kp), "stiction_force": float(fs)}
             for kd, kp, fs in zip(rng.uniform(0, 300, 11), np.exp(rng.uniform(0, 7, 11)),
                                   rng.uniform(5, 15, 11))]
    cases[3]["pi_kp"] = 1e9   # the kernel refuses it at this step: a failed run
    cases[7]["pi_kp"] = -5.0  # no model at all: invalid for the runs and the linear analysis
    return cases


def test_shares_cover_every_case_once_and_differ_by_one_at_most():
    for n, parts in [(72, 4), (7, 4), (3, 8), (1, 2), (10, 1)]:
        got = shares(n, parts)
        assert got[0][0] == 0 and got[-1][1] == n
        assert all(b == c for (_, b), (c, _) in zip(got[:-1], got[1:]))  # contiguous
        sizes = [b - a for a, b in got]
        assert min(sizes) >= 1 and max(sizes) - min(sizes) <= 1
        assert len(got) == min(n, parts)


def same(a, b):
    assert a["status"].tolist() == b["status"].tolist()
    assert a["messages"] == b["messages"]
    assert a["steps"] == b["steps"]
    assert a["values"].keys() == b["values"].keys()
    for column, value in a["values"].items():
        assert np.array_equal(value, b["values"][column], equal_nan=True), column


def test_cases_shared_over_threads_give_the_numbers_of_one_thread(problem, settings):
    one = evaluate_batch(problem, 0, settings, problem.columns, threads=1)
    for threads in (2, 3):
        same(evaluate_batch(problem, 0, settings, problem.columns, threads=threads), one)
    # the failed run and the invalid case: recorded, their run's metrics undefined
    assert one["status"][3] != 1 and one["messages"][3]
    assert one["status"][7] == 2 and "pi_kp" in one["messages"][7]
    for column in ("transmissibility_at_3_hz", "motor_force_rms", "peak_stroke"):
        assert np.isnan(one["values"][column][[3, 7]]).all()
        assert np.isfinite(np.delete(one["values"][column], [3, 7])).all()
    # a failed run still has its linear analysis (it needs no run); no model has none
    assert np.isfinite(one["values"]["hunting_amplitude"][3])
    assert np.isnan(one["values"]["hunting_amplitude"][7])


def test_a_batch_gives_its_cases_the_numbers_they_have_in_a_larger_one(problem, settings):
    whole = evaluate_batch(problem, 0, settings, problem.columns, threads=2)
    part = evaluate_batch(problem, 4, settings[4:9], problem.columns, threads=1)
    assert part["start"] == 4
    for column, value in part["values"].items():  # the linear metrics are per case too
        assert np.array_equal(value, whole["values"][column][4:9], equal_nan=True), column
    assert part["status"].tolist() == whole["status"][4:9].tolist()


def test_only_the_columns_asked_for_and_no_run_for_linear_ones(problem, settings, monkeypatch):
    from qzs.workflows.sweeps import batch

    monkeypatch.setattr(batch, "run_batch", pytest.fail)
    got = evaluate_batch(problem, 0, settings, ["phase_margin"], threads=2)
    assert list(got["values"]) == ["phase_margin"] and got["steps"] == 0


def test_the_batches_of_evaluate_cases_are_tasks_of_their_own(problem, settings, monkeypatch):
    tasks = []
    task = evaluation.evaluate_batch

    def counted(problem, start, cases, *args):
        tasks.append((start, len(cases)))
        return task(problem, start, cases, *args)

    monkeypatch.setattr(evaluation, "evaluate_batch", counted)
    values, status, messages, _ = evaluate_cases(problem, settings, batch_size=4)
    assert tasks == [(0, 4), (4, 4), (8, 3)]
    whole = evaluate_batch(problem, 0, settings, problem.columns)
    assert status.tolist() == whole["status"].tolist() and messages == whole["messages"]
    for column, value in values.items():
        assert np.array_equal(value, whole["values"][column], equal_nan=True), column
    # the linear metrics alone are one task here, whatever the batch size
    linear = copy.deepcopy(MIXED)
    linear["objectives"] = [{"metric": "phase_margin", "sense": "maximize"}]
    linear["constraints"] = [{"metric": "hunting_amplitude", "max": 0.005}]
    tasks.clear()
    evaluate_cases(load_problem(linear), settings, batch_size=4)
    assert tasks == [(0, len(settings))]


def test_on_a_dask_cluster_the_linear_metrics_are_computed_in_the_workers(problem, settings,
                                                                         monkeypatch):
    distributed = pytest.importorskip("distributed")
    local = evaluate_batch(problem, 0, settings, problem.columns, threads=1)

    def not_here(*args, **kwargs):
        raise AssertionError("the linear metrics ran in the main process")

    monkeypatch.setattr(evaluation, "linear_metrics", not_here)  # the workers keep theirs
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster, distributed.Client(cluster) as client:
        values, status, messages, steps = evaluate_cases(problem, settings, client=client,
                                                         batch_size=3)
    assert status.tolist() == local["status"].tolist() and messages == local["messages"]
    assert steps == local["steps"]
    for column, value in values.items():
        assert np.array_equal(value, local["values"][column], equal_nan=True), column
