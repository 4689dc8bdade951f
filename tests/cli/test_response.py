"""``qzs response`` (qzs.cli.response): a list of records with --json, bad input exit code 2."""
import json

import pytest

from qzs.errors import ParameterError


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


@pytest.mark.parametrize("arguments, words", [
    (dict(frequencies="3,1,2"), ["--frequencies 3,1,2", "1 Hz comes after 3 Hz",
                                 "e.g. --frequencies 1,2,3"]),
    (dict(frequencies="2,2,3"), ["--frequencies 2,2,3", "2 Hz is given twice",
                                 "e.g. --frequencies 2,3"]),
    (dict(frequencies="1,2", spacing="linear"), ["--spacing linear", "--frequencies 1,2",
                                                "--range"]),
])
def test_what_was_typed_is_never_silently_reordered_or_dropped(arguments, words):
    """--frequencies 3,1,2 used to be sorted, 2,2,3 deduplicated, --spacing ignored."""
    from qzs.cli.response import parse_frequencies

    with pytest.raises(ParameterError) as caught:
        parse_frequencies(**arguments)
    for word in words:
        assert word in str(caught.value), (word, str(caught.value))
    assert parse_frequencies("1,2.5,3") == [1.0, 2.5, 3.0]
    assert parse_frequencies(None, "1,4,3", "linear") == [1.0, 2.5, 4.0]
    assert parse_frequencies(None, "1,4,3") == pytest.approx([1.0, 2.0, 4.0])


def test_a_range_of_1e8_frequencies_fails_before_making_any():
    import time

    from qzs.cli.response import parse_frequencies
    from qzs.errors import CountLimitError
    from qzs.workflows.response.sweep import MAX_FREQUENCIES

    began = time.perf_counter()
    with pytest.raises(CountLimitError, match="`--range` asks for 100,000,000 frequencies"):
        parse_frequencies(None, "0.5,20,100000000")
    assert time.perf_counter() - began < 0.5
    assert len(parse_frequencies(None, f"0.5,20,{MAX_FREQUENCIES}")) == MAX_FREQUENCIES
