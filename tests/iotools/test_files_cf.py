"""Result files follow CF-1.10 and round-trip every value and parameter (docs/model.md §7)."""
import dataclasses

import numpy as np
import pytest
import xarray as xr

import qzs
from qzs.engine.channels import CHANNELS, FLAGS
from qzs.engine.metadata import RUN_UNITS
from qzs.engine.result_file import read_result
from qzs.iotools.cf_layout import from_file_layout
from qzs.model.registry import parameter_fields, unit_of

ISOLATOR = qzs.IsolatorParameters(stiction_force=6.0)  # stop_center stays None


@pytest.fixture(scope="module")
def run():
    return qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), ISOLATOR, duration=1.0,
                        sample_rate=500.0)


@pytest.fixture(scope="module")
def netcdf(run, tmp_path_factory):
    path = run.save(tmp_path_factory.mktemp("cf") / "run.nc")
    # the file as any reader sees it, the parameters' containers read as dotted attributes
    return from_file_layout(xr.load_dataset(path, engine="h5netcdf")), path


def test_parameters_are_in_containers_and_no_global_name_has_a_dot(netcdf, run):
    """CF attribute names are letters, digits and underscores (decision 34)."""
    raw = xr.load_dataset(netcdf[1], engine="h5netcdf")
    assert not [key for key in raw.attrs if not key.replace("_", "a").isalnum()]
    assert raw.attrs["parameter_containers"].split() == ["isolator", "controller",
                                                         "excitation", "run"]
    assert raw["isolator"].attrs["mass"] == run.isolator.mass
    assert raw["isolator"].attrs["mass_units"] == "kg"
    assert raw["run"].attrs["dt"] == run.run["dt"] and raw["run"].attrs["dt_units"] == "s"
    assert raw["isolator"].attrs["long_name"].startswith("container")


def test_global_attributes(netcdf):
    data, _ = netcdf
    attrs = data.attrs
    assert attrs["Conventions"] == "CF-1.10"
    assert "Sine" in attrs["title"] and "qzs" in attrs["source"]
    stamp, rest = attrs["history"].split(" ", 1)
    np.datetime64(stamp.replace("+00:00", ""))  # an ISO 8601 time
    assert f"qzs {qzs.__version__}" in rest and "ode3" in rest and "steps" in rest


def test_time_is_elapsed_time_in_plain_seconds(netcdf):
    """A run's time has no date: in the file it is ``elapsed_time`` in s, not a CF calendar
    time (no standard_name ``time``, no axis T, no ``since``), and reads back as ``time``
    in float seconds, not decoded to dates (decision 34)."""
    time = netcdf[0]["time"]
    assert "standard_name" not in time.attrs and "axis" not in time.attrs
    assert time.attrs["units"] == "s" and time.dtype == np.float64  # not decoded to dates
    assert time.attrs["long_name"]
    raw = xr.load_dataset(netcdf[1], engine="h5netcdf")
    assert "time" not in raw.variables and "time" not in raw.dims
    assert raw["elapsed_time"].attrs["units"] == "s" and raw["elapsed_time"].dtype == np.float64
    assert raw["relative_position"].dims == ("elapsed_time",)


def test_every_variable_has_units_and_long_name(netcdf):
    data, _ = netcdf
    for name, variable in data.variables.items():  # (the containers are read as attributes)
        assert variable.attrs.get("units"), name
        assert variable.attrs.get("long_name"), name
    for name, (_, unit, _) in CHANNELS.items():
        assert data[name].attrs["units"] == unit


@pytest.mark.parametrize("name, meanings", [("locked", "slipping locked"),
                                            ("stop_contact", "free contact")])
def test_flags_are_int8_with_flag_values(netcdf, run, name, meanings):
    flag = netcdf[0][name]
    assert flag.dtype == np.int8 and flag.attrs["units"] == "1"
    values = np.asarray(flag.attrs["flag_values"])
    assert values.dtype == np.int8 and values.tolist() == [0, 1]
    assert flag.attrs["flag_meanings"] == meanings
    assert len(flag.attrs["flag_meanings"].split()) == values.size
    np.testing.assert_array_equal(flag.values, run[name].astype(np.int8))


def test_every_parameter_carries_its_unit(netcdf, run):
    attrs = netcdf[0].attrs
    for section, params in (("isolator", run.isolator), ("controller", run.controller)):
        for field in parameter_fields(params):  # a block is no parameter (run without blocks)
            key = f"{section}.{field.name}"
            assert attrs[f"{key}_units"] == unit_of(field.name), key
    for field in dataclasses.fields(run.excitation):
        key = f"excitation.{field.name}"
        assert key in attrs and attrs[f"{key}_units"] == field.metadata["unit"], key
    for key in run.run:
        assert attrs[f"run.{key}_units"] == RUN_UNITS[key], key


def test_every_run_entry_has_a_unit(run):
    """A new entry of ``result.run`` needs its unit in RUN_UNITS (the files carry it)."""
    assert set(run.run) <= set(RUN_UNITS), set(run.run) - set(RUN_UNITS)


def test_counts_are_integers_and_booleans_ints(netcdf):
    attrs = netcdf[0].attrs
    for key in ("run.steps", "run.stop_contacts", "run.stick_events", "run.completed",
                "run.samples"):
        if key in attrs:
            assert isinstance(attrs[key], (int, np.integer)), (key, type(attrs[key]))
    assert attrs["run.completed"] == 1


def test_none_parameters_are_kept(netcdf):
    data, path = netcdf
    assert data.attrs["isolator.stop_center"] == "none"
    assert "isolator.stop_center" in data.attrs["none_parameters"].split()
    assert read_result(path).attrs["isolator.stop_center"] is None


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_round_trip_values_and_parameters(run, tmp_path, suffix):
    data = read_result(run.save(tmp_path / f"run{suffix}"))
    expected = run.to_xarray()
    tolerance = dict(rtol=1e-9, atol=1e-12) if suffix == ".csv" else dict(rtol=0, atol=0)
    for name in [*CHANNELS, *FLAGS]:
        np.testing.assert_allclose(data[name].values, np.asarray(run[name], float), **tolerance)
        assert data[name].dtype == (bool if name in FLAGS else np.float64)
        assert data[name].attrs["units"] == expected[name].attrs["units"]
    meta = run.metadata()
    assert meta["isolator.stop_center"] is None
    for key, value in meta.items():
        assert data.attrs[key] == value, key
        if isinstance(value, int):
            assert isinstance(data.attrs[key], (int, np.integer)), key
    if suffix == ".nc":  # the file reads back as the run's own dataset
        expected.attrs["isolator.stop_center"] = None
        expected.attrs["history"] = data.attrs["history"]
        xr.testing.assert_identical(data, expected)


def test_csv_header_and_trailer_carry_units(run, tmp_path):
    text = run.save(tmp_path / "run.csv").read_text().splitlines()
    assert "# Conventions = CF-1.10" in text
    assert "# isolator.mass = 6.4 [kg]" in text
    assert "# controller.pi_ki = 20.0 [N/(m*s)]" in text
    assert "# isolator.stop_center = none [m]" in text
    assert text[-1].startswith("# history = ")
    assert f"# run.steps = {run.run['steps']} [1]" in text
    header = text.index(",".join([*CHANNELS, *FLAGS]))
    assert all(line.startswith("# ") for line in text[:header])


def test_to_xarray_follows_the_same_conventions(run):
    data = run.to_xarray()
    assert data.attrs["Conventions"] == "CF-1.10"
    assert data["time"].attrs["units"] == "s" and "axis" not in data["time"].attrs
    assert data["locked"].attrs["flag_meanings"] == "slipping locked"
    data.to_netcdf(engine="h5netcdf")  # writable as it is: no None, no bool attribute


def test_batch_to_xarray():
    cases = [(qzs.IsolatorParameters(viscous_damping=cv), qzs.ControllerParameters())
             for cv in (50.0, 100.0)]
    batch = qzs.simulate_batch(cases, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.5,
                               sample_rate=200.0, workers=1, channels=("relative_position",))
    data = batch.to_xarray()
    assert dict(data.sizes) == {"case": 2, "time": batch.time.size}
    assert data.attrs["Conventions"] == "CF-1.10" and data.attrs["history"]
    assert data["time"].attrs["units"] == "s" and "standard_name" not in data["time"].attrs
    assert data["relative_position"].dims == ("case", "time")
    assert data["relative_position"].attrs["units"] == "m"
    np.testing.assert_array_equal(data["viscous_damping"].values, [50.0, 100.0])
    assert data["viscous_damping"].attrs["units"] == "N*s/m"
    assert data["stop_contacts"].dtype.kind == "i" and data["steps"].dtype.kind == "i"
    assert data["status"].dtype == np.int8
    assert data["status"].attrs["flag_meanings"] == "completed failed"
    for name, variable in data.variables.items():
        assert "long_name" in variable.attrs, name
        if variable.dtype.kind == "f":
            assert "units" in variable.attrs, name
    data.to_netcdf(engine="h5netcdf")


def test_the_file_readers_agree(run, tmp_path):
    """``qzs.read_result`` reads a run's file with the run's schema; ``qzs.iotools.read_result``
    reads any result file: a NetCDF file the same (it describes itself), a CSV one given the
    schema."""
    from qzs import iotools
    from qzs.engine.channels import simulation_schema

    assert qzs.read_result is read_result
    path = run.save(tmp_path / "run.nc")
    xr.testing.assert_identical(iotools.read_result(path), read_result(path))
    path = run.save(tmp_path / "run.csv")
    xr.testing.assert_identical(iotools.read_result(path, simulation_schema()),
                                read_result(path))
    assert iotools.read_result(path)["locked"].dtype == np.float64  # no schema: plain columns
