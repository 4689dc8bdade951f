"""A result's save by extension (qzs.iotools.result_files): the format chosen by the
extension, the extension checked before any work, every write atomic."""
import json
import math

import numpy as np
import pytest

from qzs.errors import OutputPathError
from qzs.iotools.result_files import (DATASET_SUFFIXES, RECORD_SUFFIXES, save_by_extension,
                                      suffixes_of, write_json)
from qzs.iotools.schema import Schema, Variable, to_dataset


def _dataset():
    schema = Schema(kind="a curve", dimensions={"frequency": None},
                    coordinates=(Variable(name="frequency", dims=("frequency",), units="Hz",
                                          long_name="frequency"),),
                    variables=(Variable(name="ratio", dims=("frequency",), units="1",
                                        long_name="amplitude ratio"),))
    return to_dataset(schema, {"frequency": [1.0, 2.0], "ratio": [0.5, 0.25]})


def test_each_extension_chooses_its_format(tmp_path):
    import xarray as xr

    calls = []

    def dataset():
        calls.append("dataset")
        return _dataset()

    json_path = save_by_extension(tmp_path / "a.JSON", dataset=dataset,
                                  record=lambda: {"x": 1.5, "y": math.nan})
    assert json.loads(json_path.read_text()) == {"x": 1.5, "y": None} and calls == []
    with xr.open_dataset(save_by_extension(tmp_path / "a.nc", dataset=dataset),
                         engine="h5netcdf") as read:
        assert np.array_equal(read["ratio"].values, [0.5, 0.25])
    lines = save_by_extension(tmp_path / "a.csv", dataset=dataset).read_text().splitlines()
    assert lines[-2:] == ["1,0.5", "2,0.25"] and "Hz" in lines[-3]
    toml = save_by_extension(tmp_path / "a.toml", writers={
        ".toml": lambda path: write_json({"written": True}, path)})
    assert json.loads(toml.read_text()) == {"written": True}


@pytest.mark.parametrize("given, accepted", [
    ({"dataset": _dataset}, DATASET_SUFFIXES),
    ({"record": dict}, RECORD_SUFFIXES),
    ({"dataset": _dataset, "record": dict}, (*DATASET_SUFFIXES, *RECORD_SUFFIXES))])
def test_another_extension_is_refused_before_any_work_naming_path_and_choices(
        tmp_path, given, accepted):
    def never():
        raise AssertionError("computed before the extension was checked")

    path = tmp_path / "out.txt"
    with pytest.raises(OutputPathError) as error:
        save_by_extension(path, **{key: never for key in given})
    message = str(error.value)
    assert error.value.argument == "path" and error.value.value == str(path)
    assert "'.txt'" in message and all(suffix in message for suffix in accepted)
    assert list(tmp_path.iterdir()) == []
    assert suffixes_of(dataset="dataset" in given, record="record" in given) == accepted


def test_a_record_json_cannot_hold_is_refused_and_leaves_no_file(tmp_path):
    class Unwritable:
        pass

    with pytest.raises(TypeError):
        write_json({"x": Unwritable()}, tmp_path / "bad.json")
    assert list(tmp_path.iterdir()) == []


def test_a_writer_s_extension_is_case_insensitive_too(tmp_path):
    """A writer given for ``.TOML`` writes ``a.toml`` (and ``a.Toml``): an extension chooses
    its format whatever its case, the writer's own included."""
    written = []

    def write(path):
        written.append(path.name)
        return write_json({"written": True}, path)

    for name in ("a.toml", "b.Toml"):
        save_by_extension(tmp_path / name, writers={".TOML": write})
    assert written == ["a.toml", "b.Toml"]
