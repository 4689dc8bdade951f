"""``qzs design`` on the command line: options forwarded, the report written, bad input exit 2."""
import json

import pytest

from qzs.cli import main
from qzs.cli.design import parse_list, parse_pair
from qzs.errors import ParameterError
from qzs.workflows import design as D
from qzs.engine import step_choice
from qzs.workflows.design import hunting, proportional_search
from qzs.workflows.design import cost


class FakeResult:
    """What the command needs of a DesignResult: ``to_dict`` and ``summary`` (its files:
    :func:`fake_write`)."""

    def __init__(self):
        self.saved_to = None

    def to_dict(self):
        return {"gains": {"pi_kp": 123.0, "pi_ki": 49.2, "damping_gain": float("nan")}}

    def summary(self):
        return "qzs design (quick; 1 s)"


def fake_write(result, folder, *, frequency_scale=None, progress=False):
    """:func:`qzs.workflows.design.result.write_design` of a :class:`FakeResult`."""
    result.saved_to = folder
    result.frequency_scale, result.progress = frequency_scale, progress
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "report.html").write_text("<html></html>")
    return {"report": folder / "report.html", "json": folder / "design.json"}


def test_cli_forwards_the_options_writes_the_report_and_prints_json(monkeypatch, tmp_path,
                                                                     capsys):
    seen, result = {}, FakeResult()

    def fake(isolator, controller, **options):
        seen.update(options, isolator=isolator, controller=controller)
        return result

    monkeypatch.setattr(D, "design_controller", fake)
    monkeypatch.setattr(D.result, "write_design", fake_write)
    out = tmp_path / "design"
    code = main(["design", "--out", str(out), "--json", "--quiet", "--stiction-range", "8,12",
                 "--mass-range", "6.4,6.4", "--force-steps", "2", "--cost", "peak",
                 "--delay", "0.001", "--set", "pi_kp=60", "--quick", "--frequency-axis",
                 "linear"])
    assert code == 0
    record = json.loads(capsys.readouterr().out)
    assert record["gains"] == {"pi_kp": 123.0, "pi_ki": 49.2, "damping_gain": None}
    assert record["outputs"]["report"] == str(out / "report.html")
    assert result.saved_to == out and (out / "report.html").exists()
    assert result.frequency_scale == "linear" and result.progress is False  # --quiet
    assert seen["stiction_range"] == (8.0, 12.0) and seen["mass_range"] == (6.4, 6.4)
    assert seen["force_steps"] == (2.0,) and seen["band"] == (1.0, 20.0)
    assert seen["cost"] == "peak" and seen["delay"] == 0.001 and seen["quick"] is True
    assert seen["progress"] is False and seen["controller"].pi_kp == 60.0


def test_pairs_and_lists_parse_or_name_the_option():
    assert parse_pair("--band", " 1, 20 ", "Hz") == (1.0, 20.0)
    assert parse_list("--force-steps", "-2,2", "N") == (-2.0, 2.0)
    assert parse_list("--force-steps", " ", "N") == ()
    with pytest.raises(ParameterError, match="--band expects finite LOW <= HIGH"):
        parse_pair("--band", "20,1", "Hz")
    with pytest.raises(ParameterError, match="--mass-range expects LOW,HIGH in kg"):
        parse_pair("--mass-range", "6.4", "kg")


@pytest.mark.parametrize("argv, words", [
    (["design", "--stiction-range", "5"], "--stiction-range"),
    (["design", "--band", "1,x"], "--band"),
    (["design", "--force-steps", "2,b"], "--force-steps"),
    (["design", "--set", "pi_kp=0"], "pi_kp"),
])
def test_cli_bad_input_is_exit_2_before_any_work(argv, words, monkeypatch, capsys, tmp_path):
    def forbidden(*args, **kwargs):
        raise AssertionError("simulated before checking the input")

    for module, name in [(proportional_search, "simulate"),
                         (proportional_search, "simulate_batch"),
                         (cost, "simulate_batch"), (hunting, "simulate"),
                         (step_choice, "choose")]:
        monkeypatch.setattr(module, name, forbidden)
    assert main(argv + ["--quiet", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and words in err


def test_cli_refuses_an_output_that_is_a_file(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(D, "design_controller",
                        lambda *a, **k: pytest.fail("designed before checking --out"))
    target = tmp_path / "taken"
    target.write_text("x")
    assert main(["design", "--out", str(target), "--quiet"]) == 2
    assert "--out" in capsys.readouterr().err
