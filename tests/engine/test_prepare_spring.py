"""Preparing a run with a spring law: the equilibrium check, the packed row, the stiffness the
step must resolve, the message of a refusing table (docs/model.md §3.1)."""
import numpy as np
import pytest

from qzs.engine import kernels as K
from qzs.engine.prepare import divergence_message, pack_model, prepare_run, stack_models
from qzs.engine.stability import spring_stiffness_peak
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Sine
from qzs.model.isolator import IsolatorParameters
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring

SINE = Sine(amplitude=1e-3, frequency=2.0)
PASSIVE = ControllerParameters(pi_kp=0.0, pi_ki=0.0, damping_gain=0.0)


@pytest.mark.parametrize("law, controller, match", [
    (PolynomialSpring(coefficients=(0.0, -10.0)), ControllerParameters(),
     r"short of the load"),  # the PI's 44 N hold is not enough either
    (PolynomialSpring(coefficients=(62.78, 500.0), center=-0.06), PASSIVE,
     r"negative stiffness"),
    (PolynomialSpring(coefficients=(200.0,)), PASSIVE, r"upper stop"),
])
def test_a_law_without_a_stable_equilibrium_is_refused_before_the_run(law, controller, match):
    with pytest.raises(ParameterError, match=r"`spring`: `law` .* no stable equilibrium .*"
                                             + match) as error:
        prepare_run(SINE, IsolatorParameters(spring=law), controller, duration=1.0)
    assert error.value.options[0] == "spring"


def test_the_pis_hold_and_the_magspring_keep_todays_runs():
    # the MagSpring alone falls short of the weight: the passive rig rests on its stop (no check)
    prepare_run(SINE, IsolatorParameters(spring=TanhSpring()), PASSIVE, duration=1.0)
    # 30 N short of the weight at the setpoint: the PI's integral carries it; alone, the
    # law holds the weight only at -0.16 m, below the stroke
    law = PolynomialSpring(coefficients=(32.78, -300.0), center=-0.06)
    prepare_run(SINE, IsolatorParameters(spring=law), duration=1.0)
    with pytest.raises(ParameterError, match="short of the load"):
        prepare_run(SINE, IsolatorParameters(spring=law), ControllerParameters(pi_ki=0.0),
                    duration=1.0)


def test_the_packed_row_holds_the_law_after_the_blocks_and_a_batch_pads_to_the_widest():
    table = TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.15, 0.03, 11))
    rows = [pack_model(IsolatorParameters(spring=law), ControllerParameters(), 1e-4)
            for law in (None, table)]
    assert rows[0].size == K.N_MODEL_ROW and rows[0][K.M_SPRING:].tolist() == [0.0, 60.84, 78.1]
    np.testing.assert_array_equal(rows[1][K.M_SPRING:], table.pack())
    stacked = stack_models(rows)
    assert stacked.shape == (2, rows[1].size)
    np.testing.assert_array_equal(stacked[0, :K.N_MODEL_ROW], rows[0])
    assert not stacked[0, K.N_MODEL_ROW:].any()


def test_the_step_resolves_the_laws_largest_stiffness_over_the_stroke():
    law = ObliqueSpringQZS()
    iso = IsolatorParameters(spring=law)
    u, d = 0.080, law.horizontal_distance  # the stroke's ends, from the centre (the setpoint)
    ends = law.vertical_stiffness + 2 * law.oblique_stiffness * (
        1 - law.free_length * d * d / np.hypot(u, d) ** 3)
    assert spring_stiffness_peak(iso, ControllerParameters()) == pytest.approx(ends, rel=1e-12)
    assert spring_stiffness_peak(IsolatorParameters(), ControllerParameters()) == 60.84 * 78.10


def test_a_refusing_tables_message_names_the_range_and_the_position():
    table = TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.14, 0.021, 162))
    model = pack_model(IsolatorParameters(spring=table), ControllerParameters(), 1e-4)
    state = np.zeros(K.N_STATE)
    state[K.S_Z], state[K.S_V] = -0.1399, -0.5
    text = divergence_message(state, 1234, 1e-4, K.STATUS_OUTSIDE, model)
    assert ("t = 0.1234 s: the payload left the spring table [-0.14, 0.021] m past its end at "
            "-0.14 m (last position inside z = -0.1399 m, moving at v = -0.5 m/s)") in text
    assert "outside='extend'" in text
