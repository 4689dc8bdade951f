"""The file schema (:mod:`qzs.iotools.schema`): one description of a result's variables that
its dataset and its streamed file both follow, for a toy schema and for every result type."""
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import qzs
from qzs.errors import ParameterError
from qzs.iotools.files import read_result
from qzs.iotools.schema import (CONVENTIONS, Schema, Variable, time_coordinate, to_dataset)
from qzs.iotools.writer import StreamWriter, write_netcdf
from qzs.iotools.cf_layout import from_file_layout

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "data"
TOY = Schema(kind="a toy run", dimensions={"time": None, "axis": 2}, coordinates=(
    time_coordinate(),
    Variable(name="axis", dims=("axis",), units="1", long_name="axis name", dtype="str")),
    variables=(
    Variable(name="position", dims=("time",), units="m", long_name="position x"),
    Variable(name="force", dims=("time", "axis"), units="N", long_name="force per axis"),
    Variable(name="stuck", dims=("time",), units="1", long_name="held by friction",
             dtype="int8", flag_meanings="free stuck"),
    Variable(name="events", dims=("time",), units="1", long_name="events so far",
             dtype="int64")))


def toy_values(n=7):
    rng = np.random.default_rng(1)
    return {"time": np.arange(n) * 0.1, "axis": ["x", "y"], "position": rng.standard_normal(n),
            "force": rng.standard_normal((n, 2)), "stuck": rng.random(n) > 0.5,
            "events": np.arange(n) // 3}


def test_every_variable_has_units_long_name_and_its_type():
    data = to_dataset(TOY, toy_values(), {"title": "toy"})
    assert data.attrs["Conventions"] == CONVENTIONS == "CF-1.10"
    assert list(data.attrs) == ["Conventions", "title"]
    for name, variable in data.variables.items():
        assert variable.attrs["units"] and variable.attrs["long_name"], name
    assert data["stuck"].dtype == np.int8
    assert data["stuck"].attrs["flag_values"].dtype == np.int8
    assert data["stuck"].attrs["flag_values"].tolist() == [0, 1]
    assert data["stuck"].attrs["flag_meanings"] == "free stuck"
    assert data["events"].dtype == np.int64 and data["position"].dtype == np.float64
    assert data["axis"].dtype.kind == "U"
    assert data["time"].attrs["units"] == "s" and "standard_name" not in data["time"].attrs
    assert to_dataset(TOY, toy_values(), boolean_flags=True)["stuck"].dtype == bool


def test_the_attributes_keep_their_declared_order():
    time = time_coordinate()
    assert list(time.attrs()) == ["units", "long_name", "comment"]
    flag = Variable(name="f", dims=("t",), units="1", long_name="a flag", dtype="int8",
                    flag_meanings="no yes", attributes={"comment": "c"})
    assert list(flag.attrs()) == ["units", "long_name", "comment", "flag_values",
                                  "flag_meanings"]
    assert list(Variable(name="r", dims=("t",), units="m", long_name="r",
                         order=("long_name", "units")).attrs()) == ["long_name", "units"]
    assert Variable(name="bare", dims=("t",)).attrs() == {}


@pytest.mark.parametrize("arguments, message", [
    (dict(dtype="float32"), "`dtype`"),
    (dict(flag_meanings="no yes"), "must be 'int8'"),
    (dict(attributes={"units": "m"}), "repeat"),
    (dict(units="m", order=("units", "long_name")), "`order`"),
])
def test_a_wrong_variable_is_refused(arguments, message):
    with pytest.raises(ParameterError, match=message):
        Variable(name="x", dims=("time",), **arguments)


def test_a_wrong_schema_or_wrong_values_are_refused():
    with pytest.raises(ParameterError, match="more than once"):
        Schema(kind="k", dimensions={"t": None}, variables=(Variable(name="a", dims=("t",)),
                                                            Variable(name="a", dims=("t",))))
    with pytest.raises(ParameterError, match="undeclared"):
        Schema(kind="k", dimensions={"t": None}, variables=(Variable(name="a", dims=("u",)),))
    with pytest.raises(ParameterError, match="unlimited"):
        Schema(kind="k", dimensions={"t": None, "u": None})
    values = toy_values()
    with pytest.raises(ParameterError, match=r"missing \['events'\], unknown \['extra'\]"):
        to_dataset(TOY, {**{k: v for k, v in values.items() if k != "events"}, "extra": 1})
    with pytest.raises(ParameterError, match="sizes"):
        to_dataset(TOY, {**values, "axis": ["x", "y", "z"]})


def toy_writer(path, **options):
    return StreamWriter(path, TOY, blocks={"data": 5, "flags": 1},
                        columns={"time": ("data", 0), "position": ("data", 1),
                                 "force": ("data", slice(2, 4)), "stuck": ("flags", 0),
                                 "events": ("data", 4)},
                        values={"axis": ["x", "y"]}, **options)


def blocks(values):
    data = np.column_stack([values["time"], values["position"], values["force"],
                            values["events"]])
    return data, values["stuck"][:, None]


def test_a_streamed_file_is_the_dataset_xarray_writes(tmp_path):
    """The writer, in chunks, gives what ``to_dataset``'s dataset written by xarray holds:
    the same variables, types, attributes (in order) and values."""
    values = toy_values(10)
    data, flags = blocks(values)
    with toy_writer(tmp_path / "streamed.nc", attributes={"title": "toy"}) as writer:
        for start in range(0, 10, 3):
            writer.append(data[start:start + 3], flags[start:start + 3])
        writer.finish({"history": "now"})
    expected = to_dataset(TOY, values, {"title": "toy", "history": "now"})
    write_netcdf(expected, tmp_path / "xarray.nc")  # the file layout (decision 34)
    with xr.open_dataset(tmp_path / "streamed.nc", engine="h5netcdf") as streamed, \
            xr.open_dataset(tmp_path / "xarray.nc", engine="h5netcdf") as written:
        xr.testing.assert_identical(streamed.load(), written.load())
        for name in streamed.variables:
            assert list(streamed[name].attrs) == list(written[name].attrs), name
            assert streamed[name].dtype == written[name].dtype, name
    flags_back = read_result(tmp_path / "streamed.nc")["stuck"]
    assert flags_back.dtype == bool and flags_back.values.tolist() == values["stuck"].tolist()


def test_a_csv_of_a_schema_with_two_dimensional_variables_is_refused(tmp_path):
    with pytest.raises(ParameterError, match="NetCDF"):
        toy_writer(tmp_path / "toy.csv", suffixes=(".nc", ".csv"))
    with pytest.raises(ParameterError, match=r"must end in \.nc, got"):
        toy_writer(tmp_path / "toy.csv")
    with pytest.raises(ParameterError, match="missing"):
        StreamWriter(tmp_path / "toy.nc", TOY, blocks={"data": 4}, columns={})
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- every result type
def same_variables(dataset, other, *, exact=True):
    """The same variables (coordinates too), dimensions, units and values."""
    assert set(dataset.variables) == set(other.variables)
    for name, variable in dataset.variables.items():
        theirs = other[name]
        assert variable.dims == theirs.dims, name
        assert variable.attrs.get("units") == theirs.attrs.get("units"), name
        assert variable.attrs.get("long_name") == theirs.attrs.get("long_name"), name
        if variable.dtype.kind in "US" or theirs.dtype.kind in "OUS":
            assert variable.values.astype(str).tolist() == theirs.values.astype(str).tolist()
        elif exact:
            np.testing.assert_array_equal(variable.values, theirs.values.astype(variable.dtype),
                                          err_msg=name)


def test_a_run_streamed_to_a_file_holds_its_dataset(tmp_path):
    from qzs.engine.result_file import read_result as read_run
    from qzs.engine.channels import simulation_schema
    from qzs.workflows.run import simulate_to_file

    excitation = qzs.Sine(amplitude=0.002, frequency=3.0)
    streamed = simulate_to_file(tmp_path / "run.nc", excitation, duration=0.5,
                                sample_rate=500.0)
    whole = qzs.simulate(excitation, duration=0.5, sample_rate=500.0)
    same_variables(read_run(tmp_path / "run.nc"), whole.to_xarray())
    assert set(simulation_schema().names) == set(whole.to_xarray().variables)
    assert streamed.run["samples"] == len(whole)


def test_a_batch_follows_the_single_runs_schema():
    from qzs.engine.batch import batch_schema

    cases = [(qzs.IsolatorParameters(stiction_force=f), qzs.ControllerParameters())
             for f in (5.0, 10.0)]
    batch = qzs.simulate_batch(cases, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2,
                               sample_rate=500.0, channels=("relative_position", "locked"),
                               workers=1)
    data = batch.to_xarray()
    run = qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), cases[1][0], duration=0.2,
                       sample_rate=500.0).to_xarray()
    for name in ("time", "relative_position", "locked"):
        assert data[name].attrs.keys() == run[name].attrs.keys()
        assert data[name].attrs["units"] == run[name].attrs["units"]
        np.testing.assert_array_equal(data[name].values[-1] if name != "time" else
                                      data[name].values, run[name].values.astype(data[name].dtype))
    assert data["locked"].dtype == np.int8 and data["steps"].dtype == np.int64
    assert data["status"].attrs["flag_meanings"] == "completed failed"
    assert set(data.variables) == set(batch_schema(batch).names)
    data.to_netcdf(engine="h5netcdf")


def test_a_response_file_holds_its_dataset(tmp_path):
    from qzs.workflows.response import steady_state_response

    response = steady_state_response([2.0], 0.010, dt=1e-3, workers=1)
    data = response.to_xarray()
    with xr.open_dataset(response.save(tmp_path / "response.nc"), engine="h5netcdf") as saved:
        same_variables(data, from_file_layout(saved.load()))  # containers: attributes
    assert data["converged"].dtype == np.int8 and data["periods"].dtype == np.int64


def test_a_transmissibility_estimate_follows_its_schema():
    rng = np.random.default_rng(0)
    base = rng.standard_normal(20_000)
    estimate = qzs.transmissibility(base, np.convolve(base, np.ones(5) / 5, "same"), 1000.0,
                                    fft_length=1024)
    data = estimate.to_xarray()
    assert data.attrs["Conventions"] == "CF-1.10" and data.attrs["estimator"] == "psd_ratio"
    assert data["trusted"].dtype == np.int8
    np.testing.assert_array_equal(data["trusted"].values, estimate.trusted)
    np.testing.assert_array_equal(data["magnitude"].values, estimate.magnitude)
    for variable in data.variables.values():
        assert variable.attrs["units"] and variable.attrs["long_name"]


def test_an_experiment_follows_its_schema():
    from qzs.iotools.rig import read_recording
    from qzs.workflows.experiment.process import experiment_schema, process_experiment

    recording = read_recording(EXAMPLES / "experiment.csv", EXAMPLES / "experiment_map.toml")
    result = process_experiment(recording, fft_length=8192, simulate_match=False)
    data = result.to_xarray()
    assert set(data.variables) == set(experiment_schema(result).names)
    assert "simulation" not in data and data["trusted"].dtype == np.int8
    assert data["trusted"].attrs["flag_meanings"] == "untrusted trusted"
    assert data.attrs["Conventions"] == "CF-1.10" and data.attrs["source"] == recording.source
    data.to_netcdf(engine="h5netcdf")


def test_the_six_axis_matrix_schema_declares_units_and_flags():
    from qzs.workflows.hexapod.transmissibility import transmissibility_schema

    schema = transmissibility_schema("h1")
    for variable in schema:
        assert variable.long_name, variable.name
    flags = [v.name for v in schema if v.is_flag]
    assert flags == ["trusted", "below_floor", "excited"]
    assert list(schema["excited"].attrs()) == ["units", "long_name", "flag_meanings",
                                               "flag_values"]
    assert schema["magnitude"].long_name.startswith("|H1|")


# ---------------------------------------------------------------- the file layout (CF names)
def test_dotted_keys_go_to_containers_and_come_back(tmp_path):
    """No dot in a file's attribute names, string labels as characters, no fill value on a
    coordinate; read back (from_file_layout) the dataset is what was written (decision 34)."""
    import h5py

    from qzs.iotools.cf_layout import container_attributes, from_file_layout, to_file_layout
    from qzs.iotools.writer import write_netcdf

    plain, containers = container_attributes({"title": "t", "isolator.mass": 6.4,
                                              "isolator.mass_units": "kg",
                                              "settings.leg.x": 1.0})
    assert plain == {"title": "t", "parameter_containers": "isolator settings"}
    assert containers == {"isolator": {"mass": 6.4, "mass_units": "kg"},
                          "settings": {"leg__x": 1.0}}
    dataset = xr.Dataset({"x": (("case", "f"), np.ones((2, 3)), {"units": "m",
                                                                  "long_name": "x"})},
                         coords={"case": ("case", ["a", "b µ"], {"long_name": "case"}),
                                 "f": ("f", np.arange(3.0), {"units": "Hz", "long_name": "f"})},
                         attrs={"Conventions": CONVENTIONS, "history": "made here",
                                "isolator.mass": 6.4, "settings.leg.x": 1.0})
    layout, _ = to_file_layout(dataset)
    assert set(layout.attrs) == {"Conventions", "history", "parameter_containers"}
    path = write_netcdf(dataset, tmp_path / "x.nc")
    with h5py.File(path) as raw:
        assert raw["case"].ndim == 2 and raw["case"].dtype == "S1"  # characters, not strings
        assert "_FillValue" not in raw["f"].attrs and raw["isolator"].attrs["mass"] == 6.4
        assert not [key for key in raw.attrs if "." in key]
    back = from_file_layout(xr.load_dataset(path, engine="h5netcdf"))
    xr.testing.assert_identical(back, dataset)


@pytest.mark.parametrize("dtype", ["int8", "int16", "int32"])
def test_a_flags_values_are_written_in_the_flags_own_type(tmp_path, dtype):
    """CF 1.10 §3.5: ``flag_values`` must be of the flag variable's type. A dataset whose
    flag carries them as another type (a Python list: int64) is written with them cast."""
    import h5py

    from qzs.iotools.writer import write_netcdf

    dataset = xr.Dataset({"held": (("t",), np.array([0, 1, 1], dtype=dtype),
                                   {"units": "1", "long_name": "held",
                                    "flag_values": [0, 1], "flag_meanings": "free held"})},
                         coords={"t": ("t", np.arange(3.0), {"units": "s", "long_name": "t"})},
                         attrs={"Conventions": CONVENTIONS, "history": "made here"})
    with h5py.File(write_netcdf(dataset, tmp_path / "f.nc")) as raw:
        written = raw["held"].attrs["flag_values"]
        assert written.dtype == raw["held"].dtype == np.dtype(dtype)
        assert written.tolist() == [0, 1]
