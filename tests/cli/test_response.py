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


def test_the_curve_is_written_beside_its_figure_with_a_units_row(tmp_path, capsys):
    """The figure's data beside it (.nc, .csv with its units row, .mat), the same points."""
    import numpy as np
    import pandas as pd
    import scipy.io
    import xarray as xr

    from qzs.cli import main

    plot = tmp_path / "resp.png"
    assert main(["response", "--frequencies", "3,6", "--direction", "up", "--dt", "1e-3",
                 "--no-harmonic-balance", "--plot", str(plot), "--quiet"]) == 0
    assert "resp.csv" in capsys.readouterr().out
    netcdf = xr.load_dataset(tmp_path / "resp.nc")
    table = pd.read_csv(tmp_path / "resp.csv", comment="#", header=[0, 1])
    units = dict(table.columns)
    assert units["frequency"] == "Hz" and units["transmissibility"] == "1"
    assert units["phase"] == "rad" and units["relative_amplitude"] == "m"
    np.testing.assert_allclose(table[("transmissibility", "1")].values,
                               netcdf["transmissibility"].values.ravel(), rtol=1e-9)
    mat = scipy.io.loadmat(tmp_path / "resp.mat")
    np.testing.assert_array_equal(mat["frequency"].ravel(), netcdf["frequency"].values)


def test_a_curve_file_beside_the_figure_that_cannot_be_written_fails_before_any_run(tmp_path,
                                                                                     capsys):
    from qzs.cli import main

    (tmp_path / "resp.nc").mkdir()  # a folder where the curve file would go
    assert main(["response", "--frequencies", "3", "--plot", str(tmp_path / "resp.png"),
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "--plot" in err and "resp.nc" in err


@pytest.mark.parametrize("argv, names", [
    # a tolerance below double precision never converges: it ran until killed
    (["--frequencies", "2", "--periodic-tolerance", "1e-300", "--max-periods", "1000000000",
      "--max-time", "1e9"], ["periodic_tolerance", "1e-300", "1e-12"]),
    # converging or not, the cap alone is more than a day of computing
    (["--frequencies", "0.1,0.2", "--max-periods", "1000000000000", "--max-time", "1e13",
      "--dt", "1e-4"], ["max_time", "max_periods", "1e+13"]),
])
def test_a_response_that_cannot_end_is_refused_before_any_run(argv, names, tmp_path,
                                                              monkeypatch, capsys):
    import time

    from qzs.cli import main

    monkeypatch.chdir(tmp_path)
    began = time.perf_counter()
    assert main(["response", *argv, "--quiet", "--plot", "none"]) == 2
    assert time.perf_counter() - began < 2.0
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and all(name in err for name in names)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, names", [
    (["--frequencies", "1e308"], ["frequencies", "1e+308 Hz"]),  # was an OverflowError
    (["--range", "1e-300,1,5"], ["1e-300 Hz", "lowest frequency"]),  # was an OverflowError
])
def test_frequencies_no_run_can_take_are_one_clear_line(argv, names, tmp_path, monkeypatch,
                                                        capsys):
    from qzs.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["response", *argv, "--quiet", "--plot", "none"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and all(name in err for name in names)
    assert list(tmp_path.iterdir()) == []
