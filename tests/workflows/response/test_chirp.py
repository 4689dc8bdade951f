"""The paper's chirp estimate (qzs.workflows.response.chirp) beside the steady state."""
import numpy as np

from qzs.workflows.response import steady_state_response


def test_chirp_and_steady_state_agree_where_the_payload_slides():
    """The paper's default case: above the break-away the payload slides all period long
    and the slow chirp's Welch ratio reads the steady state within 0.1 dB
    (docs/response.md §7)."""
    response = steady_state_response([5.0, 10.0], direction="up", dt=1e-3,
                                     harmonic_balance=False, compare_chirp=True, workers=1)
    chirp = response.chirp_at()
    steady = response.branch("up")["transmissibility"]
    assert np.all(np.abs(20 * np.log10(chirp / steady)) < 0.1)
