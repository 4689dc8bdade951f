"""A small response shared by the tests of its result and files."""
import pytest

from qzs.workflows.response import steady_state_response


@pytest.fixture(scope="session")
def small_response():
    """Both sweeps over 2, 4 and 8 Hz at dt <= 1 ms, with the harmonic balance."""
    return steady_state_response([2.0, 4.0, 8.0], direction="both", dt=1e-3, workers=1)
