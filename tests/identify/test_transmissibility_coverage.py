"""The transmissibility fit's intervals for a stick-slip parameter hold the truth.

Synthetic experiments with known truth: the model's own curve (random stiction and
damping) with 3 % noise, stiction fitted. The local Student-t interval of the Jacobian
held the truth in only 1 of these 4 (10 of 15 over a larger set, 18 of 30 when damping
is fitted too); the interval that carries the stick-slip jumps' share holds it in all
(15 of 15; 28 of 30), and is still informative.
"""
import warnings

import numpy as np
import pytest

import qzs
from qzs.analysis.spectral import transmissibility
from qzs.identify import fit_transmissibility

CHIRP = qzs.Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=30.0)
RATE = 100.0
#: Experiments of the study in docs/model.md §12 (truths drawn with seed 12345, noise
#: with seed k) where the local interval missed the truth, and one where it held it.
EXPERIMENTS = (3, 4, 6, 11)


def experiment(k):
    rng0 = np.random.default_rng(12345)
    damping, stiction = [(float(rng0.uniform(40, 120)), float(rng0.uniform(4, 9)))
                         for _ in range(k + 1)][k]
    truth = qzs.IsolatorParameters(viscous_damping=damping, stiction_force=stiction)
    run = qzs.simulate(CHIRP, truth, dt=5e-4, sample_rate=RATE)
    estimate = transmissibility(run.base_acceleration, run.payload_acceleration, RATE,
                                fft_length=1024)
    noise = np.exp(np.random.default_rng(k).normal(0.0, 0.03, estimate.frequency.size))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = fit_transmissibility(estimate.frequency, estimate.magnitude * noise,
                                   ("stiction_force",), excitation=CHIRP,
                                   isolator=qzs.IsolatorParameters(viscous_damping=damping))
    return stiction, fit


@pytest.fixture(scope="module")
def fits():
    return [experiment(k) for k in EXPERIMENTS]


def test_intervals_hold_the_truth(fits):
    held = [low <= truth <= high for truth, fit in fits
            for low, high in [fit.intervals["stiction_force"]]]
    assert sum(held) >= len(fits) - 1, [(truth, fit.parameters, dict(fit.intervals))
                                        for truth, fit in fits]


def test_intervals_are_informative(fits):
    for truth, fit in fits:
        low, high = fit.intervals["stiction_force"]
        value = fit.parameters["stiction_force"]
        assert low < value < high
        assert (high - low) / 2 < 0.15 * value, (truth, value, (low, high))
        assert abs(value / truth - 1) < 0.1
