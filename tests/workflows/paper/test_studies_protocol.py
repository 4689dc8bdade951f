"""A study's and a case's result protocol (issue 42): what ``save`` writes reads back as the
numbers the cases hold (the curves ``qzs paper`` writes, the rows of its ``metrics.json``),
the spring study's case as its points and fitted law."""
import csv
import json

import numpy as np
import pytest
import xarray as xr

from qzs.workflows.findings.figures import curves_of
from qzs.workflows.findings.tables import metric_rows
from qzs.workflows.paper.studies import run_study

from helpers import SMALL_STUDY


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "small.toml"
    path.write_text(SMALL_STUDY, encoding="utf-8")
    return run_study(path, workers=1, progress=False)


def test_a_saved_study_s_curves_are_its_cases_curves(small, tmp_path):
    """Each case's magnitude, phase, trusted flag and linear model read back from the .nc
    and the .csv at its own frequencies; the parameter swept is a coordinate with its unit;
    the file is the one qzs paper writes (curves_of)."""
    small.save(tmp_path / "small.nc")
    with xr.open_dataset(tmp_path / "small.nc") as back:
        assert list(back["case"].values) == [case.label for case in small.cases]
        np.testing.assert_array_equal(back["viscous_damping"].values, [60.0, 120.0])
        assert back["viscous_damping"].attrs["units"] == "N*s/m"
        for i, case in enumerate(small.cases):
            at = back.sel(case=case.label, frequency=case.frequency)
            np.testing.assert_array_equal(at["magnitude"].values, case.magnitude)
            np.testing.assert_array_equal(at["phase"].values, case.phase)
            np.testing.assert_array_equal(at["trusted"].values.astype(bool), case.trusted)
            np.testing.assert_array_equal(at["linear_magnitude"].values,
                                          case.linear["magnitude"])
        assert back.equals(curves_of(small, quick=small.quick))
    lines = [line for line in small.save(tmp_path / "small.csv").read_text(
        encoding="utf-8").splitlines() if not line.startswith("#")]
    names, units, *rows = csv.reader(lines)
    assert units[names.index("magnitude")] == "1" and units[names.index("frequency")] == "Hz"
    heavier = [row for row in rows if row[names.index("case")] == "Cv = 120 N s/m"]
    read = np.array([float(row[names.index("magnitude")]) for row in heavier])
    np.testing.assert_allclose(read, small.cases[1].magnitude, rtol=1e-9)


def test_a_saved_study_s_record_is_its_entry_of_metrics_json(small, tmp_path):
    read = json.loads(small.save(tmp_path / "small.json").read_text(encoding="utf-8"))
    assert read["title"] == "Passive isolator, two viscous frictions (small)" and read["settings"]["dt"] == 5e-4
    rows = metric_rows([small])
    assert [row["case"] for row in read["cases"]] == [row["case"] for row in rows]
    for row, case in zip(read["cases"], small.cases):
        assert row["isolation_onset"] == case.metrics["isolation_onset"]
        assert row["motor_force_rms"] == case.stats["motor_force_rms"]
        assert row["transmissibility_at_1_hz"] is None and row["transmissibility_at_1_hz_reason"]
    case = small.cases[1]
    assert json.loads(case.save(tmp_path / "case.json").read_text(encoding="utf-8")) == \
        {k: v for k, v in read["cases"][1].items() if k != "study"}


def test_a_case_s_text_names_its_trusted_peak_and_undefined_metrics(small):
    case = small.cases[0]
    k = np.flatnonzero(case.trusted)[np.argmax(case.magnitude[case.trusted])]
    text = case.summary()
    assert f"trusted peak |T| {case.magnitude[k]:.4g}" in text and f"{case.frequency[k]:.4g} Hz" \
        in text
    assert "transmissibility_at_1_hz = undefined (1 Hz lies in untrusted bins" in text
    assert f"motor_force_rms {case.stats['motor_force_rms']:.4g} N" in text
    assert small.summary().count("trusted peak") == 2 and "dt = 0.0005 s (file)" in \
        small.summary()


def test_the_spring_study_s_case_is_its_points_and_fitted_law(tmp_path):
    import matplotlib.pyplot as plt

    spring = run_study("spring", workers=1, progress=False)
    case = spring.cases[0]
    with xr.open_dataset(case.save(tmp_path / "spring.nc")) as back:
        np.testing.assert_array_equal(back["force"].values, case.extra["force"])
        np.testing.assert_array_equal(back["displacement"].values, case.extra["displacement"])
        assert back.attrs["spring_force"] == case.metrics["spring_force"]
    assert f"spring_force = {case.metrics['spring_force']:.4g} N" in case.summary()
    figure = case.plot(tmp_path / "spring.png")
    try:
        assert any("[N]" in ax.get_ylabel() for ax in figure.axes)
    finally:
        plt.close(figure)
    assert (tmp_path / "spring.png").stat().st_size > 0
