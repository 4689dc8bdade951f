"""One run's column: the Welch estimate of every platform axis per the excited base axis."""
import numpy as np
import pytest

from qzs.workflows.hexapod.transmissibility.runs import _estimate


def test_a_platform_moving_half_the_base_gives_half_on_every_trusted_bin():
    """H1 of y = 0.5 x is exactly 0.5 (phase 0) wherever the base has power; other platform
    axes, at rest, give 0."""
    rng = np.random.default_rng(3)
    n, rate = 2 ** 15, 1000.0
    base = np.zeros((n, 6))
    base[:, 2] = rng.normal(size=n)
    twist = np.zeros((n, 6))
    twist[:, 2] = 0.5 * base[:, 2]
    twist[:, 0] = 1e-3 * rng.normal(size=n)  # uncorrelated with the base
    task = dict(sample_rate=rate, fft_length=4096, overlap=0.5, estimator="h1",
                coherence_min=0.9, base_share_min=1e-10)
    estimates = _estimate({"base_velocity": base, "platform_twist": twist}, "z", task)
    z = estimates[2]
    assert np.any(z.trusted)
    np.testing.assert_allclose(z.magnitude[z.trusted], 0.5, rtol=1e-12)
    np.testing.assert_allclose(z.phase[z.trusted], 0.0, atol=1e-12)
    assert not np.any(estimates[0].trusted)  # no coherence with the base
