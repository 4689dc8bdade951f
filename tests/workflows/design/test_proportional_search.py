"""The PI search's smallest gain checked by independent simulation of every case.

Each case of the small design re-simulated alone with ``qzs.simulate``: at the chosen gain
every one stays inside the constant-force band and off the stops, at the failing gain just
below it one does not.
"""
import qzs
from qzs import ControllerParameters, IsolatorParameters
from qzs.workflows.design.cases import _cases
from qzs.workflows.design.proportional_search import _family_gains


def case_passes(case, kp, kd, result, options):
    """Simulate one case alone with qzs.simulate; is it inside the band and off the stops?"""
    settings = result.settings
    controller = ControllerParameters(pi_kp=kp, pi_ki=settings["integral_ratio"] * kp,
                                      damping_gain=kd)
    excitation, isolator, initial, duration = case.run_inputs(
        IsolatorParameters(), controller, options["excitation"], settings["duration"],
        quick=True)
    run = qzs.simulate(excitation, isolator, controller, duration=duration, dt=options["dt"],
                       sample_rate=settings["sample_rate"], initial_state=initial)
    low, high = settings["stroke_band"]
    z = run.relative_position
    return bool(z.min() >= low and z.max() <= high and run.run["stop_contacts"] == 0)


def test_the_smallest_kp_keeps_every_case_in_the_band_and_a_slightly_smaller_one_does_not(
        design, design_options):
    pi = design.pi_search
    assert pi["found"]
    kp, failing, kd = pi["pi_kp"], pi["failing_kp"], pi["damping_gain"]
    assert failing < kp <= 1.2 * failing  # a bracket of at most 20 % (quick: three bisections)
    cases = _cases((8.0, 12.0), (6.4, 6.4), (2.0,), True)
    assert len(cases) == pi["cases"] == 6
    assert all(case_passes(case, kp, kd, design, design_options) for case in cases)
    assert not all(case_passes(case, failing, kd, design, design_options) for case in cases)


def test_a_familys_gain_is_the_lowest_from_which_on_every_gain_tried_passes():
    def row(family, passes):
        return {"family": family, "passes": passes}

    details = {1.0: [row("base", False), row("step", True)],
               2.0: [row("base", True), row("step", False)],
               4.0: [row("base", False), row("step", True)],
               8.0: [row("base", True), row("step", True)]}
    # base passes at 2 but fails at 4: only from 8 on; step fails at 2: from 4 on
    assert _family_gains(details) == {"base": 8.0, "step": 4.0}
