"""The six-axis transmissibility's settings: default chirp, floor, estimators, platform size."""
from types import MappingProxyType

import numpy as np

from qzs.defaults import HEXAPOD
from qzs.model.hexapod import platform_size

#: Default chirp amplitude per base axis: 2 mm in translation [m], 0.01 rad in rotation
#: [rad] (1.2 mm at the top joints of the 0.15 m cube).
AMPLITUDE = MappingProxyType({"x": 0.002, "y": 0.002, "z": 0.002,
                              "rx": 0.01, "ry": 0.01, "rz": 0.01})
#: Default chirp: start and end frequency [Hz] and sweep time [s] (a linear sweep, as the
#: paper's, over its band; 200 s gives 11 half-overlapping Welch segments of 32768 samples
#: at 1 kHz).
CHIRP = MappingProxyType({"f0": 0.0, "f1": 20.0, "duration": 200.0})
#: Numerical floor of a trusted entry [dB]: the dimensionless response relative to the
#: base motion (see the module docstring).
FLOOR_DB = HEXAPOD["floor_db"]
#: Welch estimators with a phase (the matrix is complex).
ESTIMATORS = ("h1", "h2")
#: Welch segments a run averages at least when ``fft_length`` is not given.
MIN_SEGMENTS = 8


def _scale(size):
    """(6, 6) factors turning ``|T|`` into a dimensionless response (rotations times ``size``)."""
    length = np.array([1.0, 1.0, 1.0, size, size, size])
    return length[:, None] / length[None, :]
