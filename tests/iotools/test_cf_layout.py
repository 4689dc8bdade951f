"""The NetCDF file layout: CF's own means for what CF has no home for, and back (decision 34).

Properties: a dataset written in the file layout reads back identical (values, dimensions,
attributes and their order, variable order); each part of a variable of mixed units holds
exactly its block in one unit; a streamed file equals the whole dataset written at once;
the file spelling of dB/decade converts (UDUNITS, through cf_units) to the log-log slope.
"""
import numpy as np
import pytest
import xarray as xr

from qzs.iotools.cf_layout import (FILE_UNITS, file_schema, from_file_layout, split_parts,
                                   to_file_layout)
from qzs.iotools.schema import Schema, Variable, time_coordinate, to_dataset
from qzs.iotools.writer import StreamWriter, write_netcdf

AXES = ["x", "y", "z", "rx", "ry", "rz"]
POSE_UNITS = "x: m; y: m; z: m; rx: rad; ry: rad; rz: rad"
ENTRY = [["1" if (i < 3) == (j < 3) else ("m/rad" if i < 3 else "rad/m") for j in range(6)]
         for i in range(6)]


def toy(n=7, seed=3):
    """A dataset with every case: time, a pose over dof, a 6x6 matrix, a roll-off, params."""
    rng = np.random.default_rng(seed)
    return xr.Dataset(
        {"pose": (("time", "dof"), rng.standard_normal((n, 6)),
                  {"long_name": "pose", "units": "m, m, m, rad, rad, rad",
                   "units_by_dof": POSE_UNITS}),
         "speed": (("time",), rng.standard_normal(n), {"units": "m/s", "long_name": "speed"}),
         "matrix": (("frequency", "output_dof", "input_dof"), rng.standard_normal((4, 6, 6)),
                    {"units": "mixed (see entry_units)", "long_name": "matrix",
                     "units_by_entry": "entry_units"}),
         "phase": (("frequency", "output_dof", "input_dof"), rng.standard_normal((4, 6, 6)),
                   {"units": "rad", "long_name": "phase"}),
         "entry_units": (("output_dof", "input_dof"), np.array(ENTRY, dtype=object),
                         {"long_name": "unit of each entry"}),
         "rolloff": ((), -40.0, {"units": "dB/decade", "long_name": "roll-off"})},
        coords={"time": ("time", np.arange(n) * 0.1, time_coordinate().attrs()),
                "dof": ("dof", np.array(AXES, dtype=object), {"long_name": "dof", "units": "1"}),
                "output_dof": ("output_dof", np.array(AXES, dtype=object),
                               {"long_name": "out", "units": "1"}),
                "input_dof": ("input_dof", np.array(AXES, dtype=object),
                              {"long_name": "in", "units": "1"}),
                "frequency": ("frequency", np.arange(4.0), {"units": "Hz", "long_name": "f"})},
        attrs={"Conventions": "CF-1.10", "title": "toy", "history": "now",
               "isolator.mass": 6.4, "isolator.mass_units": "kg"})


def written(dataset, path):
    layout, encoding = to_file_layout(dataset)
    layout.to_netcdf(path, engine="h5netcdf", encoding=encoding)
    return xr.load_dataset(path, engine="h5netcdf")


def test_a_dataset_reads_back_identical(tmp_path):
    dataset = toy()
    back = from_file_layout(written(dataset, tmp_path / "toy.nc"))
    back["dof"] = back["dof"].astype(object)  # strings come back as str, not object
    xr.testing.assert_identical(back.drop_vars("entry_units"), dataset.drop_vars("entry_units"))
    assert back["entry_units"].values.tolist() == ENTRY
    assert list(back.data_vars) == list(dataset.data_vars)
    for name in dataset.variables:
        assert list(back[name].attrs) == list(dataset[name].attrs), name


def test_the_file_has_one_unit_per_variable_and_each_part_is_its_block(tmp_path):
    dataset = toy()
    raw = written(dataset, tmp_path / "toy.nc")
    assert "time" not in raw.dims and raw["elapsed_time"].attrs["units"] == "s"
    assert "pose" not in raw and "matrix" not in raw
    np.testing.assert_array_equal(raw["pose_translation"].values, dataset["pose"].values[:, :3])
    np.testing.assert_array_equal(raw["pose_rotation"].values, dataset["pose"].values[:, 3:])
    assert raw["pose_translation"].attrs["units"] == "m"
    assert raw["pose_rotation"].attrs["units"] == "rad"
    assert raw["translation"].values.tolist() == ["x", "y", "z"]
    for out, rows in (("translation", slice(0, 3)), ("rotation", slice(3, 6))):
        for into, columns in (("translation", slice(0, 3)), ("rotation", slice(3, 6))):
            part = raw[f"matrix_{out}_per_{into}"]
            assert part.dims == ("frequency", f"output_{out}", f"input_{into}")
            np.testing.assert_array_equal(part.values, dataset["matrix"].values[:, rows, columns])
            assert {part.attrs["units"]} == set(np.array(ENTRY)[rows, columns].ravel())
    assert raw["phase"].dims == ("frequency", "output_dof", "input_dof")  # one unit: whole
    assert raw["rolloff"].attrs["units"] == FILE_UNITS["dB/decade"][0]
    assert raw["isolator"].attrs["mass"] == 6.4 and "isolator.mass" not in raw.attrs


def test_a_variable_of_one_unit_is_not_split():
    assert split_parts("twist", ("time", "dof"), {"units_by_dof": "; ".join(
        f"{a}: m/s" for a in AXES)}) is None
    assert split_parts("speed", ("time",), {"units": "m/s"}) is None
    assert split_parts("phase", ("frequency", "output_dof", "input_dof"),
                       {"units_by_entry": "units"}, lambda name: [["rad"] * 6] * 6) is None
    assert split_parts("coherence", ("frequency", "output_dof", "input_dof"), {},
                       lambda name: ENTRY) is None  # its units are its own, not per entry


def test_the_roll_off_unit_converts_to_the_log_log_slope():
    """-40 dB/decade is a transmissibility falling as 1/f^2: log-log slope -2 (UDUNITS)."""
    cf_units = pytest.importorskip("cf_units")
    frequency = np.logspace(0, 2, 50)
    slope_db = np.polyfit(np.log10(frequency), 20 * np.log10(3.0 / frequency ** 2), 1)[0]
    spelled = FILE_UNITS["dB/decade"][0]
    assert cf_units.Unit(spelled).convert(slope_db, cf_units.Unit("1")) == pytest.approx(-2.0)


SCHEMA = Schema(kind="a toy platform", dimensions={"time": None, "dof": 6},
                coordinates=(time_coordinate(), Variable(name="dof", dims=("dof",), units="1",
                                                         long_name="dof", dtype="str")),
                variables=(Variable(name="pose", dims=("time", "dof"),
                                    units="m, m, m, rad, rad, rad", long_name="pose",
                                    attributes={"units_by_dof": POSE_UNITS}),
                           Variable(name="speed", dims=("time",), units="m/s",
                                    long_name="speed")))


def test_a_streamed_file_is_the_whole_dataset_written_at_once(tmp_path):
    rng = np.random.default_rng(5)
    n = 11
    rows = np.column_stack([np.arange(n) * 0.01, rng.standard_normal((n, 7))])
    with StreamWriter(tmp_path / "streamed.nc", SCHEMA, blocks={"data": 8},
                      columns={"time": ("data", 0), "pose": ("data", slice(1, 7)),
                               "speed": ("data", 7)},
                      values={"dof": AXES}, attributes={"title": "t"}) as writer:
        for start in range(0, n, 4):
            writer.append(rows[start:start + 4])
        writer.finish({"history": "now"})
    dataset = to_dataset(SCHEMA, {"time": rows[:, 0], "dof": AXES, "pose": rows[:, 1:7],
                                  "speed": rows[:, 7]}, {"title": "t", "history": "now"})
    write_netcdf(dataset, tmp_path / "whole.nc")
    streamed = xr.load_dataset(tmp_path / "streamed.nc", engine="h5netcdf")
    whole = xr.load_dataset(tmp_path / "whole.nc", engine="h5netcdf")
    xr.testing.assert_identical(streamed, whole)
    back = from_file_layout(streamed)
    np.testing.assert_array_equal(back["pose"].values, rows[:, 1:7])
    assert back["pose"].attrs == dataset["pose"].attrs


def test_the_file_schema_places_each_part_on_its_columns():
    layout, columns, values = file_schema(SCHEMA, {"time": ("data", 0),
                                                   "pose": ("data", slice(1, 7)),
                                                   "speed": ("data", 7)}, {"dof": AXES})
    assert columns["pose_translation"] == ("data", slice(1, 4))
    assert columns["pose_rotation"] == ("data", slice(4, 7))
    assert columns["elapsed_time"] == ("data", 0) and layout.unlimited == "elapsed_time"
    assert values["translation"] == ["x", "y", "z"] and values["rotation"] == ["rx", "ry", "rz"]
