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
