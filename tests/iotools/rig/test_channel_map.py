"""Channel maps (qzs.iotools.rig.channel_map): from TOML, and every bad table a clear error."""
import pytest
from helpers import LOG_MAP as MAP, check_log_recording as check, write_log_csv as write_csv

from qzs.errors import ParameterError
from qzs.iotools.rig import load_channel_map, read_recording


def test_channel_map_from_toml(tmp_path):
    (tmp_path / "map.toml").write_text(
        '[time]\nsource = "time"\nunit = "s"\n[options]\nresample = false\n'
        '[channels.base_velocity]\nsource = "shaker_vel"\nunit = "mm/s"\n'
        '[channels.payload_velocity]\nsource = "payload_vel"\nunit = "mm/s"\nscale = 2.0\n'
        '[experiment]\nhighpass_corner = 1.0\n')
    spec = load_channel_map(tmp_path / "map.toml")
    assert spec.experiment["highpass_corner"] == 1.0
    check(read_recording(write_csv(tmp_path / "log.csv"), tmp_path / "map.toml"))


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
