"""Six-axis platform set-ups: TOML files, defaults, and the reports behind ``qzs hexapod``.

A hexapod file (``qzs hexapod linear --config FILE.toml``)::

    [geometry]                # kind = "cubic" | "radial" | "joints"
    kind = "cubic"
    cube_edge = 0.15          # [m]
    cube_center_height = 0.0433   # [m]; default: the legs' lower ends on the base plane
    stroke_half = 0.080       # [m] each leg's guide: stops at z_ref +- stroke_half

    [platform]                # optional; default: the mass the six MagSprings hold at the
    mass = 21.48              # operating point [kg], a uniform disc through the top joints
    principal_inertia = [0.2, 0.2, 0.4]   # [kg*m^2] (or inertia = 3x3), about the centre of mass
    center_of_mass = [0.0, 0.0, 0.0]      # [m], top frame
    gravity = 9.81            # [m/s^2]

    [leg]                     # each leg: isolator parameters by registry name (qzs params)
    stiction_force = 10.0
    [controller]              # each leg's PI and damping loop (qzs params)
    pi_kp = 50.0
    controller_rate = 0.0     # [Hz] 0: continuous; else sampled, zero-order hold
    [controller.dither]       # optional: blocks for every leg, as a single axis's controller
    amplitude = 0.5           # file (qzs.iotools.config.controller_from_table)

    [legs.2.controller.compensation]  # optional: leg 2's own controller, from every leg's
    fraction = 0.8            # [controller] with these changes (legs numbered 1 to 6)

    [cartesian]               # optional: centralised control, the loops on the platform's
    point = "origin"          # axes at this point ("origin", "center_of_mass" or [x, y, z] [m])
    position_gain = [8000.0, 8000.0, 8000.0, 45.0, 45.0, 180.0]  # per axis x..rz; default the
    # legs' loops' stiffness on each axis; also integral_gain and damping_gain (docs/hexapod.md §9.5)

``radial`` takes ``base_radius``, ``top_radius``, ``height`` [m] and ``base_angle``,
``top_angle`` [deg]; ``joints`` takes ``base_joints`` and ``top_joints`` (6 x 3) and
``home_position`` (3) [m]. The model is described in docs/hexapod.md.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from qzs._format import number
from qzs._validation import read_toml, real
from qzs.defaults import AXES, HEXAPOD
from qzs.errors import ParameterError
from qzs.iotools.shipped import resolve_shipped
from qzs.model.controller import ControllerParameters
from qzs.model.hexapod import (LEG_COUNT, CartesianController, HexapodGeometry,
                               PlatformParameters, cubic_geometry, leg_unit_vectors,
                               radial_geometry)
from qzs.model.isolator import IsolatorParameters, spring_force
from qzs.model.registry import update_parameters
from qzs.workflows.hexapod.legs import (_checked_legs, _controller, _file_legs, _parameters,
                                        _refuse_central_blocks, _sources, _with_settings,
                                        read_leg_controllers, read_leg_springs, with_springs)

if TYPE_CHECKING:
    from qzs.analysis.hexapod_linear import HexapodLinearModel
    from qzs.engine.hexapod.result import HexapodResult

__all__ = ["HexapodSetup", "GEOMETRY_KINDS", "AXES", "load_hexapod", "hexapod_setup",
           "supported_mass", "default_platform", "default_cube_center_height",
           "linear_record", "linear_text", "plot_linear_transmissibility", "simulate_setup",
           "SHIPPED", "SHIPPED_DEFAULT", "SIMULATION_KEYS", "centralised",
           "read_leg_controllers", "read_leg_springs", "with_spring_laws"]

#: Folder of the shipped hexapod files, inside the package.
SHIPPED = "workflows/hexapod/hexapod_files"
#: The shipped file ``qzs hexapod`` uses without --config or --cubic.
SHIPPED_DEFAULT = "paper_legs_cubic"
#: Keys of a hexapod file's ``[simulation]`` table.
SIMULATION_KEYS = ("dt", "sample_rate", "solver", "duration")

#: How a ``[geometry]`` table describes the platform: its keys per kind (required, optional).
GEOMETRY_KINDS = {
    "cubic": (("cube_edge",), ("cube_center_height", "base_radius", "top_radius",
                                "stroke_half")),
    "radial": (("base_radius", "top_radius", "base_angle", "top_angle", "height"),
               ("stroke_half",)),
    "joints": (("base_joints", "top_joints", "home_position"), ("stroke_half",)),
}
#: Units of the stiffness matrix's blocks (translation rows/columns first).
STIFFNESS_UNITS = (("N/m", "N/rad"), ("N", "N*m/rad"))
_FRAME_WORDS = {"center_of_mass": "payload's centre of mass", "origin": "top frame origin",
                "cube_center": "cube's centre"}
_PLATFORM_KEYS = ("mass", "inertia", "principal_inertia", "center_of_mass", "gravity")


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


#: Units of the scalar keys of a hexapod file's tables, for the messages.
_SCALAR_UNITS = {"cube_edge": "m", "cube_center_height": "m", "base_radius": "m",
                 "top_radius": "m", "stroke_half": "m", "height": "m", "base_angle": "deg",
                 "top_angle": "deg", "mass": "kg", "gravity": "m/s^2"}
_EXAMPLES = {"mass": 21.5, "gravity": 9.81, "base_angle": 10.0, "top_angle": 10.0,
             "cube_edge": 0.15}


def _numbers(table, section, where):
    """The table with its scalar keys checked: each a real number (a TOML string such as
    ``mass = "heavy"`` is an error naming the file, the table, the key and the value)."""
    checked = dict(table)
    for key, unit in _SCALAR_UNITS.items():
        if key in checked:
            checked[key] = real(f"[{section}] {key}", checked[key],
                                fix=f"give a number in {unit}, e.g. {key} = "
                                    f"{_EXAMPLES.get(key, 0.1)}",
                                error=lambda message: ParameterError(where + message))
    return checked


def _geometry(table, where):
    table = _numbers(table, "geometry", where)
    kind = table.pop("kind", None)
    if kind not in GEOMETRY_KINDS:
        raise ParameterError(f"{where}[geometry] `kind` must be one of {sorted(GEOMETRY_KINDS)}, "
                             f"got {kind!r}.")
    required, optional = GEOMETRY_KINDS[kind]
    missing = [k for k in required if k not in table]
    unknown = sorted(set(table) - set(required) - set(optional))
    if missing or unknown:
        raise ParameterError(f"{where}[geometry] of kind {kind!r} needs {list(required)} and "
                             f"may have {list(optional)}; "
                             + (f"missing {missing}" if missing else f"unknown {unknown}") + ".")
    if kind == "cubic":
        table.setdefault("cube_center_height", default_cube_center_height(table["cube_edge"]))
        return cubic_geometry(**table), kind
    if kind == "radial":
        for name in ("base_angle", "top_angle"):
            table[name] = math.radians(float(table[name]))
        return radial_geometry(**table), kind
    return HexapodGeometry(**table), kind


def _platform(table, geometry, isolator, controller, where):
    table = _numbers(table, "platform", where)
    unknown = sorted(set(table) - set(_PLATFORM_KEYS))
    if unknown:
        raise ParameterError(f"{where}[platform]: unknown key(s) {unknown}; allowed are "
                             f"{list(_PLATFORM_KEYS)}.")
    if "inertia" in table and "principal_inertia" in table:
        raise ParameterError(f"{where}[platform]: give `inertia` (3 x 3) or `principal_inertia` "
                             "(3), not both.")
    gravity = table.get("gravity", 9.81)
    default = default_platform(geometry, isolator, controller, gravity=gravity) if (
        "mass" not in table or not ("inertia" in table or "principal_inertia" in table)) else None
    mass = table.get("mass", default.mass if default else None)
    if "principal_inertia" in table:
        given = table["principal_inertia"]
        values = np.full(0, np.nan)
        if isinstance(given, list) and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                           for v in given):
            values = np.asarray(given, dtype=float)
        if values.shape != (3,):
            raise ParameterError(f"{where}[platform] `principal_inertia` must be 3 moments "
                                 f"[kg*m^2], got {table['principal_inertia']!r}.")
        inertia = np.diag(values)
    elif "inertia" in table:
        inertia = table["inertia"]
    else:
        inertia = default.inertia * (float(mass) / default.mass)
    return PlatformParameters(mass=mass, inertia=inertia,
                              center_of_mass=table.get("center_of_mass", (0.0, 0.0, 0.0)),
                              gravity=gravity)


_CARTESIAN_KEYS = ("point", "position_gain", "integral_gain", "damping_gain")


def _cartesian(table, geometry, platform, controller, where):
    """A ``[cartesian]`` table as a CartesianController (gains left out: the legs' loops')."""
    unknown = sorted(set(table) - set(_CARTESIAN_KEYS))
    if unknown:
        raise ParameterError(f"{where}[cartesian]: unknown key(s) {unknown}; allowed are "
                             f"{list(_CARTESIAN_KEYS)}.")
    point = table.get("point", "origin")
    legs = CartesianController.from_legs(geometry, controller, platform=platform, point=point)
    return CartesianController(**{name: table.get(name, getattr(legs, name))
                                  for name in _CARTESIAN_KEYS[1:]}, point=point)


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


def load_hexapod(path: str | Path,
                 settings: Mapping[str, Any] | None = None, *,
                 controller: ControllerParameters | None = None,
                 legs: Mapping[int, ControllerParameters] | None = None,
                 names: Mapping[str, str] | None = None) -> HexapodSetup:
    """Read a hexapod TOML file (the layout of this module's docstring).

    The ``[controller]`` table is every leg's controller, blocks included (its
    ``[controller.compensation]``, ``[controller.dither]``, ``[controller.linear]`` tables,
    read by :func:`qzs.iotools.config.controller_from_table`, as a single axis's); a
    ``[legs.N.controller]`` table (N from 1 to 6) gives leg N its own: every leg's with
    that table's changes and blocks (``[legs.2.controller.dither]``).

    Parameters
    ----------
    path : str or Path
        The file, or the name of a shipped one (``paper_legs_cubic``).
    settings : dict, optional
        Registry overrides applied to every leg after the file (``--set``).
    controller : ControllerParameters, optional
        Every leg's controller instead of the file's ``[controller]`` and
        ``[legs.N.controller]`` tables (``--controller``).
    legs : dict, optional
        Leg number (1 to 6) -> that leg's controller instead of the file's
        (``--leg-controller``; :func:`read_leg_controllers`).
    names : dict, optional
        How the caller names ``controller`` and ``legs[N]`` in messages.

    Returns
    -------
    HexapodSetup

    Raises
    ------
    ParameterError
        A missing or malformed file, an unknown table or key, a bad value, a leg number
        outside 1 to 6 or given twice, blocks with centralised control (``[cartesian]``).
    """
    path = resolve_shipped(path, SHIPPED, "hexapod", "hexapod files")
    document = read_toml(path, "hexapod file", empty=(
        "write the platform's tables into it (`qzs docs hexapod` describes them; the shipped "
        "setups are examples), or give no file for the default platform"))
    where = f"{str(path)!r}: "
    allowed = {"geometry", "platform", "leg", "controller", "excitation", "simulation",
               "cartesian", "legs"}
    unknown = sorted(set(document) - allowed)
    if unknown:
        raise ParameterError(f"{where}unknown table(s) {unknown}; allowed are {sorted(allowed)}.")
    if "geometry" not in document:
        raise ParameterError(f"{where}a [geometry] table is needed (kind = 'cubic', 'radial' "
                             "or 'joints').")
    _parameters(document.get("leg", {}), "leg", "isolator", where)
    isolator, _ = update_parameters(IsolatorParameters(), ControllerParameters(),
                                    document.get("leg", {}))
    every = _controller(document.get("controller", {}), "controller", path)
    own = _file_legs(document.get("legs", {}), every, path)
    names = dict(names or {})
    sources = _sources(f"[controller] in {str(path)!r}", own,
                       lambda n: f"[legs.{n}.controller] in {str(path)!r}")
    if controller is not None:  # instead of the file's every leg and each leg's own
        every, own = controller, {}
        sources = (names.get("controller", "controller"),) * LEG_COUNT
    given = _checked_legs(legs)
    own.update(given)
    sources = tuple(names.get(f"legs[{n}]", f"legs[{n}]") if n in given else source
                    for n, source in enumerate(sources, start=1))
    isolator, controller, leg_controllers = _with_settings(isolator, every, own,
                                                           settings or {})
    geometry, kind = _geometry(document["geometry"], where)
    platform = _platform(document.get("platform", {}), geometry, isolator, controller, where)
    excitation = document.get("excitation", {})
    wrong = sorted(set(excitation) - set(AXES))
    if wrong:
        raise ParameterError(f"{where}[excitation.<axis>] axes must be among {list(AXES)}, got "
                             f"{wrong}.")
    simulation = dict(document.get("simulation", {}))
    wrong = sorted(set(simulation) - set(SIMULATION_KEYS))
    if wrong:
        raise ParameterError(f"{where}[simulation]: unknown key(s) {wrong}; allowed are "
                             f"{list(SIMULATION_KEYS)}.")
    for axis, options in excitation.items():
        if not isinstance(options, dict) or "kind" not in options:
            raise ParameterError(f"{where}[excitation.{axis}] needs a `kind` (chirp, sine, "
                                 "random or file) and its options.")
    cartesian = None
    if "cartesian" in document:
        _refuse_central_blocks(controller, leg_controllers, f"[cartesian] in {str(path)!r}",
                               sources)
        cartesian = _cartesian(document["cartesian"], geometry, platform,
                               leg_controllers or controller, where)
    return HexapodSetup(geometry=geometry, platform=platform, isolator=isolator,
                        controller=controller, kind=kind, excitation=dict(excitation),
                        simulation=simulation, source=str(path), cartesian=cartesian,
                        leg_controllers=leg_controllers)








def linear_record(setup: HexapodSetup, *, leg_stiffness: float | None = None,
                  frame: str | ArrayLike = "center_of_mass",
                  include_preload: bool = True) -> tuple[HexapodLinearModel, dict[str, Any]]:
    """The linear analysis of a set-up as data (``qzs hexapod linear --json``).

    Parameters
    ----------
    setup : HexapodSetup
        The platform.
    leg_stiffness : float, optional
        Replace every leg's axial stiffness [N/m] (a purely linear analysis).
    frame : {"center_of_mass", "origin", "cube_center"} or array_like
        Where the matrices are expressed: the payload's centre of mass, the top frame
        origin, the cube's centre (a cubic geometry only: its top frame origin), or a
        point in the top frame [m].
    include_preload : bool
        Include the geometric stiffness of the static leg forces.

    Returns
    -------
    model : HexapodLinearModel
    record : dict
        ``stiffness_matrix`` (6x6, SI: N/m, N/rad, N, N*m/rad), ``damping_matrix``,
        ``mass_matrix``, ``natural_frequencies`` [Hz] (None where a direction is
        statically unstable, with ``notes``), ``mode_shapes``, ``stable``, ``frame``,
        ``static_leg_forces`` [N], ``units``.
    """
    from qzs.analysis.hexapod_linear import hexapod_linearize

    requested = frame
    if isinstance(frame, str) and frame == "cube_center":
        if setup.kind != "cubic":
            raise ParameterError(f"`frame` 'cube_center' needs a cubic geometry, got a "
                                 f"{setup.kind!r} one; use 'center_of_mass', 'origin' or a point.")
        frame = "origin"
    model = hexapod_linearize(setup.geometry, setup.platform, setup.isolators, setup.controllers,
                              leg_stiffness=leg_stiffness, frame=frame,
                              include_preload=include_preload, cartesian=setup.cartesian)
    record = {
        "frame": requested if isinstance(requested, str) else np.asarray(frame, dtype=float),
        "axes": list(AXES),
        "stiffness_matrix": model.stiffness_matrix,
        "damping_matrix": model.damping_matrix,
        "mass_matrix": model.mass_matrix,
        "natural_frequencies": model.natural_frequencies,
        "mode_shapes": model.mode_shapes,
        "stable": bool(model.stable),
        "static_leg_forces": model.leg_forces,
        "include_preload": bool(include_preload),
        "leg_stiffness": leg_stiffness,
        "platform_mass": setup.platform.mass,
        "notes": list(model.notes),
        "units": {"stiffness_matrix": "N/m | N/rad (rows x,y,z) ; N | N*m/rad (rows rx,ry,rz)",
                  "damping_matrix": "N*s/m | N*s/rad ; N*s | N*m*s/rad",
                  "mass_matrix": "kg | kg*m ; kg*m | kg*m^2",
                  "natural_frequencies": "Hz", "static_leg_forces": "N",
                  "leg_stiffness": "N/m", "platform_mass": "kg"},
    }
    return model, record


def linear_text(setup: HexapodSetup, model: HexapodLinearModel,
                record: Mapping[str, Any]) -> str:
    """The linear analysis as text for people (``qzs hexapod linear``).

    Parameters
    ----------
    setup : HexapodSetup
        The platform.
    model : HexapodLinearModel
        Its linearisation.
    record : dict
        :func:`linear_record`'s record.

    Returns
    -------
    str
    """
    frame = record["frame"]
    lines = [f"qzs hexapod: {setup.kind} geometry, platform {setup.platform.mass:.4g} kg, "
             f"matrices at the "
             f"{_FRAME_WORDS.get(frame, frame) if isinstance(frame, str) else list(frame)}"
             + ("" if record["include_preload"] else ", without the preload stiffness")]
    if setup.cartesian is not None:
        point = setup.cartesian.point
        where = (f"the {_FRAME_WORDS[point]}" if isinstance(point, str)
                 else f"{list(point)} m")  # type: ignore[call-overload]  # a 3-vector
        gains = " ".join(f"{v:.4g}" for v in setup.cartesian.position_gain)
        lines.append(f"  centralised control: PI and damping loops on the platform's axes at "
                     f"{where}, Kp {gains} (N/m x3, N*m/rad x3)")
    if record["leg_stiffness"] is not None:
        lines.append(f"  every leg's axial stiffness set to {record['leg_stiffness']:g} N/m")
    forces = np.asarray(record["static_leg_forces"])
    lines.append("  static leg forces [N]  " + "  ".join(f"{f:8.3f}" for f in forces))
    lines.append("stiffness matrix  (rows/columns x y z [m], rx ry rz [rad]; "
                 "N/m, N/rad | N, N*m/rad)")
    header = "        " + "".join(f"{a:>12}" for a in AXES)
    lines.append(header)
    for axis, row in zip(AXES, np.asarray(record["stiffness_matrix"])):
        lines.append(f"  {axis:<6}" + "".join(f"{v:12.4g}" for v in row))
    lines.append("modes  (undamped, springs + Kp + preload; shapes at the frame point)")
    shapes = np.asarray(record["mode_shapes"])
    for j, frequency in enumerate(np.asarray(record["natural_frequencies"], dtype=float)):
        shape = shapes[:, j]
        main = AXES[int(np.argmax(np.abs(shape)))]
        shown = number(frequency, digits=4, unit="Hz", undefined="unstable")
        lines.append(f"  mode {j + 1}  {shown:>12}   mostly {main:<3} "
                     + " ".join(f"{v:8.3g}" for v in shape))
    for note in record["notes"]:
        lines.append(f"  note: {note}")
    if not record["stable"]:
        lines.append("  the platform is statically unstable in the directions without a "
                     "frequency: raise pi_kp (see `qzs docs hexapod` §6)")
    return "\n".join(lines)


def plot_linear_transmissibility(setup: HexapodSetup, model: HexapodLinearModel,
                                 out: str | Path, *,
                                 frequency_range: tuple[float, float] = (0.05, 50.0),
                                 points: int = 400, frequency_scale: str | None = None) -> Path:
    """Write the linear model's 6x6 transmissibility grid (:mod:`qzs.viz.hexapod_matrix`).

    Parameters
    ----------
    setup : HexapodSetup
        The platform (for the title).
    model : HexapodLinearModel
        Its linearisation.
    out : str or Path
        The figure file (.png, .svg or .pdf), written atomically.
    frequency_range : (float, float)
        Band drawn [Hz], log-spaced.
    points : int
        Frequencies drawn.
    frequency_scale : {"log", "linear"}, optional
        Frequency axis of the figures; default ``qzs.defaults.FIGURES["frequency_scale"]``
        (log).

    Returns
    -------
    Path
        ``out``.
    """
    from pathlib import Path

    import matplotlib.pyplot as plt

    from qzs.viz.hexapod_matrix import plot_transmissibility_matrix

    frequency = np.geomspace(*frequency_range, points)
    stability = "" if model.stable else " (linearly UNSTABLE: see the notes)"
    figure = plot_transmissibility_matrix(
        frequency, linear=model, out=out, frequency_scale=frequency_scale,
        title=f"Linear transmissibility of the {setup.kind} hexapod, platform "
              f"{setup.platform.mass:.3g} kg{stability}")
    plt.close(figure)
    return Path(out)


def simulate_setup(setup: HexapodSetup, *,
                   excitation: Mapping[str, Mapping[str, Any]] | None = None,
                   duration: float | None = None, dt: float | None = None,
                   tolerance: float | None = None, tolerance_state: float | None = None,
                   sample_rate: float | None = None, solver: str | None = None,
                   progress: bool = False, out: str | Path | None = None,
                   interruptible: bool = False, argument: str = "out",
                   names: Mapping[str, str] | None = None,
                   tolerance_db: float | None = None) -> HexapodResult:
    """Simulate a set-up: its file's ``[excitation.<axis>]`` and ``[simulation]``, overridable.

    With ``out`` every sample is streamed to that NetCDF file as the run goes
    (:class:`~qzs.engine.hexapod.result.HexapodWriter`): memory stays bounded however long
    the run, the path and the free space are checked before it starts, the file appears
    complete when it ends, and nothing is left behind on an error.

    Parameters
    ----------
    setup : HexapodSetup
        The platform (:func:`load_hexapod`, :func:`hexapod_setup`).
    excitation : dict, optional
        Axis name -> options (``kind`` and the options of
        :func:`qzs.model.build_excitation`) replacing the file's tables for those axes.
    duration : float, optional
        Simulated time [s]; default the file's, else the shortest excitation's length.
    dt : float, optional
        A literal integration step [s]. Default: the step chosen for a tolerance
        (:func:`qzs.engine.hexapod.accuracy.choose_hexapod_step`), halving down to the
        file's ``[simulation] dt`` (else 1e-4 s) and taking it where no coarser step meets
        the tolerance (:func:`qzs.engine.run_spec.resolve_hexapod`); ``result.run`` says
        which (:meth:`~qzs.engine.step_search.StepChoice.attributes`).
    tolerance : float, optional
        Tolerance [dB] on the driven axis's column of the transmissibility (one moving
        axis); the default measure, at ``qzs.defaults.ACCURACY["tolerance_db"]``, for a
        chirp along one axis.
    tolerance_state : float, optional
        Tolerance [m] on the platform's pose (rotations as arcs at the platform's size); the
        default measure, at ``ACCURACY["tolerance_state"]``, for any other base motion.
        At most one of the two, and neither with ``dt``.
    sample_rate : float, optional
        Output rate [Hz]; default the file's, else 1000.
    solver : {"ode3", "rk4", "euler"}, optional
        Integrator; default the file's, else ode3.
    progress : bool
        Show a progress bar over the step's probes and simulated time.
    out : str or Path, optional
        Stream the run to this ``.nc`` or ``.mat`` (MATLAB) file; the result then holds a
        preview (every ``run["preview_every"]``-th sample) and the statistics of all of them.
    interruptible : bool
        Ctrl-C ends the run after the chunk under way and keeps (and writes) what was
        simulated; ``run["completed"]`` says so.
    argument : str
        How the caller names ``out`` in messages (``"--out"`` on the command line).
    names : dict, optional
        How the caller names the options of ``excitation`` in messages (the command line's
        ``{"duration": "--excitation-duration"}``); the file's are named by their table
        (``[excitation.z] duration``).
    tolerance_db : float, optional
        Deprecated name of ``tolerance`` (warns; removed in the next release).

    Returns
    -------
    HexapodResult

    Raises
    ------
    ParameterError
        No excitation on any axis, an invalid one, or invalid run settings (before any
        integration).
    OutputPathError
        ``out`` cannot be written (suffix, folder, permissions, free space), before the run.
    """
    from qzs._validation import renamed_keyword
    from qzs.defaults import SIMULATION
    from qzs.engine.hexapod import simulate_hexapod
    from qzs.engine.hexapod.prepare import record_option
    from qzs.engine.run_spec import resolve_hexapod
    from qzs.model.excitation import build_excitation

    tolerance = renamed_keyword("tolerance", tolerance, "tolerance_db", tolerance_db)

    tables = {**setup.excitation, **(excitation or {})}
    if not tables:
        raise ParameterError("no base motion: give an [excitation.<axis>] table (e.g. "
                             "[excitation.z] kind = 'chirp') or --axis with --excitation.")
    built = {}
    for axis, options in tables.items():
        options = dict(options)
        kind = options.pop("kind", None)
        spelling = ({**{o: o for o in options}, **(names or {})} if axis in (excitation or {})
                    else {o: f"[excitation.{axis}] {o}" for o in options})
        built[axis] = build_excitation(kind, options, names=spelling)
    run = {**setup.simulation}
    for name, value in (("duration", duration), ("sample_rate", sample_rate),
                        ("solver", solver)):
        if value is not None:
            run[name] = value
    arguments = dict(excitation=built, duration=run.get("duration"),
                     dt=run.get("dt", SIMULATION["dt"]) if dt is None else dt,
                     sample_rate=run.get("sample_rate", SIMULATION["sample_rate"]),
                     solver=run.get("solver", SIMULATION["solver"]))
    if out is not None:
        check_out = _out_check(out, argument, arguments, built)
        check_out()
    try:
        resolved = resolve_hexapod(
            setup.geometry, setup.platform, setup.isolators, setup.controllers, excitation=built,
            duration=arguments["duration"], dt=dt, tolerance=tolerance,
            tolerance_state=tolerance_state, sample_rate=arguments["sample_rate"],
            solver=arguments["solver"], cartesian=setup.cartesian, finest=arguments["dt"],
            step="chosen", progress=progress)
    except ParameterError as error:  # an excitation's length, as the caller gave it
        raise error.renamed({
            record_option(axis): ((names or {}).get("duration", "duration")
                                  if axis in (excitation or {}) else f"[excitation.{axis}] duration")
            for axis in built}) from None
    common = dict(cartesian=setup.cartesian, progress=progress, interruptible=interruptible,
                  **resolved.arguments())
    if out is None:
        result = simulate_hexapod(setup.geometry, setup.platform, setup.isolators,
                                  setup.controllers, **common)
        result.run.update(resolved.step.attributes())
        return result
    from qzs.engine.hexapod.prepare import has_blocks
    from qzs.engine.hexapod.result import HexapodWriter

    check_out()  # again: the probes took a while
    with HexapodWriter(out, blocks=has_blocks(setup.controllers)) as writer:
        result = simulate_hexapod(setup.geometry, setup.platform, setup.isolators,
                                  setup.controllers, sink=writer.append, **common)
        result.run.update(resolved.step.attributes())
        writer.finish(result)
    return result


def _out_check(out, argument, arguments, built):
    """``check()``: can ``out`` take the run (suffix, folder, free space)?"""
    from pathlib import Path

    from qzs.engine.hexapod.result import HEXAPOD_SUFFIXES, estimated_hexapod_size
    from qzs.iotools.paths import check_output_path

    length = arguments["duration"]
    if length is None:
        lengths = [e.duration for e in built.values() if e.duration is not None]
        length = min(lengths) if lengths else None
    size = None
    samples = (length * arguments["sample_rate"]
               if isinstance(length, (int, float)) and length > 0 and arguments["sample_rate"] > 0
               else None)
    if samples is not None and samples < 1e15:  # larger: refused with its reason before the run
        suffix = Path(out).suffix.lower()
        size = estimated_hexapod_size(int(round(samples)) + 1,
                                      suffix if suffix in HEXAPOD_SUFFIXES else ".nc")
    return lambda: check_output_path(out, argument=argument, suffixes=HEXAPOD_SUFFIXES,
                                     estimated_bytes=size)
