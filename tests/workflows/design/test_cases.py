"""The cases of the PI search: how many, and how each family starts."""
import pytest

from qzs import Chirp, ControllerParameters, IsolatorParameters
from qzs.analysis import control_design as cd
from qzs.model.isolator import spring_force
from qzs.workflows.design.cases import DesignCase, _cases, _preload


def test_the_design_hunting_case_starts_on_the_predicted_cycle():
    controller = ControllerParameters(pi_kp=200.0, pi_ki=80.0)
    case = DesignCase("hunting", 10.0, 6.4)
    excitation, isolator, initial, duration = case.run_inputs(
        IsolatorParameters(), controller, Chirp(duration=60.0), 60.0)
    prediction = cd.predict_hunting(isolator, controller)
    assert excitation.amplitude == 0.0
    assert initial.relative_position - controller.position_setpoint == pytest.approx(
        prediction.amplitude)
    assert duration > 4 * prediction.relay_period


def test_a_step_case_adds_the_force_step_to_the_integrals_preload():
    """``Ki*I0`` is the weight deficit at the setpoint plus the step."""
    controller = ControllerParameters(pi_kp=100.0, pi_ki=40.0)
    case = DesignCase("step", 10.0, 6.5, force_step=-2.0)
    _, isolator, initial, _ = case.run_inputs(IsolatorParameters(), controller,
                                              Chirp(duration=60.0), 60.0)
    assert isolator.mass == 6.5 and isolator.stiction_force == 10.0
    deficit = 6.5 * isolator.gravity - float(spring_force(-0.06, isolator))
    assert controller.pi_ki * initial.pi_integral == pytest.approx(deficit - 2.0, rel=1e-12)
    assert controller.pi_ki * _preload(isolator, controller) == pytest.approx(deficit)


def test_the_cases_cover_the_ranges_ends_and_the_middle_stiction_unless_quick():
    full = _cases((5.0, 15.0), (6.2, 6.6), (-2.0, 2.0), quick=False)
    # 3 stictions x 2 masses: 6 base, 12 step, 6 hunting
    assert [c.family for c in full].count("base") == 6 and len(full) == 24
    assert {c.stiction_force for c in full} == {5.0, 10.0, 15.0}
    quick = _cases((5.0, 15.0), (6.4, 6.4), (), quick=True)
    assert [(c.family, c.stiction_force) for c in quick] == [
        ("base", 5.0), ("base", 15.0), ("hunting", 5.0), ("hunting", 15.0)]
    assert quick[0].label == "base: Fs 5 N, m 6.4 kg"
    assert DesignCase("step", 5.0, 6.4, 2.0).label == "step: Fs 5 N, m 6.4 kg, dF +2 N"
