"""The two damping metrics against closed forms on synthetic curves."""
import math

import numpy as np
import pytest

from qzs.analysis.damping import band_rms, damping_change
from qzs.errors import ParameterError

#: A uniform grid of bins, 0.1 Hz apart [Hz].
FREQUENCY = np.arange(0.0, 30.0, 0.1)


def test_band_rms_of_a_square_root_curve_is_the_closed_form():
    """T^2 = f/F on bins f_i = i*df, i = 1..N: mean(T^2) = (N + 1) df / (2 F)."""
    F, band = 20.0, (0.1, 20.0)
    magnitude = np.sqrt(FREQUENCY / F)
    inside = (FREQUENCY >= band[0] - 1e-12) & (FREQUENCY <= band[1] + 1e-12)
    n = int(inside.sum())
    df = 0.1
    expected = math.sqrt((n + 1) * df / (2 * F))
    assert band_rms(FREQUENCY, magnitude, band) == pytest.approx(expected, rel=1e-9)


def test_untrusted_bins_enter_neither_metric():
    reference = np.ones_like(FREQUENCY)
    damped = np.full_like(FREQUENCY, 0.5)       # -6.02 dB everywhere...
    damped[50] = 1e-6                           # ...but a spike down at 5 Hz, untrusted
    trusted = np.ones(FREQUENCY.shape, bool)
    trusted[50] = False
    change = damping_change(FREQUENCY, reference, damped, band=(1.0, 20.0),
                            damped_trusted=trusted)
    assert change.largest_reduction_db == pytest.approx(20 * math.log10(2), rel=1e-12)
    assert change.band_rms_change_db == pytest.approx(-20 * math.log10(2), rel=1e-12)


def test_a_narrow_dip_is_a_large_per_bin_reduction_but_a_small_band_change():
    """Halving T in one bin of N: the RMS falls to sqrt((N - 1 + 1/4)/N) of its value."""
    band = (1.0, 20.0)
    reference = np.ones_like(FREQUENCY)
    damped = reference.copy()
    damped[100] = 0.5                          # 10 Hz
    change = damping_change(FREQUENCY, reference, damped, band=band)
    n = change.bins
    assert change.largest_reduction_db == pytest.approx(20 * math.log10(2), rel=1e-12)
    assert change.largest_reduction_frequency == pytest.approx(10.0)
    assert change.band_rms_change_db == pytest.approx(
        10 * math.log10((n - 0.75) / n), rel=1e-9)
    assert change.reference_rms == pytest.approx(1.0)


def test_no_trusted_bin_gives_nan_not_an_error():
    change = damping_change(FREQUENCY, np.ones_like(FREQUENCY), np.ones_like(FREQUENCY),
                            band=(1.0, 2.0), reference_trusted=np.zeros(FREQUENCY.shape, bool))
    assert math.isnan(change.largest_reduction_db) and math.isnan(change.band_rms_change_db)
    assert change.bins == 0


def test_bad_inputs_name_the_argument():
    with pytest.raises(ParameterError, match="`reference`"):
        damping_change(FREQUENCY, np.ones(3), np.ones(3), band=(1.0, 2.0))
    with pytest.raises(ParameterError, match="`band`"):
        band_rms(FREQUENCY, np.ones_like(FREQUENCY), (5.0, 1.0))
    with pytest.raises(ParameterError, match="`damped`"):
        damping_change(FREQUENCY, np.ones_like(FREQUENCY), np.ones(3), band=(1.0, 2.0))


def test_the_band_change_is_read_on_the_bins_both_curves_trust():
    """A high reference bin the damped curve does not trust counts in neither RMS: the band
    cannot fall more than the largest per-bin reduction."""
    reference = np.ones_like(FREQUENCY)
    reference[100] = 30.0                      # a tall peak at 10 Hz...
    damped = np.full_like(FREQUENCY, 0.9)
    trusted = np.ones(FREQUENCY.shape, bool)
    trusted[100] = False                       # ...that the damped curve does not trust
    change = damping_change(FREQUENCY, reference, damped, band=(1.0, 20.0),
                            damped_trusted=trusted)
    assert change.largest_reduction_db == pytest.approx(-20 * math.log10(0.9), rel=1e-12)
    assert change.band_rms_change_db == pytest.approx(20 * math.log10(0.9), rel=1e-12)
    assert change.reference_rms == pytest.approx(1.0)
