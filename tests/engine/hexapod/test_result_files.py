"""A hexapod run streamed to NetCDF (``simulate_setup(..., out=)``, ``qzs hexapod simulate
--out``): the file holds exactly what the in-memory run holds, memory stays bounded (a
preview), the summary covers every sample, Ctrl-C keeps what was simulated, and a failure
leaves no file behind."""
import signal

import numpy as np
import pytest
import xarray as xr

from qzs.cli import main
from qzs.engine import driver as driver_module
from qzs.engine.hexapod import simulate as hexapod_simulate
from qzs.errors import OutputPathError, ParameterError
from qzs.engine.hexapod.result import HexapodWriter, estimated_hexapod_size
from qzs.workflows.hexapod.setups import load_hexapod, simulate_setup
from qzs.iotools.cf_layout import from_file_layout

#: Longer than one kernel chunk (200,000 steps at dt 1e-4 s), so that chunks join in the file.
DURATION = 24.0


@pytest.fixture(scope="module")
def setup():
    return load_hexapod("paper_legs_cubic", {"stiction_force": 2.0, "coulomb_force": 1.0})


@pytest.fixture(scope="module")
def in_memory(setup):
    return simulate_setup(setup, duration=DURATION)


def test_the_streamed_file_is_the_in_memory_run(setup, in_memory, tmp_path):
    path = tmp_path / "platform.nc"
    streamed = simulate_setup(setup, duration=DURATION, out=path)
    expected = in_memory.to_xarray()
    with xr.open_dataset(path) as raw:
        written = from_file_layout(raw)  # the parameters' containers as dotted attributes
        assert dict(written.sizes) == dict(expected.sizes)
        for name in expected.data_vars:
            assert np.array_equal(written[name].values.astype(expected[name].dtype),
                                  expected[name].values), name
            assert written[name].dims == expected[name].dims, name
            assert list(written[name].attrs) == list(expected[name].attrs), name
            for key in ("units", "long_name", "flag_meanings", "units_by_dof"):
                assert written[name].attrs.get(key) == expected[name].attrs.get(key), name
        for name in ("dof", "leg"):  # one schema (hexapod_schema) for both
            assert written[name].attrs == expected[name].attrs
        assert list(written["dof"].values) == list(expected["dof"].values)
        assert set(written.attrs) == set(expected.attrs)
        assert written.attrs["run.samples"] == len(in_memory)
    assert streamed.statistics == in_memory.statistics
    assert streamed.run["stick_events"] == in_memory.run["stick_events"]
    assert [p.name for p in tmp_path.iterdir()] == ["platform.nc"]  # no temporary file left


def test_a_long_run_keeps_a_preview_and_summarises_every_sample(setup, in_memory, tmp_path,
                                                                monkeypatch):
    """With more samples than the preview holds, the result keeps the min/max envelope of
    groups of k samples, as a single run's preview does (before, every k-th sample: an
    aliased pick); the statistics (and so the summary) are still those of all of them, to
    the last bit."""
    monkeypatch.setattr(driver_module, "PREVIEW_SAMPLES", 1000)
    streamed = simulate_setup(setup, duration=DURATION, out=tmp_path / "long.nc")
    every = streamed.run["preview_every"]
    assert every == -(-len(in_memory) // 500) and len(streamed) <= 1000
    full = in_memory["relative_position"]
    groups = [full[i:i + every] for i in range(0, len(full), every)]
    preview = streamed["relative_position"]
    np.testing.assert_array_equal(preview[0::2], [g.min(axis=0) for g in groups])
    np.testing.assert_array_equal(preview[1::2], [g.max(axis=0) for g in groups])
    locked = streamed["locked"]
    np.testing.assert_array_equal(locked[1::2], [g.any(axis=0) for g in
                                                 (in_memory["locked"][i:i + every]
                                                  for i in range(0, len(full), every))])
    assert streamed.statistics == in_memory.statistics
    assert f"envelope of groups of {every} samples" in streamed.summary()
    assert streamed.summary().split("\n")[1:-1] == in_memory.summary().split("\n")[1:]


def test_ctrl_c_keeps_what_was_simulated(setup, tmp_path, monkeypatch):
    """Ctrl-C during an interruptible run: the chunk under way ends, the file holds every
    sample simulated, and the run says it did not complete."""
    original = HexapodWriter.append
    calls = []

    def append(self, data, flags):
        original(self, data, flags)
        calls.append(len(data))
        if len(calls) == 2:  # after the first chunk
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(HexapodWriter, "append", append)
    monkeypatch.setattr(hexapod_simulate, "PREVIEW_CHUNK", 2000)  # 13 chunks
    path = tmp_path / "stopped.nc"
    result = simulate_setup(setup, duration=DURATION, out=path, interruptible=True)
    assert result.run["completed"] is False
    # the kernel steps the next chunk while the last is written: it ends after that one
    assert result.run["samples"] == 1 + 2 * 2000
    with xr.open_dataset(path) as raw:
        written = from_file_layout(raw)  # the file layout read back (decision 34)
        assert written.sizes["time"] == result.run["samples"] == sum(calls)
        assert written.attrs["run.completed"] == 0  # the run's container, read back
    assert "Interrupted" in result.summary()


def test_a_failure_during_the_run_leaves_nothing(setup, tmp_path, monkeypatch):
    original = HexapodWriter.append
    calls = []

    def append(self, data, flags):
        calls.append(1)
        if len(calls) == 3:
            raise OSError(28, "No space left on device")
        original(self, data, flags)

    monkeypatch.setattr(HexapodWriter, "append", append)
    with pytest.raises(OSError):
        simulate_setup(setup, duration=DURATION, dt=1e-4, out=tmp_path / "full.nc")
    assert list(tmp_path.iterdir()) == []


def test_bad_outputs_are_refused_before_the_run(setup, tmp_path, capsys):
    with pytest.raises(OutputPathError, match="out"):
        simulate_setup(setup, duration=DURATION, out=tmp_path / "run.csv")
    with pytest.raises(ParameterError, match=r"\.nc"):
        HexapodWriter(tmp_path / "run.txt")
    assert main(["hexapod", "simulate", "--duration", "1", "--out",
                 str(tmp_path / "missing" / "deeper" / "x.csv")]) == 2
    assert "--out" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
    small, large = estimated_hexapod_size(1), estimated_hexapod_size(2_000_001)
    assert small < 4e6 and 1.6e9 < large < 1.8e9  # 99 float channels + 12 flags per sample, in
    # whole chunks of 4096 samples


def test_a_run_streamed_to_mat_is_the_netcdf_in_matlab_layout(setup, tmp_path):
    """`out="run.mat"` (`qzs hexapod simulate --out run.mat`): the same variables as the
    NetCDF file, (time, dof) arrays n x 6, flags logical, labels a cell array."""
    import scipy.io

    nc, mat = tmp_path / "p.nc", tmp_path / "p.mat"
    simulate_setup(setup, duration=0.5, out=nc)
    simulate_setup(setup, duration=0.5, out=mat)
    read = scipy.io.loadmat(mat)
    with xr.open_dataset(nc) as raw:
        netcdf = from_file_layout(raw)  # the file layout read back (decision 34)
        for name in ("platform_pose", "relative_position", "kinetic_energy", "time"):
            expected = netcdf[name].values
            assert np.array_equal(read[name], expected if expected.ndim == 2
                                  else expected[:, None]), name
        assert np.array_equal(read["locked"], netcdf["locked"].values)
        assert read["units"][0, 0]["relative_position"][0] == "m"
    assert [str(c[0]) for c in read["dof"][:, 0]] == ["x", "y", "z", "rx", "ry", "rz"]
    assert dict((n, c) for n, _, c in scipy.io.whosmat(mat))["locked"] == "logical"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.mat", "p.nc"]


def test_save_writes_the_held_run_and_refuses_a_preview(setup, in_memory, tmp_path, monkeypatch):
    path = in_memory.save(tmp_path / "saved.nc")
    with xr.open_dataset(path) as raw:
        written = from_file_layout(raw)  # the file layout read back (decision 34)
        assert np.array_equal(written["platform_pose"].values, in_memory["platform_pose"])
        assert written.sizes["time"] == len(in_memory)
    monkeypatch.setattr(driver_module, "PREVIEW_SAMPLES", 1000)
    preview = simulate_setup(setup, duration=DURATION, out=tmp_path / "streamed.nc")
    with pytest.raises(ParameterError, match="preview"):
        preview.save(tmp_path / "again.nc")
