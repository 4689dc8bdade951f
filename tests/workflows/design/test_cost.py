"""The transmissibility cost against signals whose amplitude ratio is known."""
import math

import numpy as np
import pytest

from qzs import DataWarning
from qzs.workflows.design.cost import transmissibility_cost


def white(seed, count):
    return np.random.default_rng(seed).standard_normal(count)


def test_a_payload_that_is_half_the_base_costs_one_half_rms_and_peak():
    base = white(1, 40_000)
    for cost in ("rms", "peak"):
        value, share, estimate = transmissibility_cost(base, 0.5 * base, 200.0, band=(1.0, 20.0),
                                                       cost=cost, fft_length=2048)
        assert value == pytest.approx(0.5, rel=1e-9) and share == 1.0
        assert estimate.magnitude.shape == estimate.frequency.shape


def test_the_peak_is_the_largest_and_the_rms_lies_between_the_bins_extremes():
    base = white(2, 40_000)
    payload = np.convolve(base, [0.3, 0.5, 0.2], mode="same")  # a smooth low-pass
    rms, _, estimate = transmissibility_cost(base, payload, 200.0, band=(1.0, 20.0))
    peak, _, _ = transmissibility_cost(base, payload, 200.0, band=(1.0, 20.0), cost="peak")
    inside = (estimate.frequency >= 1.0) & (estimate.frequency <= 20.0) & estimate.trusted
    t = estimate.magnitude[inside]
    assert peak == t.max() and t.min() <= rms <= peak
    assert rms == pytest.approx(np.sqrt(np.mean(t ** 2)), rel=1e-12)


def test_an_unrelated_payload_has_too_few_trusted_bins_and_no_cost():
    with pytest.warns(DataWarning, match="no trusted bin"):
        value, share, _ = transmissibility_cost(white(3, 40_000), white(4, 40_000), 200.0,
                                                band=(1.0, 20.0))
    assert math.isnan(value) and share < 0.5


def test_a_batch_costs_each_design_what_its_own_run_costs():
    """_costs estimates a batch's cases in one batched Welch: each value, share and curve the
    same bits as transmissibility_cost of that case's own run (qzs.simulate)."""
    from types import SimpleNamespace

    import qzs
    from qzs.workflows.design.cost import _costs

    settings = SimpleNamespace(excitation=qzs.Chirp(duration=20.0), duration=None, dt=1e-3,
                               sample_rate=200.0, workers=1, band=(1.0, 15.0), cost="rms",
                               fft_length=1024)
    pairs = [(qzs.IsolatorParameters(stiction_force=force),
              qzs.ControllerParameters(pi_kp=gain, damping_gain=damping))
             for force, gain, damping in ((6.0, 20.0, 0.0), (10.0, 200.0, 40.0),
                                          (14.0, 800.0, 90.0))]
    for (value, share, estimate, reason, _), pair in zip(_costs(pairs, settings), pairs):
        run = qzs.simulate(settings.excitation, *pair, dt=settings.dt,
                           sample_rate=settings.sample_rate)
        alone = transmissibility_cost(run.base_acceleration, run.payload_acceleration,
                                      settings.sample_rate, band=settings.band,
                                      fft_length=settings.fft_length)
        assert (value, share) == alone[:2] or (math.isnan(value) and math.isnan(alone[0]))
        assert np.array_equal(estimate.magnitude, alone[2].magnitude, equal_nan=True)
        assert np.array_equal(estimate.trusted, alone[2].trusted)
