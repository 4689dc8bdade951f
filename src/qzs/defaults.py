"""The defaults of runs and analyses, in one place (python-control ``config.defaults`` style).

Model parameters carry their defaults in their own fields (:mod:`qzs.model.registry`
lists them with units); this module holds the settings of a run and of the spectral
analysis that several layers share: :func:`qzs.simulate`, the paper's studies, sweeps,
identification and the command line all read them here.
"""
from types import MappingProxyType

__all__ = ["SIMULATION", "ANALYSIS", "REPORTED_FREQUENCIES", "ACCURACY"]

#: Integration settings: the paper's (Section 3): Simulink's ode3 at dt = 1e-4 s [s],
#: output at 1 kHz [Hz].
SIMULATION = MappingProxyType({"dt": 1e-4, "solver": "ode3", "sample_rate": 1000.0})

#: Spectral analysis: the paper's Welch settings (32768-point Hann segments, 122
#: averages at 1 kHz, half overlap) [samples, -, Hz], the quick variant used by
#: ``--quick`` and sweeps, and the band [Hz] the studies keep. Which bins of a
#: transmissibility estimate are trusted (docs/model.md §10): magnitude-squared coherence
#: at least ``coherence_min`` [-] (the PSD ratio then exceeds the coherent response
#: |H1| by at most 1/sqrt(0.9) = +0.46 dB), the bin holding at least ``base_share_min``
#: [-] of the base's own power (DC excluded; below it the base did not excite the bin),
#: and at least ``highpass_factor`` [-] times a measurement high-pass corner.
ANALYSIS = MappingProxyType({
    "sample_rate": 1000.0, "fft_length": 32768, "n_averages": 122, "overlap": 0.5,
    "quick_fft_length": 16384, "quick_n_averages": 30, "band": (0.0, 20.0),
    "coherence_min": 0.9, "base_share_min": 1e-10, "highpass_factor": 1.5})

#: Frequencies [Hz] at which reports and sweeps quote the transmissibility.
REPORTED_FREQUENCIES = (1.0, 2.0, 3.0, 4.0, 8.0, 12.0, 16.0)

#: Accuracy-driven step (docs/model.md §7): the tolerance on the transmissibility [dB] that
#: sweeps meet by default when their file gives no ``dt``; the paper keeps its dt = 1e-4 s.
ACCURACY = MappingProxyType({"tolerance_db": 0.01})
