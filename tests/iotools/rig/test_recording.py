"""Reading a rig log (qzs.iotools.rig.recording): unit conversion to SI, time units, time
checks, NaN policy, bad files, the Recording's own checks."""
import numpy as np
import pytest
from helpers import (LOG_BASE as BASE, LOG_MAP as MAP, LOG_RATE as RATE, LOG_TIME as TIME,
                     write_log_csv as write_csv)

from qzs.errors import DataError, DataWarning, ParameterError
from qzs.iotools.rig import Recording, read_recording


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
    from qzs.iotools.rig.channel_map import UNITS

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
