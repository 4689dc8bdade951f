"""The one verdict on a controller's loop, and the margins of a controller with blocks.

The verdict's poles against the characteristic polynomial written by hand (over-compensated
viscous friction, a controller unstable alone in a stable loop), against the sampled loop of
PI + damping, and the margins of blocks that add nothing against PI + damping's.
"""
import math

import numpy as np
import pytest

from qzs import FrictionCompensation, IsolatorParameters, LinearController, ParameterError, \
    PIDamping
from qzs.analysis import control_design as cd
from qzs.analysis.linear import loop_constants

NOTHING = FrictionCompensation(fraction=0.0)


@pytest.mark.parametrize("rate, delay", [(0.0, 0.0), (0.0, 2e-3), (1000.0, 0.0),
                                         (200.0, 1.3e-3)])
def test_margins_of_blocks_that_add_nothing_are_pi_and_dampings(rate, delay):
    controller = PIDamping(damping_gain=100.0)
    reference = cd.loop_margins(None, controller, rate, delay)
    general = cd.loop_margins(None, controller + NOTHING, rate, delay)
    assert general.stable == reference.stable and general.rate == reference.rate
    for name in ("gain_margin", "phase_margin", "gain_crossover_frequency"):
        assert getattr(general, name) == pytest.approx(getattr(reference, name), rel=1e-6)


def test_over_compensated_viscous_friction_is_an_unstable_loop_with_its_poles(validation):
    """Fraction 1.5 of ``Cv`` (the compensator's ``Cv' = Cv``: ``viscous_damping=None``) and no
    damping gain: ``m s^3 + (1 - a) Cv s^2 + K s + Ki``."""
    isolator = IsolatorParameters()
    controller = PIDamping(damping_gain=0.0) + FrictionCompensation(fraction=1.5,
                                                                    viscous_damping=None)
    m, cv, k, kp, ki, _, w = loop_constants(isolator, controller)
    expected = np.concatenate([np.roots([m, (1 - 1.5) * cv, k + kp, ki]), [-w]])
    verdict = cd.loop_stability(isolator, controller)
    np.testing.assert_allclose(np.sort_complex(verdict.poles), np.sort_complex(expected),
                               rtol=1e-9)
    assert not verdict.stable and not verdict.sampled
    assert verdict.unstable_poles.size == 2
    assert "unstable loop" in verdict.message and "growth rate" in verdict.reasons["stable"]
    assert math.isnan(verdict.margins.phase_margin)  # no margins, the reason instead
    assert "no margin" in verdict.margins.reasons["phase_margin"]
    growth = max(np.roots([m, (1 - 1.5) * cv, k + kp, ki]).real)
    validation("Loop verdict: growth rate of over-compensated viscous friction",
               "largest real root of m s^3 + (1 - a) Cv s^2 + (k + Kp) s + Ki",
               abs(verdict.unstable_poles.real.max() / growth - 1), 1e-9)


def test_compensating_the_viscous_friction_costs_the_pi_loop_its_damping():
    """Without a damping loop, ``m s^3 + (1 - a) Cv s^2 + K s + Ki`` is stable only while
    ``(1 - a) Cv K > m Ki``: the fraction's limit ``a* = 1 - m Ki/(K Cv)`` (0.975 here), with
    the compensator's ``Cv' = Cv`` (``viscous_damping=None``). The default compensator
    (``Cv' = 0``, Coulomb and Stribeck alone) leaves ``Cv`` in place: PI + damping's poles."""
    isolator = IsolatorParameters()
    m, cv, k, kp, ki, _, _ = loop_constants(isolator, PIDamping())
    limit = 1 - m * ki / ((k + kp) * cv)
    for fraction, stable in ((limit - 0.002, True), (limit + 0.002, False)):
        verdict = cd.loop_stability(isolator, PIDamping() + FrictionCompensation(
            fraction=fraction, viscous_damping=None))
        assert verdict.stable is stable
    assert limit == pytest.approx(0.975, abs=1e-3)
    plain = cd.loop_stability(isolator, PIDamping())
    for fraction in (limit + 0.002, 1.5):
        verdict = cd.loop_stability(isolator, PIDamping() + FrictionCompensation(
            fraction=fraction))
        assert verdict.stable
        np.testing.assert_allclose(np.sort_complex(verdict.poles),
                                   np.sort_complex(plain.poles), rtol=1e-9)


def test_a_controller_unstable_alone_is_accepted_when_its_loop_is_stable():
    """``F = Kp e + 100/(s - 0.2) e``: a pole at +0.2 rad/s, closed stably: the loop's
    polynomial ``(s - 0.2)(m s^2 + Cv s + K) + 100`` (Routh: all its coefficients positive
    and ``(Cv - 0.2 m)(K - 0.2 Cv) > m (100 - 0.2 K)``), and the idle high-pass ``-w``."""
    isolator = IsolatorParameters()
    unstable = LinearController.from_transfer_function([100.0], [1.0, -0.2], "position_error")
    controller = PIDamping(pi_ki=0.0, damping_gain=0.0) + unstable
    m, cv, k, kp, _, _, w = loop_constants(isolator, controller)
    polynomial = np.polyadd(np.polymul([1.0, -0.2], [m, cv, k + kp]), [100.0])
    expected = np.concatenate([np.roots(polynomial), [-w]])
    verdict = cd.loop_stability(isolator, controller)
    np.testing.assert_allclose(np.sort_complex(verdict.poles), np.sort_complex(expected),
                               rtol=1e-8)
    assert verdict.stable and np.all(expected.real < 0)
    assert verdict.controller_unstable and "accepted" in verdict.reasons["controller_unstable"]
    assert verdict.message.startswith("stable loop: ")
    assert cd.loop_margins(isolator, controller).stable


def test_the_sampled_verdict_is_the_sampled_loops():
    """At 50 Hz the paper's damping gain is unstable, at 1 kHz stable (docs/design.md §6)."""
    for rate, stable in ((50.0, False), (1000.0, True)):
        controller = PIDamping(damping_gain=1000.0, controller_rate=rate)
        verdict = cd.loop_stability(None, controller)
        closed = cd.sampled_loop(None, controller)
        import control

        poles = np.asarray(control.feedback(closed, 1).poles())
        assert verdict.sampled and verdict.period == pytest.approx(1 / rate)
        assert verdict.stable is stable is bool(np.all(np.abs(poles) < 1))
        assert verdict.stable == cd.loop_margins(None, controller).stable
        assert verdict.to_dict()["stable"] is stable


def test_bad_input_names_the_argument():
    with pytest.raises(ParameterError, match=r"`controller` must be a ControllerParameters, "
                                             r"got FrictionCompensation; .*PIDamping\(\) \+"):
        cd.loop_stability(controller=FrictionCompensation(fraction=0.5))
    with pytest.raises(ParameterError, match="`isolator`"):
        cd.loop_stability(isolator="Table 1")
