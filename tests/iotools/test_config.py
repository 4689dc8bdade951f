"""Files: TOML configs, result round trips, atomic writes, displacement records."""
import numpy as np
import pytest

import qzs
from qzs.errors import DataError, ParameterError
from qzs.iotools import (
    atomic_path,
    load_config,
    read_displacement_csv,
    read_result,
    save_config,
)
from qzs.model.registry import update_parameters


@pytest.fixture(scope="module")
def short_run():
    return qzs.simulate(qzs.Sine(amplitude=0.005, frequency=3.0), duration=2.0,
                        sample_rate=500.0)


def test_config_round_trip(tmp_path):
    isolator = qzs.IsolatorParameters(mass=7.5, stop_model="plastic", stop_center=-0.05)
    controller = qzs.ControllerParameters(pi_kp=12.0, controller_rate=1000.0)
    path = save_config(tmp_path / "run.toml", isolator, controller,
                       excitation={"kind": "sine", "frequency": 2.0}, simulation={"dt": 5e-5})
    config = load_config(path)
    assert config["isolator"] == isolator
    assert config["controller"] == controller
    assert config["excitation"] == {"kind": "sine", "frequency": 2.0}
    assert config["simulation"] == {"dt": 5e-5}


def test_default_config_has_every_parameter(tmp_path):
    config = load_config(save_config(tmp_path / "d.toml"))
    assert config["isolator"] == qzs.IsolatorParameters()
    assert config["controller"] == qzs.ControllerParameters()


@pytest.mark.parametrize("text, match", [
    ("[isolator]\nmas = 1.0\n", "unknown parameter 'mas'"),
    ("[isolator]\nmass = -1.0\n", "`mass` must be positive, got -1.0"),
    ("[isolator]\npi_kp = 3.0\n", r"\['pi_kp'\] belong in \[controller\]"),
    ("[plant]\nmass = 1.0\n", r"unknown table\(s\) \['plant'\]"),
    ("[simulation]\nstep = 1e-4\n", r"unknown key\(s\) \['step'\]"),
    ("[isolator\nmass = 1\n", "is not valid TOML"),
])
def test_bad_config_is_refused(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        load_config(path)


def test_missing_config_names_the_file(tmp_path):
    with pytest.raises(ParameterError, match="config file not found"):
        load_config(tmp_path / "nope.toml")


def test_update_parameters_parses_strings_and_routes_names():
    isolator, controller = update_parameters(
        qzs.IsolatorParameters(), qzs.ControllerParameters(),
        {"mass": "7", "pi_kp": "1e2", "stop_center": "none", "stop_model": "plastic"})
    assert isolator.mass == 7.0 and controller.pi_kp == 100.0
    assert isolator.stop_center is None and isolator.stop_model == "plastic"


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_result_round_trip(tmp_path, short_run, suffix):
    path = short_run.save(tmp_path / f"run{suffix}")
    data = read_result(path)
    for name in ("relative_position", "payload_acceleration", "base_work", "locked"):
        np.testing.assert_allclose(data[name].values, np.asarray(short_run[name], float),
                                   rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(data["time"].values, short_run.time, rtol=1e-12)
    assert data.attrs["qzs_version"] == qzs.__version__
    assert data.attrs["isolator.mass"] == 6.4
    assert data.attrs["controller.pi_kp"] == 50.0
    assert data.attrs["excitation"] == "Sine"
    if suffix == ".nc":
        assert data["relative_position"].attrs["units"] == "m"


def test_bad_result_suffix(tmp_path, short_run):
    with pytest.raises(ParameterError, match=r"must end in \.nc, \.csv or \.mat"):
        short_run.save(tmp_path / "run.txt")


def test_atomic_path_gives_the_usual_permissions(tmp_path):
    import os
    import stat

    mask = os.umask(0o022)
    try:
        with atomic_path(tmp_path / "f.txt") as tmp:
            tmp.write_text("x")
    finally:
        os.umask(mask)
    assert stat.S_IMODE((tmp_path / "f.txt").stat().st_mode) == 0o644


def test_atomic_path_leaves_nothing_on_error(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half-written")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert list(tmp_path.iterdir()) == [target]


def test_displacement_csv(tmp_path):
    path = tmp_path / "base.csv"
    t = np.linspace(0, 1, 11)
    path.write_text("time,displacement\n" + "\n".join(f"{a},{b}" for a, b in zip(t, t ** 2)))
    time, disp = read_displacement_csv(path)
    np.testing.assert_allclose(disp, t ** 2)
    record = qzs.DisplacementRecord.from_file(path)
    assert record.duration == pytest.approx(1.0)


@pytest.mark.parametrize("text, match", [
    ("t,displacement\n0,0\n1,1\n", r"no column\(s\) \['time'\]; columns found: \['t', 'displacement'\]"),
    ("time,displacement\n0,0\n1,abc\n", "non-numeric"),
    ("time,displacement\n0,0\n1,nan\n", "1 non-finite samples"),
    ("", "is empty"),
])
def test_bad_displacement_csv(tmp_path, text, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(DataError, match=match):
        read_displacement_csv(path)
