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
    assert f"argument {option}: must be an integer >= 1, got 0" in capsys.readouterr().err


def test_sweep_export_writes_the_store_as_a_mat_file(tmp_path, capsys):
    """`qzs sweep-export STORE` -> STORE's name with .mat: every per-case output under its
    own name; a wrong extension is refused before the store is read."""
    import numpy as np
    import scipy.io

    from qzs.workflows.sweeps import open_sweep, run_sweep

    store = tmp_path / "tiny.zarr"
    run_sweep({"sweep": {"name": "tiny", "batch_size": 2}, "grid": {"pi_kp": [5.0, 20.0]},
               "excitation": {"f1": 10.0},
               "analysis": {"fft_length": 1024, "n_averages": 4, "band": [0.0, 10.0]}},
              store, progress=False)
    assert main(["sweep-export", str(store)]) == 0
    assert f"wrote {tmp_path / 'tiny.mat'}" in capsys.readouterr().out
    read, data = scipy.io.loadmat(tmp_path / "tiny.mat"), open_sweep(store).load()
    np.testing.assert_array_equal(read["pi_kp"][:, 0], data["pi_kp"].values)
    np.testing.assert_array_equal(read["transmissibility"], data["transmissibility"].values)
    np.testing.assert_array_equal(read["done"][:, 0], data["done"].values)
    assert read["units"][0, 0]["frequency"][0] == "Hz"
    assert read["attributes"][0, 0]["sweep_name"][0] == "tiny"
    assert main(["sweep-export", str(store), "--out", str(tmp_path / "t.nc")]) == 2
    assert "--out" in capsys.readouterr().err and not (tmp_path / "t.nc").exists()


def test_a_sweep_of_absurdly_long_runs_leaves_no_store(sweep_file, tmp_path, capsys):
    import tomllib

    document = tomllib.loads(sweep_file.read_text())
    document["analysis"] = {"duration": 1e9}
    sweep_file.write_text(tomli_w.dumps(document))
    store = tmp_path / "plan.zarr"
    assert main(["sweep", str(sweep_file), "--out", str(store), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "`duration` = 1e+09 s" in err
    assert not store.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["plan.toml"]


def test_the_default_store_is_named_anew_and_a_named_one_refused(tmp_path, monkeypatch,
                                                                 capsys):
    """A sweep's store may hold hours of work: run again without --out, it is kept and the
    new one is plan-2.zarr; --resume without --out continues plan.zarr."""
    from qzs.workflows.sweeps import open_sweep

    monkeypatch.chdir(tmp_path)
    small = tmp_path / "small.toml"
    small.write_text(tomli_w.dumps({
        "sweep": {"name": "plan"}, "grid": {"pi_kp": [5.0]}, "excitation": {"f1": 10.0},
        "analysis": {"fft_length": 1024, "n_averages": 4, "band": [0.0, 10.0]}}))
    assert main(["sweep", str(small), "--quiet"]) == 0, capsys.readouterr().err
    first = sorted(p.name for p in (tmp_path / "plan.zarr").rglob("*"))
    assert main(["sweep", str(small), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert "plan.zarr exists; writing plan-2.zarr (--out names another)" in captured.err
    assert "wrote            plan-2.zarr" in captured.out
    assert open_sweep("plan-2.zarr").sizes["case"] == 1
    assert sorted(p.name for p in (tmp_path / "plan.zarr").rglob("*")) == first
    assert main(["sweep", str(small), "--quiet", "--resume"]) == 0
    assert "plan.zarr" in capsys.readouterr().out and not (tmp_path / "plan-3.zarr").exists()
    assert main(["sweep", str(small), "--quiet", "--out", "plan.zarr"]) == 2
    assert "--out 'plan.zarr' exists" in capsys.readouterr().err
