"""CSV rig logs (qzs.iotools.rig.csv): a header of names, comments, a units row, the
name part of an indexed source, a missing signal listed with those found."""
import pytest
from helpers import (LOG_MAP as MAP, LOG_RATE as RATE, LOG_TIME as TIME,
                     check_log_recording as check, write_log_csv as write_csv)

from qzs.errors import DataError
from qzs.iotools.rig import read_recording


def test_a_csv_with_a_units_row_reads_as_without(tmp_path):
    """The layout qzs writes (a row of units under the names) reads as a rig log too."""
    path = write_csv(tmp_path / "log.csv")
    lines = path.read_text().splitlines()
    lines.insert(2, "s, mm/s, mm/s, 1")
    path.write_text("\n".join(lines) + "\n")
    check(read_recording(path, MAP))


def test_csv(tmp_path):
    recording = read_recording(write_csv(tmp_path / "log.csv"), MAP)
    check(recording)
    dataset = recording.to_xarray()
    assert dataset["base_velocity"].attrs["units"] == "m/s"
    assert dataset.attrs["sample_rate"] == pytest.approx(RATE)
    assert "csv" in recording.source and recording.duration == pytest.approx(TIME[-1])
    indexed = {"channels": {**MAP["channels"], "base_velocity": {"source": "Y[7]/shaker_vel",
                                                                 "unit": "mm/s"}}}
    check(read_recording(tmp_path / "log.csv", indexed))  # the name part outside MAT files


def test_missing_channel_lists_those_found(tmp_path):
    spec = {"channels": {"base_velocity": {"source": "shaker_velocity", "unit": "mm/s"}}}
    with pytest.raises(DataError, match=r"no signal 'shaker_velocity'.*'shaker_vel', "
                                        r"'payload_vel', 'unused'"):
        read_recording(write_csv(tmp_path / "log.csv"), spec)


def test_a_csv_qzs_wrote_reads_without_a_warning_as_numbers(tmp_path):
    """`qzs experiment` on a run's CSV printed pandas' "Columns (...) have mixed types"
    DtypeWarning: the units row made every column text until it was dropped. The run's
    velocities come back as written (the CSV's %.10g digits)."""
    import warnings

    import numpy as np

    from qzs import Chirp, simulate

    run = simulate(Chirp(duration=100.0), dt=1e-3, sample_rate=1000.0)  # 100,001 rows
    path = run.save(tmp_path / "run.csv")
    spec = {"channels": {"base_velocity": {"source": "base_velocity", "unit": "m/s"},
                         "payload_velocity": {"source": "payload_velocity", "unit": "m/s"}}}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        recording = read_recording(path, spec)
    dataset = recording.to_xarray()
    assert dataset["time"].dtype == np.float64 and dataset["time"].size == len(run)
    for name in ("base_velocity", "payload_velocity"):
        np.testing.assert_allclose(dataset[name].values, run[name], rtol=1e-9, atol=1e-15)
