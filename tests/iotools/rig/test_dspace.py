"""dSPACE MAT exports (qzs.iotools.rig.dspace): v5 and v7.3 written here read back, the v7.3
file in MATLAB's layout, Y(k) indices checked by name and range."""
import numpy as np
import pytest
from helpers import (LOG_BASE as BASE, LOG_MAP as MAP, LOG_PAYLOAD as PAYLOAD, LOG_TIME as TIME,
                     check_log_recording as check)

from qzs.errors import DataError
from qzs.iotools.rig import read_recording, write_dspace_mat


@pytest.mark.parametrize("version", ["5", "7.3"])
def test_dspace_mat(tmp_path, version):
    path = write_dspace_mat(tmp_path / "log.mat", TIME, {
        "Model Root/Sensors/other": np.zeros_like(TIME),
        "Model Root/Sensors/shaker_vel": BASE,
        "Model Root/Sensors/payload_vel": PAYLOAD.astype(np.float32)}, version=version)
    indexed = {"channels": {"base_velocity": {"source": "Y[2]/shaker_vel", "unit": "mm/s"},
                            "payload_velocity": {"source": "Y[3]", "unit": "mm/s", "scale": 2.0}}}
    check(read_recording(path, indexed), rtol=1e-6)  # payload stored as MATLAB single
    check(read_recording(path, MAP), rtol=1e-6)  # by name: the last path component


def test_mat73_is_matlab_layout(tmp_path):
    import h5py
    import scipy.io

    path = write_dspace_mat(tmp_path / "log.mat", TIME, {"a": BASE, "b": PAYLOAD}, version="7.3")
    with pytest.raises(NotImplementedError):  # scipy sees a v7.3 (HDF5) MAT file
        scipy.io.loadmat(path)
    with h5py.File(path) as handle:
        top = handle["qzs_log"]
        assert top.attrs["MATLAB_class"] == b"struct"
        assert top["Y"]["Data"].dtype == h5py.ref_dtype and top["Y"]["Data"].shape == (2, 1)
        name = handle[top["Y"]["Name"][1, 0]]
        assert name.attrs["MATLAB_class"] == b"char" and name.dtype == np.uint16
        assert "".join(map(chr, name[()].ravel())) == "b"
        assert top["X"]["Data"].shape == (TIME.size, 1)  # a 1x1 struct keeps its fields


def test_mat_index_checks_name_and_range(tmp_path):
    path = write_dspace_mat(tmp_path / "log.mat", TIME, {"Root/a": BASE, "Root/b": PAYLOAD})
    for source, match in (("Y[1]/b", "Y\\(1\\) is named 'Root/a', not 'b'"),
                          ("Y[5]", "out of range, Y has 2"), ("c", "no signal 'c'")):
        spec = {"channels": {"base_velocity": {"source": source, "unit": "m/s"}}}
        with pytest.raises(DataError, match=match):
            read_recording(path, spec)


def test_mat_without_dspace_struct(tmp_path):
    import scipy.io

    scipy.io.savemat(tmp_path / "plain.mat", {"a": np.arange(3.0)})
    with pytest.raises(DataError, match="one struct with fields X and Y"):
        read_recording(tmp_path / "plain.mat", MAP)
