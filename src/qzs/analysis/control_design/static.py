"""The static design at the setpoint: what the MagSpring carries, what is left for control.

:func:`static_design` gives what the MagSpring carries at the setpoint, the static deficit
``m*g - F_spring(z_ref)`` the PI integral must supply, the motor force left for control, and
the payloads spring and motor can hold; :func:`constant_force_band` the band of relative
positions about the setpoint inside the spring's constant-force region.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from qzs._validation import interval
from qzs.errors import ParameterError
from qzs.model.isolator import spring_force
from qzs.model.registry import model_inputs

__all__ = ["StaticDesign", "static_design", "constant_force_band", "PAPER_ADDED_MASS"]

#: Mass the paper added on top of the moving parts to balance the MagSpring [kg] (Section 4).
PAPER_ADDED_MASS = 5.5


@dataclass(frozen=True)
class StaticDesign:
    """What the MagSpring carries at the operating point, and what is left for control.

    Attributes
    ----------
    position_setpoint : float
        Operating point z_ref [m].
    spring_force_at_setpoint : float
        Upward force of the MagSpring at the setpoint, ``F_spring(z_ref) = -a*tanh(b*z_ref)`` [N].
    weight : float
        Weight ``m*g`` of the moving mass [N].
    static_deficit : float
        ``m*g - spring force`` [N]: what the PI integral must supply at rest (negative: the
        spring pushes up more than the weight, the motor must hold it down).
    motor_force_max : float
        Motor saturation [N].
    motor_force_left : float
        ``F_max - |static deficit|`` [N]: force left for the loops; negative: the motor
        cannot hold the payload at the setpoint at all.
    balanced_mass : float
        Mass the spring alone carries at the setpoint, ``spring force/g`` [kg] (NaN
        without gravity).
    holdable_mass : tuple of float
        Masses spring and saturated motor can hold at the setpoint [kg, kg]:
        ``(spring force - F_max)/g`` to ``(spring force + F_max)/g``.
    constant_force_band : tuple of float
        Relative positions [m, m] around the setpoint inside the constant-force region
        (spring force within 1 % of its plateau): the edge ``-atanh(0.99)/b`` above the
        setpoint, mirrored below it.
    spring_force_band : tuple of float
        Least and largest spring force over that band [N, N].
    mass_range : tuple of float
        The payload masses considered [kg, kg] (the design's range; the mass itself if none).
    deficit_range : tuple of float
        Static deficit at the lightest and heaviest of them [N, N].
    motor_force_left_min : float
        Least force left for control over the mass range [N].
    moving_mass_without_added : float
        The moving mass less the paper's added 5.5 kg [kg] (its rig without the payload).
    deficit_without_added : float
        Static deficit of that lighter moving mass [N]: beyond ``-F_max`` the motor could not
        hold the spring down, which is why the paper added the payload.
    reasons : dict
        Name -> why a number is NaN.
    """

    position_setpoint: float
    spring_force_at_setpoint: float
    weight: float
    static_deficit: float
    motor_force_max: float
    motor_force_left: float
    balanced_mass: float
    holdable_mass: tuple
    constant_force_band: tuple
    spring_force_band: tuple
    mass_range: tuple
    deficit_range: tuple
    motor_force_left_min: float
    moving_mass_without_added: float
    deficit_without_added: float
    reasons: dict = field(default_factory=dict)

    def to_dict(self):
        """The numbers as a plain ``dict`` (tuples as lists)."""
        return {name: (list(value) if isinstance(value, tuple) else value)
                for name, value in self.__dict__.items()}


def constant_force_band(isolator=None, controller=None):
    """Relative positions [m, m] of the constant-force band around the setpoint.

    Above the setpoint the band ends at the spring's constant-force edge
    (:attr:`IsolatorParameters.constant_force_edge`, the spring within 1 % of its
    plateau); below it the band is mirrored (the paper: a region of about 60 mm with the
    setpoint in its middle; the ``tanh`` fit itself stays flat below).

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies the setpoint; defaults if omitted.

    Returns
    -------
    tuple of float
        ``(low, high)`` [m]; ``high`` is the edge, ``low = 2*z_ref - edge``.

    Raises
    ------
    ParameterError
        The setpoint lies above the edge, outside the constant-force region.
    """
    isolator, controller = model_inputs(isolator, controller)
    edge = isolator.constant_force_edge
    setpoint = controller.position_setpoint
    if setpoint >= edge:
        raise ParameterError(
            f"the `position_setpoint` ({setpoint:g} m) lies at or above the spring's "
            f"constant-force edge ({edge:.4g} m): the design needs the setpoint inside the "
            "constant-force region; lower it (e.g. -0.060 m).")
    return (2 * setpoint - edge, edge)


def static_design(isolator=None, controller=None, *, mass_range=None):
    """The static design at the setpoint: spring load, deficit and the force left for control.

    Parameters
    ----------
    isolator : IsolatorParameters, optional
        Plant parameters; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Supplies the setpoint; defaults if omitted.
    mass_range : tuple of float, optional
        Payload masses to consider [kg, kg]; default the isolator's mass alone.

    Returns
    -------
    StaticDesign
    """
    isolator, controller = model_inputs(isolator, controller)
    z_ref = controller.position_setpoint
    lifted = float(spring_force(z_ref, isolator))
    g = isolator.gravity
    weight = isolator.mass * g
    deficit = weight - lifted
    f_max = isolator.motor_force_max
    reasons = {}
    if g > 0:
        balanced = lifted / g
        holdable = (max(0.0, (lifted - f_max) / g), (lifted + f_max) / g)
    else:
        balanced, holdable = math.nan, (math.nan, math.nan)
        reason = "no gravity: the payload's weight does not load the spring"
        reasons.update(balanced_mass=reason, holdable_mass=reason)
    band = constant_force_band(isolator, controller)
    forces = spring_force(np.linspace(band[0], band[1], 201), isolator)
    masses = (isolator.mass, isolator.mass) if mass_range is None else interval(
        "mass_range", mass_range, "kg", minimum=1e-12)
    deficits = (masses[0] * g - lifted, masses[1] * g - lifted)
    left_min = f_max - max(abs(d) for d in deficits)
    bare = isolator.mass - PAPER_ADDED_MASS
    if bare > 0:
        bare_deficit = bare * g - lifted
    else:
        bare_deficit = math.nan
        reasons["deficit_without_added"] = (f"the moving mass ({isolator.mass:g} kg) is not "
                                            f"above the paper's added {PAPER_ADDED_MASS:g} kg")
    return StaticDesign(
        position_setpoint=z_ref, spring_force_at_setpoint=lifted, weight=weight,
        static_deficit=deficit, motor_force_max=f_max, motor_force_left=f_max - abs(deficit),
        balanced_mass=balanced, holdable_mass=holdable, constant_force_band=band,
        spring_force_band=(float(forces.min()), float(forces.max())), mass_range=masses,
        deficit_range=deficits, motor_force_left_min=left_min,
        moving_mass_without_added=bare if bare > 0 else math.nan,
        deficit_without_added=bare_deficit, reasons=reasons)
