"""Every bad argument of ``design_controller`` fails, naming it, before any simulation."""
import pytest

import qzs
from qzs import Chirp, ControllerParameters, ParameterError
from qzs.workflows import design as D
from qzs.workflows.design import hunting, proportional_search
from qzs.engine import step_choice
from qzs.workflows.design import cost

#: Where the design simulates: (module, name) of every simulating function it calls.
SIMULATORS = [(proportional_search, "simulate"), (proportional_search, "simulate_batch"),
              (cost, "simulate_batch"), (hunting, "simulate"),
              (step_choice, "choose")]


def forbid_simulation(monkeypatch):
    """Make every simulation of the design fail the test."""
    def forbidden(*args, **kwargs):
        raise AssertionError("simulated before checking the input")

    for module, name in SIMULATORS:
        monkeypatch.setattr(module, name, forbidden)


@pytest.mark.parametrize("change, words", [
    (dict(stiction_range=(0.5, 2.0)), "stiction_range"),
    (dict(band=(1.0, 50.0)), "band"),
    (dict(band=(0.0, 20.0)), "band"),
    (dict(cost="mean"), "cost"),
    (dict(controller=ControllerParameters(pi_kp=0.0)), "pi_kp"),
    (dict(excitation=qzs.Sine()), "excitation"),
    (dict(force_steps=("a",)), "force_steps"),
    (dict(force_steps=2.0), "force_steps"),
    (dict(delay=-1.0), "delay"),
    (dict(controller_rate=300.0), "controller_rate"),
    (dict(controller_rate=333.0, dt=None), r"`controller_rate` \(333 Hz\).*share no integration step"),
    (dict(excitation=Chirp(duration=15.0, f1=20.0)), "too short"),
    (dict(mass_range=(6.0,)), "mass_range"),
    (dict(dt=0.0), "`dt`"),
    (dict(damping_gain_max=0.0), "damping_gain_max"),
])
def test_bad_input_fails_before_any_simulation(monkeypatch, design_options, change, words):
    forbid_simulation(monkeypatch)
    with pytest.raises(ParameterError, match=words):
        D.design_controller(**{**design_options, **change})


@pytest.mark.parametrize("change, message", [
    (dict(delay=True), "`delay` must be a number, got the boolean True; in seconds, e.g. 0.002."),
    (dict(dt=0.0), "`dt` must be positive, got 0.0; in seconds, e.g. 0.001."),
    (dict(band=(20.0, 1.0)), "`band` must satisfy 0 <= low <= high (finite, in Hz), got "
                             "(20.0, 1.0); e.g. (1, 20)."),
    (dict(mass_range="heavy"), "`mass_range` must be two numbers (low, high) in kg, got "
                               "'heavy'; e.g. (6.2, 6.6)."),
])
def test_a_bad_number_or_range_is_named_with_its_unit_and_an_example(monkeypatch, design_options,
                                                                      change, message):
    forbid_simulation(monkeypatch)
    with pytest.raises(ParameterError) as info:
        D.design_controller(**{**design_options, **change})
    assert str(info.value) == message


def test_a_quick_design_shortens_a_long_chirp_to_the_same_sweep_in_200_s():
    from qzs.workflows.design.inputs import _excitation

    long = Chirp(duration=2000.0)
    quick, duration = _excitation(long, quick=True)
    assert duration == 200.0 and quick.duration == 200.0
    assert (quick.f0, quick.f1, quick.amplitude) == (long.f0, long.f1, long.amplitude)
    assert _excitation(long, quick=False) == (long, 2000.0)
