"""The plan of the six-axis runs: where a chirp's trusted band starts."""
import pytest

from qzs.workflows.hexapod.transmissibility.plan import sweep_trusted_from


@pytest.mark.parametrize("f0, f1, duration, fft_length, rate", [
    (0.0, 20.0, 60.0, 16384, 1000.0), (2.0, 12.0, 200.0, 32768, 1000.0),
    (0.5, 5.0, 30.0, 4096, 500.0)])
def test_the_trusted_band_starts_where_the_chirp_is_a_quarter_segment_in(f0, f1, duration,
                                                                         fft_length, rate):
    """A linear chirp is at f0 + (f1 - f0) t / T after t [s]; a quarter segment is
    fft_length / (4 rate) [s]: bins below that frequency sit under the first segment's
    rising taper alone."""
    quarter = fft_length / rate / 4
    assert sweep_trusted_from(f0, f1, duration, fft_length, rate) == pytest.approx(
        f0 + (f1 - f0) * quarter / duration)
