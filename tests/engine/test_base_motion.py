"""The base-motion kernels (qzs.engine.base_motion): a sine's closed form, and the phase
rotated from a nearby time equal to the phase evaluated directly."""
import numpy as np
import pytest

from qzs import Chirp, Sine
from qzs.engine.base_motion import (advance_phase, base_motion, base_motion_near,
                                    base_motion_series, excitation_tuple)


def test_a_sine_without_fade_in_is_its_closed_form():
    amplitude, frequency, phase = 0.004, 3.0, 0.3
    t = np.linspace(0.0, 2.0, 801)
    y, yd, ydd = base_motion_series(Sine(amplitude=amplitude, frequency=frequency, phase=phase,
                                         fade_in=0.0), t)
    w = 2 * np.pi * frequency
    np.testing.assert_allclose(y, amplitude * np.sin(w * t + phase), rtol=0, atol=1e-17)
    np.testing.assert_allclose(yd, amplitude * w * np.cos(w * t + phase), rtol=0, atol=1e-15)
    np.testing.assert_allclose(ydd, -amplitude * w ** 2 * np.sin(w * t + phase), rtol=0,
                               atol=1e-13)


@pytest.mark.parametrize("excitation", [Sine(amplitude=0.01, frequency=7.0, fade_in=0.0),
                                        Chirp(), Chirp(method="logarithmic", f0=0.5)],
                         ids=["sine", "linear chirp", "log chirp"])
def test_the_phase_rotated_from_a_nearby_time_is_the_direct_one(excitation):
    """``base_motion_near`` rotates sin/cos from a phase up to 0.1 rad away (Taylor), and
    evaluates directly beyond: both agree with ``base_motion`` to rounding."""
    scalars, table = excitation.pack()
    E = excitation_tuple(scalars)
    for t0, dt in ((1.0, 1e-4), (3.7, 2e-3), (5.0, 0.05)):
        phase0, sin0, cos0 = advance_phase(t0, 0.0, 0.0, 1.0, E, True)
        assert (sin0, cos0) == (np.sin(phase0), np.cos(phase0))
        near = base_motion_near(t0 + dt, phase0, sin0, cos0, E, table)
        direct = base_motion(t0 + dt, E, table)
        np.testing.assert_allclose(near, direct, rtol=1e-13, atol=1e-13 * abs(direct[0]) + 1e-18)
        phase, s, c = advance_phase(t0 + dt, phase0, sin0, cos0, E, False)
        assert s == pytest.approx(np.sin(phase), abs=1e-15)
        assert c == pytest.approx(np.cos(phase), abs=1e-15)
