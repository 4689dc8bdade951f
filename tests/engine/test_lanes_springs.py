"""A spring law is data to the one general kernel: the tanh through it is the default run bit
for bit, the lanes equal the single runs for every law, and a refusing table stops the run."""
import numpy as np
import pytest

import qzs
from qzs.engine import kernels as K
from qzs.engine import lanes as _lanes
from qzs.engine.batch import simulate_batch
from qzs.engine.prepare import prepare_run
from qzs.errors import SimulationError
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Sine
from qzs.model.isolator import InitialState, IsolatorParameters
from qzs.model.springs import (ObliqueSpringQZS, PolynomialSpring, TabulatedSpring,
                               TanhSpring)

SINE = Sine(amplitude=5e-3, frequency=5.0, fade_in=0.0)  # base 4.9 m/s^2: stick-slip
#: The stroke of the default rig (stops at the setpoint -0.060 +- 0.080 m) and a margin.
SPAN = np.linspace(-0.15, 0.03, 181)


def _laws():
    oblique = ObliqueSpringQZS()
    return {"oblique": oblique,
            "polynomial": PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -2e5),
                                           center=-0.06),
            "table": TabulatedSpring.from_law(oblique, SPAN),
            "tanh": TanhSpring(plateau=60.84, shape=78.10)}


def _run(kernel, run, steps):
    state, flags = run.state.copy(), run.flags.copy()
    data = np.zeros((steps // run.decimation + 1, K.N_CHANNELS))
    marks = np.zeros((data.shape[0], 2), dtype=np.bool_)
    status, rows = kernel(run.solver_code, steps, run.decimation, state, flags, run.params,
                          run.model, *run.packed, data, marks, 0)
    assert status == K.STATUS_OK and rows == data.shape[0] - 1
    return data[:rows, :K.N_BASE_CHANNELS], marks[:rows], state, flags


def test_the_tanh_through_the_general_kernel_is_the_default_run_bit_for_bit():
    """run_single_blocks (the spring from M) and run_single (the tanh of P) on one run."""
    run = prepare_run(SINE, duration=1.0)
    assert _lanes.single_kernel(run.model) is _lanes.run_single
    assert run.model[K.M_SPRING] == 0.0  # the default law packed: the tanh
    steps = 10_000
    literal = _run(_lanes.run_single, run, steps)
    general = _run(_lanes.run_single_blocks, run, steps)
    assert literal[1].any() and not literal[1].all()  # stick-slip: events through the spring
    for a, b in zip(literal, general):
        np.testing.assert_array_equal(a, b)
    # a TanhSpring given is the fields' run, on the literal kernel
    given = prepare_run(SINE, IsolatorParameters(spring=TanhSpring()), duration=1.0)
    assert _lanes.single_kernel(given.model) is _lanes.run_single
    np.testing.assert_array_equal(given.params, run.params)
    np.testing.assert_array_equal(given.model, run.model)


@pytest.mark.parametrize("workers", [1, 2])
def test_lanes_equal_single_runs_for_every_law(workers):
    """A mixed batch (every law, the default last) equals each case's single run bit for bit."""
    laws = _laws()
    cases = [(IsolatorParameters(spring=law), ControllerParameters()) for law in laws.values()]
    cases.append((IsolatorParameters(), ControllerParameters()))
    channels = ("relative_position", "spring_force", "spring_energy", "motor_force")
    batch = simulate_batch(cases, SINE, duration=0.5, sample_rate=1000.0, channels=channels,
                           workers=workers)
    assert not batch.status.any()
    for c, (isolator, controller) in enumerate(cases):
        single = qzs.simulate(SINE, isolator, controller, duration=0.5, sample_rate=1000.0)
        for name in channels:
            np.testing.assert_array_equal(batch.channels[name][c], getattr(single, name),
                                          err_msg=f"case {c} ({name})")
    # the laws differ (their force is the weight at the setpoint, their energy is not theirs)
    energy = batch.channels["spring_energy"]
    assert not np.array_equal(energy[0], energy[1]) and not np.array_equal(energy[0], energy[3])
    z = batch.channels["relative_position"]
    assert 0 < np.abs(z[0] - z[2]).max() < 1e-6  # the table of the oblique law: nearly it


def test_a_refusing_table_stops_the_run_naming_the_position_and_the_range():
    """Thrown at the lower stop, the payload presses into it past the table's first position."""
    table = TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.14, 0.021, 162))
    isolator = IsolatorParameters(spring=table)
    start = InitialState(relative_position=-0.13, relative_velocity=-1.0)
    with pytest.raises(SimulationError, match=r"left the spring table \[-0\.14, 0\.021\] m past "
                                              r"its end at -0\.14 m") as error:
        qzs.simulate(Sine(amplitude=0.0, frequency=1.0), isolator, duration=0.1,
                     initial_state=start)
    assert "outside='extend'" in str(error.value)
    z = float(str(error.value).split("inside z = ")[1].split(" m")[0])
    assert -0.1401 < z < -0.13  # the last position inside the table, near its end
    # the same in a batch: the case fails with that message, the others go on
    batch = simulate_batch([(isolator, ControllerParameters()),
                            (IsolatorParameters(), ControllerParameters())],
                           Sine(amplitude=0.1, frequency=2.0, fade_in=0.0), duration=1.0,
                           workers=1)
    assert batch.status.tolist() == [1, 0]
    assert "left the spring table" in batch.messages[0]
