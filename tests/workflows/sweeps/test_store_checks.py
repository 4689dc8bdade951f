"""A sweep's store checked before any run (qzs.workflows.sweeps.store_checks): resume and
overwrite exclude each other, resume needs a store, the name ends in .zarr, an existing
store needs resume or overwrite; the time series' length is the duration at the output
rate."""
import pytest

from qzs.errors import OutputPathError, ParameterError
from qzs.workflows.sweeps.cases import case_settings
from qzs.workflows.sweeps.definition import load_sweep, sample_cases
from qzs.workflows.sweeps.store_checks import check_resume, check_store_path, time_samples

DOCUMENT = {"sweep": {"name": "checks"}, "grid": {"pi_kp": [5.0, 20.0]},
            "simulation": {"dt": 1e-4},
            "analysis": {"fft_length": 1024, "n_averages": 4}}


def test_resume_and_overwrite(tmp_path):
    with pytest.raises(ParameterError, match="give one of them, not both"):
        check_resume(tmp_path / "s.zarr", "--out", True, True)
    with pytest.raises(OutputPathError, match="nothing to resume") as caught:
        check_resume(tmp_path / "s.zarr", "--out", True, False, work="the search")
    assert caught.value.argument == "--out" and "start the search" in str(caught.value)
    (tmp_path / "s.zarr").mkdir()
    check_resume(tmp_path / "s.zarr", "--out", True, False)  # a store to resume: fine


def test_the_store_path_is_checked_before_any_run(tmp_path):
    sweep = load_sweep(DOCUMENT)
    with pytest.raises(OutputPathError, match=r"it must end in \.zarr"):
        check_store_path(sweep, tmp_path / "s.nc", argument="--out")
    existing = tmp_path / "s.zarr"
    existing.mkdir()
    with pytest.raises(OutputPathError, match="exists; pass resume=True"):
        check_store_path(sweep, existing)
    check_store_path(sweep, existing, overwrite=True)
    check_store_path(sweep, existing, resume=True)
    check_store_path(sweep, tmp_path / "new.zarr")


def test_time_samples_are_the_duration_at_the_output_rate():
    sweep = load_sweep(DOCUMENT)
    settings = case_settings(sweep, sample_cases(sweep))
    assert time_samples(sweep, settings) == 0  # no time series kept
    kept = load_sweep({**DOCUMENT, "outputs": {"time_series": ["relative_position"]}})
    duration, rate = kept.analysis["duration"], kept.analysis["sample_rate"]
    assert time_samples(kept, settings) == int(round(duration * rate)) + 1


def test_a_refusal_names_the_switches_as_the_caller_spells_them(tmp_path):
    """Python's run_sweep on an existing store said "pass `resume` (--resume)": a flag that
    Python has not. Each caller reads its own spelling: resume=True in Python, --resume on
    the command line; the error is a ParameterError carrying the argument and the path."""
    from qzs.errors import ParameterError
    from qzs.workflows.design_space.store import check

    sweep = load_sweep(DOCUMENT)
    existing = tmp_path / "s.zarr"
    existing.mkdir()
    for checked in (lambda **spelt: check_store_path(sweep, existing, **spelt),
                    lambda **spelt: check(existing, **spelt)):
        with pytest.raises(ParameterError) as python:
            checked()
        assert "pass resume=True to continue it, overwrite=True to replace it" in str(
            python.value) and "--" not in str(python.value)
        assert python.value.argument == "store" and str(python.value.value) == str(existing)
        with pytest.raises(ParameterError) as command_line:
            checked(argument="--out")
        assert "pass --resume to continue it, --overwrite to replace it" in str(
            command_line.value) and "=True" not in str(command_line.value)
    with pytest.raises(ParameterError, match=r"^resume=True continues the store and "
                                             r"overwrite=True replaces it"):
        check_store_path(sweep, existing, resume=True, overwrite=True)
    with pytest.raises(ParameterError, match=r"leave out resume=True"):
        check_store_path(sweep, tmp_path / "missing.zarr", resume=True)


def test_a_batch_whose_samples_exceed_the_memory_is_refused_before_any_run(monkeypatch):
    """What simulate_batch refuses once the store is made (a batch's samples beyond half the
    memory) is refused by the checks before it: the same bytes, the same error."""
    from qzs.engine import driver
    from qzs.engine.channels import sample_bytes
    from qzs.errors import ResultTooLargeError
    from qzs.workflows.sweeps.cases import batch_channels
    from qzs.workflows.sweeps.store_checks import check_run_length

    sweep = load_sweep({**DOCUMENT, "sweep": {"name": "checks", "batch_size": 2},
                        "simulation": {"dt": 1e-3}})
    settings = case_settings(sweep, sample_cases(sweep))
    duration, rate = sweep.analysis["duration"], sweep.analysis["sample_rate"]
    needed = 2 * (int(round(duration * rate)) + 1) * sample_bytes(batch_channels(sweep))
    assert needed > 0  # the accelerations its estimate needs
    monkeypatch.setattr(driver, "available_memory", lambda: 2 * needed)  # exactly half: fine
    check_run_length(sweep, settings, cases=2)
    monkeypatch.setattr(driver, "available_memory", lambda: 2 * needed - 2)
    with pytest.raises(ResultTooLargeError) as caught:
        check_run_length(sweep, settings, cases=2)
    assert caught.value.needed == needed and caught.value.duration == duration
    assert "[sweep] batch_size" in str(caught.value) and "[analysis] sample_rate" in str(
        caught.value)


def test_a_sweep_of_1e9_s_cases_is_refused_by_the_store_checks(tmp_path):
    from qzs.errors import ResultTooLargeError

    sweep = load_sweep({**DOCUMENT, "simulation": {}, "excitation": {"duration": 1e9}})
    with pytest.raises(ResultTooLargeError, match="a 1e[+]09 s run at 1000 Hz keeps"):
        check_store_path(sweep, tmp_path / "s.zarr", argument="--out")
    assert list(tmp_path.iterdir()) == []
