"""The real Fourier basis of harmonic balance: synthesis, analysis and d/dtau on one period.

Coefficients ``[c0, a1, b1, ..., aH, bH]`` stand for ``c0 + sum a_k cos(k tau) + b_k
sin(k tau)``, ``tau = w t``, sampled on ``N`` equidistant phases (``N > 2H``: the analysis
is exact). The alternating frequency-time method (Cameron & Griffin 1989) and Hill's matrix
both go through these matrices.

References
----------
Cameron, T. M., Griffin, J. H. (1989). An alternating frequency/time domain method for
calculating the steady-state response of nonlinear dynamic systems. J. Appl. Mech. 56, 149-154.
"""
from functools import lru_cache

import numpy as np

from qzs._validation import integer

__all__ = ["DEFAULT_HARMONICS"]

#: Harmonics of the relative position kept by default [-]: enough for the default
#: regularisation at the paper's 10 mm (the reversal of the friction force then takes about
#: 1/300 of a period at 5 Hz).
DEFAULT_HARMONICS = 40


class _Basis:
    """Real Fourier basis of ``H`` harmonics on ``N`` equidistant phases of one period.

    Coefficient layout ``[c0, a1, b1, ..., aH, bH]`` for ``c0 + sum a_k cos(k tau) + b_k
    sin(k tau)``, ``tau = w t``; ``synthesis`` maps coefficients to samples, ``analysis``
    back (exact for ``N > 2H``), ``derivative`` is d/dtau on coefficients.
    """

    def __init__(self, harmonics, time_points):
        self.harmonics = harmonics
        self.time_points = time_points
        self.size = 2 * harmonics + 1
        tau = 2 * np.pi * np.arange(time_points) / time_points
        k = np.arange(1, harmonics + 1)
        self.tau = tau
        self.synthesis = np.ones((time_points, self.size))
        self.synthesis[:, 1::2] = np.cos(np.outer(tau, k))
        self.synthesis[:, 2::2] = np.sin(np.outer(tau, k))
        self.analysis = self.synthesis.T * (2.0 / time_points)
        self.analysis[0] = 1.0 / time_points
        self.derivative = np.zeros((self.size, self.size))
        for h in k:
            self.derivative[2 * h - 1, 2 * h] = h
            self.derivative[2 * h, 2 * h - 1] = -h
        self.synthesis_derivative = self.synthesis @ self.derivative


@lru_cache(maxsize=16)
def _basis(harmonics, time_points):
    """The cached :class:`_Basis` of ``harmonics`` on ``time_points`` phases."""
    return _Basis(harmonics, time_points)


def _block(values):
    """Real (2x2 per harmonic) form of multiplying complex amplitudes by ``values``."""
    n = values.size
    matrix = np.zeros((2 * n, 2 * n))
    idx = np.arange(n)
    matrix[2 * idx, 2 * idx] = values.real
    matrix[2 * idx, 2 * idx + 1] = values.imag
    matrix[2 * idx + 1, 2 * idx] = -values.imag
    matrix[2 * idx + 1, 2 * idx + 1] = values.real
    return matrix


def _default_time_points(harmonics):
    """Phases per period for AFT and Hill: a power of two >= 8 H (aliasing of the
    regularised friction's steep tanh), at least 64."""
    return int(max(64, 2 ** int(np.ceil(np.log2(8 * harmonics)))))


def _check_settings(harmonics, time_points):
    """``(harmonics, time_points)`` checked; the phases default to
    :func:`_default_time_points`."""
    harmonics = integer("harmonics", harmonics, 1)
    if time_points is None:
        time_points = _default_time_points(harmonics)
    time_points = integer("time_points", time_points, 4 * harmonics + 2)
    return harmonics, time_points
