"""Floquet exponents of a periodic solution by Hill's method, and the stability they decide.

References
----------
Lazarus, A., Thomas, O. (2010). A harmonic-based method for computing the stability of periodic
solutions of dynamical systems. C. R. Mécanique 338, 510-517 (Hill's method, eigenvalue choice).
"""
import numpy as np

from qzs.analysis.harmonic_balance.blas import _single_threaded_blas
from qzs.analysis.harmonic_balance.fourier import _basis, _check_settings

__all__ = ["floquet_exponents"]

#: Real parts of Floquet exponents below ``-STABILITY_MARGIN * omega`` count as negative [-].
STABILITY_MARGIN = 1e-7


def floquet_exponents(solution, *, time_points=None):
    """Floquet exponents of a periodic solution by Hill's method [1/s].

    The linearisation ``dx/dt = J(t) x`` about the solution, with ``x = e^{lambda t} p(t)``
    and ``p`` expanded in the solution's harmonics, gives the eigenproblem of the Hill
    matrix ``[J_{r-c} - i r w delta_rc]``; of its eigenvalues, the ``n`` whose
    eigenvectors weigh most on the central harmonic are the exponents (Lazarus & Thomas
    2010), ``n`` the states of :attr:`SmoothModel.states`.

    Parameters
    ----------
    solution : HarmonicBalanceSolution
        The periodic solution.
    time_points : int, optional
        Phases per period to expand ``J(t)`` [-]; default as for the solution.

    Returns
    -------
    ndarray of complex, shape (n,)
        The exponents [1/s], largest real part first; the Floquet multipliers are
        ``exp(exponent / frequency)``.
    """
    model = solution.model
    harmonics = solution.harmonics
    _, time_points = _check_settings(harmonics, time_points)
    series = solution.time_series(points=time_points)
    omega = 2 * np.pi * solution.frequency
    spring_slope = model.spring(series["relative_position"])[1]
    friction_slope = model.friction(series["relative_velocity"])[1]
    states = model.states
    n = len(states)
    index = {name: i for i, name in enumerate(states)}
    jac = np.zeros((n, n, time_points))
    m = model.mass
    jac[index["z"], index["v"]] = 1.0
    jac[index["v"], index["z"]] = (spring_slope - model.pi_kp) / m
    jac[index["v"], index["v"]] = (friction_slope - model.damping_gain) / m
    if "w" in index:
        jac[index["v"], index["w"]] = model.damping_gain / m
        jac[index["w"], index["v"]] = model.highpass_omega
        jac[index["w"], index["w"]] = -model.highpass_omega
    if "I" in index:
        jac[index["v"], index["I"]] = model.pi_ki / m
        jac[index["I"], index["z"]] = -1.0
    # Hill's matrix in the real Fourier basis (the same eigenvalues as the complex form
    # [J_{r-c} - i r w delta_rc], at a quarter of the cost): the Galerkin projection of
    # multiplying by J(t), minus w d/dtau.
    basis = _basis(harmonics, time_points)
    size = basis.size
    hill = np.zeros((n * size, n * size))
    for i in range(n):
        for j in range(n):
            if np.any(jac[i, j]):
                hill[i * size:(i + 1) * size, j * size:(j + 1) * size] = (
                    basis.analysis @ (jac[i, j][:, None] * basis.synthesis))
        hill[i * size:(i + 1) * size, i * size:(i + 1) * size] -= omega * basis.derivative
    with _single_threaded_blas():
        values, vectors = np.linalg.eig(hill)
    # weight of each eigenvector on the central harmonic of the complex form: a cos + b sin
    # is (a - ib)/2 e^{ik tau} + (a + ib)/2 e^{-ik tau}
    vectors = vectors.reshape(n, size, -1)
    centre = np.sum(np.abs(vectors[:, 0]) ** 2, axis=0)
    cos, sin = vectors[:, 1::2], vectors[:, 2::2]
    total = centre + 0.25 * np.sum(np.abs(cos - 1j * sin) ** 2 + np.abs(cos + 1j * sin) ** 2,
                                   axis=(0, 1))
    weight = centre / total
    # Each exponent appears as a family lambda + i k w; the member in the strip
    # |Im| <= w/2 is its representative. Of the candidates there, the n whose eigenvectors
    # weigh most on the central harmonic (the least affected by truncation) are taken; the
    # weight alone can pick two members of one real family and miss another exponent.
    in_strip = np.abs(values.imag) <= 0.5 * omega * (1 + 1e-9)
    order = np.argsort(-(weight + 2.0 * in_strip))
    chosen = values[order[:n]]
    return chosen[np.argsort(-chosen.real)]


def _is_stable(exponents, omega):
    """All ``exponents`` [1/s] have real parts below ``STABILITY_MARGIN * omega`` [rad/s]."""
    return bool(np.max(exponents.real) < STABILITY_MARGIN * omega)
