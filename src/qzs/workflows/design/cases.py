"""The cases of the PI search: what disturbs the payload, and how each case starts.

Three families (see :mod:`qzs.workflows.design`): ``base`` (the base motion alone),
``step`` (plus a payload force step at ``t = 0``) and ``hunting`` (the base at rest, the
payload stuck at the plateau the describing function predicts), each over the ends of the
stiction and mass ranges (and the middle stiction, unless ``quick``).
"""
import dataclasses
from dataclasses import dataclass

import numpy as np

from qzs.analysis import control_design as cd
from qzs.model.excitation import Sine
from qzs.model.isolator import InitialState, spring_force, spring_stiffness
from qzs.workflows.design.settings import HUNTING_MAX

__all__ = ["DesignCase"]


@dataclass(frozen=True)
class DesignCase:
    """One case of the PI search.

    Attributes
    ----------
    family : {"base", "step", "hunting"}
        What disturbs the payload (see the module's text).
    stiction_force : float
        Breakaway friction of this case [N].
    mass : float
        Moving mass of this case [kg].
    force_step : float
        Payload force step at t = 0 [N], upward positive (``step`` cases; else 0).
    """

    family: str
    stiction_force: float
    mass: float
    force_step: float = 0.0

    @property
    def label(self):
        """A short description for tables."""
        text = f"{self.family}: Fs {self.stiction_force:g} N, m {self.mass:g} kg"
        if self.family == "step":
            text += f", dF {self.force_step:+g} N"
        return text

    def isolator(self, nominal):
        """The nominal isolator with this case's stiction and mass.

        Parameters
        ----------
        nominal : IsolatorParameters
            Every other parameter.

        Returns
        -------
        IsolatorParameters
        """
        return dataclasses.replace(nominal, stiction_force=self.stiction_force, mass=self.mass)

    def run_inputs(self, nominal, controller, excitation, duration, quick=False):
        """What a single run of this case simulates (``step`` and ``hunting`` cases).

        Parameters
        ----------
        nominal : IsolatorParameters
            Every parameter but this case's stiction and mass.
        controller : ControllerParameters
            The gains tried (``pi_ki`` must be positive).
        excitation : Chirp, RandomExcitation or DisplacementRecord
            The design's base motion (``base`` and ``step`` cases).
        duration : float
            Its simulated length [s].
        quick : bool
            The quick design's hunting runs are at most 600 s long, else 1500 s.

        Returns
        -------
        excitation : object
            The base motion (at rest for a ``hunting`` case).
        isolator : IsolatorParameters
        initial_state : InitialState or None
            ``None`` for a ``base`` case (the default start).
        duration : float
            Simulated time [s].
        """
        isolator = self.isolator(nominal)
        if self.family == "base":
            return excitation, isolator, None, duration
        if self.family == "step":
            integral = _preload(isolator, controller) + self.force_step / controller.pi_ki
            return excitation, isolator, InitialState(pi_integral=integral), duration
        offset, length = _hunting_start(isolator, controller, HUNTING_MAX[bool(quick)])
        return QUIET, isolator, InitialState(
            relative_position=controller.position_setpoint + offset), length


def _levels(low, high, count):
    if high == low:
        return (low,)
    return (low, high) if count == 2 else tuple(np.linspace(low, high, count))


def _cases(stiction_range, mass_range, force_steps, quick):
    """Stiction at its range's ends (and middle unless quick), mass at its ends: the effects of
    both are monotone in what was measured, stiction's strongly (the hunting plateau grows
    with it), so the ends bound them and the middle checks it."""
    plants = [(fs, m) for fs in _levels(*stiction_range, 2 if quick else 3)
              for m in _levels(*mass_range, 2)]
    cases = [DesignCase("base", fs, m) for fs, m in plants]
    cases += [DesignCase("step", fs, m, step) for fs, m in plants for step in force_steps]
    cases += [DesignCase("hunting", fs, m) for fs, m in plants]
    return cases


def _preload(isolator, controller):
    """The integral [m*s] the default start preloads (docs/model.md §5)."""
    z_ref = controller.position_setpoint
    needed = isolator.mass * isolator.gravity - float(spring_force(z_ref, isolator))
    needed = float(np.clip(needed, -isolator.motor_force_max, isolator.motor_force_max))
    return needed / controller.pi_ki


QUIET = Sine(amplitude=0.0, frequency=1.0, fade_in=0.0)


def _loop_stiffness(isolator, controller):
    """``k(z_ref) + Kp`` [N/m]."""
    return float(spring_stiffness(controller.position_setpoint, isolator)) + controller.pi_kp


def _hunting_start(isolator, controller, maximum):
    """Release offset [m] and duration [s] of a hunting case at these gains."""
    d = 0.5 * cd.slip_jump(isolator, controller)[0]
    k_total = _loop_stiffness(isolator, controller)
    if d > 0 and k_total > 0:
        offset = d / k_total
        period = 4 * (isolator.stiction_force - d) * k_total / (controller.pi_ki * d)
    else:
        offset, period = 0.005, 30.0
    offset = float(np.clip(offset, 0.001, 0.5 * isolator.stroke_half))
    first = isolator.stiction_force / (controller.pi_ki * offset)
    return offset, float(np.clip(first + 4 * period, 30.0, maximum))
