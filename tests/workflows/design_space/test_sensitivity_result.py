"""The result of a sensitivity analysis (qzs.workflows.design_space.sensitivity_result): its
files round-trip every index and interval, Morris indices carry the metric's unit, the text
table ranks as :func:`parameter_ranking` does; the analysis module still exports the names."""
import importlib

import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.workflows.design_space import sensitivity_result
from qzs.workflows.design_space.sensitivity import sensitivity
from qzs.workflows.design_space.sensitivity_result import SensitivityResult, parameter_ranking

from workflows.design_space.ishigami import ISHIGAMI_COLUMN, ishigami, ishigami_problem


def test_the_analysis_module_exports_the_very_result_names():
    # the package's `sensitivity` is the function: the module by its full name
    analysis = importlib.import_module("qzs.workflows.design_space.sensitivity")
    for name in sensitivity_result.__all__:
        assert getattr(analysis, name) is getattr(sensitivity_result, name), name
    assert set(sensitivity_result.__all__) <= set(analysis.__all__)


def test_the_result_round_trips_through_its_files(ishigami_sobol, tmp_path):
    import scipy.io
    import xarray as xr

    result = ishigami_sobol
    dataset = result.to_xarray()
    assert dataset["first_order"].dims == ("metric", "parameter")
    assert dataset["total_order"].attrs["units"] == "1"
    assert list(dataset["parameter_unit"].values) == ["N/m", "N/(m*s)", "N*s/m"]
    assert dataset.attrs["Conventions"] == "CF-1.10"
    assert dataset.attrs["samples"] == 4096 and dataset.attrs["confidence_level"] == 0.95

    with xr.open_dataset(result.save(tmp_path / "ishigami.nc"), engine="h5netcdf") as back:
        for name in ("first_order", "total_order"):
            assert np.array_equal(back[name].values, getattr(result, name))
            assert np.array_equal(back[f"{name}_lower"].values,
                                  result.intervals[name][0])
            assert np.array_equal(back[f"{name}_upper"].values,
                                  result.intervals[name][1])
        assert list(back["parameter"].values) == list(result.parameters)
        assert back.attrs["method"] == "sobol"

    import csv

    text = result.save(tmp_path / "ishigami.csv").read_text()
    names, units, *rows = csv.reader(line for line in text.splitlines()
                                     if not line.startswith("#"))
    column = {name: [row[k] for row in rows] for k, name in enumerate(names)}
    assert column["parameter"] == list(result.parameters)
    assert units[names.index("total_order")] == "1"
    assert np.allclose(np.array(column["total_order"], float), result.total_order[0],
                       rtol=1e-9)
    assert np.allclose(np.array(column["first_order_lower"], float),
                       result.intervals["first_order"][0][0], rtol=1e-9)

    mat = scipy.io.loadmat(result.save(tmp_path / "ishigami.mat"))
    assert np.array_equal(np.asarray(mat["total_order"], float).reshape(1, 3),
                          result.total_order)
    with pytest.raises(ParameterError):
        result.save(tmp_path / "ishigami.json")


def test_morris_units_are_the_metrics_own(tmp_path):
    result = sensitivity(ishigami_problem(method="morris", trajectories=4), evaluate=ishigami,
                         progress=False)
    dataset = result.to_xarray()
    assert set(dataset.data_vars) == {"mu_star", "mu_star_lower", "mu_star_upper", "mu",
                                      "sigma", "reason"}
    assert dataset["mu_star"].attrs["units"] == "1"  # the metric's (an amplitude ratio)
    assert dataset.attrs["levels"] == 4
    assert "mu*" in result.summary()


def test_summary_and_ranking(ishigami_sobol):
    text = ishigami_sobol.summary()
    assert "4096 base samples, 20480 cases" in text
    rows = [line.split()[0] for line in text.splitlines() if line.startswith("  pi_")
            or line.startswith("  damping")]
    assert rows == list(ishigami_sobol.ranking())
    assert parameter_ranking(ishigami_sobol, ISHIGAMI_COLUMN) == ishigami_sobol.ranking()
    with pytest.raises(ParameterError, match="`metric` must be one of"):
        ishigami_sobol.ranking("peak_stroke")
    assert isinstance(ishigami_sobol, SensitivityResult)


def test_intervals_are_one_mapping_and_the_old_names_warn(ishigami_sobol):
    """``intervals``: each estimated index -> (low, high) about it; ``<index>_interval``
    (deprecated, one release) warns with the new name and gives the same numbers."""
    result = ishigami_sobol
    assert set(result.intervals) == {"first_order", "total_order"} and result.confidence == 0.95
    for name, (low, high) in result.intervals.items():
        estimate = getattr(result, name)
        assert low.shape == high.shape == estimate.shape
        assert np.all(low <= estimate) and np.all(estimate <= high) and np.all(low < high)
        with pytest.warns(DeprecationWarning, match=rf"use `intervals\['{name}'\]`"):
            old = getattr(result, f"{name}_interval")
        assert np.array_equal(old, np.stack([low, high], axis=-1))
    with pytest.warns(DeprecationWarning):
        assert result.mu_star_interval is None  # a Sobol result has no Morris interval


def test_the_summary_shows_each_index_and_its_interval_s_half_width(ishigami_sobol):
    """Each row: S1 +- half its interval's width, ST +- half its (three decimals)."""
    result = ishigami_sobol
    rows = {line.split()[0]: [float(x) for x in line.split()[-4:]]
            for line in result.summary().splitlines() if line.startswith(("  pi_", "  damping"))}
    assert len(rows) == len(result.parameters)
    for j, name in enumerate(result.parameters):
        s1, s1_half, st, st_half = rows[name]
        (low1, high1), (lowt, hight) = (result.intervals[k] for k in ("first_order",
                                                                      "total_order"))
        assert s1 == pytest.approx(result.first_order[0, j], abs=6e-4)
        assert s1_half == pytest.approx((high1[0, j] - low1[0, j]) / 2, abs=6e-4)
        assert st == pytest.approx(result.total_order[0, j], abs=6e-4)
        assert st_half == pytest.approx((hight[0, j] - lowt[0, j]) / 2, abs=6e-4)
