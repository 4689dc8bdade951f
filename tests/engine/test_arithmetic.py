"""Kernel arithmetic: exp in plain arithmetic, tanh from it, and a single-rounding fma."""
import numpy as np
from numba import njit

from qzs.engine import arithmetic as K


@njit(cache=True)
def _exp_all(x, out):
    for i in range(x.size):
        out[i] = K.exp(x[i])


@njit(cache=True)
def _tanh_all(x, out):
    for i in range(x.size):
        out[i] = K.tanh(x[i])


@njit(cache=True)
def _fma(a, b, c):
    return K.fma(a, b, c)


def test_exp_is_within_two_ulp_of_libm():
    x = np.concatenate([np.linspace(-700.0, 700.0, 400_001), np.linspace(-1.0, 1.0, 100_001),
                        [0.0, 1e-300, -1e-300, 0.5 * np.log(2.0)]])
    out = np.empty_like(x)
    _exp_all(x, out)
    reference = np.exp(x)
    assert np.max(np.abs(out - reference) / reference) <= 2.0 * np.finfo(float).eps
    assert out[-4] == 1.0


def test_exp_clamps_far_arguments_instead_of_overflowing():
    out = np.empty(3)
    _exp_all(np.array([-1e4, 1e4, -np.inf]), out)
    assert 0.0 < out[0] < 1e-300 and out[2] == out[0]  # stands in for 0
    assert np.isfinite(out[1]) and out[1] > 1e300


def test_tanh_matches_numpy_and_saturates_exactly():
    x = np.concatenate([np.linspace(-25.0, 25.0, 200_001), [0.0, 20.0, -20.0, 40.0]])
    out = np.empty_like(x)
    _tanh_all(x, out)
    assert np.max(np.abs(out - np.tanh(x))) <= 3e-16
    assert out[-2] == -1.0 and out[-1] == 1.0 and out[-4] == 0.0


def test_fma_rounds_once():
    # (1 + 2^-52)(1 - 2^-52) - 1 = -2^-104 exactly; rounding the product first gives 0
    a, b = 1.0 + 2.0 ** -52, 1.0 - 2.0 ** -52
    assert a * b - 1.0 == 0.0
    assert _fma(a, b, -1.0) == -2.0 ** -104
