"""What the step searches share (qzs.engine.accuracy): the band an error is measured over and
the one tolerance given, checked with the fix named."""
import pytest

from qzs.engine.accuracy import check_band as error_band
from qzs.engine.accuracy import frequency_range as excitation_range
from qzs.errors import ParameterError
from qzs.model.excitation import Chirp, Sine


def test_the_band_is_the_excitations_from_one_hertz_or_a_band_inside_it():
    chirp = Chirp(f0=0.0, f1=20.0, duration=10.0)
    assert excitation_range(chirp, 1000.0) == (0.0, 20.0)
    assert excitation_range(Sine(frequency=3.0), 1000.0) == (3.0, 3.0)
    assert error_band(None, chirp, 1000.0) == (1.0, 20.0)  # trust is thin below 1 Hz
    assert error_band((2, 5), chirp, 1000.0) == (2.0, 5.0)
    with pytest.raises(ParameterError, match="outside the excitation's frequencies"):
        error_band((25.0, 30.0), chirp, 1000.0)
    with pytest.raises(ParameterError, match="above the output's Nyquist frequency 10 Hz"):
        error_band((5.0, 15.0), chirp, 20.0)
    with pytest.raises(ParameterError, match="0 <= low <= high"):
        error_band((5.0, 2.0), chirp, 1000.0)


