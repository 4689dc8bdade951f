"""The response's files (qzs.workflows.response.files): NetCDF, CSV and JSON written whole,
an unknown format refused, the dataset's dimensions."""
import json

import numpy as np
import pytest

from qzs import ParameterError


@pytest.mark.parametrize("suffix", [".nc", ".csv", ".json", ".mat"])
def test_save_writes_whole_files(small_response, tmp_path, suffix):
    path = small_response.save(tmp_path / f"response{suffix}")
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left
    if suffix == ".nc":
        import xarray as xr

        data = xr.load_dataset(path, engine="h5netcdf")
        np.testing.assert_allclose(data["transmissibility"].sel(direction="up").values,
                                   small_response.branch("up")["transmissibility"])
        assert data["frequency"].attrs["units"] == "Hz"
        assert data["isolator"].attrs["stiction_force_units"] == "N"  # a container (CF)
    elif suffix == ".mat":  # the dataset's variables; strings as cells, units in a struct
        import scipy.io

        read = scipy.io.loadmat(path)
        np.testing.assert_allclose(read["transmissibility"][0],
                                   small_response.branch("up")["transmissibility"])
        assert read["transmissibility"].shape == (2, 3)  # (direction, frequency)
        assert [str(d[0]) for d in read["direction"][:, 0]] == ["up", "down"]
        assert read["units"][0, 0]["frequency"][0] == "Hz"
        assert read["parameter_units"][0, 0]["isolator"][0, 0]["stiction_force"][0] == "N"
    elif suffix == ".json":
        record = json.loads(path.read_text())
        assert {"frequency", "transmissibility"} <= set(record["points"][0])
    else:
        text = path.read_text()
        assert "# amplitude = 0.01 [m]" in text and "direction,frequency,transmissibility" in text
        assert len([line for line in text.splitlines() if line.startswith(("up", "down"))]) == 6


def test_save_refuses_an_unknown_format(small_response, tmp_path):
    with pytest.raises(ParameterError, match="extension"):
        small_response.save(tmp_path / "response.xlsx")
    assert list(tmp_path.iterdir()) == []


def test_the_dataset_has_the_sweeps_on_direction_and_frequency(small_response):
    data = small_response.to_xarray()
    assert data["transmissibility"].dims == ("direction", "frequency")
    assert data["harmonics"].sizes["harmonic"] == 4
    assert "balance_transmissibility" in data
