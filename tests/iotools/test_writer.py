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
from qzs.iotools.writer import StreamWriter, estimated_file_size, write_dataset

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
    assert lines[:6] == ["# Conventions = CF-1.10", "# title = toy", "# mass = 6.4 [kg]",
                         "# column names on line 5, units on line 6, data from line 7",
                         "time,x,held", "s,m,1"]
    assert lines[-1] == "# outcome = 3 [1]" and len(lines) == 6 + 100 + 1
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


def test_the_units_row_reads_with_pandas_and_numpy(tmp_path):
    """The CSV layout's promise: pandas reads (name, unit) columns, numpy the numbers after
    the line the layout line names, and both agree with the schema's units."""
    import pandas as pd

    with line_writer(tmp_path / "line.csv") as writer:
        writer.append(*block(30))
        path = writer.finish({"outcome": 3})
    table = pd.read_csv(path, comment="#", header=[0, 1])
    assert list(table.columns) == [(v.name, v.units) for v in LINE]
    np.testing.assert_allclose(table[("x", "m")].to_numpy(), np.sin(np.arange(30) * 1e-3),
                               rtol=1e-9)
    layout = next(line for line in path.read_text().splitlines() if "column names on line" in line)
    names_line = int(layout.split("column names on line ")[1].split(",")[0])
    numbers = np.loadtxt(path, delimiter=",", skiprows=names_line + 1)
    assert numbers.shape == (30, 3)
    np.testing.assert_allclose(numbers[:, 1], table[("x", "m")].to_numpy())


def test_a_dataset_of_two_dimensions_writes_a_long_table_with_units(tmp_path):
    import pandas as pd
    import xarray as xr

    frequency = np.array([1.0, 2.0, 3.0])
    data = xr.Dataset(
        {"magnitude": (("case", "frequency"), np.array([[1.0, 0.5, np.nan], [2.0, 1.0, 0.5]]),
                       {"units": "1"}),
         "trusted": (("case", "frequency"), np.array([[1, 1, 0], [1, 0, 1]], np.int8),
                     {"units": "1"})},
        coords={"case": ("case", ["a, with comma", "b"]),
                "frequency": ("frequency", frequency, {"units": "Hz"}),
                "mass": ("case", [6.4, 7.0], {"units": "kg"})},
        attrs={"Conventions": "CF-1.10", "title": "toy"})
    path = write_dataset(data, tmp_path / "curves.csv")
    table = pd.read_csv(path, comment="#", header=[0, 1])
    assert list(table.columns) == [("case", "Unnamed: 0_level_1"), ("frequency", "Hz"),
                                   ("mass", "kg"), ("magnitude", "1"), ("trusted", "1")]
    table.columns = [name for name, _ in table.columns]
    back = table.set_index(["case", "frequency"]).to_xarray()
    np.testing.assert_array_equal(back["magnitude"].sel(case="a, with comma").values,
                                  [1.0, 0.5, np.nan])
    np.testing.assert_array_equal(back["trusted"].values, data["trusted"].values)
    assert list(back["mass"].isel(frequency=0).values) == [6.4, 7.0]
    nc = write_dataset(data, tmp_path / "curves.nc")
    written = xr.load_dataset(nc)
    assert written.attrs.pop("history").endswith("written")  # the file's own history line
    xr.testing.assert_identical(written, data)
    with pytest.raises(ParameterError, match=r"\.nc, \.csv or \.mat"):
        write_dataset(data, tmp_path / "curves.txt")
    assert leftovers(tmp_path) == ["curves.csv", "curves.nc"]


def test_variables_of_different_dimension_orders_are_written_row_by_row_right(tmp_path):
    """As :func:`write_dataset` says: one row per point of the dataset's dimensions, every
    variable's value at that point whatever the order of its own dimensions. The values are
    a known function of the coordinates (``case + frequency / 100``), written (case,
    frequency) by one variable, (frequency, case) by another, (frequency,) by a third; the
    sizes (3 x 4) are not square, but a transposed array would still fit the reshape."""
    import pandas as pd
    import xarray as xr

    case, frequency = np.array([10.0, 20.0, 30.0]), np.array([1.0, 2.0, 5.0, 7.0])
    grid = case[:, None] + frequency[None, :] / 100.0
    data = xr.Dataset(
        {"by_case": (("case", "frequency"), grid, {"units": "1"}),
         "by_frequency": (("frequency", "case"), 2.0 * grid.T, {"units": "1"}),
         "per_frequency": (("frequency",), frequency ** 2, {"units": "Hz2"})},
        coords={"case": ("case", case, {"units": "1"}),
                "frequency": ("frequency", frequency, {"units": "Hz"})})
    table = pd.read_csv(write_dataset(data, tmp_path / "long.csv"), comment="#",
                        header=[0, 1])
    table.columns = [name for name, _ in table.columns]
    assert len(table) == case.size * frequency.size
    assert set(zip(table["case"], table["frequency"])) == {(c, f) for c in case
                                                            for f in frequency}
    expected = table["case"] + table["frequency"] / 100.0
    np.testing.assert_allclose(table["by_case"], expected, rtol=1e-9)
    np.testing.assert_allclose(table["by_frequency"], 2.0 * expected, rtol=1e-9)
    np.testing.assert_allclose(table["per_frequency"], table["frequency"] ** 2, rtol=1e-9)
