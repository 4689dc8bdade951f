"""Steady-state frequency response by stepped-sine simulation (docs/response.md).

For each frequency the isolator is simulated under a sine until its response is periodic:
the state at the same phase of successive periods agrees within a tolerance. Each frequency
starts from the last one's final state, in a sweep up and a sweep down, so that coexisting
branches and the jumps between them show. Then the fundamental amplitude ratio of payload to
base acceleration (the steady-state transmissibility), its higher harmonics, the relative
amplitude, the share of the period the payload is locked and the stop contacts are read from
the last period (or the last two or three, for a sub-harmonic response).

>>> import numpy as np
>>> from qzs.workflows.response import steady_state_response
>>> response = steady_state_response(np.linspace(0.5, 20, 40))  # doctest: +SKIP
>>> response.branch("up")["transmissibility"]  # doctest: +SKIP

The harmonic balance of the smooth model (:mod:`qzs.analysis.harmonic_balance`) is drawn over
it, with its unstable branch and folds; the paper's chirp-and-Welch estimate can be set beside
it (:func:`chirp_transmissibility`).

=============  ===============================================================================
``result``     :class:`ResponsePoint` and :class:`SteadyStateResponse`: the points and views
``files``      the response's dataset, CSV and JSON, written atomically
``frequency``  one frequency simulated period by period until periodic, and its analysis
``pool``       the sweeps' chains of frequencies, inline or in a pool of processes
``chirp``      :func:`chirp_transmissibility`, the paper's chirp-and-Welch estimate
``sweep``      :func:`steady_state_response`: checks, step choice, sweeps, gathered result
=============  ===============================================================================
"""
from qzs.workflows.response.chirp import chirp_transmissibility
from qzs.workflows.response.files import RESPONSE_SUFFIXES
from qzs.workflows.response.frequency import PERIODIC_TOLERANCE, SAMPLES_PER_PERIOD, steps_for
from qzs.workflows.response.result import ResponsePoint, SteadyStateResponse
from qzs.workflows.response.sweep import (DIRECTIONS, MAX_PERIODS, response_step,
                                          settle_time_cap, steady_state_response)

__all__ = ["ResponsePoint", "SteadyStateResponse", "steady_state_response",
           "chirp_transmissibility", "steps_for", "DIRECTIONS", "RESPONSE_SUFFIXES",
           "SAMPLES_PER_PERIOD", "PERIODIC_TOLERANCE", "MAX_PERIODS", "settle_time_cap",
           "response_step"]
