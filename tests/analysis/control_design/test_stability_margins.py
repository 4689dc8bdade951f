"""Margins of loops whose margins are known by hand, and the controller rate a design needs."""
import math

import control
import pytest

from qzs import ControllerParameters, ParameterError
from qzs.analysis import control_design as cd


def test_margins_of_a_discrete_integrator_against_the_hand_computation(validation):
    gain, period = 10.0, 0.01
    loop = control.tf([gain * period], [1.0, -1.0], period)  # K*T/(z - 1)
    margins = cd.stability_margins_of(loop)
    assert margins.stable
    # phase crossing at the Nyquist frequency, |L(-1)| = K*T/2
    assert margins.gain_margin == pytest.approx(20 * math.log10(2 / (gain * period)), abs=1e-9)
    assert margins.phase_crossover_frequency == pytest.approx(50.0)
    # |L| = K*T/(2 sin(wT/2)) = 1; the phase is -(90 deg + wT/2)
    assert margins.phase_margin == pytest.approx(
        90.0 - math.degrees(math.asin(gain * period / 2)), abs=1e-4)
    validation("Gain margin of a discrete integrator K T/(z - 1)", "20 log10(2/(K T))",
               abs(margins.gain_margin - 20 * math.log10(2 / (gain * period))), 1e-9,
               measure="absolute error [dB]")
    validation("Phase margin of a discrete integrator K T/(z - 1)", "90 deg - asin(K T/2)",
               abs(margins.phase_margin - (90.0 - math.degrees(math.asin(gain * period / 2)))),
               1e-4, measure="absolute error [deg]")


def test_margins_of_a_delayed_continuous_integrator(validation):
    w0, tau = 2.0, 0.1
    margins = cd.stability_margins_of(control.tf([w0], [1.0, 0.0]), delay=tau)
    assert margins.phase_margin == pytest.approx(90.0 - math.degrees(w0 * tau), abs=1e-3)
    assert margins.gain_margin == pytest.approx(20 * math.log10(math.pi / (2 * w0 * tau)),
                                                abs=1e-3)
    assert margins.gain_crossover_frequency == pytest.approx(w0 / (2 * math.pi), rel=1e-4)
    validation("Phase margin of a delayed integrator w0 e^(-s tau)/s (Pade)",
               "90 deg - w0 tau", abs(margins.phase_margin - (90.0 - math.degrees(w0 * tau))),
               1e-3, measure="absolute error [deg]")


def test_sampled_margins_approach_the_continuous_ones_and_a_slow_rate_fails():
    controller = ControllerParameters(damping_gain=300.0)
    continuous = cd.loop_margins(controller=controller, rate=0.0)
    fast = cd.loop_margins(controller=controller, rate=1e5)
    assert fast.phase_margin == pytest.approx(continuous.phase_margin, abs=0.1)
    slow = cd.loop_margins(controller=controller, rate=20.0)
    assert not slow.stable


def test_the_required_rate_meets_the_margins_and_a_slower_one_does_not():
    controller = ControllerParameters(damping_gain=300.0)
    rate, reason = cd.required_controller_rate(controller=controller, delay=0.001)
    assert math.isfinite(rate) and reason == ""
    assert cd.loop_margins(controller=controller, rate=rate, delay=0.001).meets()
    assert not cd.loop_margins(controller=controller, rate=0.97 * rate, delay=0.001).meets()


@pytest.mark.parametrize("call, words", [
    (lambda: cd.loop_margins(rate=-1.0), "`rate`"),
    (lambda: cd.loop_margins(delay=float("nan")), "`delay`"),
    (lambda: cd.stability_margins_of(control.tf([1], [1, -1], 0.1), delay=0.1), "`delay`"),
    (lambda: cd.required_controller_rate(rate_range=(10.0, 1.0)), "`rate_range`"),
])
def test_bad_input_names_the_argument(call, words):
    with pytest.raises(ParameterError, match=words):
        call()


def test_an_unstable_loop_has_no_margins_only_their_reason():
    """K T/(z - 1) with K T = 3 closes with its pole at 1 - K T = -2: unstable. |L| at the
    -180 deg crossing (Nyquist) is K T/2 = 1.5, so a reading of 3.52 dB there is the gain
    cut that would restore stability, not a margin; it must not look like one."""
    gain, period = 300.0, 0.01
    margins = cd.stability_margins_of(control.tf([gain * period], [1.0, -1.0], period))
    assert not margins.stable and not margins.meets(gain_margin_min=0.0, phase_margin_min=0.0)
    for name in ("gain_margin", "phase_margin", "gain_crossover_frequency",
                 "phase_crossover_frequency"):
        assert math.isnan(getattr(margins, name)), name
        assert "unstable" in margins.reasons[name]
    cut = 20 * math.log10(gain * period / 2)
    assert f"{cut:.3g} dB" in margins.reasons["gain_margin"]
    record = margins.to_dict()
    assert math.isnan(record["gain_margin"]) and "unstable" in record["reasons"]["gain_margin"]


def test_the_sampled_design_loop_that_is_unstable_has_no_gain_margin():
    slow = cd.loop_margins(controller=ControllerParameters(damping_gain=200.0), rate=10.0)
    assert not slow.stable and math.isnan(slow.gain_margin)
    stable = cd.loop_margins(controller=ControllerParameters(damping_gain=200.0), rate=20.0)
    assert stable.stable and stable.gain_margin > 0


@pytest.mark.parametrize("gain_period, stable", [(1.999, True), (2.0, False), (2.001, False)])
def test_a_discrete_loop_is_stable_only_with_its_poles_strictly_inside_the_unit_circle(
        gain_period, stable):
    """K T/(z - 1) closed: the pole is z = 1 - K T (by hand), inside the unit circle for
    K T < 2, on it at K T = 2 (not asymptotically stable: no margins), outside beyond."""
    margins = cd.stability_margins_of(control.tf([gain_period], [1.0, -1.0], 0.01))
    assert margins.stable is stable
    assert math.isnan(margins.gain_margin) is not stable
    if stable:  # the hand computation's 20 log10(2/(K T)), just above 0 dB
        assert margins.gain_margin == pytest.approx(20 * math.log10(2 / gain_period), abs=1e-9)
