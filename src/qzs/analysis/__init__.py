"""Analysis of runs and measurements: spectra, transmissibility metrics, linearisation, statistics.

``spectral``    transmissibility (Welch ratio, H1, H2, coherence), run sizing, metrics, bands
``linear``      the linearised closed loop at the operating point (python-control)
``statistics``  run statistics (stroke, time locked, motor effort)
``summary``     the one-screen text summary of a run
"""
from qzs.analysis.spectral import (TransmissibilityEstimate, TransmissibilityMetrics,
                                   amplitude_spectrum, band_mask, highpass, required_duration,
                                   required_samples, transmissibility, transmissibility_metrics,
                                   welch_average_count)
from qzs.analysis.statistics import STATISTICS, RunStatistics, run_statistics

__all__ = ["TransmissibilityEstimate", "TransmissibilityMetrics", "amplitude_spectrum",
           "band_mask", "highpass", "required_duration", "required_samples", "transmissibility",
           "transmissibility_metrics", "welch_average_count", "STATISTICS", "RunStatistics",
           "run_statistics", "linearize"]


def __getattr__(name):  # python-control is imported only when the linear model is asked for
    if name == "linearize":
        from qzs.analysis.linear import linearize

        return linearize
    raise AttributeError(f"module 'qzs.analysis' has no attribute {name!r}")
