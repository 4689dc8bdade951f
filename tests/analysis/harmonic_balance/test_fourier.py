"""The real Fourier basis of harmonic balance (qzs.analysis.harmonic_balance.fourier) against
trigonometric sums written out: synthesis, analysis, d/dtau and complex multiplication."""
import numpy as np
import pytest

from qzs import ParameterError
from qzs.analysis.harmonic_balance.fourier import (DEFAULT_HARMONICS, _basis, _block,
                                                   _check_settings, _default_time_points)


def trigonometric_sum(q, tau):
    """``c0 + sum a_k cos(k tau) + b_k sin(k tau)`` and its derivative, term by term."""
    value = np.full(tau.shape, q[0])
    derivative = np.zeros(tau.shape)
    for k in range(1, (q.size - 1) // 2 + 1):
        a, b = q[2 * k - 1], q[2 * k]
        value += a * np.cos(k * tau) + b * np.sin(k * tau)
        derivative += k * (b * np.cos(k * tau) - a * np.sin(k * tau))
    return value, derivative


@pytest.mark.parametrize("harmonics, time_points", [(1, 6), (5, 22), (12, 64), (40, 512)])
def test_synthesis_analysis_and_derivative_are_the_trigonometric_sum(harmonics, time_points):
    basis = _basis(harmonics, time_points)
    q = np.random.default_rng(harmonics).normal(size=2 * harmonics + 1)
    value, derivative = trigonometric_sum(q, basis.tau)
    np.testing.assert_allclose(basis.synthesis @ q, value, atol=1e-12 * np.abs(q).sum())
    np.testing.assert_allclose(basis.synthesis_derivative @ q, derivative,
                               atol=1e-12 * harmonics * np.abs(q).sum())
    # analysis inverts synthesis (N > 2H phases resolve every harmonic)
    np.testing.assert_allclose(basis.analysis @ (basis.synthesis @ q), q, atol=1e-13)
    assert np.allclose(basis.derivative @ basis.derivative @ q,
                       -np.repeat(np.arange(harmonics + 1) ** 2, 2)[1:] * q)


def test_block_is_multiplying_complex_amplitudes():
    """``a cos + b sin`` is ``Re[(a - i b) e^{i tau}]``: the 2x2 blocks multiply ``a - i b``."""
    rng = np.random.default_rng(3)
    values = rng.normal(size=4) + 1j * rng.normal(size=4)
    q = rng.normal(size=8)
    amplitudes = q[0::2] - 1j * q[1::2]
    out = _block(values) @ q
    np.testing.assert_allclose(out[0::2] - 1j * out[1::2], values * amplitudes, rtol=1e-14)


def test_the_basis_is_cached():
    assert _basis(7, 64) is _basis(7, 64)


@pytest.mark.parametrize("harmonics", [1, 8, 9, 40, 100])
def test_default_phases_are_a_power_of_two_of_at_least_8_per_harmonic(harmonics):
    points = _default_time_points(harmonics)
    assert points >= max(64, 8 * harmonics) and points & (points - 1) == 0
    assert points < 2 * max(64, 8 * harmonics)
    assert _check_settings(harmonics, None) == (harmonics, points)
    assert DEFAULT_HARMONICS >= 1


@pytest.mark.parametrize("harmonics, time_points, name", [
    (0, None, "harmonics"), (2.5, None, "harmonics"), (10, 41, "time_points"),
])
def test_too_few_harmonics_or_phases_are_refused(harmonics, time_points, name):
    with pytest.raises(ParameterError, match=name):
        _check_settings(harmonics, time_points)
    assert _check_settings(10, 42) == (10, 42)  # 4H + 2: products of two sums alias no more
