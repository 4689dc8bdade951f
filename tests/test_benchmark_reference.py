"""The benchmarks' C baseline (benchmarks/c_reference) is qzs's own C model, and runs qzs' case.

It is the model of src/qzs/export/csrc compiled for this CPU; the kernels' equality with it
over many cases is tests/export/test_cmodel.py's. Here: the baseline's wrapper, as
benchmarks/run_all.py calls it, gives qzs' run on the paper's chirp (stick-slip included) to
the last bit, and reports its counters.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

import qzs
from qzs.engine.channels import CHANNELS

REFERENCE = Path(__file__).resolve().parents[1] / "benchmarks" / "c_reference"
sys.path.insert(0, str(REFERENCE))
import reference  # noqa: E402

if reference.compiler() is None:
    pytest.skip("no C compiler for the C reference model", allow_module_level=True)


@pytest.fixture(scope="module")
def library():
    try:
        return reference.build()
    except RuntimeError as error:  # a compiler that cannot build: not this test's concern
        pytest.skip(f"C reference did not build: {error}")


def test_the_baseline_runs_qzs_case_bit_for_bit(library):
    excitation = qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=20.0)
    kwargs = dict(duration=10.0, dt=1e-4, sample_rate=1000.0)
    ours = qzs.simulate(excitation, **kwargs)
    theirs = reference.run_reference(excitation, **kwargs)
    assert theirs["status"] == "ok" and theirs["steps"] == 100000
    assert theirs["rows"] == len(ours.time)
    assert theirs["stick_events"] == ours.run["stick_events"] > 0
    for channel, (column, _, _) in CHANNELS.items():
        np.testing.assert_array_equal(theirs["out"][:, column], np.asarray(ours[channel]),
                                      err_msg=channel)


def test_the_numba_time_beside_it_is_of_the_same_run(library):
    run = reference.prepare(qzs.Sine(amplitude=0.01, frequency=5.0), duration=1.0, dt=1e-4,
                            sample_rate=1000.0)
    theirs = reference.run_prepared(run)
    out = np.zeros_like(theirs["out"])
    seconds = reference.numba_seconds(run, out)
    assert 0.0 < seconds < 60.0
    assert run.flags[qzs.engine.kernels.I_STEP] == 0  # the prepared run is left as it was
    # row 0 is the initial sample, written by the caller (qzs.simulate) in both
    np.testing.assert_array_equal(out[1:], theirs["out"][1:])  # the C run's rows, to the bit
