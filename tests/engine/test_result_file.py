"""A run's result file (qzs.engine.result_file): save and read back every channel, flag and
parameter; a preview refused; the size estimate an upper bound. The writer's streaming,
failures and CF layout are tested in tests/iotools/test_files.py and test_files_cf.py."""
import numpy as np
import pytest

from qzs import simulate
from qzs.engine.channels import CHANNELS, FLAGS
from qzs.engine.result_file import RESULT_SUFFIXES, estimated_size, read_result, save_result
from qzs.errors import ParameterError


@pytest.fixture(scope="module")
def run():
    from helpers import SHORT_CHIRP

    return simulate(SHORT_CHIRP, duration=0.5, dt=1e-4, sample_rate=200.0)


@pytest.mark.parametrize("suffix", [".nc", ".csv"])
def test_save_and_read_back(run, tmp_path, suffix):
    path = save_result(run, tmp_path / f"run{suffix}")
    assert path.suffix in RESULT_SUFFIXES
    back = read_result(path)
    for name in [*CHANNELS, *FLAGS]:
        if suffix == ".nc":
            np.testing.assert_array_equal(back[name].values, run[name])
        else:  # CSV keeps 10 significant digits
            np.testing.assert_allclose(back[name].values, run[name], rtol=1e-9, atol=1e-300)
    assert back.attrs["run.steps"] == run.run["steps"]
    assert estimated_size(len(run), suffix) >= path.stat().st_size


def test_a_preview_is_refused(run, tmp_path):
    preview = type(run)(run._data, run._flags, isolator=run.isolator, controller=run.controller,
                        excitation=run.excitation, run={**run.run, "preview_every": 4})
    with pytest.raises(ParameterError, match="every 4th sample"):
        save_result(preview, tmp_path / "run.nc")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("suffix", [".nc", ".csv", ".mat"])
def test_a_controller_with_blocks_reads_back_from_its_file_equal(tmp_path, suffix):
    """The file of a run carries its controller, blocks included (a linear controller's
    matrices with their units, its sensors, name and timing; None levels), and
    :func:`qzs.read_controller` gives back ``result.controller``."""
    import qzs

    linear = qzs.LinearController(a=[[1 / 3, 0.1], [-0.2, 2 / 3]], b=[[1.0, 0.0], [1 / 7, 1.0]],
                                  c=[3.0, -1.5], d=[0.0, 4.0],
                                  inputs=("position_error", "measured_payload_velocity"),
                                  sample_time=1e-3, tracking_time=0.3, name="lead lag")
    controller = (qzs.PIDamping(pi_kp=70.0) + qzs.FrictionCompensation(
        fraction=0.8, viscous_damping=None, deadband=1e-3) + qzs.Dither(amplitude=0.5)
        + linear)
    result = qzs.simulate(qzs.Sine(frequency=3.0), controller=controller, duration=0.05,
                          dt=1e-4, sample_rate=200.0)
    path = result.save(tmp_path / f"run{suffix}")
    assert qzs.read_controller(path) == result.controller == controller
    if suffix != ".mat":
        data = qzs.read_result(path)
        assert data.attrs["controller.linear.a_units"] == "1/s"
        assert data.attrs["controller.compensation.fraction_units"] == "-"
        assert qzs.read_controller(data) == controller
    else:
        import scipy.io

        units = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)[
            "parameter_units"].controller
        assert units.linear.c == "N" and units.dither.frequency == "Hz"


def test_a_file_without_a_controller_s_attributes_is_a_data_error(tmp_path):
    import qzs
    from qzs.errors import DataError

    with pytest.raises(DataError, match="controller.linear|make no controller"):
        qzs.engine.metadata.controller_from_attributes(
            {"controller.linear.a": [1.0], "controller.linear.inputs": "position_error"})
