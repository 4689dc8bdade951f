"""What every fit shares (qzs.identify._protocol): the deprecated alias, the intervals as
attributes, the shared plot docstring, and a fit's files read back."""
import json
import warnings
from dataclasses import dataclass

import numpy as np
import pytest

from qzs.identify import FrictionFit, SpringFit, TransmissibilityFit
from qzs._validation import deprecated_alias
from qzs.identify._protocol import (FREQUENCY_SCALE_OPTION, FitProtocol, interval_attributes,
                                    plot_doc)


@dataclass(frozen=True)
class _Fit(FitProtocol):
    """A fit of two numbers, as small as a fit gets."""

    intervals: dict
    confidence: float = 0.9
    old = deprecated_alias("old", "intervals['gain']", lambda fit: fit.intervals["gain"])

    def estimates(self):
        return {"gain": 2.0, "offset": 0.5}


def test_the_alias_warns_naming_the_new_spelling_and_returns_its_value():
    fit = _Fit({"gain": (1.5, 2.5)})
    with pytest.warns(DeprecationWarning, match=r"`_Fit.old` is deprecated .* use "
                                                r"`intervals\['gain'\]`"):
        assert fit.old == (1.5, 2.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert fit.intervals["gain"] == (1.5, 2.5)


def test_interval_attributes_name_each_estimate_its_ends_and_unit():
    fit = _Fit({"gain": (1.5, 2.5)})
    attrs = interval_attributes(fit, {"gain": "N/m", "offset": "N"}.get)
    assert attrs == {"confidence_level": 0.9, "gain": 2.0, "gain_lower": 1.5,
                     "gain_upper": 2.5, "gain_units": "N/m", "offset": 0.5,
                     "offset_units": "N"}  # no interval: no ends


def test_every_fit_shares_one_plot_docstring_with_its_own_options():
    assert SpringFit.plot.__doc__ == FrictionFit.plot.__doc__ == plot_doc()
    assert TransmissibilityFit.plot.__doc__ == plot_doc(FREQUENCY_SCALE_OPTION)
    assert "frequency_scale" in TransmissibilityFit.plot.__doc__
    assert "frequency_scale" not in FrictionFit.plot.__doc__
    assert SpringFit.save is FrictionFit.save is FitProtocol.save  # one writer


def test_a_spring_fits_json_and_dataset_read_back(tmp_path):
    import xarray as xr

    from qzs import fit_spring, spring_force, IsolatorParameters

    z = np.linspace(-0.1, 0.1, 31)
    fit = fit_spring(z, spring_force(z, IsolatorParameters())
                     + np.random.default_rng(1).normal(0, 0.3, z.size))
    record = json.loads(fit.save(tmp_path / "fit.json").read_text())
    assert record["intervals"]["plateau"] == list(fit.intervals["plateau"])
    assert record["confidence"] == fit.confidence == 0.95
    with xr.open_dataset(fit.save(tmp_path / "fit.nc"), engine="h5netcdf") as read:
        assert np.array_equal(read["force"].values, fit.force)
        assert read["displacement"].attrs["units"] == "m"
        assert read.attrs["plateau_lower"] == fit.intervals["plateau"][0]


def test_the_alias_s_warning_points_at_the_line_that_reads_it():
    """The warning names the caller's file and line (where the old spelling is to be
    changed), not qzs's."""
    fit = _Fit({"gain": (1.5, 2.5)})
    with pytest.warns(DeprecationWarning) as record:
        line = _line() + 1
        _ = fit.old  # the read is what warns
    assert (record[0].filename, record[0].lineno) == (__file__, line)


def _line():
    import inspect

    return inspect.currentframe().f_back.f_lineno
