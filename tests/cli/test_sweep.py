"""``qzs sweep`` (qzs.cli.sweep): a dry run prints the plan (cases, batches) without running,
and bad worker counts are refused before any case."""
import pytest
import tomli_w

from qzs.cli import main


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "plan.toml"
    path.write_text(tomli_w.dumps({
        "sweep": {"name": "plan", "batch_size": 4},
        "grid": {"pi_kp": [5.0, 20.0, 50.0], "stiction_force": [5.0, 15.0]},
        "excitation": {"f1": 10.0}, "simulation": {"dt": 1e-4},
        "analysis": {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0]}}))
    return path


def test_a_dry_run_prints_the_cases_and_batches_and_runs_nothing(sweep_file, tmp_path, capsys):
    """3 x 2 grid points in batches of 4: 6 cases, ceil(6/4) = 2 batches."""
    assert main(["sweep", str(sweep_file), "--dry-run", "--out", str(tmp_path / "s.zarr")]) == 0
    out = capsys.readouterr().out
    assert "6 cases (grid), 2 batches of 4" in out
    assert "pi_kp" in out and "5 .. 50 (3 distinct)" in out
    assert not (tmp_path / "s.zarr").exists()


@pytest.mark.parametrize("option", ["--workers", "--threads"])
def test_fewer_than_one_worker_or_thread_is_refused(sweep_file, option, capsys):
    assert main(["sweep", str(sweep_file), option, "0"]) == 2
    assert f"`{option}` must be >= 1, got 0" in capsys.readouterr().err
