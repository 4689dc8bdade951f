"""One single-axis run at a given step (qzs.engine.single): what qzs.simulate integrates.

Properties that fail if the run is wrong:

* ``qzs.simulate`` is :func:`integrate` of its resolved run, to the bit;
* the step's record travels with the run: a literal step says "given", a chosen one its
  tolerance and estimate, in ``result.run`` and on ``result.step``;
* :func:`result_bytes` is what a run's arrays take in memory, so the memory guard checks the
  right number.
"""
import numpy as np
import pytest

import qzs
from qzs import Chirp, Sine
from qzs.engine.single import integrate, result_bytes
from qzs.engine.step_search import StepChoice

SINE = Sine(amplitude=0.002, frequency=3.0)


def test_simulate_is_integrate_of_its_resolved_run():
    resolved = qzs.resolve(Chirp(duration=20.0, f1=5.0), tolerance=0.05)
    direct = integrate(**resolved.arguments())
    through = qzs.simulate(Chirp(duration=20.0, f1=5.0), tolerance=0.05)
    np.testing.assert_array_equal(direct._data, through._data)
    np.testing.assert_array_equal(direct._flags, through._flags)
    assert through.run["dt"] == resolved.dt == through.step.dt


def test_the_step_record_travels_with_the_run():
    literal = integrate(SINE, duration=0.5, dt=5e-4)
    assert literal.run["step"] == "given" and not literal.step.chosen
    choice = qzs.resolve(SINE, duration=2.0, tolerance_state=1e-6).step
    chosen = integrate(SINE, duration=2.0, dt=choice.dt, step=choice)
    assert chosen.step is choice and chosen.run["step"] == "accuracy-driven"
    assert chosen.run["step_tolerance_m"] == 1e-6
    assert 0 <= chosen.run["step_error_m"] <= 1e-6


@pytest.mark.parametrize("controller", [None, qzs.PIDamping() + qzs.Dither(amplitude=2.0)],
                         ids=["no blocks", "dither"])
def test_result_bytes_is_what_the_arrays_take(controller):
    """24 float channels without blocks, 28 with them (the blocks' forces), and 2 flags."""
    run = integrate(SINE, controller=controller, duration=0.75, dt=1e-3, sample_rate=200.0)
    assert result_bytes(0.75, 200.0, controller) == run._data.nbytes + run._flags.nbytes
