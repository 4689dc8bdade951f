"""The Pareto figure (qzs.viz.design_space): it draws the result's own points, with units."""
import matplotlib
import numpy as np
import pytest

from qzs.viz.design_space import plot_pareto
from qzs.workflows.design_space.optimizer import optimize

matplotlib.use("Agg")
pytest.importorskip("pymoo")

PROBLEM = {
    "problem": {"name": "fig", "title": "figure test"},
    "variables": {"viscous_damping": {"low": 10.0, "high": 500.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "parameters": {"damping_gain": 0.0},
    "objectives": [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                   {"metric": "linear_transmissibility_at", "frequency": 12.0}],
    "constraints": [{"metric": "linear_transmissibility_at", "frequency": 5.0, "max": 0.5}],
    "optimizer": {"population": 8, "generations": 2, "seed": 1},
}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    return optimize(PROBLEM, tmp_path_factory.mktemp("f") / "f.zarr", progress=False)


def test_the_figure_draws_every_design_the_front_and_the_chosen_one(result, tmp_path):
    import matplotlib.pyplot as plt

    fig = plot_pareto(result, path=tmp_path / "p.png")
    ax = fig.axes[0]
    offsets = {c.get_label().split(" (")[0]: c.get_offsets() for c in ax.collections}
    values = result.goal_values[:, :2]
    assert np.allclose(offsets["feasible"], values[result.feasible])
    assert np.allclose(offsets["infeasible"], values[~result.feasible])
    front = offsets["Pareto set"]
    assert sorted(map(tuple, front)) == sorted(map(tuple, values[result.pareto]))
    assert np.allclose(offsets["chosen"], values[[result.chosen]])
    assert ax.get_xlabel() == "linear transmissibility at 1 Hz [-]"
    assert ax.get_ylabel() == "linear transmissibility at 12 Hz [-]"
    assert (tmp_path / "p.png").stat().st_size > 10_000
    plt.close(fig)


def test_one_objective_is_drawn_against_the_generation(tmp_path):
    import copy

    import matplotlib.pyplot as plt

    document = copy.deepcopy(PROBLEM)
    document["objectives"] = document["objectives"][:1]
    result = optimize(document, tmp_path / "one.zarr", progress=False)
    fig = plot_pareto(result)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "generation [-]"
    best = ax.lines[0].get_ydata()
    assert np.all(np.diff(best) <= 0)  # the best so far never gets worse
    plt.close(fig)
