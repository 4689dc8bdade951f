"""The curves behind a study's figures, read back from their files and redrawn.

No simulation: synthetic cases (as in test_report.py). The figure function is wrapped to
keep the arrays it was given; the NetCDF file (xarray) and the CSV file (pandas) must give
those arrays back, with the units of the schema.
"""
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from qzs.iotools.writer import write_dataset
from qzs.model.registry import unit_of
from qzs.workflows.findings import figures
from qzs.workflows.paper import report
from qzs.workflows.paper.curves import curves_dataset, curves_schema, spring_dataset, write_curves
from qzs.workflows.paper.studies import CaseResult, Study, StudyResult

FREQUENCY = np.round(np.arange(0.0, 20.0 + 1e-9, 0.25), 10)


def case(label, settings, level, *, phase=True):
    f = FREQUENCY
    magnitude = level / np.sqrt(1.0 + (f / 3.0) ** 4)
    return CaseResult(label, dict(settings), f, magnitude, np.clip(1 - f / 40, 0, 1), f > 0.5,
                      stats={"n_averages": 12, "stop_contacts": 0, "locked_fraction": 0.1},
                      run={"fft_length": 1024, "dt": 1e-3, "solver": "euler"},
                      linear={"undamped_natural_frequency": 0.2, "magnitude": 0.9 * magnitude},
                      phase=-np.arctan(f / 3.0) if phase else None)


@pytest.fixture
def damping_study():
    definition = Study(name="damping", title="damping gains", kind="transmissibility",
                       cases=({}, {}, {}), views=({"figure": "fig14_damping",
                                                   "frequency_range": [0.0, 20.0]},))
    return StudyResult(definition, [case("Kd = 0 N s/m", {"damping_gain": 0.0}, 1.0),
                                    case("Kd = 50 N s/m", {"damping_gain": 50.0, "pi_kp": 60.0},
                                         0.8),
                                    case("Kd = 100 N s/m", {"damping_gain": 100.0}, 0.6)],
                       quick=True)


@pytest.fixture
def drawn(monkeypatch):
    """The curves each figure was drawn from, by figure file name."""
    seen = {}
    original = figures.plot_transmissibility

    def keep(curves, **options):
        seen[options["path"].stem] = [dict(c) for c in curves]
        return original(curves, **options)

    monkeypatch.setattr(figures, "plot_transmissibility", keep)
    return seen


def test_the_curve_files_redraw_the_figures_data(damping_study, drawn, tmp_path):
    report.write_paper_outputs([damping_study], tmp_path, workers=1)
    curves = drawn["fig14_damping"]
    from_nc = xr.load_dataset(tmp_path / "damping_curves.nc")
    table = pd.read_csv(tmp_path / "damping_curves.csv", comment="#", header=[0, 1])
    units = dict(table.columns)
    table.columns = [name for name, _ in table.columns]
    from_csv = table.set_index(["case", "frequency"]).to_xarray()
    assert list(from_nc["case"].values) == [c["label"] for c in curves]
    for i, curve in enumerate(curves):
        label = curve["label"]
        for data, rtol in ((from_nc, 0.0), (from_csv.sel(case=label), 1e-9)):
            row = data.isel(case=i) if data is from_nc else data
            np.testing.assert_array_equal(row["frequency"].values, curve["frequency"])
            for name, key in (("magnitude", "magnitude"), ("phase", "phase"),
                              ("coherence", "coherence"), ("linear_magnitude", "linear")):
                np.testing.assert_allclose(row[name].values, curve[key], rtol=rtol, atol=0)
            np.testing.assert_array_equal(row["trusted"].values.astype(bool), curve["trusted"])
        # the parameters of the case, its default where the case does not set one
        assert float(from_nc["pi_kp"][i]) == curve["parameters"]["pi_kp"]
    # the MATLAB file: the NetCDF's variables, (case, frequency) as MATLAB reads them
    import scipy.io

    from_mat = scipy.io.loadmat(tmp_path / "damping_curves.mat")
    np.testing.assert_array_equal(from_mat["magnitude"], from_nc["magnitude"].values)
    np.testing.assert_array_equal(from_mat["frequency"][:, 0], from_nc["frequency"].values)
    assert from_mat["units"]["magnitude"][0, 0][0] == from_nc["magnitude"].attrs["units"]
    assert list(from_nc["damping_gain"].values) == [0.0, 50.0, 100.0]
    assert list(from_nc["pi_kp"].values)[1] == 60.0
    # the units: the schema's, the registry's for parameters, in both files
    schema = curves_schema({"damping_gain": ("N*s/m", "", "float64"),
                            "pi_kp": ("N/m", "", "float64")}, 3, FREQUENCY.size)
    for variable in schema:
        if variable.units is not None:
            assert from_nc[variable.name].attrs["units"] == variable.units
            assert units[variable.name] == variable.units
    assert units["damping_gain"] == unit_of("damping_gain")
    assert units["pi_kp"] == unit_of("pi_kp")
    assert from_nc["trusted"].attrs["flag_meanings"] == "untrusted trusted"
    assert from_nc.attrs["fft_length"] == 1024 and from_nc.attrs["dt_units"] == "s"
    html = (tmp_path / "report.html").read_text()
    assert "href='damping_curves.nc'" in html and "href='damping_curves.csv'" in html


def test_the_processing_study_keeps_both_curves(tmp_path, drawn):
    ideal = case("Kp = 50 N/m", {"pi_kp": 50.0}, 1.0)
    ideal.extra = {"frequency": FREQUENCY[4:], "magnitude": 0.5 * ideal.magnitude[4:],
                   "phase": ideal.phase[4:], "coherence": ideal.coherence[4:],
                   "trusted": ideal.trusted[4:], "highpass": 1.0, "n_averages": 29,
                   "metrics": {}, "untrusted_below": 1.5}
    definition = Study(name="processing", title="processing", kind="processing", cases=({},),
                       views=({"figure": "fig13_processing", "frequency_range": [0.0, 20.0]},))
    report.write_paper_outputs([StudyResult(definition, [ideal], quick=True)], tmp_path,
                               workers=1)
    data = xr.load_dataset(tmp_path / "processing_curves.nc")
    curves = drawn["fig13_processing"]
    assert list(data["case"].values) == [c["label"] for c in curves]
    experiment = data.isel(case=1)
    # the shorter curve lies on the common frequency axis; the bins it lacks are NaN, untrusted
    assert np.isnan(experiment["magnitude"].values[:4]).all()
    assert not experiment["trusted"].values[:4].any()
    np.testing.assert_array_equal(experiment["magnitude"].values[4:], curves[1]["magnitude"])
    assert np.isnan(experiment["linear_magnitude"].values).all()  # not drawn: no linear model


def test_a_curve_without_phase_or_coherence_is_nan_there(tmp_path):
    data = curves_dataset([{"label": "a", "frequency": [1.0, 2.0], "magnitude": [1.0, 0.5]}])
    assert np.isnan(data["phase"].values).all() and data["trusted"].values.all()
    paths = write_curves(data, tmp_path, "toy")
    assert [p.name for p in paths] == ["toy_curves.nc", "toy_curves.csv", "toy_curves.mat"]
    write_dataset(data, tmp_path / "again.nc")
    first, again = xr.load_dataset(paths[0]), xr.load_dataset(tmp_path / "again.nc")
    for written in (first, again):  # each file's history line is the time of its writing
        written.attrs.pop("history")
    xr.testing.assert_identical(first, again)


def test_metrics_csv_has_a_units_row_from_the_definitions(damping_study, tmp_path):
    damping_study.cases[0].metrics = {"resonance_frequency": 1.2, "resonance_peak": 1.5,
                                      "transmissibility_at_12_hz": 0.1, "trusted_from": 0.5}
    report.write_paper_outputs([damping_study], tmp_path, workers=1)
    table = pd.read_csv(tmp_path / "metrics.csv", comment="#", header=[0, 1])
    units = {name: ("" if unit.startswith("Unnamed") else unit) for name, unit in table.columns}
    assert units["param.damping_gain"] == "N*s/m" and units["param.pi_kp"] == "N/m"
    assert units["resonance_frequency"] == "Hz" and units["resonance_peak"] == "1"
    assert units["transmissibility_at_12_hz"] == "1" and units["trusted_from"] == "Hz"
    assert units["run.dt"] == "s" and units["run.solver"] == ""
    assert units["stop_contacts"] == "1" and units["seconds"] == "s"
    assert units["study"] == "" and units["case"] == ""
    assert len(table) == 3
    assert table[("resonance_frequency", "Hz")].iloc[0] == 1.2


def test_a_column_without_a_unit_is_a_programming_error():
    with pytest.raises(KeyError, match="no unit"):
        report.column_unit("made_up_column")


def test_the_spring_data_holds_the_points_and_the_fitted_law(tmp_path):
    """The fitted force at the points is the model's law -a tanh(b z) (docs/model.md)."""
    z = np.linspace(-0.1, 0.1, 21)
    data = spring_dataset(z, 60.0 * np.tanh(80.0 * z), 60.0, 80.0)
    np.testing.assert_allclose(data["fitted_force"].values, -60.0 * np.tanh(80.0 * z),
                               rtol=1e-12)
    assert data["displacement"].attrs["units"] == "m" and data.attrs["spring_shape_units"] == "1/m"
    nc, csv, _ = write_curves(data, tmp_path, "spring")
    table = pd.read_csv(csv, comment="#", header=[0, 1])
    assert list(table.columns) == [("displacement", "m"), ("force", "N"), ("fitted_force", "N")]
    written = xr.load_dataset(nc)
    assert written.attrs.pop("history").endswith("written")  # the file's own history line
    xr.testing.assert_identical(written, data)


class _Recorder:
    """A progress bar that records, at each step, the files the folder holds."""

    def __init__(self, folder, total, disable):
        self.folder, self.total, self.disable, self.steps = folder, total, disable, []

    def update(self, n):
        self.steps.append((n, sorted(p.name for p in self.folder.iterdir())))

    def __enter__(self):
        return self

    def __exit__(self, *_):
        return False


@pytest.mark.parametrize("workers", [1, 2])
def test_drawing_and_writing_advance_a_progress_bar_file_by_file(damping_study, tmp_path,
                                                                 monkeypatch, workers):
    """Never silent while the figures draw and the report is written: a step per part."""
    from qzs.engine import progress

    bars = []

    def bar(*, total, disable, **_):
        bars.append(_Recorder(tmp_path, total, disable))
        return bars[-1]

    monkeypatch.setattr(progress, "progress_bar", bar)
    report.write_paper_outputs([damping_study], tmp_path, workers=workers, progress=True)
    (recorder,) = bars
    assert not recorder.disable
    assert [n for n, _ in recorder.steps] == [1] * recorder.total  # each part, and all of them
    first, *_, last = [files for _, files in recorder.steps]
    assert "fig14_damping.png" in first and "metrics.json" not in first  # figures first
    assert "report.html" in last and all("report.html" not in f for _, f in recorder.steps[:-1])
    assert [len(f) for _, f in recorder.steps] == sorted(len(f) for _, f in recorder.steps)
    report.write_paper_outputs([damping_study], tmp_path, workers=1)
    assert bars[-1].disable  # progress=False: no bar shown


def test_without_a_trusted_flag_every_bin_above_0_hz_is_trusted():
    """As :func:`curves_dataset` documents: a curve without ``trusted`` trusts each of its
    bins above 0 Hz and not its 0 Hz bin; bins it lacks are untrusted; a flag given is kept
    as given, at 0 Hz too."""
    grid = np.array([0.0, 0.5, 1.0, 2.0])
    data = curves_dataset([
        {"label": "default", "frequency": grid, "magnitude": np.ones(4)},
        {"label": "shifted", "frequency": grid[1:] + 0.25, "magnitude": np.ones(3)},
        {"label": "given", "frequency": grid, "magnitude": np.ones(4),
         "trusted": np.array([True, False, True, False])}])
    frequency = data["frequency"].values
    trusted = data["trusted"].values.astype(bool)
    np.testing.assert_array_equal(trusted[0], np.isin(frequency, grid) & (frequency > 0))
    np.testing.assert_array_equal(trusted[1], np.isin(frequency, grid[1:] + 0.25))
    assert trusted[2, frequency == 0.0].all()
    np.testing.assert_array_equal(trusted[2][np.isin(frequency, grid)], [True, False, True,
                                                                         False])
    assert not trusted[2][~np.isin(frequency, grid)].any()
