"""``qzs params`` (qzs.cli.params): every parameter with its unit, and a TOML file that
round-trips through ``load_config``."""
from qzs.cli import main


def test_params_lists_every_parameter_with_units(capsys):
    assert main(["params"]) == 0
    out = capsys.readouterr().out
    for name, unit in (("mass", "kg"), ("stiction_force", "N"), ("pi_ki", "N/(m*s)"),
                       ("velocity_highpass", "Hz"), ("stop_center", "m")):
        line = next(line for line in out.splitlines() if f" {name} " in f" {line} ")
        assert unit in line


def test_params_toml_round_trips(tmp_path):
    path = tmp_path / "p.toml"
    assert main(["params", "--toml", str(path), "--set", "mass=7"]) == 0
    from qzs.iotools import load_config

    assert load_config(path)["isolator"].mass == 7.0
