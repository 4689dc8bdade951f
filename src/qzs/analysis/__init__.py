"""Analysis of runs and measurements: spectra, transmissibility metrics, linearisation, statistics.

====================  =============================================================================
``spectral``          transmissibility (Welch ratio, H1, H2, coherence), run sizing, metrics, bands
``welch``             Welch spectra and transmissibility arrays of one record or a population at once
``damping``           what active damping changes: largest per-bin reduction and band-RMS change
``linear``            the linearised closed loop at the operating point, any controller (python-control)
``hexapod_linear``    the six-leg platform of isolator legs linearised at its home pose
``control_design``    static design, Routh-Hurwitz, sampled-loop margins, hunting (describing functions)
``harmonic_balance``  periodic responses of the smooth model: AFT, continuation, Hill stability
``statistics``        run statistics (stroke, time locked, motor effort)
``summary``           the one-screen text summary of a run
``estimate_views``    a transmissibility estimate's summary, figure and files (the result protocol)
====================  =============================================================================
"""
from qzs._lazy import lazy_exports

_SPECTRAL = ("TransmissibilityEstimate", "TransmissibilityMetrics", "amplitude_spectrum",
             "band_mask", "rolloff_slope", "highpass", "required_duration", "required_samples",
             "transmissibility", "transmissibility_batch", "transmissibility_at",
             "transmissibility_metrics", "trusted_bins", "welch_average_count")
_EXPORTS = {**{name: "qzs.analysis.spectral" for name in _SPECTRAL},
            **{name: "qzs.analysis.statistics"
               for name in ("STATISTICS", "RunStatistics", "run_statistics",
                            "SUMMARY_STATISTICS", "SummaryStatistics")},
            **{name: "qzs.analysis.linear"
               for name in ("linearize", "plant_system", "controller_system")},
            **{name: "qzs.analysis.control_design"
               for name in ("static_design", "routh_hurwitz", "loop_margins",
                            "required_controller_rate", "predict_hunting", "loop_stability",
                            "predict_sliding_cycle")},
            **{name: "qzs.analysis.harmonic_balance"
               for name in ("SmoothModel", "HarmonicBalanceSolution", "FrequencyResponseCurve",
                            "periodic_response", "frequency_response_curve",
                            "floquet_exponents", "smooth_right_hand_side")},
            **{name: "qzs.analysis.hexapod_linear"
               for name in ("HexapodLinearModel", "hexapod_linearize", "geometric_stiffness",
                            "off_diagonal_coupling", "entry_unit")}}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)  # scipy.signal, python-control on use
