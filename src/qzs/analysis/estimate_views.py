"""What a transmissibility estimate shows: its summary, its figure, its files (issue 42).

:class:`EstimateProtocol` gives :class:`~qzs.analysis.spectral.TransmissibilityEstimate` the
result protocol by delegation: :func:`estimate_text` for ``summary``,
:func:`qzs.viz.transmissibility.plot_transmissibility` for ``plot``,
:func:`qzs.iotools.result_files.save_by_extension` of its ``to_xarray`` for ``save``.
"""
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._format import decibels
from qzs.iotools.result_files import DATASET_SUFFIXES, save_by_extension, save_doc

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["EstimateProtocol", "estimate_text", "ESTIMATOR_LABELS"]

#: How each estimator's magnitude is said on a figure's axis.
ESTIMATOR_LABELS = {"psd_ratio": "sqrt(S_payload/S_base)", "h1": "H1 = S_bp/S_bb",
                    "h2": "H2 = S_pp/S_pb"}


def estimate_text(estimate: Any) -> str:
    """A transmissibility estimate as text: its bins, its settings, its trusted peak.

    Parameters
    ----------
    estimate : TransmissibilityEstimate
        The estimate.

    Returns
    -------
    str
    """
    f = estimate.frequency
    lines = [f"transmissibility estimate ({estimate.estimator}): {f.size} bins "
             f"{f[0]:g}-{f[-1]:g} Hz; {estimate.fft_length} samples per segment, "
             f"{estimate.n_averages} averages at {estimate.sample_rate:g} Hz"]
    trusted = np.flatnonzero(estimate.trusted)
    if trusted.size == 0:
        lines.append("  no trusted bin (coherence, base power or high-pass): no peak")
    else:
        k = trusted[np.argmax(estimate.magnitude[trusted])]
        peak = estimate.magnitude[k]
        lines.append(f"  trusted: {trusted.size} bins, {f[trusted[0]]:.4g}-{f[trusted[-1]]:.4g} "
                     f"Hz; peak |T| {peak:.4g} ({decibels(peak):.3g} dB) at {f[k]:.4g} Hz")
    if estimate.highpass_corner is not None:
        lines.append(f"  untrusted below {estimate.untrusted_below:g} Hz (high-pass at "
                     f"{estimate.highpass_corner:g} Hz)")
    return "\n".join(lines)


class EstimateProtocol:
    """``summary``, ``plot`` and ``save`` of a transmissibility estimate (it has
    ``to_xarray``)."""

    #: The extensions :meth:`save` accepts.
    save_suffixes = DATASET_SUFFIXES

    def summary(self) -> str:
        """The estimate as text (:func:`estimate_text`).

        Returns
        -------
        str
        """
        return estimate_text(self)

    def plot(self, path: str | Path | None = None, *, title: str | None = None,
             frequency_scale: str | None = None) -> "Figure":
        """The curve in dB, trusted bins solid, and the coherence below
        (:func:`qzs.viz.transmissibility.plot_transmissibility`).

        Parameters
        ----------
        path : str or Path, optional
            Write the figure there, atomically (a .png also as .svg).
        title : str, optional
            Figure title; default none.
        frequency_scale : {"log", "linear"}, optional
            Frequency axis; default ``qzs.defaults.FIGURES["frequency_scale"]`` (log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from qzs.viz.transmissibility import plot_transmissibility

        e: Any = self
        curve = {"label": e.estimator, "frequency": e.frequency, "magnitude": e.magnitude,
                 "trusted": e.trusted, "coherence": e.coherence}
        return plot_transmissibility(
            [curve], frequency_range=(0.0, float(e.frequency[-1])),
            frequency_scale=frequency_scale, title=title or "", path=path,
            untrusted_below=e.untrusted_below or None,
            estimator=ESTIMATOR_LABELS.get(e.estimator, e.estimator),
            coherence_min=e.coherence_min)

    def save(self, path: str | Path) -> Path:
        return save_by_extension(path, dataset=self.to_xarray)  # type: ignore[attr-defined]

    save.__doc__ = save_doc("``.nc`` (NetCDF, CF-1.10), ``.csv`` (one row per bin) or "
                            "``.mat`` (MATLAB) of ``to_xarray()``: magnitude [1], phase "
                            "[rad], coherence [1], base share [1] and the trusted flag on "
                            "frequency [Hz]")
