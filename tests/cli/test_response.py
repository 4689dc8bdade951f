"""``qzs response`` (qzs.cli.response): a list of records with --json, bad input exit code 2."""
import json

import pytest


def test_command_line_prints_a_list_of_records(tmp_path, capsys):
    from qzs.cli import main

    out = tmp_path / "r.csv"
    code = main(["response", "--frequencies", "3,6", "--direction", "up", "--dt", "1e-3",
                 "--no-harmonic-balance", "--plot", "none", "--out", str(out), "--json",
                 "--quiet"])
    assert code == 0
    records = json.loads(capsys.readouterr().out)
    assert isinstance(records, list) and [r["frequency"] for r in records] == [3.0, 6.0]
    assert all(0 < r["transmissibility"] < 1 for r in records)
    assert out.exists()


@pytest.mark.parametrize("argv, text", [
    (["response", "--range", "1,2"], "--range"),
    (["response", "--frequencies", "1,x"], "--frequencies"),
    (["response", "--frequencies", "-1", "--dt", "1e-3"], "frequencies"),
    (["response", "--out", "r.xlsx"], "--out"),
])
def test_command_line_bad_input_is_exit_code_2(argv, text, capsys):
    from qzs.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and text in err and err.count("\n") == 1
