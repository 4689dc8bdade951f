"""The verdict's labels and the band transmissibility of a case."""
import math

import numpy as np
import pytest

from qzs.workflows.questions.common import Answer, CaseCurve, band_transmissibility


def test_an_answer_refuses_an_unknown_label():
    with pytest.raises(ValueError, match="label"):
        Answer("q", "s", "maybe", "a", "e")
    assert Answer("q", "s", "partly", "a", "e").to_dict()["label"] == "partly"


def test_the_band_transmissibility_is_the_rms_over_the_trusted_bins():
    f = np.array([0.5, 1.0, 2.0, 3.0, 4.0])
    t = np.array([9.0, 3.0, 4.0, 0.0, 9.0])
    trusted = np.array([True, True, True, False, True])
    curve = CaseCurve("c", f, t, trusted)
    assert band_transmissibility(curve, (1.0, 3.0)) == pytest.approx(math.sqrt((9 + 16) / 2))


@pytest.mark.parametrize("dt", [0.0, -1e-4, float("nan"), "1e-4", True])
def test_a_bad_step_is_refused_naming_dt(dt):
    from qzs.errors import ParameterError
    from qzs.workflows.questions.common import check_step

    with pytest.raises(ParameterError, match="`dt`"):
        check_step(dt)


def test_a_case_curve_s_files_hold_its_curve_metrics_and_statistics(tmp_path):
    """A written curve reads back bin for bin (trusted flag, magnitude), its metrics and
    statistics as attributes with units; the text names the trusted peak, not a higher
    untrusted bin."""
    import xarray as xr

    f = np.array([0.5, 1.0, 2.0, 3.0, 4.0])
    t = np.array([9.0, 3.0, 4.0, 0.5, 0.2])
    trusted = np.array([False, True, True, True, True])
    curve = CaseCurve("c", f, t, trusted, {"isolation_onset": 2.5, "resonance_peak": 4.0},
                      {}, {"motor_force_rms": 1.25, "stick_events": 3.0})
    assert "trusted peak |T| 4 (12 dB) at 2 Hz" in curve.summary()
    assert "motor_force_rms 1.25 N" in curve.summary()
    with xr.open_dataset(curve.save(tmp_path / "c.nc")) as back:
        np.testing.assert_array_equal(back["frequency"].values, f)
        np.testing.assert_array_equal(back["magnitude"].values[0], t)
        np.testing.assert_array_equal(back["trusted"].values[0], trusted.astype(np.int8))
        assert back.attrs["isolation_onset"] == 2.5 and back.attrs["isolation_onset_units"] == "Hz"
        assert back.attrs["motor_force_rms_units"] == "N"
        assert str(back["case"].values[0]) == "c"
