"""The streaming atomic CF writer (:class:`qzs.iotools.writer.StreamWriter`) of any schema:
nothing left behind whatever ends a stream, CSV for a one-dimensional schema, size estimates.
The single run's and the six-axis run's configurations are tested in tests/test_writer.py and
tests/test_hexapod_streaming.py."""
import errno
import os

import numpy as np
import pytest

from qzs.errors import DataError, ParameterError, Terminated, WriteError
from qzs.iotools import writer as stream
from qzs.iotools.files import read_result
from qzs.iotools.schema import Schema, Variable, time_coordinate
from qzs.iotools.writer import StreamWriter, estimated_file_size

LINE = Schema(kind="a toy line", dimensions={"time": None}, coordinates=(time_coordinate(),),
              variables=(Variable(name="x", dims=("time",), units="m", long_name="position"),
                         Variable(name="held", dims=("time",), units="1", long_name="held",
                                  dtype="int8", flag_meanings="free held")))


def line_writer(path):
    return StreamWriter(path, LINE, blocks={"data": 2, "flags": 1},
                        columns={"time": ("data", 0), "x": ("data", 1), "held": ("flags", 0)},
                        attributes={"title": "toy", "mass": 6.4, "mass_units": "kg"},
                        suffixes=(".nc", ".csv"))


def block(n=50, start=0):
    time = (start + np.arange(n)) * 1e-3
    return np.column_stack([time, np.sin(time)]), (np.arange(start, start + n) % 3 == 0)[:, None]


def leftovers(folder):
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("ending", [KeyboardInterrupt, Terminated, SystemExit, RuntimeError,
                                    OSError])
@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_whatever_ends_a_stream_leaves_nothing_behind(tmp_path, suffix, ending):
    target = tmp_path / f"line{suffix}"
    with pytest.raises(ending):
        with line_writer(target) as writer:
            writer.append(*block())
            assert len(leftovers(tmp_path)) == 1  # the hidden .part file, meanwhile
            assert leftovers(tmp_path)[0].startswith(".line") and leftovers(tmp_path)[0].endswith(
                ".part")
            raise ending()
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("ending", [KeyboardInterrupt, Terminated])
def test_an_interruption_inside_a_write_leaves_nothing_behind(tmp_path, monkeypatch, ending):
    """Interrupted while the library writes a chunk (not only between chunks): removed too,
    and an existing target is left as it was."""
    target = tmp_path / "line.nc"
    target.write_text("old")
    writer = line_writer(target)
    writer.append(*block())

    def interrupted(*args):
        raise ending()

    monkeypatch.setattr(writer, "_append_netcdf", interrupted)
    with pytest.raises(ending):
        writer.append(*block(start=50))
    assert leftovers(tmp_path) == ["line.nc"] and target.read_text() == "old"
    with pytest.raises(ParameterError, match="already finished or aborted"):
        writer.finish()


def test_a_full_disk_while_appending_is_a_write_error(tmp_path, monkeypatch):
    writer = line_writer(tmp_path / "line.nc")

    def full(*args):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(stream, "_reserve_space", full)
    with pytest.raises(WriteError, match="disk is full") as caught:
        writer.append(*block())
    assert isinstance(caught.value, DataError) and caught.value.reason == "the disk is full"
    assert leftovers(tmp_path) == []


def test_a_dropped_writer_leaves_nothing_behind(tmp_path):
    writer = line_writer(tmp_path / "line.csv")
    writer.append(*block())
    del writer
    assert leftovers(tmp_path) == []


def test_a_one_dimensional_schema_streams_to_csv(tmp_path):
    with line_writer(tmp_path / "line.csv") as writer:
        for start in range(0, 100, 40):
            writer.append(*block(min(40, 100 - start), start))
        path = writer.finish({"outcome": 3, "outcome_units": "1"})
    lines = path.read_text().splitlines()
    assert lines[:4] == ["# Conventions = CF-1.10", "# title = toy", "# mass = 6.4 [kg]",
                         "time,x,held"]
    assert lines[-1] == "# outcome = 3 [1]" and len(lines) == 4 + 100 + 1
    data = read_result(path, LINE)
    assert data["held"].dtype == bool and data["x"].attrs["units"] == "m"
    np.testing.assert_allclose(data["x"].values, np.sin(np.arange(100) * 1e-3), rtol=1e-9)
    assert data.attrs["outcome"] == 3 and data.attrs["mass_units"] == "kg"
    assert read_result(path)["held"].dtype == np.float64  # without the schema: plain columns


def test_wrong_blocks_are_refused(tmp_path):
    with line_writer(tmp_path / "line.nc") as writer:
        with pytest.raises(ParameterError, match=r"`data` \(n, 2\) and `flags` \(n, 1\)"):
            writer.append(np.zeros((3, 2)))
        with pytest.raises(ParameterError, match="must have shape"):
            writer.append(np.zeros((3, 2)), np.zeros((4, 1), bool))
        assert writer.rows == 0
    assert leftovers(tmp_path) == []


def test_the_size_estimate_bounds_the_file(tmp_path):
    for suffix in (".nc", ".csv"):
        with line_writer(tmp_path / f"line{suffix}") as writer:
            writer.append(*block(5000))
            path = writer.finish()
        estimate = estimated_file_size(LINE, 5000, suffix)
        assert path.stat().st_size <= estimate < 3 * path.stat().st_size + (1 << 20)
    chunks = -(-10**6 // 4096)
    assert estimated_file_size(LINE, 10**6, ".nc") == (chunks * (4096 * 17 + 128 * 3)
                                                       + (128 << 10))
