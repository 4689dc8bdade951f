"""Readers: each format on files written here, unit conversion, time checks, bad input."""
import numpy as np
import pytest

from qzs.errors import DataError, ParameterError
from qzs.iotools.rig.recording import (DataWarning, Recording, load_channel_map, read_recording,
                         write_dspace_mat)

RATE = 200.0
TIME = np.arange(400) / RATE
BASE = 50.0 * np.sin(2 * np.pi * 3.0 * TIME)  # [mm/s]
PAYLOAD = 20.0 * np.cos(2 * np.pi * 3.0 * TIME)
MAP = {"channels": {"base_velocity": {"source": "shaker_vel", "unit": "mm/s"},
                    "payload_velocity": {"source": "payload_vel", "unit": "mm/s", "scale": 2.0}}}


def check(recording, rtol=1e-7):
    assert isinstance(recording, Recording)
    assert recording.sample_rate == pytest.approx(RATE)
    np.testing.assert_allclose(recording.time, TIME, atol=1e-9)
    np.testing.assert_allclose(recording["base_velocity"], BASE * 1e-3, rtol=rtol, atol=1e-9)
    np.testing.assert_allclose(recording["payload_velocity"], 2 * PAYLOAD * 1e-3, rtol=rtol,
                               atol=1e-9)
    assert dict(recording.units) == {"base_velocity": "m/s", "payload_velocity": "m/s"}


def write_csv(path, time=TIME, base=BASE, payload=PAYLOAD):
    with open(path, "w") as handle:
        handle.write("# a comment line\ntime, shaker_vel, payload_vel, unused\n")
        for row in zip(time, base, payload, np.zeros(len(time))):
            handle.write(",".join(repr(float(x)) for x in row) + "\n")
    return path


def test_a_csv_with_a_units_row_reads_as_without(tmp_path):
    """The layout qzs writes (a row of units under the names) reads as a rig log too."""
    path = write_csv(tmp_path / "log.csv")
    lines = path.read_text().splitlines()
    lines.insert(2, "s, mm/s, mm/s, 1")
    path.write_text("\n".join(lines) + "\n")
    check(read_recording(path, MAP))


def test_csv(tmp_path):
    recording = read_recording(write_csv(tmp_path / "log.csv"), MAP)
    check(recording)
    dataset = recording.to_xarray()
    assert dataset["base_velocity"].attrs["units"] == "m/s"
    assert dataset.attrs["sample_rate"] == pytest.approx(RATE)
    assert "csv" in recording.source and recording.duration == pytest.approx(TIME[-1])
    indexed = {"channels": {**MAP["channels"], "base_velocity": {"source": "Y[7]/shaker_vel",
                                                                 "unit": "mm/s"}}}
    check(read_recording(tmp_path / "log.csv", indexed))  # the name part outside MAT files


def test_channel_map_from_toml(tmp_path):
    (tmp_path / "map.toml").write_text(
        '[time]\nsource = "time"\nunit = "s"\n[options]\nresample = false\n'
        '[channels.base_velocity]\nsource = "shaker_vel"\nunit = "mm/s"\n'
        '[channels.payload_velocity]\nsource = "payload_vel"\nunit = "mm/s"\nscale = 2.0\n'
        '[experiment]\nhighpass_corner = 1.0\n')
    spec = load_channel_map(tmp_path / "map.toml")
    assert spec.experiment["highpass_corner"] == 1.0
    check(read_recording(write_csv(tmp_path / "log.csv"), tmp_path / "map.toml"))


@pytest.mark.parametrize("version", ["5", "7.3"])
def test_dspace_mat(tmp_path, version):
    path = write_dspace_mat(tmp_path / "log.mat", TIME, {
        "Model Root/Sensors/other": np.zeros_like(TIME),
        "Model Root/Sensors/shaker_vel": BASE,
        "Model Root/Sensors/payload_vel": PAYLOAD.astype(np.float32)}, version=version)
    indexed = {"channels": {"base_velocity": {"source": "Y[2]/shaker_vel", "unit": "mm/s"},
                            "payload_velocity": {"source": "Y[3]", "unit": "mm/s", "scale": 2.0}}}
    check(read_recording(path, indexed), rtol=1e-6)  # payload stored as MATLAB single
    check(read_recording(path, MAP), rtol=1e-6)  # by name: the last path component


def test_mat73_is_matlab_layout(tmp_path):
    import h5py
    import scipy.io

    path = write_dspace_mat(tmp_path / "log.mat", TIME, {"a": BASE, "b": PAYLOAD}, version="7.3")
    with pytest.raises(NotImplementedError):  # scipy sees a v7.3 (HDF5) MAT file
        scipy.io.loadmat(path)
    with h5py.File(path) as handle:
        top = handle["qzs_log"]
        assert top.attrs["MATLAB_class"] == b"struct"
        assert top["Y"]["Data"].dtype == h5py.ref_dtype and top["Y"]["Data"].shape == (2, 1)
        name = handle[top["Y"]["Name"][1, 0]]
        assert name.attrs["MATLAB_class"] == b"char" and name.dtype == np.uint16
        assert "".join(map(chr, name[()].ravel())) == "b"
        assert top["X"]["Data"].shape == (TIME.size, 1)  # a 1x1 struct keeps its fields


def test_mf4(tmp_path):
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    mdf.append([Signal(BASE, TIME, name="shaker_vel", unit="mm/s"),
                Signal(PAYLOAD, TIME, name="payload_vel", unit="mm/s")])
    mdf.save(tmp_path / "log.mf4", overwrite=True)
    check(read_recording(tmp_path / "log.mf4", MAP))


def test_mf4_different_rates_need_resampling(tmp_path):
    from asammdf import MDF, Signal

    slow = TIME[::2]
    mdf = MDF(version="4.10")
    mdf.append([Signal(BASE, TIME, name="shaker_vel")])
    mdf.append([Signal(PAYLOAD[::2], slow, name="payload_vel")])
    mdf.save(tmp_path / "log.mf4", overwrite=True)
    with pytest.raises(DataError, match="different time bases.*resample"):
        read_recording(tmp_path / "log.mf4", MAP)
    recording = read_recording(tmp_path / "log.mf4", MAP, resample=True)
    assert recording.sample_rate == pytest.approx(RATE)
    np.testing.assert_allclose(recording["base_velocity"], BASE[:-1] * 1e-3, atol=1e-12)


def test_netcdf(tmp_path):
    import xarray as xr

    xr.Dataset({"shaker_vel": ("time", BASE), "payload_vel": ("time", PAYLOAD)},
               coords={"time": TIME}).to_netcdf(tmp_path / "log.nc", engine="h5netcdf")
    check(read_recording(tmp_path / "log.nc", MAP))


def test_units_scale_and_time_unit(tmp_path):
    path = tmp_path / "log.csv"
    with open(path, "w") as handle:
        handle.write("t_ms,acc,pos,f,cmd\n")
        for k in range(10):
            handle.write(f"{k * 2.0},{1.0},{3.0},{0.5},{2.0}\n")
    spec = {"time": {"source": "t_ms", "unit": "ms"},
            "channels": {"base_acceleration": {"source": "acc", "unit": "g"},
                         "relative_position": {"source": "pos", "unit": "um", "scale": 10.0},
                         "force": {"source": "f", "unit": "kN"},
                         "motor_command": {"source": "cmd", "unit": "V", "scale": -1.0}}}
    recording = read_recording(path, spec)
    assert recording.sample_rate == pytest.approx(500.0)
    assert recording["base_acceleration"][0] == pytest.approx(9.80665)
    assert recording["relative_position"][0] == pytest.approx(3e-5)
    assert recording["force"][0] == pytest.approx(500.0)
    assert recording["motor_command"][0] == pytest.approx(-2.0)
    assert recording.units["base_acceleration"] == "m/s^2"


#: Every unit a channel map accepts, with its SI unit and factor written out here by hand
#: (1 g is the standard gravity 9.80665 m/s^2 by definition), not copied from the table.
EXPECTED_UNITS = {
    "m": ("m", 1.0), "mm": ("m", 0.001), "um": ("m", 0.000001), "µm": ("m", 0.000001),
    "m/s": ("m/s", 1.0), "mm/s": ("m/s", 0.001), "um/s": ("m/s", 0.000001),
    "m/s^2": ("m/s^2", 1.0), "m/s2": ("m/s^2", 1.0), "mm/s^2": ("m/s^2", 0.001),
    "mm/s2": ("m/s^2", 0.001), "g": ("m/s^2", 9.80665),
    "N": ("N", 1.0), "kN": ("N", 1000.0), "V": ("V", 1.0),
}
#: A role for each SI unit.
ROLE_OF = {"m": "relative_position", "m/s": "base_velocity", "m/s^2": "base_acceleration",
           "N": "force", "V": "motor_command"}


def test_every_unit_of_the_table_is_tested():
    from qzs.iotools.rig.recording import UNITS

    assert set(UNITS) == set(EXPECTED_UNITS)  # a new unit needs its expectation here


@pytest.mark.parametrize("unit", sorted(EXPECTED_UNITS))
@pytest.mark.parametrize("scale", [1.0, -2.0])
def test_each_unit_converts_to_si(tmp_path, unit, scale):
    si_unit, factor = EXPECTED_UNITS[unit]
    role = ROLE_OF[si_unit]
    raw = np.array([2.5, -1.25, 0.0, 4.0])
    path = tmp_path / "log.csv"
    path.write_text("time,signal\n" + "".join(f"{k * 0.01!r},{v!r}\n"
                                               for k, v in enumerate(raw.tolist())))
    recording = read_recording(path, {"channels": {role: {"source": "signal", "unit": unit,
                                                          "scale": scale}}})
    np.testing.assert_allclose(recording[role], raw * scale * factor, rtol=1e-15, atol=0)
    assert recording.units[role] == si_unit


@pytest.mark.parametrize("unit, step", [("s", 0.01), ("ms", 0.00001)])
def test_each_time_unit_converts_to_seconds(tmp_path, unit, step):
    path = tmp_path / "log.csv"
    path.write_text("t,x\n" + "".join(f"{k * 0.01!r},1.0\n" for k in range(5)))
    recording = read_recording(path, {"time": {"source": "t", "unit": unit},
                                      "channels": {"force": {"source": "x", "unit": "N"}}})
    np.testing.assert_allclose(recording.time, np.arange(5) * step, rtol=1e-12)
    assert recording.sample_rate == pytest.approx(1.0 / step)


def test_non_uniform_time_is_an_error_or_resampled(tmp_path):
    time = TIME.copy()
    time[100:] += 0.5 / RATE  # one long interval
    path = write_csv(tmp_path / "log.csv", time=time)
    with pytest.raises(DataError, match="not uniform.*resample = true"):
        read_recording(path, MAP)
    recording = read_recording(path, {**MAP, "options": {"resample": True}})
    assert np.ptp(np.diff(recording.time)) < 1e-12
    assert recording.sample_rate == pytest.approx(RATE)
    expected = np.interp(recording.time, time, BASE * 1e-3)
    np.testing.assert_allclose(recording["base_velocity"], expected)


@pytest.mark.parametrize("index, what", [(50, "duplicated"), (None, "decreasing")])
def test_bad_time_is_an_error(tmp_path, index, what):
    time = TIME.copy()
    if index is None:
        time[[10, 11]] = time[[11, 10]]
    else:
        time[index] = time[index - 1]
    with pytest.raises(DataError, match=f"strictly increasing.*{what}"):
        read_recording(write_csv(tmp_path / "log.csv", time=time), MAP, resample=True)


def test_nan_samples(tmp_path):
    base = BASE.copy()
    base[[5, 6, 70]] = np.nan
    path = write_csv(tmp_path / "log.csv", base=base)
    with pytest.raises(DataError, match="base_velocity has 3 non-finite"):
        read_recording(path, MAP)
    with pytest.warns(DataWarning, match="3 non-finite samples of 400 filled"):
        recording = read_recording(path, {**MAP, "options": {"nan": "interpolate"}})
    assert np.all(np.isfinite(recording["base_velocity"]))


def test_missing_channel_lists_those_found(tmp_path):
    spec = {"channels": {"base_velocity": {"source": "shaker_velocity", "unit": "mm/s"}}}
    with pytest.raises(DataError, match=r"no signal 'shaker_velocity'.*'shaker_vel', "
                                        r"'payload_vel', 'unused'"):
        read_recording(write_csv(tmp_path / "log.csv"), spec)


def test_mat_index_checks_name_and_range(tmp_path):
    path = write_dspace_mat(tmp_path / "log.mat", TIME, {"Root/a": BASE, "Root/b": PAYLOAD})
    for source, match in (("Y[1]/b", "Y\\(1\\) is named 'Root/a', not 'b'"),
                          ("Y[5]", "out of range, Y has 2"), ("c", "no signal 'c'")):
        spec = {"channels": {"base_velocity": {"source": source, "unit": "m/s"}}}
        with pytest.raises(DataError, match=match):
            read_recording(path, spec)


def test_mat_without_dspace_struct(tmp_path):
    import scipy.io

    scipy.io.savemat(tmp_path / "plain.mat", {"a": np.arange(3.0)})
    with pytest.raises(DataError, match="one struct with fields X and Y"):
        read_recording(tmp_path / "plain.mat", MAP)


@pytest.mark.parametrize("spec, match", [
    ({"channels": {}}, "no \\[channels"),
    ({"channels": {"base_speed": {"source": "a", "unit": "m/s"}}}, "unknown role 'base_speed'"),
    ({"channels": {"base_velocity": {"source": "a", "unit": "N"}}}, "'N' is not a unit of m/s"),
    ({"channels": {"base_velocity": {"source": "a", "unit": "furlong"}}}, "not supported"),
    ({"channels": {"base_velocity": {"source": "a"}}}, "needs `unit`"),
    ({"channels": {"base_velocity": "a"}}, "needs a unit"),
    ({"channels": {"base_velocity": {"source": "a", "unit": "m/s", "offset": 1}}},
     "unknown key\\(s\\) \\['offset'\\]"),
    ({"channels": {"base_velocity": {"source": "a", "unit": "m/s", "scale": 0}}}, "non-zero"),
    ({**MAP, "options": {"nan": "drop"}}, "nan must be one of"),
    ({**MAP, "time": {"unit": "h"}}, "unit must be one of"),
    ({**MAP, "extras": {}}, "unknown key\\(s\\) \\['extras'\\]"),
])
def test_bad_channel_map(spec, match):
    with pytest.raises(ParameterError, match=match):
        load_channel_map(spec)


def test_bad_files(tmp_path):
    with pytest.raises(DataError, match="log file not found"):
        read_recording(tmp_path / "missing.csv", MAP)
    (tmp_path / "log.xyz").write_text("x")
    with pytest.raises(ParameterError, match="cannot tell the format"):
        read_recording(tmp_path / "log.xyz", MAP)
    with pytest.raises(ParameterError, match="channel map not found"):
        read_recording(write_csv(tmp_path / "log.csv"), tmp_path / "missing.toml")


def test_recording_validates_shapes():
    with pytest.raises(DataError, match="one sample per time"):
        Recording(time=TIME, channels={"force": TIME[:-1]}, units={"force": "N"},
                  sample_rate=RATE, source="test")
