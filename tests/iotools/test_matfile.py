"""MATLAB files (qzs.iotools.matfile): MAT 5 and MAT 7.3 read back with scipy.io and h5py,
the layout MATLAB's ``load`` expects, names, structs, atomic writes and the streamed file."""
import os

import h5py
import numpy as np
import pytest
import scipy.io
import xarray as xr

from qzs.errors import OutputPathError, ParameterError
from qzs.iotools import matfile
from qzs.iotools.matfile import MatStream, mat_layout, matlab_name, write_mat
from qzs.iotools.schema import Schema, Variable, time_coordinate
from qzs.iotools.writer import StreamWriter

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


@pytest.fixture
def dataset():
    """A small result: 1-D and 2-D floats, a count, a flag, labels, parameters with units."""
    rng = np.random.default_rng(1)
    return xr.Dataset(
        {"displacement": ("time", rng.normal(size=7), {"units": "m", "long_name": "x"}),
         "force": (("time", "leg"), rng.normal(size=(7, 3)), {"units": "N"}),
         "contacts": ("leg", np.array([0, 5, 2], dtype=np.int64), {"units": "1"}),
         "locked": ("time", np.array([0, 1, 1, 0, 0, 1, 0], dtype=np.int8),
                    {"units": "1", "flag_values": np.array([0, 1], dtype=np.int8),
                     "flag_meanings": "slipping locked"})},
        coords={"time": ("time", np.arange(7) / 10, {"units": "s"}),
                "leg": ("leg", ["a", "bb", ""])},
        attrs={"Conventions": "CF-1.10", "title": "a toy run", "isolator.mass": 6.4,
               "isolator.mass_units": "kg", "controller.pi_ki": "none",
               "none_parameters": "controller.pi_ki", "amplitude": 0.01,
               "amplitude_units": "m", "excitation": "Chirp", "run.steps": 12,
               "history": "made here"})


def mclass(node):
    """The MATLAB_class attribute read in its own type (no conversion), and its padding."""
    attribute = h5py.h5a.open(node.id, b"MATLAB_class")
    kind = attribute.get_type()
    data = np.zeros((), dtype=f"S{kind.get_size()}")
    attribute.read(data, mtype=kind)
    return data.item().decode(), kind.get_strpad()


def char(node):
    """A MATLAB char dataset of a MAT 7.3 file as text."""
    if "MATLAB_empty" in node.attrs:
        return ""
    assert mclass(node)[0] == "char" and node.attrs["MATLAB_int_decode"] == 2
    assert node.dtype == np.uint16 and node.shape[1] == 1  # 1 x n in MATLAB
    return node[()].ravel().astype(np.uint16).tobytes().decode("utf-16-le")


# ---------------------------------------------------------------- names and layout
def test_names_are_kept_or_made_valid_as_matlab_does():
    assert matlab_name("relative_position") == "relative_position"
    assert matlab_name("excitation.f1") == "excitation_f1"
    assert matlab_name("2nd harmonic") == "x2nd_harmonic"
    assert matlab_name("_FillValue") == "x_FillValue"
    assert matlab_name("end") == "xEnd"
    assert len(matlab_name("a" * 80)) == 63
    for name in ("relative_position", "excitation.f1", "2nd", "end", "a" * 80, "é"):
        assert matlab_name(name)[0].isascii() and matlab_name(name)[0].isalpha()


def test_names_that_collide_in_matlab_are_an_error():
    with pytest.raises(ParameterError, match="'a.b' and 'a_b' both become"):
        mat_layout({"a.b": {}, "a_b": {}}, {})
    with pytest.raises(ParameterError, match="names of the MAT file's structs"):
        mat_layout({"units": {}}, {})


def test_a_parameter_that_heads_a_section_is_its_value():
    _, structs = mat_layout({}, {"excitation.z.amplitude": 0.01, "excitation.z": "Chirp",
                                 "excitation.z.amplitude_units": "m"})
    assert structs["parameters"] == {"excitation": {"z": {"amplitude": 0.01, "value": "Chirp"}}}
    assert structs["parameter_units"]["excitation"]["z"] == {"amplitude": "m", "value": ""}
    with pytest.raises(ParameterError, match="which is taken"):
        mat_layout({}, {"a.b": 1, "a_b": 2, "a.b_c": 3, "a.b.c": 4, "a.b.value": 5})


def test_the_layout_splits_parameters_from_the_other_attributes(dataset):
    names, structs = mat_layout({n: dict(dataset[n].attrs) for n in dataset.variables},
                                dataset.attrs)
    assert names["displacement"] == "displacement"
    assert structs["parameters"] == {"isolator": {"mass": 6.4}, "controller": {"pi_ki": None},
                                     "amplitude": 0.01, "run": {"steps": 12}}
    assert structs["parameter_units"] == {"isolator": {"mass": "kg"},
                                          "controller": {"pi_ki": ""}, "amplitude": "m",
                                          "run": {"steps": ""}}
    assert set(structs["attributes"]) == {"Conventions", "title", "excitation",
                                          "none_parameters", "history"}
    assert structs["units"]["force"] == "N" and structs["units"]["leg"] == ""
    assert "units" not in structs["variable_attributes"]["displacement"]
    assert structs["description"].startswith("a toy run.")
    assert "netcdf_names" not in structs


# ---------------------------------------------------------------- MAT 5
def test_mat5_round_trip_with_scipy(dataset, tmp_path):
    path = write_mat(dataset, tmp_path / "run.mat")
    assert path.read_bytes()[:19] == b"MATLAB 5.0 MAT-file"  # the 128-byte MAT 5 header
    assert path.read_bytes()[126:128] == b"IM"
    data = scipy.io.loadmat(path)
    np.testing.assert_array_equal(data["displacement"], dataset["displacement"].values[:, None])
    np.testing.assert_array_equal(data["force"], dataset["force"].values)  # 7 x 3
    np.testing.assert_array_equal(data["time"][:, 0], dataset["time"].values)
    np.testing.assert_array_equal(data["contacts"][:, 0], [0, 5, 2])
    np.testing.assert_array_equal(data["locked"][:, 0], dataset["locked"].values)
    assert [str(np.squeeze(c)) if c.size else "" for c in data["leg"][:, 0]] == ["a", "bb", ""]
    classes = {name: cls for name, _, cls in scipy.io.whosmat(path)}
    assert classes["locked"] == "logical" and classes["contacts"] == "int64"
    assert classes["leg"] == "cell" and classes["units"] == "struct"
    units = data["units"][0, 0]
    assert units["displacement"][0] == "m" and units["force"][0] == "N"
    parameters, parameter_units = data["parameters"][0, 0], data["parameter_units"][0, 0]
    assert parameters["isolator"][0, 0]["mass"][0, 0] == 6.4
    assert parameter_units["isolator"][0, 0]["mass"][0] == "kg"
    assert parameters["controller"][0, 0]["pi_ki"].size == 0  # None -> []
    assert parameters["amplitude"][0, 0] == 0.01 and parameter_units["amplitude"][0] == "m"
    assert data["attributes"][0, 0]["history"][0] == "made here"
    assert data["variable_attributes"][0, 0]["locked"][0, 0]["flag_meanings"][0] == \
        "slipping locked"
    assert str(data["description"][0]).startswith("a toy run.")


def test_changed_names_are_listed(tmp_path):
    data = xr.Dataset({"excitation.f1": ("case", [1.0, 2.0], {"units": "Hz"})})
    read = scipy.io.loadmat(write_mat(data, tmp_path / "s.mat"))
    np.testing.assert_array_equal(read["excitation_f1"][:, 0], [1.0, 2.0])
    assert read["netcdf_names"][0, 0]["excitation_f1"][0] == "excitation.f1"
    assert read["units"][0, 0]["excitation_f1"][0] == "Hz"


def test_mat5_refuses_a_variable_above_its_limit_and_says_how_to_split(dataset, tmp_path):
    with pytest.raises(ParameterError, match=r"split the dataset along 'time'") as caught:
        write_mat(dataset, tmp_path / "run.mat", version="5", limit=1100)
    assert "MAT 7.3" in str(caught.value)
    with pytest.raises(ParameterError, match="`version` must be one of"):
        write_mat(dataset, tmp_path / "run.mat", version="6")
    with pytest.raises(OutputPathError, match="must end in .mat"):
        write_mat(dataset, tmp_path / "run.nc")
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- MAT 7.3
def test_a_variable_above_the_limit_makes_the_file_mat73(dataset, tmp_path):
    path = write_mat(dataset, tmp_path / "run.mat", limit=1100)  # force 168 > 1100 - 1024
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["force"][()].T, dataset["force"].values)
        np.testing.assert_array_equal(f["displacement"][()].T[:, 0],
                                      dataset["displacement"].values)
        np.testing.assert_array_equal(f["locked"][()].T[:, 0], dataset["locked"].values)
        assert char(f["units/force"]) == "N"
        assert f["parameters/isolator/mass"][()].item() == 6.4
        assert char(f["parameter_units/isolator/mass"]) == "kg"
        assert char(f["attributes/history"]) == "made here"
        assert [char(f[ref]) for ref in f["leg"][()].ravel()] == ["a", "bb", ""]
    with pytest.raises(NotImplementedError):  # scipy sends MAT 7.3 to an HDF5 reader
        scipy.io.loadmat(path)


def test_the_mat73_layout_is_what_matlab_load_expects(dataset, tmp_path):
    path = write_mat(dataset, tmp_path / "run.mat", version="7.3")
    head = path.read_bytes()[:1024]
    text = head[:116].decode("ascii")
    assert text.startswith("MATLAB 7.3 MAT-file, Platform: ")
    assert ", Created on: " in text and text.rstrip().endswith("HDF5 schema 1.00 .")
    assert head[116:124] == b"\0" * 8                      # subsystem offset
    assert head[124:126] == b"\x00\x02" and head[126:128] == b"IM"  # version 0x0200, endian
    assert head[512:520] == HDF5_SIGNATURE                 # the superblock after the userblock
    with h5py.File(path, "r") as f:
        assert f.userblock_size == 512
        # MATLAB_class: a scalar fixed-length NULLTERM string, the class's length
        for name, cls in (("displacement", "double"), ("contacts", "int64"),
                          ("locked", "logical"), ("units", "struct"), ("leg", "cell"),
                          ("units/time", "char")):
            assert mclass(f[name]) == (cls, h5py.h5t.STR_NULLTERM), name
            assert f[name].attrs.get_id("MATLAB_class").shape == ()
        assert f["locked"].dtype == np.uint8 and f["locked"].attrs["MATLAB_int_decode"] == 1
        # an (n, m) array is stored (m, n): MATLAB reads HDF5 column-major
        assert dataset["force"].shape == (7, 3) and f["force"].shape == (3, 7)
        assert f["displacement"].shape == (1, 7)  # a column, 7 x 1, in MATLAB
        # structs: groups with their fields in MATLAB_fields (vlen of single characters)
        fields = [b"".join(field).decode() for field in f["units"].attrs["MATLAB_fields"]]
        assert fields == list(f["units"]) or sorted(fields) == sorted(f["units"])
        assert h5py.check_vlen_dtype(f["units"].attrs["MATLAB_fields"].dtype) == np.dtype("S1")
        # [] : an empty double holding its dimensions
        empty = f["parameters/controller/pi_ki"]
        assert mclass(empty)[0] == "double" and empty.attrs["MATLAB_empty"] == 1
        assert mclass(f["leg"])[0] == "cell" and f["leg"].dtype == h5py.ref_dtype
        assert set(f["#refs#"]) and char(f[f["leg"][0, 1]]) == "bb"


def test_a_large_variable_is_copied_in_slabs(dataset, tmp_path, monkeypatch):
    monkeypatch.setattr(matfile, "_SLAB", 40)  # a few rows at a time
    path = write_mat(dataset, tmp_path / "run.mat", version="7.3")
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["force"][()].T, dataset["force"].values)
        np.testing.assert_array_equal(f["locked"][()].T[:, 0], dataset["locked"].values)
        assert mclass(f["force"])[0] == "double"


# ---------------------------------------------------------------- atomic
@pytest.mark.parametrize("version, writer", [("5", "_savemat"), ("7.3", "_h5_write")])
def test_an_error_mid_write_leaves_nothing(dataset, tmp_path, monkeypatch, version, writer):
    target = tmp_path / "run.mat"
    target.write_bytes(b"the old file")
    real, calls = getattr(matfile, writer), []

    def failing(*args, **kwargs):
        calls.append(args[1])
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(matfile, writer, failing)
    with pytest.raises(KeyboardInterrupt):
        write_mat(dataset, target, version=version)
    assert os.listdir(tmp_path) == ["run.mat"] and target.read_bytes() == b"the old file"


# ---------------------------------------------------------------- streamed
def toy_schema():
    return Schema(kind="a toy run", dimensions={"time": None, "leg": 2},
                  coordinates=(time_coordinate(), Variable(name="leg", dims=("leg",),
                                                           dtype="str")),
                  variables=(Variable(name="x", dims=("time",), units="m", long_name="x"),
                             Variable(name="f", dims=("time", "leg"), units="N"),
                             Variable(name="stuck", dims=("time",), units="1", dtype="int8",
                                      flag_meanings="free stuck")),
                  chunk_rows=4)


def stream(path, blocks, **finish):
    with StreamWriter(path, toy_schema(), blocks={"data": 4, "flags": 1},
                      columns={"time": ("data", 0), "x": ("data", 1), "f": ("data", slice(2, 4)),
                               "stuck": ("flags", 0)},
                      values={"leg": ["left", "right"]}, suffixes=(".mat",),
                      attributes={"title": "toy", "isolator.mass": 2.0,
                                  "isolator.mass_units": "kg"}) as writer:
        for data, flags in blocks:
            writer.append(data, flags)
        return writer.finish(finish)


def toy_blocks(n=11, size=3):
    rng = np.random.default_rng(2)
    data = np.column_stack([np.arange(n) * 0.1, rng.normal(size=(n, 3))])
    flags = rng.integers(0, 2, size=(n, 1)).astype(bool)
    return data, flags, [(data[i:i + size], flags[i:i + size]) for i in range(0, n, size)]


def test_a_streamed_run_is_mat5_when_it_fits(tmp_path):
    data, flags, blocks = toy_blocks()
    path = stream(tmp_path / "run.mat", blocks, **{"run.steps": 10})
    assert os.listdir(tmp_path) == ["run.mat"]  # neither the MAT 7.3 spool nor the copy
    assert path.read_bytes()[:19] == b"MATLAB 5.0 MAT-file"
    read = scipy.io.loadmat(path)
    np.testing.assert_array_equal(read["time"][:, 0], data[:, 0])
    np.testing.assert_array_equal(read["x"][:, 0], data[:, 1])
    np.testing.assert_array_equal(read["f"], data[:, 2:4])
    np.testing.assert_array_equal(read["stuck"][:, 0], flags[:, 0])
    assert dict((n, c) for n, _, c in scipy.io.whosmat(path))["stuck"] == "logical"
    assert [str(c[0]) for c in read["leg"][:, 0]] == ["left", "right"]
    assert read["parameters"][0, 0]["isolator"][0, 0]["mass"][0, 0] == 2.0
    assert read["parameters"][0, 0]["run"][0, 0]["steps"][0, 0] == 10
    assert read["units"][0, 0]["f"][0] == "N"


def test_a_streamed_run_above_the_limit_stays_mat73(tmp_path, monkeypatch):
    monkeypatch.setattr(matfile, "MAT5_LIMIT", 1024 + 40)  # x: 88 bytes > 40
    data, flags, blocks = toy_blocks()
    path = stream(tmp_path / "run.mat", blocks)
    assert os.listdir(tmp_path) == ["run.mat"]
    assert path.read_bytes()[:19] == b"MATLAB 7.3 MAT-file"
    with h5py.File(path, "r") as f:
        assert f["f"].shape == (2, 11) and f["f"].chunks == (2, 4)
        np.testing.assert_array_equal(f["f"][()].T, data[:, 2:4])
        np.testing.assert_array_equal(f["x"][()].T[:, 0], data[:, 1])
        np.testing.assert_array_equal(f["stuck"][()].T[:, 0], flags[:, 0])
        assert mclass(f["stuck"])[0] == "logical" and mclass(f["time"])[0] == "double"
        assert [char(f[ref]) for ref in f["leg"][()].ravel()] == ["left", "right"]
        assert char(f["parameter_units/isolator/mass"]) == "kg"


def test_a_streamed_run_of_no_samples_is_empty(tmp_path, monkeypatch):
    read = scipy.io.loadmat(stream(tmp_path / "a.mat", []))
    assert read["x"].size == 0 and read["f"].size == 0
    monkeypatch.setattr(matfile, "MAT5_LIMIT", 0)
    with h5py.File(stream(tmp_path / "b.mat", []), "r") as f:
        assert f["x"].attrs["MATLAB_empty"] == 1


@pytest.mark.parametrize("limit", [None, 0])
def test_an_interrupted_stream_leaves_nothing(tmp_path, monkeypatch, limit):
    if limit is not None:
        monkeypatch.setattr(matfile, "MAT5_LIMIT", limit)
    _, _, blocks = toy_blocks()
    with pytest.raises(KeyboardInterrupt):
        with StreamWriter(tmp_path / "run.mat", toy_schema(), blocks={"data": 4, "flags": 1},
                          columns={"time": ("data", 0), "x": ("data", 1),
                                   "f": ("data", slice(2, 4)), "stuck": ("flags", 0)},
                          values={"leg": ["l", "r"]}, suffixes=(".mat",)) as writer:
            writer.append(*blocks[0])
            raise KeyboardInterrupt
    assert os.listdir(tmp_path) == []


def test_a_failed_conversion_to_mat5_leaves_nothing(tmp_path, monkeypatch):
    def failing(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(matfile, "_savemat", failing)
    _, _, blocks = toy_blocks()
    with pytest.raises(Exception, match="the disk is full"):
        stream(tmp_path / "run.mat", blocks)
    assert os.listdir(tmp_path) == []


def test_strings_cannot_be_streamed(tmp_path):
    schema = Schema(kind="words", dimensions={"time": None},
                    variables=(Variable(name="w", dims=("time",), dtype="str"),))
    with pytest.raises(ParameterError, match="streams numbers only"):
        MatStream(tmp_path / "w.mat", schema, {})
