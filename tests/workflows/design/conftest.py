"""The one small design every test of ``qzs.workflows.design`` reads, run once per session.

A 60 s chirp, two stiction values, one mass, one force step, a fixed step: its chosen
smallest proportional gain must keep every case inside the constant-force band and off the
stops when re-simulated one by one with ``qzs.simulate``, and the failing gain just below it
must not.
"""
import pytest

from qzs import Chirp
from qzs.workflows import design as D

#: The base motion of the small design.
EXCITATION = Chirp(duration=60.0)
#: Its fixed integration step [s].
DT = 1e-3
#: The arguments of the small design.
OPTIONS = dict(excitation=EXCITATION, stiction_range=(8.0, 12.0), mass_range=(6.4, 6.4),
               force_steps=(2.0,), band=(1.0, 20.0), quick=True, dt=DT, damping_gain_max=300.0)


@pytest.fixture(scope="session")
def design_options():
    """The arguments of the small design (a fresh dict)."""
    return dict(OPTIONS)


@pytest.fixture(scope="session")
def design():
    """The small design's :class:`~qzs.workflows.design.DesignResult`."""
    return D.design_controller(**OPTIONS)
