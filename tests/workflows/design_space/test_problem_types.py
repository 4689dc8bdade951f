"""The validated problem's types (qzs.workflows.design_space.problem_types): a goal combines
a design's draws on its bad side, a log variable maps its search space by powers of ten, a
list of values is drawn in equal shares by its quantiles; the loader still exports them."""
import numpy as np
import pytest

from qzs.workflows.design_space import problem, problem_types
from qzs.workflows.design_space.problem_types import Goal, Uncertainty, Variable


def test_the_loader_exports_the_very_types():
    for name in problem_types.__all__:
        assert getattr(problem, name) is getattr(problem_types, name)


def test_a_log_variable_is_searched_on_log10_and_an_integer_one_rounded():
    gain = Variable(name="pi_kp", low=1.0, high=1000.0, scale="log")
    assert gain.search_bounds == (0.0, 3.0)
    np.testing.assert_allclose(gain.to_unit([0.0, 1.5, 3.0]), [1.0, 10 ** 1.5, 1000.0],
                               rtol=1e-15)
    steps = Variable(name="controller_rate", low=1.0, high=10.0, integer=True)
    assert steps.to_unit([2.4, 2.6]).tolist() == [2.0, 3.0]


def test_a_list_of_values_has_equal_shares_of_the_probability():
    mass = Uncertainty(name="mass", distribution="values", settings={"values": [6.0, 6.4, 6.8]})
    assert mass.quantile([0.1, 0.34, 0.5, 0.99]).tolist() == [6.0, 6.4, 6.4, 6.8]
    assert mass.nominal == 6.4
    uniform = Uncertainty(name="stiction_force", distribution="uniform",
                          settings={"low": 5.0, "high": 15.0})
    assert uniform.quantile(0.25) == pytest.approx(7.5) and uniform.nominal == pytest.approx(10.0)


@pytest.mark.parametrize("statistic, sense, expected", [
    ("mean", "minimize", [2.0, 5.0]), ("worst", "minimize", [3.0, 9.0]),
    ("worst", "maximize", [1.0, 1.0])])
def test_a_goal_combines_the_draws_of_each_design(statistic, sense, expected):
    goal = Goal(metric="peak_stroke", column="peak_stroke", options={}, statistic=statistic,
                sense=sense)
    assert goal.aggregate([[1.0, 2.0, 3.0], [1.0, 5.0, 9.0]]).tolist() == expected


def test_a_quantile_is_taken_from_the_bad_side_of_a_maximised_metric():
    values = np.arange(101.0)[None, :]
    low = Goal(metric="phase_margin", column="phase_margin", options={},
               statistic="quantile", quantile=0.9, sense="maximize")
    high = Goal(metric="peak_stroke", column="peak_stroke", options={},
                statistic="quantile", quantile=0.9, sense="minimize")
    assert low.aggregate(values)[0] == pytest.approx(10.0)
    assert high.aggregate(values)[0] == pytest.approx(90.0)
