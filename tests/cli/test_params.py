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


def test_params_toml_without_a_file_prints_the_config_to_stdout(tmp_path, capsys, monkeypatch):
    """`qzs params --toml > my.toml` (what the help texts point to) failed with `--toml
    expected one argument` and left an empty my.toml; now stdout holds the file's text."""
    from qzs.iotools import load_config
    from qzs.iotools.config import config_text
    from qzs.model.controller import ControllerParameters

    monkeypatch.chdir(tmp_path)
    assert main(["params", "--toml", "--set", "pi_kp=75"]) == 0
    out = capsys.readouterr().out
    assert out == config_text(controller=ControllerParameters(pi_kp=75.0))
    (tmp_path / "my.toml").write_text(out)
    assert load_config(tmp_path / "my.toml")["controller"].pi_kp == 75.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my.toml"]  # nothing else written
    assert main(["params", "--toml", "-"]) == 0  # "-": stdout too
    assert capsys.readouterr().out == config_text()


def test_params_toml_round_trips_a_controller_with_blocks(tmp_path, capsys):
    """`--set compensation.fraction=...` adds the block; `--toml` writes the blocks' tables;
    `--controller` reads them back; the table shows the blocks' dotted names."""
    import qzs
    from qzs.iotools import load_config

    path = tmp_path / "p.toml"
    assert main(["params", "--toml", str(path), "--set", "compensation.fraction=0.8",
                 "--set", "dither.frequency=40", "--set", "pi_kp=70"]) == 0
    expected = (qzs.PIDamping(pi_kp=70.0) + qzs.FrictionCompensation(fraction=0.8)
                + qzs.Dither(frequency=40.0))
    assert load_config(path)["controller"] == expected
    controller = tmp_path / "c.toml"
    text = path.read_text()
    controller.write_text(text[text.index("[controller]"):])
    capsys.readouterr()
    assert main(["params", "--controller", str(controller),
                 "--set", "compensation.deadband=0.002"]) == 0
    rows = {line.split()[1]: line.split()[2] for line in capsys.readouterr().out.splitlines()[1:]}
    assert rows["compensation.fraction"] == "0.8" and rows["compensation.deadband"] == "0.002"
    assert rows["dither.frequency"] == "40" and rows["pi_kp"] == "70"
    assert rows["linear.tracking_time"] == "no"  # "no block"
