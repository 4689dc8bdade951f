"""The single run's streaming writer (:class:`qzs.engine.result_file.ResultWriter`, a
configuration of :class:`qzs.iotools.writer.StreamWriter`): same file in chunks, bounded
memory, clean I/O failures."""
import errno
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import xarray as xr

import qzs
from qzs.engine import kernels as K
from qzs.errors import DataError, ParameterError, Terminated
from qzs.engine.result_file import ResultWriter, estimated_size, read_result, save_result
from qzs.iotools import writer as stream


@pytest.fixture(scope="module")
def run():
    return qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), duration=1.0,
                        sample_rate=1000.0)


@pytest.fixture
def fixed_clock(monkeypatch):
    monkeypatch.setattr("qzs.engine.metadata._now", lambda: "2024-01-02T03:04:05+00:00")


def writer(path, run):
    return ResultWriter(path, isolator=run.isolator, controller=run.controller,
                        excitation=run.excitation)


def write_in_chunks(path, run, size):
    with writer(path, run) as w:
        for start in range(0, len(run), size):
            w.append(run._data[start:start + size], run._flags[start:start + size])
        return w.finish(run.run)


def leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.mark.parametrize("suffix", [".nc", ".csv", ".mat"])
def test_many_appends_make_the_same_file(tmp_path, run, fixed_clock, suffix):
    at_once = save_result(run, tmp_path / f"once{suffix}")
    chunked = write_in_chunks(tmp_path / f"chunked{suffix}", run, 97)
    if suffix == ".mat":
        import scipy.io

        once, parts = scipy.io.loadmat(at_once), scipy.io.loadmat(chunked)
        assert set(once) == set(parts)
        for name in set(once) - {"__header__"}:  # the header holds the time of writing
            assert str(once[name]) == str(parts[name]), name
        np.testing.assert_array_equal(once["payload_acceleration"][:, 0],
                                      run.payload_acceleration)
        with pytest.raises(DataError, match="is a MATLAB file"):
            read_result(at_once)
        assert leftovers(tmp_path) == []
        return
    if suffix == ".nc":
        xr.testing.assert_identical(xr.load_dataset(at_once, engine="h5netcdf"),
                                    xr.load_dataset(chunked, engine="h5netcdf"))
    else:
        assert at_once.read_text() == chunked.read_text()
    xr.testing.assert_identical(read_result(at_once), read_result(chunked))
    assert leftovers(tmp_path) == []


def test_netcdf_time_is_unlimited(tmp_path, run):
    import h5netcdf

    with h5netcdf.File(run.save(tmp_path / "r.nc"), "r") as f:
        # the file's name of `time` (decision 34)
        time = f.dimensions["elapsed_time"]
        assert time.isunlimited() and time.size == len(run)


def test_writer_rejects_bad_input(tmp_path, run):
    with pytest.raises(ParameterError, match=r"must end in \.nc, \.csv or \.mat"):
        writer(tmp_path / "r.txt", run)
    with writer(tmp_path / "r.nc", run) as w:
        with pytest.raises(ParameterError, match="must have shape"):
            w.append(np.zeros((3, 5)), np.zeros((3, 2), bool))
    assert leftovers(tmp_path) == [] and not (tmp_path / "r.nc").exists()
    w = writer(tmp_path / "r.csv", run)
    w.append(run._data, run._flags)
    w.finish(run.run)
    with pytest.raises(ParameterError, match="already finished"):
        w.append(run._data, run._flags)
    w.abort()  # idempotent, and leaves the finished file alone
    assert (tmp_path / "r.csv").exists()


@pytest.mark.parametrize("interruption", [KeyboardInterrupt, SystemExit, Terminated,
                                          RuntimeError])
@pytest.mark.parametrize("suffix", [".nc", ".csv", ".mat"])
def test_interrupted_writer_leaves_nothing(tmp_path, run, suffix, interruption):
    target = tmp_path / f"r{suffix}"
    target.write_text("old")
    with pytest.raises(interruption):
        with writer(target, run) as w:
            w.append(run._data[:100], run._flags[:100])
            assert leftovers(tmp_path)  # the temporary file exists meanwhile
            raise interruption()
    assert leftovers(tmp_path) == [] and target.read_text() == "old"


def test_unfinished_writer_leaves_nothing(tmp_path, run):
    with writer(tmp_path / "r.nc", run) as w:
        w.append(run._data[:10], run._flags[:10])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".nc", ".csv", ".mat"])
@pytest.mark.parametrize("stage", ["create", "append", "finish"])
def test_full_disk_is_a_clean_error(tmp_path, run, monkeypatch, suffix, stage):
    """ENOSPC at any stage: a DataError with path and reason, nothing left behind."""
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    if stage == "create":
        monkeypatch.setattr(stream, "_reserve_space", full)
    elif stage == "append":
        name = {".nc": "_append_netcdf", ".csv": "_append_csv", ".mat": "_append_mat"}[suffix]
        monkeypatch.setattr(ResultWriter, name, full)
    else:
        monkeypatch.setattr(stream, "_release_reserve", full)
    target = tmp_path / f"r{suffix}"
    with pytest.raises(DataError, match="disk is full") as caught:
        run.save(target)
    assert caught.value.path == target and caught.value.reason == "the disk is full"
    assert list(tmp_path.iterdir()) == []


def test_permission_denied_is_a_clean_error(tmp_path, run, monkeypatch):
    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))

    monkeypatch.setattr(stream.tempfile, "mkstemp", denied)
    with pytest.raises(DataError, match="permission denied") as caught:
        run.save(tmp_path / "r.nc")
    assert caught.value.reason == "permission denied"


@pytest.fixture
def small_disk(tmp_path):
    """A 3 MiB tmpfs (needs root and mount; skipped elsewhere)."""
    folder = tmp_path / "small"
    folder.mkdir()
    if sys.platform != "linux" or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root on Linux")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3m", "tmpfs", str(folder)],
                          capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {done.stderr.decode().strip()}")
    yield folder
    subprocess.run(["umount", str(folder)], check=True)


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_real_full_disk(small_disk, run, suffix):
    """A run larger than the disk: a clean error, no crash, no file; a small one fits."""
    code = textwrap.dedent(f"""
        import sys, qzs
        from qzs.errors import DataError
        run = qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), duration=20.0,
                           sample_rate=1000.0)
        try:
            run.save(sys.argv[1])
        except DataError as error:
            print("DataError", error.reason)
    """)
    done = subprocess.run([sys.executable, "-c", code, str(small_disk / f"big{suffix}")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]  # no segmentation fault
    assert done.stdout.strip() == "DataError the disk is full"
    assert done.stderr == ""
    assert list(small_disk.iterdir()) == []
    small = run.save(small_disk / f"small{suffix}")  # 1001 samples fit
    assert read_result(small).sizes["time"] == len(run)
    assert os.statvfs(small_disk).f_bfree * os.statvfs(small_disk).f_frsize > 1 << 20


def test_estimated_size_bounds_the_file(tmp_path, run):
    for suffix in (".nc", ".csv"):
        size = run.save(tmp_path / f"r{suffix}").stat().st_size
        estimate = estimated_size(len(run), suffix)
        assert size <= estimate < 3 * size + (1 << 20), (suffix, size, estimate)
    assert estimated_size(10**6, ".nc") == pytest.approx(10**6 * (24 * 8 + 2), rel=0.02)
    assert estimated_size(10**6, "x.csv") == pytest.approx(10**6 * 26 * 17, rel=0.01)


#: The writer's peak memory growth in a fresh interpreter [bytes]: its image's high-water
#: mark (VmHWM), which ``ru_maxrss`` is not: Linux keeps there, across ``exec``, the peak of
#: the process this one was started from (pytest's, above this one's, deep in the suite:
#: the growth then read 0 whatever the writer held).
MEMORY = """
import sys
import numpy as np
import h5netcdf, xarray
import qzs
from qzs.engine import kernels as K
from qzs.engine.result_file import ResultWriter

rows, chunk, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
run = qzs.simulate(qzs.Sine(amplitude=0.001, frequency=1.0), duration=0.01, sample_rate=1000.0)
data = np.random.default_rng(0).standard_normal((chunk, K.N_BASE_CHANNELS))  # no blocks
flags = np.zeros((chunk, 2), dtype=bool)
def peak():
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
before = peak()
with ResultWriter(path, isolator=run.isolator, controller=run.controller,
                  excitation=run.excitation) as writer:
    for start in range(0, rows, chunk):
        data[:, 0] = (start + np.arange(chunk)) * 1e-3
        writer.append(data, flags)
    writer.finish(run.run)
print((peak() - before) * 1024)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="VmHWM in /proc/self/status on Linux")
def test_streaming_memory_is_bounded(tmp_path):
    """2e6 samples x 24 channels in chunks of 1e5: the peak grows by far less than the
    384 MB one array of them would take."""
    rows, chunk = 2_000_000, 100_000
    path = tmp_path / "long.nc"
    done = subprocess.run([sys.executable, "-c", MEMORY, str(rows), str(chunk), str(path)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    growth = int(done.stdout.split()[-1])
    one_array = rows * K.N_BASE_CHANNELS * 8
    assert growth < 64 * 2**20, f"peak RSS grew by {growth / 2**20:.0f} MiB"
    assert growth < one_array / 5
    with xr.open_dataset(path, engine="h5netcdf") as data:
        assert data.sizes["elapsed_time"] == rows  # the file's `time` (decision 34)
        np.testing.assert_array_equal(data["elapsed_time"][-3:].values,
                                      (rows - 3 + np.arange(3)) * 1e-3)
    assert leftovers(tmp_path) == []
