"""The design's result: strict JSON, frozen, and its files written atomically."""
import dataclasses
import json

import pytest

from qzs.errors import ParameterError
from qzs.workflows.design.result import write_design


def test_to_dict_is_strict_json_and_the_result_is_frozen(design):
    text = json.dumps(design.to_dict(), allow_nan=False)
    assert json.loads(text)["gains"]["pi_kp"] == pytest.approx(design.gains["pi_kp"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        design.gains = {}


def test_save_writes_report_json_and_every_figure_atomically(design, tmp_path):
    written = write_design(design, tmp_path / "out")
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert "report.html" in names and "design.json" in names
    for figure in ("static_design", "pi_search", "hunting", "damping", "margins",
                   "damping_effect"):
        assert f"{figure}.png" in names and f"{figure}.svg" in names
    assert not [n for n in names if n.startswith(".")]  # no temporary file left
    record = json.loads(written["json"].read_text())
    assert record["gains"]["damping_gain"] == pytest.approx(design.gains["damping_gain"])
    html = written["report"].read_text()
    assert "Why active damping did not help much" in html and "pi_search.png" in html


def test_save_returns_the_folder_and_plot_one_named_figure_written_where_asked(design, tmp_path):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    assert design.save(tmp_path / "out") == tmp_path / "out"
    figure = design.plot(tmp_path / "margins.png", title="the margins", figure="margins")
    assert isinstance(figure, Figure) and figure._suptitle.get_text() == "the margins"
    assert (tmp_path / "margins.png").stat().st_size > 0
    plt.close(figure)
    with pytest.raises(ParameterError, match="`figure` must be one of 'static_design'.*"
                                             "got 'bode'"):
        design.plot(figure="bode")
    assert plt.get_fignums() == []  # the figures not returned are closed


def test_save_writes_the_damping_curves_the_figure_draws(design, tmp_path):
    """The curves file holds every gain tried; those the figure draws read back exactly."""
    import numpy as np
    import pandas as pd
    import xarray as xr

    written = write_design(design, tmp_path / "out")
    data = xr.load_dataset(written["curves_nc"])
    table = pd.read_csv(written["curves_csv"], comment="#", header=[0, 1])
    assert dict(table.columns)["damping_gain"] == "N*s/m" == data["damping_gain"].attrs["units"]
    assert dict(table.columns)["frequency"] == "Hz"
    drawn = design.series["damping_curves"]
    assert sorted(data["damping_gain"].values) == sorted(drawn)
    for gain in (0.0, design.gains["damping_gain"]):
        frequency, magnitude, trusted = drawn[gain]
        row = data.isel(case=int(np.flatnonzero(data["damping_gain"].values == gain)[0]))
        np.testing.assert_array_equal(row["frequency"].values, frequency)
        np.testing.assert_array_equal(row["magnitude"].values, magnitude)
        np.testing.assert_array_equal(row["trusted"].values.astype(bool), trusted)
        rows = table[table[("damping_gain", "N*s/m")] == gain]
        np.testing.assert_allclose(rows[("magnitude", "1")].to_numpy(), magnitude, rtol=1e-9)
    assert "href='damping_curves.nc'" in written["report"].read_text()


def test_saving_advances_a_progress_bar_part_by_part(design, tmp_path, monkeypatch):
    """Never silent while the figures draw and the files are written: a step per part, each
    after its file is there, the report last."""
    from qzs.engine import progress

    folder, steps, bars = tmp_path / "out", [], []

    class Recorder:
        def __init__(self, total, disable):
            self.total, self.disable = total, disable

        def update(self, n):
            steps.append((n, {p.name for p in folder.iterdir()}))

        def __enter__(self):
            return self

        def __exit__(self, *_):
            return False

    def bar(*, total, disable, **_):
        bars.append(Recorder(total, disable))
        return bars[-1]

    monkeypatch.setattr(progress, "progress_bar", bar)
    from qzs.workflows.design.result import write_design

    written = write_design(design, folder, progress=True)
    (recorder,) = bars
    assert not recorder.disable and [n for n, _ in steps] == [1] * recorder.total
    figures = [name for name in written if name not in ("report", "json")
               and not name.startswith("curves_")]
    assert recorder.total == len(figures) + 4
    assert steps[0][1] == set()  # the drawing, before any file
    assert [len(files) for _, files in steps] == sorted(len(files) for _, files in steps)
    assert "report.html" in steps[-1][1] and all("report.html" not in f for _, f in steps[:-1])
