"""What the step searches share (qzs.engine.accuracy): the band an error is measured over and
the one tolerance given, checked with the fix named."""
import pytest

from qzs.engine.accuracy import check_band as error_band
from qzs.engine.accuracy import frequency_range as excitation_range
from qzs.engine.step_search import tolerance_measure
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


def test_exactly_one_tolerance_is_given():
    assert tolerance_measure(0.01, None) == ("transmissibility_db", 0.01)
    assert tolerance_measure(None, 1e-6) == ("state_m", 1e-6)
    with pytest.raises(ParameterError, match="got tolerance_db and tolerance_state"):
        tolerance_measure(0.01, 1e-6)
    with pytest.raises(ParameterError, match="got neither"):
        tolerance_measure(None, None)
    with pytest.raises(ParameterError, match="tolerance_db"):
        tolerance_measure(-1.0, None)
