"""The design store (qzs.workflows.design_space.store): its path is checked before any
work, and only a store of the same problem is continued."""
import pytest

from qzs.errors import OutputPathError, ParameterError
from qzs.workflows.design_space.problem import load_problem
from qzs.workflows.design_space.store import DesignStore, check, stored_generations

PROBLEM = {"problem": {"name": "p"},
           "variables": {"pi_kp": {"low": 1.0, "high": 10.0}},
           "objectives": [{"metric": "hunting_amplitude"}]}


@pytest.mark.parametrize("name, kwargs, message", [
    ("s.zarr", {"resume": True, "overwrite": True}, "not both"),
    ("s.zarr", {"resume": True}, "nothing to resume"),
    ("s.nc", {}, ".zarr"),
])
def test_a_bad_store_path_is_refused_before_any_work(tmp_path, name, kwargs, message):
    with pytest.raises((OutputPathError, ParameterError), match=message):
        check(tmp_path / name, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_a_zarr_store_of_something_else_is_not_continued(tmp_path):
    import zarr

    zarr.open_group(str(tmp_path / "other.zarr"), mode="w").attrs["x"] = 1
    with pytest.raises(OutputPathError, match="not a design store"):
        DesignStore(tmp_path / "other.zarr", load_problem(PROBLEM), resume=True)
    assert stored_generations(tmp_path / "other.zarr") == 0
    assert stored_generations(tmp_path / "missing.zarr") == 0


def test_a_new_store_is_empty_and_records_its_problem(tmp_path):
    problem = load_problem(PROBLEM)
    store = DesignStore(tmp_path / "s.zarr", problem)
    assert (store.designs, store.generations, store.step) == (0, 0, None)
    store.set_step(1e-3, "fixed")
    again = DesignStore(tmp_path / "s.zarr", problem, resume=True)
    assert again.step == (1e-3, "fixed")
    assert again.group.attrs["problem_hash"] == problem.hash
    with pytest.raises(OutputPathError, match="exists"):
        check(tmp_path / "s.zarr")
    DesignStore(tmp_path / "s.zarr", problem, overwrite=True)
    assert DesignStore(tmp_path / "s.zarr", problem, resume=True).step is None
