"""The C reference model of the benchmarks (benchmarks/c_reference) integrates what qzs does.

On cases without events (a frictionless guide, so nothing can stick, and no stop contact)
the C loop and qzs take the same ode3 steps on the same grid with the same arithmetic, so
their trajectories agree to rounding. The one difference left: qzs still locates each zero
crossing of v inside its step (and splits the step there), which the C does not; at the
low frequencies used here that costs well under 1e-9 relative.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

import qzs

REFERENCE = Path(__file__).resolve().parents[1] / "benchmarks" / "c_reference"
sys.path.insert(0, str(REFERENCE))
import reference  # noqa: E402

if reference.compiler() is None:
    pytest.skip("no C compiler (gcc) for the C reference model", allow_module_level=True)

FRICTIONLESS = qzs.IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)
SLIPPING = qzs.InitialState(locked=False)
CASES = {
    "2 Hz sine": (qzs.Sine(amplitude=0.01, frequency=2.0, fade_in=0.0), 2.0),
    "0-20 Hz chirp over 20 s": (qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0), 5.0),
}


@pytest.fixture(scope="module")
def library():
    try:
        return reference.build()
    except RuntimeError as error:  # a compiler that cannot build: not this test's concern
        pytest.skip(f"C reference did not build: {error}")


def _both(excitation, duration):
    kwargs = dict(duration=duration, dt=1e-4, sample_rate=1000.0, initial_state=SLIPPING)
    q = qzs.simulate(excitation, FRICTIONLESS, **kwargs)
    c = reference.run_reference(excitation, FRICTIONLESS, **kwargs)
    return q, c


@pytest.mark.parametrize("name", list(CASES))
def test_same_trajectory_as_qzs(library, name):
    excitation, duration = CASES[name]
    q, c = _both(excitation, duration)
    assert c["status"] == "ok"
    assert q.run["stick_events"] == 0 and q.run["stop_contacts"] == 0 and c["stop_contacts"] == 0
    from qzs.engine.channels import CHANNELS

    assert c["rows"] == len(q.time)
    for channel, (column, _, _) in CHANNELS.items():
        ours = np.asarray(q[channel])
        theirs = c["out"][:, column]
        scale = max(np.abs(ours).max(), 1e-300)
        rel = np.abs(ours - theirs).max() / scale
        assert rel < 1e-9, f"{channel}: max difference {rel:.3g} of its largest value"
    z, v = np.asarray(q.relative_position), np.asarray(q.relative_velocity)
    # until v first crosses zero (qzs then splits the step at the crossing) both compute
    # the very same operations: the same numbers to the last bits
    crossing = np.flatnonzero(v[1:] * v[:-1] < 0.0)
    first = crossing[0] + 1 if crossing.size else z.size
    assert first > 10
    np.testing.assert_allclose(c["out"][:first, 7], z[:first], rtol=1e-13, atol=0)
    np.testing.assert_allclose(c["out"][:first, 8], v[:first], rtol=1e-12, atol=1e-18)


def test_sticking_case_runs(library):
    """The paper's defaults stick: the C model, without locking, chatters but stays bounded
    and close (it is a baseline of cost, not of the stick-slip answer)."""
    excitation = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=2000.0)
    q = qzs.simulate(excitation, duration=2.0, dt=1e-4, sample_rate=1000.0)
    c = reference.run_reference(excitation, duration=2.0, dt=1e-4, sample_rate=1000.0)
    assert c["status"] == "ok" and c["steps"] == 20000
    z = np.asarray(q.relative_position)
    assert np.abs(c["out"][:, 7] - z).max() < 1e-3
