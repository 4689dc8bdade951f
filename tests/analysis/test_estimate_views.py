"""A transmissibility estimate's summary, figure and files (qzs.analysis.estimate_views)."""
import matplotlib.pyplot as plt
import numpy as np
import pytest

import qzs
from qzs.analysis.estimate_views import ESTIMATOR_LABELS, estimate_text
from qzs.analysis.spectral import TransmissibilityEstimate


def _estimate(trusted, magnitude=None, highpass_corner=None):
    frequency = np.linspace(0.0, 10.0, 11)
    magnitude = np.linspace(0.5, 2.0, 11) if magnitude is None else magnitude
    return TransmissibilityEstimate(
        frequency=frequency, magnitude=magnitude, phase=np.zeros(11), coherence=np.ones(11),
        base_share=np.full(11, 0.1), trusted=np.asarray(trusted, bool), estimator="h1",
        fft_length=20, n_averages=7, sample_rate=20.0, highpass_corner=highpass_corner)


def test_the_summary_names_the_trusted_peak_not_an_untrusted_larger_one():
    magnitude = np.array([9.0, 1.0, 1.5, 3.0, 2.0, 1.0, 0.5, 0.4, 0.3, 0.2, 8.0])
    trusted = [False] + [True] * 9 + [False]  # DC and the last bin untrusted, and larger
    text = estimate_text(_estimate(trusted, magnitude))
    assert "peak |T| 3 (9.54 dB) at 3 Hz" in text
    assert "9 bins, 1-9 Hz" in text and "20 samples per segment, 7 averages at 20 Hz" in text


def test_no_trusted_bin_says_so_and_the_high_pass_is_named():
    text = estimate_text(_estimate([False] * 11, highpass_corner=1.0))
    assert "no trusted bin" in text and "peak" not in text.split("\n")[1].replace("no peak", "")
    assert "untrusted below 1.5 Hz (high-pass at 1 Hz)" in text


def test_the_figure_labels_the_estimator_and_units(tmp_path):
    estimate = _estimate([False] + [True] * 10)
    figure = estimate.plot(tmp_path / "t.png", frequency_scale="linear")
    try:
        labels = [ax.get_ylabel() for ax in figure.axes]
        assert any(ESTIMATOR_LABELS["h1"] in label and "[dB]" in label for label in labels)
        assert (tmp_path / "t.png").exists()
    finally:
        plt.close(figure)


def test_save_writes_the_dataset_and_refuses_a_record(tmp_path):
    import xarray as xr

    estimate = _estimate([False] + [True] * 10)
    with xr.open_dataset(estimate.save(tmp_path / "t.nc"), engine="h5netcdf") as read:
        assert np.array_equal(read["magnitude"].values, estimate.magnitude)
    with pytest.raises(qzs.errors.OutputPathError, match=r"'\.json'.*\.nc, \.csv or \.mat"):
        estimate.save(tmp_path / "t.json")
