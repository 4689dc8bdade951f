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
