"""A case's spectral reduction: its transmissibility curve, band means and metrics.

:func:`reduce_case` is what :func:`qzs.workflows.sweeps.batch.run_batch` keeps of each
case's base and payload signals (``[outputs]`` of the sweep file); :func:`estimate_cases`
gives it the transmissibility of a batch's cases from one batched Welch estimate.
"""
import numpy as np

from qzs.analysis.spectral import (band_mask, transmissibility, transmissibility_batch,
                                   transmissibility_metrics)
from qzs.errors import DataError, ParameterError

__all__ = ["estimate_cases", "reduce_case"]


def estimate_cases(definition, base, payload):
    """The transmissibility of each case of a batch, as :func:`reduce_case` estimates it.

    One batched Welch estimate of all the cases
    (:func:`qzs.analysis.spectral.transmissibility_batch`, each case the same bits as its
    own); if it is refused (a case's signals cannot be analysed), case by case, so that
    only those cases fail.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep (its ``[analysis]``).
    base, payload : ndarray, shape (n_cases, n_samples)
        The cases' base and payload accelerations at ``[analysis] sample_rate`` [m/s^2].

    Returns
    -------
    list
        Per case, its :class:`~qzs.analysis.spectral.TransmissibilityEstimate`, or the
        :class:`~qzs.errors.DataError` or :class:`~qzs.errors.ParameterError` its own
        estimate raised.
    """
    a = definition.analysis
    options = dict(fft_length=a["fft_length"], overlap=a["overlap"])
    try:
        return list(transmissibility_batch(base, payload, a["sample_rate"], **options))
    except (DataError, ParameterError):
        pass
    estimates = []
    for case_base, case_payload in zip(base, payload):
        try:
            estimates.append(transmissibility(case_base, case_payload, a["sample_rate"],
                                              **options))
        except (DataError, ParameterError) as error:
            estimates.append(error)
    return estimates


def reduce_case(definition, base, payload, arrays, i, estimate=None):
    """Reduce one case's signals to the outputs the sweep keeps, into row ``i`` of ``arrays``.

    The transmissibility from ``base`` to ``payload`` (Welch, the sweep's ``[analysis]``),
    its curve and coherence over the band, the mean and RMS transmissibility over each
    of ``[outputs]``'s bands and its metrics (trusted bins only; NaN where a band holds
    none) and the number of averages.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    base, payload : ndarray, shape (n_samples,)
        The case's base and payload accelerations at ``[analysis] sample_rate`` [m/s^2].
    arrays : dict of str to ndarray
        The batch's arrays, first axis the cases (``n_averages``, ``transmissibility``,
        ``coherence``, ``mean_transmissibility_<band>``, ``rms_transmissibility_<band>``
        and the metrics the sweep keeps), written in place.
    i : int
        The case's row.
    estimate : TransmissibilityEstimate, optional
        The case's transmissibility if already estimated (:func:`estimate_cases`; then
        ``base`` and ``payload`` are not read); default estimated here.

    Raises
    ------
    DataError, ParameterError
        The signals cannot be analysed.
    """
    a, out = definition.analysis, definition.outputs
    if estimate is None:
        estimate = transmissibility(base, payload, a["sample_rate"], fft_length=a["fft_length"],
                                    overlap=a["overlap"])
    f, magnitude = estimate.frequency, estimate.magnitude
    low, high = a["band"]
    keep = band_mask(f, low, high)
    arrays["n_averages"][i] = estimate.n_averages
    if out["transmissibility"]:
        arrays["transmissibility"][i] = magnitude[keep]
    if out["coherence"]:
        arrays["coherence"][i] = estimate.coherence[keep]
    for label, (lo, hi) in out["bands"].items():  # trusted bins only; NaN if none
        inside = band_mask(f, lo, hi, trusted=estimate.trusted)
        arrays[f"mean_transmissibility_{label}"][i] = (magnitude[inside].mean() if inside.any()
                                                       else np.nan)
    for label, (lo, hi) in out["rms_bands"].items():
        inside = band_mask(f, lo, hi, trusted=estimate.trusted)
        arrays[f"rms_transmissibility_{label}"][i] = (
            np.sqrt(np.mean(magnitude[inside] ** 2)) if inside.any() else np.nan)
    if out["metrics"]:
        metrics = transmissibility_metrics(f[keep], magnitude[keep],
                                           trusted=estimate.trusted[keep],
                                           at_frequencies=a["at_frequencies"]).to_dict()
        for name in out["metrics"]:
            arrays[name][i] = metrics[name]

