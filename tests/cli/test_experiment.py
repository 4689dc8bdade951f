"""``qzs experiment`` (qzs.cli.experiment): it parses, hands every option to
``run_experiment`` under its API name, and refuses bad numbers before any work."""
from pathlib import Path
from types import SimpleNamespace

import pytest

import qzs.workflows.experiment.process
from qzs.cli import main


def test_options_reach_the_workflow_under_their_api_names(tmp_path, monkeypatch, capsys):
    seen = {}

    def run_experiment(log, channel_map, **options):
        seen.update(log=log, channel_map=channel_map, **options)
        result = SimpleNamespace(summary=lambda: "measured", to_record=lambda: {"band": [0, 9]})
        paths = {"report": tmp_path / "report.md", "figure": tmp_path / "t.png",
                 "table": tmp_path / "t.csv"}
        return result, paths

    monkeypatch.setattr(qzs.workflows.experiment.process, "run_experiment", run_experiment)
    out = tmp_path / "out"
    assert main(["experiment", "log.csv", "--map", "map.toml", "--out", str(out),
                 "--fft-length", "1024", "--averages", "7", "--no-simulation", "--resample",
                 "--config", "p.toml", "--frequency-axis", "linear"]) == 0
    assert seen == {"log": "log.csv", "channel_map": "map.toml", "out": str(out),
                    "fft_length": 1024, "n_averages": 7, "config": "p.toml", "resample": True,
                    "simulate_match": False, "frequency_scale": "linear"}
    assert "measured" in capsys.readouterr().out
    assert main(["experiment", "log.csv", "--map", "map.toml", "--out", str(out),
                 "--json"]) == 0
    assert seen["fft_length"] is None and seen["simulate_match"] is True
    assert seen["frequency_scale"] is None   # the default axis, log
    assert '"files": {"report": "' in capsys.readouterr().out


@pytest.mark.parametrize("option, value", [("--fft-length", "4"), ("--averages", "0")])
def test_numbers_below_their_bound_are_usage_errors(option, value, capsys):
    assert main(["experiment", "log.csv", "--map", "map.toml", option, value]) == 2
    assert "must be an integer >=" in capsys.readouterr().err


def test_an_output_folder_that_is_a_file_is_refused_before_reading(tmp_path, capsys):
    (tmp_path / "taken").write_text("")
    assert main(["experiment", str(Path("no-such-log.csv")), "--map", "map.toml",
                 "--out", str(tmp_path / "taken")]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err


def test_write_map_writes_the_template_without_a_log(tmp_path, capsys):
    from qzs.iotools.rig import load_channel_map
    from qzs.workflows.experiment.map_template import PLACEHOLDER, channel_map_template

    path = tmp_path / "sub" / "map.toml"
    assert main(["experiment", "--write-map", str(path)]) == 0
    assert path.read_text() == channel_map_template()
    assert f"wrote {path}" in capsys.readouterr().out
    load_channel_map(path)  # placeholders included, it parses


@pytest.mark.parametrize("name, reason", [("map.toml", "exists; choose another name"),
                                          ("map.txt", "it must end in .toml")])
def test_write_map_refuses_a_taken_or_wrong_name(tmp_path, capsys, name, reason):
    (tmp_path / "map.toml").write_text("mine")
    assert main(["experiment", "--write-map", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error: --write-map ") and reason in err and err.count("\n") == 1
    assert (tmp_path / "map.toml").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.toml"]


def test_a_run_still_needs_log_and_map(capsys):
    assert main(["experiment", "log.csv"]) == 2
    assert "required: --map" in capsys.readouterr().err
