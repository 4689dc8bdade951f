"""The hexapod study (qzs.workflows.hexapod.study): its comparison figure draws, per excited
axis, the diagonal and the cross-axis entry the linear model couples most, compared without
units (a rotation per translation times the platform's size)."""
from types import SimpleNamespace

import numpy as np

from qzs.workflows.hexapod.study import comparison_figure

F = np.linspace(0.0, 20.0, 81)
SIZE = 0.1  # [m]


def study_case():
    response = np.zeros((F.size, 6, 6), complex)
    for k in range(6):
        response[:, k, k] = 1.0 / (1.0 + 1j * F)
    linear = response.copy()
    linear[:, 4, 0] = 5.0    # ry per x: 5 rad/m, 0.5 without units
    linear[:, 1, 0] = 0.8    # y per x: 0.8, the stronger coupling without units
    trusted = np.zeros(response.shape, bool)
    trusted[1:, range(6), range(6)] = True   # no cross-axis bin trusted
    settings = {"platform_size": SIZE, "coherence_min": 0.9, "f1": 20.0, "trusted_from": 0.5,
                "duration": 60.0}
    return SimpleNamespace(frequency=F, response=response, magnitude=np.abs(response),
                           trusted=trusted, coherence=np.ones(response.shape),
                           linear_stable=True, linear_response=linear, settings=settings,
                           setup=SimpleNamespace(platform=SimpleNamespace(mass=21.48)),
                           amplitude={"z": 0.002, "x": 0.002})


def test_the_figure_shows_the_coupling_that_is_largest_without_units():
    figure = comparison_figure({"PI": study_case()})
    titles = [ax.get_title() for ax in figure.axes if ax.get_visible() and ax.get_title()]
    assert titles == ["platform z per base z: transmissibility [-]",
                      "platform x per base x: transmissibility [-]",
                      "platform y per base x: cross-axis response [-]"]


def test_writing_the_study_advances_a_progress_bar_file_by_file(tmp_path, monkeypatch):
    """Never silent while the figures draw and the files are written: a step per part, each
    after its file is there (the runs' own bars come before)."""
    import matplotlib.pyplot as plt

    from qzs.engine import progress
    from qzs.workflows.hexapod import study

    def figure_to(path, **_):
        figure = plt.figure()
        path.write_bytes(b"png")
        return figure

    def case():
        return SimpleNamespace(plot=figure_to, save=lambda path: path.write_bytes(b"nc") and path,
                               linear_stable=True, linear_natural_frequencies=[1.0],
                               settings={"tolerance_db": 0.5}, runs={})

    steps, bars = [], []

    class Recorder:
        def __init__(self, total, disable):
            self.total, self.disable = total, disable

        def update(self, n):
            steps.append((n, sorted(p.name for p in tmp_path.iterdir())))

        def __enter__(self):
            return self

        def __exit__(self, *_):
            return False

    def bar(*, total, disable, **_):
        bars.append(Recorder(total, disable))
        return bars[-1]

    monkeypatch.setattr(progress, "progress_bar", bar)
    monkeypatch.setattr(study, "comparison_figure", lambda cases, out, **_: figure_to(out))
    monkeypatch.setattr(study, "study_markdown", lambda *_, **__: "report")
    monkeypatch.setattr(study, "CASES", {"PI": ("with PI", {}), "no PI": ("without", {})})
    study.write_study_outputs({"PI": case(), "no PI": case()}, [], [], tmp_path, progress=True)
    (recorder,) = bars
    assert not recorder.disable and [n for n, _ in steps] == [1] * recorder.total
    assert [len(files) for _, files in steps] == list(range(1, recorder.total + 1))
    assert "report.md" in steps[-1][1]
    assert all("report.md" not in files for _, files in steps[:-1])


def test_a_study_at_a_given_step_writes_its_steps_and_saves_its_matrices(tmp_path):
    """With a given dt the runs have no step search: metrics.json says so (it raised a
    KeyError on 'step_error_db'); the saved study is its metrics.json and its cases'
    matrices stacked on 'case', each the one its hexapod_matrix_<case>.nc holds."""
    import json
    import math

    from qzs.iotools.files import read_result

    from helpers import tiny_hexapod_study

    study = tiny_hexapod_study(tmp_path / "out")
    written = json.loads((tmp_path / "out" / "metrics.json").read_text(encoding="utf-8"))
    step = written["cases"]["PI"]["steps"]["z"]
    assert step["dt_s"] == 1e-3 and step["error_db"] is None
    assert step["reason"] == "given by the caller" and written["wall_seconds"] == 1.5
    saved = json.loads(study.save(tmp_path / "study.json").read_text(encoding="utf-8"))
    assert saved["rows"] == written["rows"] and saved["cases"] == written["cases"]
    assert saved["wall_seconds"] >= 1.5 and math.isclose(saved["wall_seconds"],
                                                         study.wall_seconds)
    with read_result(study.save(tmp_path / "study.nc")) as back:
        assert list(back["case"].values) == ["PI", "P only", "no position loop"]
        for label, slug in (("PI", "pi"), ("no position loop", "no_position_loop")):
            with read_result(tmp_path / "out" / f"hexapod_matrix_{slug}.nc") as one:
                for name in ("magnitude", "phase", "trusted", "linear_magnitude"):
                    np.testing.assert_array_equal(back[name].sel(case=label).values,
                                                  one[name].values)
        assert back["magnitude"].attrs["units"] and back["frequency"].attrs["units"] == "Hz"
