"""Running sweeps: batched results equal single runs, failures are recorded, interrupted
sweeps resume to the same Dataset, a Dask cluster gives the same Dataset, the command line.

Runs are short chirps (9 s, 0-10 Hz) analysed with a 2048-point FFT.
"""
import argparse

import numpy as np
import pytest
import xarray as xr

import qzs
from qzs import ParameterError
from qzs.workflows.sweeps import batch as sweep_batch
from qzs.analysis.spectral import band_mask, transmissibility, transmissibility_metrics
from qzs.cli.sweep import add_parsers, run_sweep_command
from qzs.workflows.sweeps import load_sweep, run_sweep
from qzs.workflows.sweeps.store import FAILED, INVALID, OK

ANALYSIS = {"fft_length": 2048, "n_averages": 8, "band": [0.0, 10.0],
            "at_frequencies": [2.0, 4.0]}


def document(batch_size=2, **outputs):
    return {"sweep": {"name": "small", "batch_size": batch_size},
            "grid": {"pi_kp": [5.0, 200.0], "stiction_force": [5.0, 15.0]},
            "parameters": {"pi_ki": 2.0},
            "excitation": {"f1": 10.0},
            "analysis": dict(ANALYSIS),
            "outputs": {"bands": {"low": [1.0, 3.0], "all": [0.0, 10.0]}, **outputs}}


#: A weightless, frictionless linear plant whose P loop, sampled at 100 Hz with a gain of
#: 1e6 N/m, is violently unstable (tests/engine/test_simulate.py's divergence test).
DIVERGING = {
    "sweep": {"name": "diverging", "batch_size": 4},
    "parameters": {"gravity": 0.0, "stiction_force": 0.0, "coulomb_force": 0.0,
                   "spring_shape": 1e-3, "spring_force": 1e-6, "viscous_damping": 100.0,
                   "stop_center": 0.0, "stroke_half": 1.0, "motor_force_max": 1e12,
                   "position_setpoint": 0.0, "pi_ki": 0.0, "velocity_highpass": 0.0,
                   "controller_rate": 100.0},
    # 1e6 diverges, 1e12 is too stiff for dt (refused by the stability check when its batch
    # runs); a value no case can take (-1) refuses the whole sweep before any case runs
    "grid": {"pi_kp": [10.0, 1e6, 15.0, 1e12, 20.0]},
    "excitation": {"f1": 10.0},
    "analysis": dict(ANALYSIS),
}


def load(path):
    return xr.open_zarr(path, consolidated=False).load()


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The small sweep run once in-process, keeping two time series."""
    store = tmp_path_factory.mktemp("sweep") / "reference.zarr"
    definition = load_sweep(document(time_series=["relative_position",
                                                  "payload_acceleration"]))
    return definition, run_sweep(definition, store, progress=False).load(), store


def test_batched_results_equal_single_runs(reference):
    definition, data, _ = reference
    assert data.sizes["case"] == 4 and bool(data["done"].all())
    assert (data["status"].values == OK).all()
    for case in range(4):
        kp = float(data["pi_kp"][case])
        stiction = float(data["stiction_force"][case])
        run = qzs.simulate(qzs.Chirp(f1=10.0, duration=definition.analysis["duration"]),
                           qzs.IsolatorParameters(stiction_force=stiction),
                           qzs.ControllerParameters(pi_kp=kp, pi_ki=2.0),
                           dt=float(data.attrs["dt"]))  # the step chosen for the sweep
        row = data.isel(case=case)
        np.testing.assert_array_equal(row["relative_position"].values, run.relative_position)
        np.testing.assert_array_equal(row["payload_acceleration"].values,
                                      run.payload_acceleration)
        assert row["stop_contacts"] == run.run["stop_contacts"]
        assert row["stick_events"] == run.run["stick_events"]
        center = run.controller.position_setpoint
        assert float(row["peak_stroke"]) == pytest.approx(  # stop centre: (low + high) / 2
            np.abs(run.relative_position - center).max(), rel=1e-12)
        assert float(row["motor_force_rms"]) == pytest.approx(
            np.sqrt(np.mean(run.motor_force ** 2)), rel=1e-12)
        estimate = transmissibility(run.base_acceleration, run.payload_acceleration, 1000.0,
                                    fft_length=2048)
        keep = (estimate.frequency > 0) & (estimate.frequency <= 10.0)
        np.testing.assert_array_equal(data["frequency"].values, estimate.frequency[keep])
        np.testing.assert_array_equal(row["transmissibility"].values, estimate.magnitude[keep])
        metrics = transmissibility_metrics(estimate.frequency[keep], estimate.magnitude[keep],
                                           trusted=estimate.trusted[keep],
                                           at_frequencies=[2.0, 4.0]).to_dict()
        for name in ("resonance_frequency", "isolation_onset", "transmissibility_at_2_hz"):
            np.testing.assert_equal(float(row[name]), metrics[name])
        # band means and metrics from the estimate's trusted bins only (docs/model.md §10)
        band = (estimate.frequency >= 1.0) & (estimate.frequency <= 3.0) & estimate.trusted
        assert band.any() and not estimate.trusted[keep].all()
        assert float(row["mean_transmissibility_low"]) == estimate.magnitude[band].mean()
        whole = band_mask(estimate.frequency, 0.0, 10.0) & estimate.trusted  # some untrusted
        assert float(row["mean_transmissibility_all"]) == estimate.magnitude[whole].mean()
        assert int(row["n_averages"]) == 8


def test_a_sweep_over_a_controller_block_s_parameter_is_its_single_runs(tmp_path):
    """A TOML sweep over ``compensation.fraction`` (an unquoted dotted key): each case is the
    single run of the default controller plus that compensation, bit for bit."""
    path = tmp_path / "compensation.toml"
    path.write_text('[sweep]\nname = "compensation"\nbatch_size = 2\n'
                    '[grid]\ncompensation.fraction = [0.0, 0.6, 1.2]\n'
                    '[excitation]\nf1 = 10.0\n[simulation]\ndt = 5e-4\n'
                    '[analysis]\nfft_length = 2048\nn_averages = 8\nband = [0.0, 10.0]\n'
                    '[outputs]\ntime_series = ["relative_position", "motor_force"]\n')
    definition = load_sweep(path)
    assert definition.grid == {"compensation.fraction": (0.0, 0.6, 1.2)}
    data = run_sweep(definition, tmp_path / "compensation.zarr", threads=1,
                     progress=False).load()
    assert (data["status"].values == OK).all()
    assert data["compensation.fraction"].attrs["units"] == "-"
    for case, fraction in enumerate((0.0, 0.6, 1.2)):
        assert float(data["compensation.fraction"][case]) == fraction
        run = qzs.simulate(qzs.Chirp(f1=10.0, duration=definition.analysis["duration"]),
                           controller=qzs.PIDamping() + qzs.FrictionCompensation(
                               fraction=fraction), dt=5e-4)
        row = data.isel(case=case)
        np.testing.assert_array_equal(row["relative_position"].values, run.relative_position)
        np.testing.assert_array_equal(row["motor_force"].values, run.motor_force)
        assert row["stick_events"] == run.run["stick_events"]
    assert not np.array_equal(data["motor_force"][0], data["motor_force"][2])


def test_store_layout_units_and_attributes(reference):
    definition, data, _ = reference
    assert set(data.dims) == {"case", "frequency", "time"}
    assert data["pi_kp"].attrs["units"] == "N/m" and data["pi_kp"].dims == ("case",)
    assert data["peak_stroke"].attrs["units"] == "m"
    assert "sqrt(S_payload / S_base)" in data["transmissibility"].attrs["long_name"]
    assert data.attrs["sweep_hash"] == definition.hash
    assert data["message"].values.tolist() == [""] * 4


def test_store_has_consolidated_metadata_and_integer_counts(reference):
    import zarr

    _, data, store = reference
    group = zarr.open_group(store, mode="r", use_consolidated=True)  # raises without it
    assert group.metadata.consolidated_metadata is not None
    assert "done" in group.metadata.consolidated_metadata.metadata
    for name in ("stop_contacts", "stick_events", "steps", "n_averages"):
        assert data[name].dtype.kind == "i", name
        assert (data[name].values >= 0).all(), name


def test_counts_of_cases_without_a_run_are_minus_one(tmp_path):
    data = run_sweep(DIVERGING, tmp_path / "d.zarr", progress=False).load()
    invalid = data["status"].values == INVALID
    assert invalid.any() and data["stop_contacts"].dtype.kind == "i"
    assert (data["stop_contacts"].values[invalid] == -1).all()
    assert (data["steps"].values[~invalid] > 0).all()


def test_a_store_without_consolidated_metadata_still_opens(reference, tmp_path):
    import warnings

    from qzs.workflows.sweeps import open_sweep

    _, expected, store = reference
    plain = tmp_path / "plain.zarr"
    xr.open_zarr(store, consolidated=True).to_zarr(plain, consolidated=False,
                                                   zarr_format=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "failed to open consolidated" warning
        data = open_sweep(plain).load()
    xr.testing.assert_identical(data, expected)


def test_time_series_are_off_by_default(tmp_path):
    data = run_sweep(document(batch_size=4), tmp_path / "s.zarr", progress=False)
    assert "time" not in data.dims and "relative_position" not in data
    ok = data.where(data["status"] == OK, drop=True)  # lazily opened, still selectable
    assert ok.sizes["case"] == 4 and ok["message"].dtype == object


def test_failing_cases_are_recorded_and_the_sweep_goes_on(tmp_path):
    data = run_sweep(DIVERGING, tmp_path / "d.zarr", progress=False).load()
    status = data["status"].values.tolist()
    assert status == [OK, FAILED, OK, INVALID, OK]
    messages = data["message"].values
    assert "diverged at t = " in messages[1] and "relative position z =" in messages[1]
    assert "largest stable step" in messages[3]
    assert np.isnan(data["transmissibility"].values[[1, 3]]).all()
    assert np.isfinite(data["transmissibility"].values[[0, 2, 4]]).all()
    assert bool(data["done"].all())


def test_a_sweep_with_invalid_values_runs_no_case_and_writes_nothing(tmp_path):
    """A negative gain is decided before the run: the cases are named, no store is made."""
    from qzs.errors import InvalidCasesError

    sweep = {**DIVERGING, "grid": {"pi_kp": [10.0, -1.0, 20.0, float("nan")]}}
    with pytest.raises(InvalidCasesError, match=r"2 of 4 cases are invalid, so none runs: "
                                                r"case 1 \(pi_kp = -1.0\)"):
        run_sweep(sweep, tmp_path / "d.zarr", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_resume_needs_a_store_and_excludes_overwrite(tmp_path):
    from qzs.errors import OutputPathError

    with pytest.raises(OutputPathError, match="does not exist, so there is nothing to resume"):
        run_sweep(DIVERGING, tmp_path / "missing.zarr", resume=True, progress=False)
    with pytest.raises(ParameterError, match="give one of them, not both"):
        run_sweep(DIVERGING, tmp_path / "d.zarr", resume=True, overwrite=True, progress=False)
    with pytest.raises(OutputPathError, match=r"'\.nc'; it must end in \.zarr"):
        run_sweep(DIVERGING, tmp_path / "store.nc", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_an_unreachable_scheduler_fails_at_once_saying_what_it_waited_for(tmp_path, capsys):
    pytest.importorskip("distributed")
    import socket
    import time

    from qzs.errors import SchedulerError

    with socket.socket() as closed:  # a port nothing listens on
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
    began = time.perf_counter()
    with pytest.raises(SchedulerError, match=f"nothing listens on port {port}") as caught:
        run_sweep(DIVERGING, tmp_path / "d.zarr", scheduler=f"tcp://127.0.0.1:{port}",
                  progress=False)
    assert time.perf_counter() - began < 2.0
    assert caught.value.address == f"tcp://127.0.0.1:{port}"
    assert list(tmp_path.iterdir()) == []


class SimulatedInterrupt(Exception):
    """The test's stand-in for Ctrl-C: an ordinary exception, so it cannot abort the session."""


def _count_cases(monkeypatch, interrupt_at=None, exception=SimulatedInterrupt):
    """Patch the batch call: count the cases it runs; raise ``exception`` at call `interrupt_at`.

    The original is taken from the module now (not from an earlier patch) and the patch is
    undone by ``monkeypatch`` (pass ``monkeypatch.context()`` to undo it sooner). The
    interruption fires once, so a later run through the same patch cannot raise it.
    """
    calls = []
    original = sweep_batch.simulate_batch

    def patched(cases, *args, **kwargs):
        calls.append(len(cases))
        if interrupt_at is not None and len(calls) == interrupt_at:
            raise exception("interrupted by the test")
        return original(cases, *args, **kwargs)

    monkeypatch.setattr(sweep_batch, "simulate_batch", patched)
    return calls


def test_resume_after_an_interrupt_gives_the_same_dataset(reference, tmp_path, monkeypatch):
    definition, expected, _ = reference
    store = tmp_path / "resumed.zarr"
    unpatched = sweep_batch.simulate_batch
    with monkeypatch.context() as patch:
        calls = _count_cases(patch, interrupt_at=2)
        with pytest.raises(SimulatedInterrupt):
            run_sweep(definition, store, progress=False)
        assert calls == [2, 2]
    assert sweep_batch.simulate_batch is unpatched  # the interrupting patch is gone
    partial = load(store)
    assert partial["done"].values.tolist() == [True, True, False, False]
    with pytest.raises(ParameterError, match="exists; pass resume=True"):
        run_sweep(definition, store, progress=False)
    calls = _count_cases(monkeypatch)
    resumed = run_sweep(definition, store, resume=True, progress=False).load()
    assert calls == [2]  # only the batch that was not stored
    xr.testing.assert_identical(resumed, expected)


def test_a_batch_killed_before_its_done_flags_is_recomputed(reference, tmp_path, monkeypatch):
    definition, expected, store = reference
    import shutil

    copy = tmp_path / "killed.zarr"
    shutil.copytree(store, copy)
    # a process killed after writing batch 0's data but before its done flags:
    xr.Dataset({"done": ("case", np.zeros(2, bool)),
                "peak_stroke": ("case", np.full(2, -1.0))}).to_zarr(
        copy, region={"case": slice(0, 2)}, mode="r+", consolidated=False)
    calls = _count_cases(monkeypatch)
    resumed = run_sweep(definition, copy, resume=True, progress=False).load()
    assert sum(calls) == 2
    xr.testing.assert_identical(resumed, expected)
    assert run_sweep(definition, copy, resume=True, progress=False) is not None
    assert sum(calls) == 2  # nothing left to run


def test_resume_refuses_a_different_definition(reference, tmp_path):
    _, _, store = reference
    changed = document(time_series=["relative_position", "payload_acceleration"])
    changed["grid"]["pi_kp"] = [5.0, 100.0]
    with pytest.raises(ParameterError, match="different sweep definition"):
        run_sweep(changed, store, resume=True, progress=False)


def test_overwrite_replaces_a_store(tmp_path):
    store = tmp_path / "o.zarr"
    run_sweep(DIVERGING, store, progress=False)
    data = run_sweep(document(batch_size=4), store, overwrite=True, progress=False)
    assert data.attrs["sweep_name"] == "small"


@pytest.fixture(scope="module")
def dask_cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  processes=True) as cluster:
        with distributed.Client(cluster) as client:
            yield cluster, client


def test_dask_cluster_run_equals_the_local_run(reference, dask_cluster, tmp_path):
    definition, expected, _ = reference
    cluster, client = dask_cluster
    data = run_sweep(definition, tmp_path / "dask.zarr", scheduler=client, progress=False)
    xr.testing.assert_identical(data.load(), expected)
    failing = run_sweep(DIVERGING, tmp_path / "dask-fail.zarr",
                        scheduler=cluster.scheduler_address, progress=False).load()
    local = run_sweep(DIVERGING, tmp_path / "local-fail.zarr", progress=False).load()
    xr.testing.assert_identical(failing, local)


@pytest.mark.filterwarnings("ignore:Port 8787 is already in use")  # an in-process worker's
def test_failed_dask_tasks_are_retried(reference, tmp_path, monkeypatch):
    """A task that raises (a lost worker, a full disk) runs again; the Dataset is unchanged."""
    distributed = pytest.importorskip("distributed")
    definition, expected, _ = reference
    calls = []
    run_group = sweep_batch._run_group

    def flaky(*args, **kwargs):  # every other call fails, so each task fails once
        calls.append(None)
        if len(calls) % 2:
            raise OSError("transient failure (injected by the test)")
        return run_group(*args, **kwargs)

    # an in-process cluster: its worker threads see the patched module
    monkeypatch.setattr(sweep_batch, "_run_group", flaky)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            data = run_sweep(definition, tmp_path / "retried.zarr", scheduler=client,
                             progress=False).load()
    xr.testing.assert_identical(data, expected)
    assert len(calls) == 2 * definition.n_cases // definition.batch_size


def test_cases_with_their_own_excitation_run_side_by_side(tmp_path):
    """Per-case excitations make one group per case: run in parallel, the same Dataset."""
    sweep = document(batch_size=4)
    sweep["grid"] = {"pi_kp": [5.0, 200.0], "excitation.amplitude": [0.005, 0.010]}
    parallel = run_sweep(sweep, tmp_path / "parallel.zarr", threads=2, progress=False).load()
    serial = run_sweep(sweep, tmp_path / "serial.zarr", threads=1, progress=False).load()
    xr.testing.assert_identical(parallel, serial)
    assert np.all(parallel["status"].values == OK)


@pytest.mark.filterwarnings("ignore:Port 8787 is already in use")  # the fixture's scheduler
def test_workers_start_a_local_cluster(tmp_path):
    pytest.importorskip("distributed")
    data = run_sweep(DIVERGING, tmp_path / "own.zarr", workers=1, progress=False).load()
    local = run_sweep(DIVERGING, tmp_path / "local.zarr", progress=False).load()
    xr.testing.assert_identical(data, local)


# ---------------------------------------------------------------- command line
def parse(*argv):
    parser = argparse.ArgumentParser(prog="qzs")
    add_parsers(parser.add_subparsers(dest="command", required=True))
    return parser.parse_args(argv)


@pytest.fixture
def sweep_file(tmp_path):
    import tomli_w

    path = tmp_path / "small.toml"
    path.write_text(tomli_w.dumps(document(batch_size=4)))
    return path


def test_command_runs_prints_and_refuses_reuse(sweep_file, tmp_path, capsys):
    store = tmp_path / "cli.zarr"
    assert run_sweep_command(parse("sweep", str(sweep_file), "--dry-run")) == 0
    assert "4 cases (grid), 1 batches of 4" in capsys.readouterr().out
    assert run_sweep_command(parse("sweep", str(sweep_file), "--out", str(store),
                                   "--quiet")) == 0
    out = capsys.readouterr().out
    assert "4 of 4 cases stored" in out and "ok 4, invalid 0, failed 0" in out
    with pytest.raises(ParameterError, match="exists"):
        run_sweep_command(parse("sweep", str(sweep_file), "--out", str(store)))
    with pytest.raises(SystemExit) as stop:  # a usage error of the parser (exit 2)
        parse("sweep", str(sweep_file), "--workers", "0")
    assert stop.value.code == 2
    assert "argument --workers: must be an integer >= 1, got 0" in capsys.readouterr().err


def test_command_interrupt_exits_130_with_the_resume_hint(sweep_file, tmp_path, capsys,
                                                          monkeypatch):
    _count_cases(monkeypatch, interrupt_at=1, exception=KeyboardInterrupt)  # a real Ctrl-C
    store = tmp_path / "int.zarr"
    try:
        code = run_sweep_command(parse("sweep", str(sweep_file), "--out", str(store),
                                       "--quiet"))
    except KeyboardInterrupt:  # must not escape: it would end the whole pytest session
        pytest.fail("Ctrl-C escaped `qzs sweep` instead of ending it with exit code 130")
    assert code == 130
    err = capsys.readouterr().err
    assert "0 of 4 cases are stored" in err and "--resume" in err


def test_command_sigterm_exits_143_with_the_resume_hint(sweep_file, tmp_path, capsys,
                                                        monkeypatch):
    from qzs.errors import Terminated

    _count_cases(monkeypatch, interrupt_at=1, exception=lambda message: Terminated(15))
    store = tmp_path / "term.zarr"
    try:
        code = run_sweep_command(parse("sweep", str(sweep_file), "--out", str(store),
                                       "--quiet"))
    except Terminated:
        pytest.fail("SIGTERM's exception escaped `qzs sweep` instead of ending it with 143")
    assert code == 143
    err = capsys.readouterr().err
    assert "terminated; 0 of 4 cases are stored" in err and "--resume" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml", "term.zarr"]
    assert run_sweep_command(parse("sweep", str(sweep_file), "--out", str(store), "--resume",
                                   "--quiet")) == 0


def test_export_writes_the_time_series_in_matlab_order(reference, tmp_path, monkeypatch):
    """A sweep store to .mat: (case, time) series read back cases x samples, in MAT 5 and,
    above the limit, MAT 7.3 (stored transposed, as MATLAB reads HDF5)."""
    import h5py
    import scipy.io

    from qzs.iotools import matfile
    from qzs.workflows.sweeps import export_sweep

    _, data, store = reference
    read = scipy.io.loadmat(export_sweep(store, tmp_path / "s5.mat"))
    np.testing.assert_array_equal(read["relative_position"], data["relative_position"].values)
    np.testing.assert_array_equal(read["stiction_force"][:, 0], data["stiction_force"].values)
    assert read["units"][0, 0]["relative_position"][0] == "m"
    monkeypatch.setattr(matfile, "MAT5_LIMIT", 4096)
    with h5py.File(export_sweep(store, tmp_path / "s73.mat"), "r") as f:
        np.testing.assert_array_equal(f["relative_position"][()].T,
                                      data["relative_position"].values)
        assert f["relative_position"].shape == data["relative_position"].shape[::-1]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s5.mat", "s73.mat"]


@pytest.mark.slow
def test_the_shipped_sweep_runs_without_a_warning_and_defines_the_band_it_asks_for(tmp_path):
    """pi_vs_stiction is the example every page runs: it must run clean. Its grid once held
    settings no answer can come from: no integral action, where the 1.9 N the spring cannot
    carry sets the payload on its lower stop (no trusted bin in the 1-3 Hz band: a
    DataWarning per batch, and a probe no step meets), and Kp = 1000 N/m at 15 N of stiction,
    whose stick-slip each step refinement redraws (the step choice warned)."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = run_sweep("pi_vs_stiction", tmp_path / "pi.zarr", progress=False)
    assert [str(w.message) for w in caught] == []
    assert bool((data.status == OK).all())
    assert not np.isnan(data.mean_transmissibility_low).any()
    assert float(data.peak_stroke.max()) < 0.080          # inside the stops: +-80 mm
    assert int(data.stop_contacts.sum()) == 0
    assert "no step" not in data.attrs.get("dt_note", "")


def test_a_sweep_over_a_spring_law_s_parameter_is_its_single_runs(tmp_path):
    """A TOML sweep with a [spring] table (an oblique-spring QZS, docs/model.md §3.1) over
    ``spring.vertical_stiffness``: each case is the single run of that law, bit for bit, and
    the store keeps the varied value with its unit."""
    path = tmp_path / "oblique.toml"
    path.write_text('[sweep]\nname = "oblique"\nbatch_size = 2\n'
                    '[spring]\nlaw = "oblique"\nvertical_stiffness = "quasi-zero"\n'
                    '[grid]\nspring.vertical_stiffness = [200.0, 400.0]\n'
                    '[excitation]\nf1 = 10.0\n[simulation]\ndt = 5e-4\n'
                    '[analysis]\nfft_length = 2048\nn_averages = 8\nband = [0.0, 10.0]\n'
                    '[outputs]\ntime_series = ["relative_position", "spring_force"]\n')
    definition = load_sweep(path)
    assert definition.spring == qzs.ObliqueSpringQZS.quasi_zero()
    data = run_sweep(definition, tmp_path / "oblique.zarr", threads=1, progress=False).load()
    assert (data["status"].values == OK).all()
    assert data["spring.vertical_stiffness"].attrs["units"] == "N/m"
    for case, stiffness in enumerate((200.0, 400.0)):
        assert float(data["spring.vertical_stiffness"][case]) == stiffness
        law = qzs.ObliqueSpringQZS(vertical_stiffness=stiffness)
        run = qzs.simulate(qzs.Chirp(f1=10.0, duration=definition.analysis["duration"]),
                           qzs.IsolatorParameters(spring=law), dt=5e-4)
        row = data.isel(case=case)
        np.testing.assert_array_equal(row["relative_position"].values, run.relative_position)
        np.testing.assert_array_equal(row["spring_force"].values, run.spring_force)
    assert not np.array_equal(data["spring_force"][0], data["spring_force"][1])
