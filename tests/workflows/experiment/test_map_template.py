"""The channel map template (qzs.workflows.experiment.map_template): every key the map reader takes,
and, once its placeholders are filled in, a map the real reader reads and a log it opens."""
import re

import numpy as np
import pytest

from qzs.errors import OutputPathError
from qzs.iotools.rig import load_channel_map, read_recording
from qzs.iotools.rig.channel_map import EXPERIMENT_KEYS, ROLES, UNITS
from qzs.workflows.experiment.map_template import (PLACEHOLDER, channel_map_template,
                                                   write_channel_map_template)


def uncommented(text):
    """The template with every commented-out table and key switched on."""
    return re.sub(r"^# (\[[a-z_.]+\]$|[a-z_0-9]+ = )", r"\1", text, flags=re.MULTILINE)


def test_the_template_reads_as_a_map_once_filled_in(tmp_path):
    path = write_channel_map_template(tmp_path / "map.toml")
    filled = path.read_text().replace(PLACEHOLDER, "col")
    spec = load_channel_map(_write(tmp_path / "filled.toml", filled))
    assert set(spec.channels) == {"base_velocity", "payload_velocity"}
    assert spec.channels["base_velocity"].unit == "m/s" and spec.time_unit == "s"
    assert spec.experiment == {"highpass_corner": 1.0}


def test_every_key_the_reader_accepts_is_in_the_template(tmp_path):
    """Switched on, every commented role and key parses: the template names nothing the
    reader refuses, and every role and [experiment] key the reader knows."""
    text = uncommented(channel_map_template()).replace(PLACEHOLDER, "col")
    text = text.replace('variable = "NAME"', 'variable = "data"')
    spec = load_channel_map(_write(tmp_path / "all.toml", text))
    assert set(spec.channels) == set(ROLES)
    assert set(spec.experiment) == set(EXPERIMENT_KEYS)
    assert spec.variable == "data" and spec.time_source == "time"


def test_each_role_names_only_its_own_units():
    lines = channel_map_template().splitlines()
    for role, units in ROLES.items():
        table = next(i for i, line in enumerate(lines) if line.endswith(f"[channels.{role}]"))
        comment = lines[table - 1]
        assert comment.startswith("# ") and f"[{' or '.join(units)}]" in comment, role
        listed = comment.split("unit one of: ")[1].split(", ")
        assert {UNITS[unit][0] for unit in listed} == set(units), role


def test_a_filled_in_template_reads_a_log(tmp_path):
    time = np.arange(200) / 100.0
    log = tmp_path / "log.csv"
    np.savetxt(log, np.column_stack([time, 2 * time, 3 * time]), delimiter=",",
               header="time,shaker,payload", comments="")
    template = write_channel_map_template(tmp_path / "map.toml").read_text()
    filled = re.sub(r'(\[channels\.(base|payload)_velocity\]\nsource = )"[^"]*"\nunit = "m/s"',
                    lambda m: f'{m[1]}"{"shaker" if m[2] == "base" else "payload"}"\n'
                              'unit = "mm/s"', template)
    recording = read_recording(log, _write(tmp_path / "filled.toml", filled))
    assert recording.sample_rate == pytest.approx(100.0)
    np.testing.assert_allclose(recording["payload_velocity"], 3e-3 * time)


def test_an_existing_map_is_never_replaced(tmp_path):
    path = _write(tmp_path / "map.toml", "mine")
    with pytest.raises(OutputPathError, match="exists"):
        write_channel_map_template(path)
    assert path.read_text() == "mine"
    write_channel_map_template(path, overwrite=True)
    assert PLACEHOLDER in path.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.toml"]   # no temporary file


def test_only_toml_names(tmp_path):
    with pytest.raises(OutputPathError, match=r"\.toml"):
        write_channel_map_template(tmp_path / "map.txt")
    assert not list(tmp_path.iterdir())


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path
