"""The defaults of runs and analyses, in one place (python-control ``config.defaults`` style).

Model parameters carry their defaults in their own fields (:mod:`qzs.model.registry`
lists them with units); this module holds the settings of a run and of the spectral
analysis that several layers share: :func:`qzs.simulate`, the paper's studies, sweeps,
identification and the command line all read them here. It also names what several
layers must spell alike: the six axes of the platform and their units, the paper's
excitation amplitude, the shipped cube's edge, and the amplitude ratio figures draw for 0.
"""
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

__all__ = ["SIMULATION", "ANALYSIS", "REPORTED_FREQUENCIES", "ACCURACY", "EXCITATION",
           "HEXAPOD", "AXES", "AXIS_UNITS", "AXIS_RATE_UNITS", "FIGURES",
           "FREQUENCY_SCALES"]

#: Integration settings: the paper's (Section 3): Simulink's ode3 at dt = 1e-4 s [s],
#: output at 1 kHz [Hz].
SIMULATION: Mapping[str, Any] = MappingProxyType({"dt": 1e-4, "solver": "ode3", "sample_rate": 1000.0})

#: Spectral analysis: the paper's Welch settings (32768-point Hann segments, 122
#: averages at 1 kHz, half overlap) [samples, -, Hz], the quick variant used by
#: ``--quick`` and sweeps, and the band [Hz] the studies keep. Which bins of a
#: transmissibility estimate are trusted (docs/model.md §10): magnitude-squared coherence
#: at least ``coherence_min`` [-] (the PSD ratio then exceeds the coherent response
#: |H1| by at most 1/sqrt(0.9) = +0.46 dB), the bin holding at least ``base_share_min``
#: [-] of the base's own power (DC excluded; below it the base did not excite the bin),
#: and at least ``highpass_factor`` [-] times a measurement high-pass corner.
ANALYSIS: Mapping[str, Any] = MappingProxyType({
    "sample_rate": 1000.0, "fft_length": 32768, "n_averages": 122, "overlap": 0.5,
    "quick_fft_length": 16384, "quick_n_averages": 30, "band": (0.0, 20.0),
    "coherence_min": 0.9, "base_share_min": 1e-10, "highpass_factor": 1.5})

#: Frequencies [Hz] at which reports and sweeps quote the transmissibility.
REPORTED_FREQUENCIES = (1.0, 2.0, 3.0, 4.0, 8.0, 12.0, 16.0)

#: The paper's claim "active damping did not help much" (``qzs paper``, ``qzs design``,
#: :mod:`qzs.analysis.damping`): the band it is read over [Hz] (above the low end where
#: stiction locks the payload) and the change below which damping "did not help much",
#: per bin and over the band [dB].
DAMPING_CLAIM: Mapping[str, Any] = MappingProxyType({"band": (1.5, 20.0), "small_db": 3.0})

#: Accuracy-driven step (docs/model.md §7): what a command (simulate, paper, study, sweep, the
#: six-axis runs, the page) meets when given no step: the
#: transmissibility within ``tolerance_db`` [dB], or, for a sine (no band to estimate it
#: over), the relative position within ``tolerance_state`` [m] (0.1 % of the paper's 10 mm).
#: ``--dt`` gives a literal step instead; the Python functions keep ``SIMULATION["dt"]``.
ACCURACY: Mapping[str, Any] = MappingProxyType({"tolerance_db": 0.01, "tolerance_state": 1e-5})

#: Base excitation: the paper's displacement amplitude, 10 mm [m] (the default of
#: :class:`~qzs.model.excitation.Chirp` and :class:`~qzs.model.excitation.Sine`, of the
#: steady-state response and of the transmissibility fits).
EXCITATION: Mapping[str, Any] = MappingProxyType({"amplitude": 0.010})

#: Six-axis platform: the edge [m] of the cubic configuration used when none is given
#: (``qzs hexapod --cubic``, :func:`qzs.workflows.hexapod.setups.hexapod_setup`), and the numerical
#: floor [dB] below which a transmissibility entry is rounding, not a response (relative to
#: the base motion, rotations as arcs at the platform's size; docs/hexapod.md §10.2).
HEXAPOD: Mapping[str, Any] = MappingProxyType({"cube_edge": 0.15, "floor_db": -100.0})

#: The six axes of a pose, a twist and the 6x6 matrices, in order: translations x, y, z,
#: then rotations rx, ry, rz about them.
AXES = ("x", "y", "z", "rx", "ry", "rz")
#: Units of a pose along :data:`AXES`, and of its rate.
AXIS_UNITS = ("m", "m", "m", "rad", "rad", "rad")
AXIS_RATE_UNITS = ("m/s", "m/s", "m/s", "rad/s", "rad/s", "rad/s")

#: Figures: the amplitude ratio [-] drawn for 0 on a dB axis (-240 dB), so that a zero
#: magnitude stays on the plot; the scale of every frequency axis (``"log"``: the
#: resonances and stiction features below 2.5 Hz and the roll-off to 20 Hz span
#: decades; ``"linear"`` on request), and the lowest frequency [Hz] a log axis shows when
#: the data give none (0 Hz cannot be drawn on it).
FIGURES: Mapping[str, Any] = MappingProxyType({"magnitude_floor": 1e-12, "frequency_scale": "log",
                                                  "frequency_floor": 0.1})
#: The scales a frequency axis may take (``frequency_scale=``, ``--frequency-axis``).
FREQUENCY_SCALES = ("log", "linear")
