"""Session-scoped simulation runs shared by the test modules.

Every run here is short (seconds of simulated time) so that the whole suite stays fast
once numba has compiled (and cached) the kernel.
"""
import pytest
from helpers import PASSIVE, SHORT_CHIRP

from qzs import ControllerParameters, IsolatorParameters, Sine, simulate


@pytest.fixture(scope="session")
def default_chirp_run():
    """Table 1 defaults, default PI, 20 s of the paper's chirp, sampled at every step."""
    return simulate(SHORT_CHIRP, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def passive_chirp_run():
    """The passive isolator (no PI) on the same chirp: it reaches the compliant stops."""
    return simulate(SHORT_CHIRP, controller=PASSIVE, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def plastic_sine_run():
    """The passive isolator on a perfectly plastic stop, 3 Hz sine for 10 s (sinks to it)."""
    return simulate(Sine(amplitude=0.010, frequency=3.0), IsolatorParameters(stop_model="plastic"),
                    PASSIVE, duration=10.0, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def sampled_chirp_run():
    """Default plant, PI plus active damping sampled at 1 kHz with zero-order hold."""
    controller = ControllerParameters(controller_rate=1000.0, damping_gain=20.0)
    return simulate(SHORT_CHIRP, controller=controller, dt=1e-4, sample_rate=1e4)
