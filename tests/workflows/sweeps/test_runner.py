"""A sweep run end to end (qzs.workflows.sweeps.runner): the report counts the cases run and
those that failed; a resumed run of a finished store runs nothing and keeps it."""
import xarray as xr

from qzs.workflows.sweeps.definition import load_sweep
from qzs.workflows.sweeps.runner import execute
from qzs.workflows.sweeps.store import INVALID, OK

#: A weightless, frictionless linear plant (tests/workflows/sweeps/test_init.py's): a P gain
#: of 1e12 N/m is too stiff for the step, refused when its batch runs.
DOCUMENT = {
    "sweep": {"name": "runner", "batch_size": 2},
    "parameters": {"gravity": 0.0, "stiction_force": 0.0, "coulomb_force": 0.0,
                   "spring_shape": 1e-3, "spring_force": 1e-6, "viscous_damping": 100.0,
                   "stop_center": 0.0, "stroke_half": 1.0, "motor_force_max": 1e12,
                   "position_setpoint": 0.0, "pi_ki": 0.0, "velocity_highpass": 0.0,
                   "controller_rate": 100.0},
    "grid": {"pi_kp": [10.0, 1e12, 15.0, 20.0, 25.0]},  # the step is chosen on 0, 2 and 4
    "excitation": {"f1": 10.0},
    "analysis": {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0]},
}


def test_the_report_counts_cases_and_failures_and_a_resume_runs_nothing(tmp_path):
    sweep = load_sweep(DOCUMENT)
    store = tmp_path / "s.zarr"
    report = execute(sweep, store, progress=False)
    assert report["cases"] == 5 and report["failed"] == 1
    assert report["steps"] > 0 and report["wall"] > 0
    data = xr.open_zarr(store, consolidated=False).load()
    assert data["status"].values.tolist() == [OK, INVALID, OK, OK, OK]
    again = execute(sweep, store, resume=True, progress=False)
    assert again["cases"] == 0 and again["failed"] == 0 and again["steps"] == 0
    xr.testing.assert_identical(xr.open_zarr(store, consolidated=False).load(), data)


def test_a_refused_sweep_leaves_no_store_behind(tmp_path, monkeypatch):
    """1e9 s cases: refused before any probe (the step choice is not reached) or store."""
    import pytest

    from qzs.errors import ResultTooLargeError
    from qzs.workflows.sweeps import runner

    monkeypatch.setattr(runner, "choose_sweep_step", pytest.fail)
    sweep = load_sweep({**DOCUMENT, "excitation": {"f1": 10.0, "duration": 1e9}})
    with pytest.raises(ResultTooLargeError, match="1e[+]09 s run"):
        execute(sweep, tmp_path / "deep" / "s.zarr", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_failing_before_its_first_batch_is_stored_removes_its_store(tmp_path,
                                                                            monkeypatch):
    """Whatever fails once the store is made and before a batch is in it (here the batch
    task itself refusing) leaves nothing behind: not the store, not the folders made for
    it; a store holding batches is kept (it resumes)."""
    import pytest

    from qzs.errors import ParameterError
    from qzs.workflows.sweeps import runner

    def refused(*args, **kwargs):
        raise ParameterError("refused by the batch")

    monkeypatch.setattr(runner, "run_local", refused)
    sweep = load_sweep(DOCUMENT)
    with pytest.raises(ParameterError, match="refused by the batch"):
        execute(sweep, tmp_path / "deep" / "s.zarr", progress=False)
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept").mkdir()
    with pytest.raises(ParameterError, match="refused by the batch"):
        execute(sweep, tmp_path / "kept" / "s.zarr", progress=False)
    assert list(tmp_path.iterdir()) == [tmp_path / "kept"]
    assert list((tmp_path / "kept").iterdir()) == []
