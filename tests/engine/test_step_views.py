"""A step choice's candidates as a dataset, its figure and its files."""
import json

import numpy as np
import pytest

import qzs
from qzs.engine.accuracy import choose_step
from qzs.engine.step_search import StepChoice


@pytest.fixture(scope="module")
def choice():
    """A choice that tries several candidates (a tight tolerance on a short chirp)."""
    return choose_step(qzs.Chirp(duration=20.0, f1=20.0), tolerance=1e-4)


def test_the_dataset_is_the_history_with_the_record(choice):
    data = choice.to_xarray()
    history = np.array(choice.history)
    assert data.sizes["candidate"] == len(choice.history) >= 2
    for column, name in enumerate(("step", "difference", "estimated_error")):
        assert np.array_equal(data[name].values, history[:, column])
    assert data["step"].attrs["units"] == "s" and data["estimated_error"].attrs["units"] == "1"
    assert "decibels" in data["estimated_error"].attrs["comment"]  # UDUNITS has no dB
    assert data.attrs["dt"] == choice.dt and data.attrs["step"] == "accuracy-driven"
    # the chosen step is a candidate, and the halving is the search's: dt_j = dt_0 / 2**j
    steps = data["step"].values
    assert choice.dt in steps
    np.testing.assert_allclose(steps[1:] / steps[:-1], 0.5, rtol=1e-12)


def test_a_literal_step_has_no_candidate_and_still_a_figure_and_files(tmp_path):
    literal = StepChoice.literal(1e-4)
    assert literal.to_xarray().sizes["candidate"] == 0
    figure = literal.plot()
    assert figure.axes[0].get_xlabel() == "step dt [s]"
    assert json.loads(literal.save(tmp_path / "literal.json").read_text()) == literal.to_dict()


def test_the_files_read_back(choice, tmp_path):
    import scipy.io
    import xarray as xr

    with xr.open_dataset(choice.save(tmp_path / "step.nc")) as back:
        assert np.array_equal(back["estimated_error"].values, choice.to_xarray()["estimated_error"].values)
    assert json.loads(choice.save(tmp_path / "step.json").read_text())["dt"] == choice.dt
    mat = scipy.io.loadmat(choice.save(tmp_path / "step.mat"))
    assert np.allclose(np.ravel(mat["step"]), [row[0] for row in choice.history], rtol=0)
    with pytest.raises(qzs.OutputPathError, match="path"):
        choice.save(tmp_path / "step.xlsx")
    assert not (tmp_path / "step.xlsx").exists()
