"""The transmissibility cost the damping gain minimises: simulated, and of the linear loop."""
import math

import numpy as np

from qzs.analysis import control_design as cd
from qzs.analysis.damping import band_rms, damping_change
from qzs.analysis.spectral import band_mask, transmissibility, transmissibility_batch
from qzs.engine.batch import simulate_batch
from qzs.workflows.design.settings import FFT_LENGTH, TRUSTED_SHARE_MIN

__all__ = ["transmissibility_cost"]


def transmissibility_cost(base_acceleration, payload_acceleration, sample_rate, *, band,
                          cost="rms", fft_length=FFT_LENGTH[True]):
    """The design's transmissibility cost of one run, from its trusted bins.

    Parameters
    ----------
    base_acceleration : array_like
        Base acceleration samples [m/s^2].
    payload_acceleration : array_like
        Payload acceleration samples [m/s^2].
    sample_rate : float
        Their rate [Hz].
    band : tuple of float
        Band of the cost [Hz, Hz].
    cost : {"rms", "peak"}
        RMS of the amplitude ratio over the trusted bins of the band
        (:func:`qzs.analysis.damping.band_rms`, the band RMS ``qzs paper`` uses too), or its
        largest value.
    fft_length : int
        Welch segment length [samples].

    Returns
    -------
    value : float
        The cost [-]; NaN when fewer than half the band's bins are trusted.
    share : float
        Share of the band's bins that are trusted [-].
    estimate : TransmissibilityEstimate
        The curve it was read from.
    """
    estimate = transmissibility(base_acceleration, payload_acceleration, sample_rate,
                                fft_length=fft_length)
    return _cost_of(estimate, band, cost)


def _cost_of(estimate, band, cost):
    """:func:`transmissibility_cost` of an estimate: ``(value, share, estimate)``."""
    inside = band_mask(estimate.frequency, *band)
    keep = band_mask(estimate.frequency, *band, trusted=estimate.trusted)
    share = float(keep.sum() / max(inside.sum(), 1))
    if share < TRUSTED_SHARE_MIN:
        return math.nan, share, estimate
    value = (band_rms(estimate.frequency, estimate.magnitude, band, trusted=estimate.trusted)
             if cost == "rms" else float(np.max(estimate.magnitude[keep])))
    return value, share, estimate


def _damping_metrics(reference, damped, band, defined=True):
    """Both damping metrics of ``damped`` against ``reference`` (estimates), as row entries.

    :func:`qzs.analysis.damping.damping_change`, the definitions ``qzs paper`` decides the
    damping claim with; NaN when an estimate is missing or ``defined`` is False (a cost
    undefined for too few trusted bins).
    """
    if reference is None or damped is None or not defined:
        return {"largest_reduction_db": math.nan, "band_rms_change_db": math.nan}
    change = damping_change(reference.frequency, reference.magnitude, damped.magnitude,
                            band=band, reference_trusted=reference.trusted,
                            damped_trusted=damped.trusted)
    return {"largest_reduction_db": change.largest_reduction_db,
            "band_rms_change_db": change.band_rms_change_db}


def _linear_cost(frequency, isolator, controller, settings, *, rate=None, delay=None):
    t = cd.sampled_transmissibility(frequency, isolator, controller,
                                    rate=settings.controller_rate if rate is None else rate,
                                    delay=settings.delay if delay is None else delay)
    return float(np.sqrt(np.mean(t ** 2))) if settings.cost == "rms" else float(np.max(t))


def _band_grid(band):
    return np.linspace(max(band[0], 1e-3), band[1], 400)


def _costs(pairs, settings):
    """Simulated costs of ``(isolator, controller)`` pairs, one lockstep batch."""
    batch = simulate_batch(pairs, settings.excitation, duration=settings.duration,
                           dt=settings.dt, sample_rate=settings.sample_rate,
                           workers=settings.workers)
    ran = np.flatnonzero(batch.status == 0)  # their estimates from one batched Welch
    estimates = dict(zip(ran.tolist(), transmissibility_batch(
        batch.channels["base_acceleration"][ran], batch.channels["payload_acceleration"][ran],
        settings.sample_rate, fft_length=settings.fft_length)))
    out = []
    for i in range(len(pairs)):
        if batch.status[i]:
            out.append((math.nan, 0.0, None, batch.messages[i], math.nan))
            continue
        value, share, estimate = _cost_of(estimates[i], settings.band, settings.cost)
        reason = "" if math.isfinite(value) else (
            f"only {100 * share:.0f} % of the band's bins are trusted (coherence below the "
            "threshold: the payload barely responds to the base there)")
        out.append((value, share, estimate, reason, float(batch.stats["motor_force_rms"][i])))
    return out
