"""A six-axis platform's set-up as an object: :class:`HexapodSetup`, the platform the legs'
springs hold by default, and the set-ups made from objects (:func:`hexapod_setup`), with
centralised control (:func:`centralised`) or other spring laws (:func:`with_spring_laws`).

A hexapod file is read into one by :func:`qzs.workflows.hexapod.setups.load_hexapod`, which
re-exports these names. The model is described in docs/hexapod.md.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from qzs.defaults import HEXAPOD
from qzs.errors import ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.hexapod import (LEG_COUNT, CartesianController, HexapodGeometry,
                               PlatformParameters, cubic_geometry, leg_unit_vectors)
from qzs.model.isolator import IsolatorParameters, spring_force
from qzs.workflows.hexapod.legs import (_checked_legs, _refuse_central_blocks, _sources,
                                        _with_settings, with_springs)

__all__ = ["HexapodSetup", "hexapod_setup", "supported_mass", "default_platform",
           "default_cube_center_height", "centralised", "with_spring_laws"]


@dataclass(frozen=True, kw_only=True)
class HexapodSetup:
    """A six-legged platform ready to analyse or simulate.

    Attributes
    ----------
    geometry : HexapodGeometry
        Joints and home pose.
    platform : PlatformParameters
        The rigid top with its payload.
    isolator : IsolatorParameters
        Each leg's plant (its ``mass`` and ``gravity`` are not used: the platform's are).
    controller : ControllerParameters
        Every leg's controller (the ``[controller]`` table): PI and damping, and blocks
        (docs/hexapod.md §9.5a).
    kind : str
        How the geometry was described (``cubic``, ``radial``, ``joints``).
    excitation : dict
        ``[excitation.<axis>]`` tables, axis name -> options (for a simulation).
    simulation : dict
        ``[simulation]`` options (for a simulation).
    source : str
        The file it was read from ('' if built from arguments).
    cartesian : CartesianController or None
        Centralised control (the ``[cartesian]`` table); None: a loop per leg.
    leg_controllers : tuple of six ControllerParameters or None
        Each leg's own controller where one leg's differs (``[legs.N.controller]``
        tables); None: ``controller`` on every leg.
    leg_isolators : tuple of six IsolatorParameters or None
        Each leg's own plant where one leg's spring law differs (:func:`with_spring_laws`); None:
        ``isolator`` on every leg.
    """

    geometry: HexapodGeometry
    platform: PlatformParameters
    isolator: IsolatorParameters
    controller: ControllerParameters
    kind: str = "joints"
    excitation: dict = field(default_factory=dict)
    simulation: dict = field(default_factory=dict)
    source: str = ""
    cartesian: CartesianController | None = None
    leg_controllers: tuple[ControllerParameters, ...] | None = None
    leg_isolators: tuple[IsolatorParameters, ...] | None = None

    @property
    def isolators(self) -> IsolatorParameters | tuple[IsolatorParameters, ...]:
        """What the engine takes: ``isolator`` for every leg, or the six ``leg_isolators``."""
        return self.isolator if self.leg_isolators is None else self.leg_isolators

    @property
    def controllers(self) -> ControllerParameters | tuple[ControllerParameters, ...]:
        """What the engine takes: ``controller`` for every leg, or the six
        ``leg_controllers``."""
        return self.controller if self.leg_controllers is None else self.leg_controllers


def default_cube_center_height(cube_edge: float) -> float:
    """Height [m] of the cube's centre that puts the legs' lower ends on the base plane.

    The six legs of the cubic configuration run along six edges of a cube standing on a
    vertex, between its three lower and three upper side vertices, which lie
    ``a/(2*sqrt(3))`` below and above its centre.

    Parameters
    ----------
    cube_edge : float
        Edge of the cube [m].

    Returns
    -------
    float
        ``cube_edge / (2 * sqrt(3))`` [m].
    """
    return float(cube_edge) / (2.0 * math.sqrt(3.0))


def supported_mass(geometry, isolator=None, controller=None, *, gravity=9.81):
    """The mass [kg] the legs' MagSprings hold at the operating point, by themselves.

    Each spring pushes with ``spring_force(z_ref)`` along its leg at the home pose;
    the vertical part of their sum, divided by ``gravity``, is the payload they carry
    without help from the PI loop (the paper's single leg: 60.84 N, 6.20 kg at 9.81).

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform.
    isolator : IsolatorParameters, optional
        Each leg's plant; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Each leg's loop (its setpoint is the operating point); defaults if omitted.
    gravity : float
        Gravitational acceleration [m/s^2], > 0.

    Returns
    -------
    float
        Mass [kg].
    """
    isolator = isolator or IsolatorParameters()
    controller = controller or ControllerParameters()
    if not gravity > 0:
        raise ParameterError(f"`gravity` must be positive to carry a mass, got {gravity!r} m/s^2.")
    force = float(spring_force(controller.position_setpoint, isolator))  # > 0: pushes it away
    vertical = float(np.sum(leg_unit_vectors(geometry)[:, 2])) * force
    if not vertical > 0:
        raise ParameterError(f"the legs' springs push the platform down ({vertical:g} N) at "
                             "the operating point: they hold no payload; give [platform] mass.")
    return vertical / gravity


def default_platform(geometry, isolator=None, controller=None, *, gravity=9.81):
    """A platform the legs' springs hold at the operating point: a disc through the top joints.

    Mass :func:`supported_mass`; centre of mass at the top frame origin; the inertia of
    a uniform thin disc whose radius is the top joints' mean distance from the top
    frame's z axis (``m r^2/4`` about x and y, ``m r^2/2`` about z).

    Parameters
    ----------
    geometry : HexapodGeometry
        The platform.
    isolator : IsolatorParameters, optional
        Each leg's plant.
    controller : ControllerParameters, optional
        Each leg's loop.
    gravity : float
        Gravitational acceleration [m/s^2].

    Returns
    -------
    PlatformParameters
    """
    mass = supported_mass(geometry, isolator, controller, gravity=gravity)
    radius = float(np.mean(np.hypot(geometry.top_joints[:, 0], geometry.top_joints[:, 1])))
    inertia = mass * radius ** 2 * np.diag([0.25, 0.25, 0.5])
    return PlatformParameters(mass=mass, inertia=inertia, gravity=gravity)


def hexapod_setup(*, geometry: HexapodGeometry | None = None,
                  platform: PlatformParameters | None = None,
                  isolator: IsolatorParameters | None = None,
                  controller: ControllerParameters | None = None,
                  settings: Mapping[str, Any] | None = None, kind: str = "joints",
                  cartesian: CartesianController | str | None = None,
                  legs: Mapping[int, ControllerParameters] | None = None) -> HexapodSetup:
    """A :class:`HexapodSetup` from objects, with registry overrides applied to every leg.

    Parameters
    ----------
    geometry : HexapodGeometry, optional
        Default: the cubic configuration of edge 0.15 m with its lower ends on the base
        plane (:func:`default_cube_center_height`).
    platform : PlatformParameters, optional
        Default: :func:`default_platform` (after ``settings``).
    isolator : IsolatorParameters, optional
        Each leg's plant; Table 1 defaults if omitted.
    controller : ControllerParameters, optional
        Each leg's loop; defaults if omitted.
    settings : dict, optional
        ``name -> value`` overrides by registry name (``qzs params``; ``--set``).
    kind : str
        How ``geometry`` was described, for reports.
    cartesian : CartesianController or "legs", optional
        Centralised control; ``"legs"`` for the Cartesian loops with the legs' stiffness on
        each axis at the top frame origin (:meth:`CartesianController.from_legs`).
    legs : dict, optional
        Leg number (1 to 6) -> that leg's own controller (``controller`` on the others);
        ``settings`` apply to them too. Refused with ``cartesian`` if one has blocks.

    Returns
    -------
    HexapodSetup
    """
    own = _checked_legs(legs)
    if geometry is None:
        edge = HEXAPOD["cube_edge"]
        geometry = cubic_geometry(cube_edge=edge,
                                  cube_center_height=default_cube_center_height(edge))
        kind = "cubic"
    if not isinstance(geometry, HexapodGeometry):
        raise ParameterError(f"`geometry` must be a HexapodGeometry, got "
                             f"{type(geometry).__name__}.")
    isolator, controller, leg_controllers = _with_settings(
        isolator or IsolatorParameters(), controller or ControllerParameters(), own,
        settings or {})
    if platform is None:
        platform = default_platform(geometry, isolator, controller)
    if not isinstance(platform, PlatformParameters):
        raise ParameterError(f"`platform` must be a PlatformParameters, got "
                             f"{type(platform).__name__}.")
    if isinstance(cartesian, str) and cartesian == "legs":
        cartesian = CartesianController.from_legs(geometry, controller)
    if cartesian is not None and not isinstance(cartesian, CartesianController):
        raise ParameterError(f"`cartesian` must be a CartesianController, 'legs' or None, got "
                             f"{cartesian!r}.")
    if cartesian is not None:
        _refuse_central_blocks(controller, leg_controllers, "`cartesian`",
                               _sources("controller", own, lambda n: f"legs[{n}]"))
    return HexapodSetup(geometry=geometry, platform=platform, isolator=isolator,
                        controller=controller, kind=kind, cartesian=cartesian,
                        leg_controllers=leg_controllers)


def centralised(setup: HexapodSetup, *,
                point: str | ArrayLike = "origin") -> HexapodSetup:
    """The set-up with centralised control: Cartesian loops with the legs' stiffness on each
    axis (:meth:`~qzs.model.hexapod.CartesianController.from_legs`, docs/hexapod.md §9.5).

    Parameters
    ----------
    setup : HexapodSetup
        A set-up with per-leg loops.
    point : {"origin", "center_of_mass"} or array_like, shape (3,)
        Where the axes are (the top frame origin: the cube's centre of a cubic geometry).

    Returns
    -------
    HexapodSetup

    Raises
    ------
    ParameterError
        The set-up has its own ``[cartesian]`` loops already, or a leg's controller has
        blocks (they act on a leg's own loop).
    """
    import dataclasses

    if setup.cartesian is not None:
        raise ParameterError("the set-up has centralised loops already (its [cartesian] table); "
                             "leave out --centralised, or the table.")
    _refuse_central_blocks(setup.controller, setup.leg_controllers, "--centralised",
                           [f"leg {n}'s controller" for n in range(1, LEG_COUNT + 1)])
    cartesian = CartesianController.from_legs(setup.geometry, setup.controllers,
                                              platform=setup.platform, point=point)
    return dataclasses.replace(setup, cartesian=cartesian)


def with_spring_laws(setup: HexapodSetup, spring: Any = None,
            legs: Mapping[int, Any] | None = None) -> HexapodSetup:
    """The set-up with its legs' spring laws replaced (``--spring``, ``--leg-spring``).

    The platform stays the set-up's (a default one is what the set-up's springs hold at the
    setpoint; the PI's integral carries what a new law holds less, docs/model.md §5).

    Parameters
    ----------
    setup : HexapodSetup
        The platform.
    spring : SpringLaw, optional
        Every leg's law (docs/model.md §3.1); default the set-up's.
    legs : dict, optional
        Leg number (1 to 6) -> that leg's own law (:func:`read_leg_springs`).

    Returns
    -------
    HexapodSetup
    """
    import dataclasses

    plants = with_springs(setup.isolator, spring, legs)
    if isinstance(plants, IsolatorParameters):
        return dataclasses.replace(setup, isolator=plants, leg_isolators=None)
    every = with_springs(setup.isolator, spring)
    assert isinstance(every, IsolatorParameters)  # no legs given: one plant for all
    return dataclasses.replace(setup, isolator=every, leg_isolators=plants)
