"""Six-axis platform set-ups read from hexapod files (TOML), and a set-up's simulated run
(``qzs hexapod simulate``). The set-up object and its defaults (:mod:`.platform_setup`) and
the linear report (:mod:`.linear_report`) are re-exported here.

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
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from qzs._validation import known_keys, read_toml, real
from qzs.defaults import AXES
from qzs.errors import ParameterError
from qzs.iotools.shipped import resolve_shipped
from qzs.model.controller import ControllerParameters
from qzs.model.hexapod import (LEG_COUNT, CartesianController, HexapodGeometry,
                               PlatformParameters, cubic_geometry, radial_geometry)
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters
from qzs.workflows.hexapod.legs import (_checked_legs, _controller, _file_legs, _parameters,
                                        _refuse_central_blocks, _sources, _with_settings,
                                        read_leg_controllers, read_leg_springs)
from qzs.workflows.hexapod.linear_report import (linear_record, linear_text,
                                                 plot_linear_transmissibility)
from qzs.workflows.hexapod.platform_setup import (HexapodSetup, centralised,
                                                  default_cube_center_height, default_platform,
                                                  hexapod_setup, supported_mass,
                                                  with_spring_laws)

if TYPE_CHECKING:
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
_PLATFORM_KEYS = ("mass", "inertia", "principal_inertia", "center_of_mass", "gravity")


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
    known_keys(table, optional, f"[geometry] (kind = {kind!r})", where, required=required)
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
    known_keys(table, _PLATFORM_KEYS, "[platform]", where)
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
    known_keys(table, _CARTESIAN_KEYS, "[cartesian]", where)
    point = table.get("point", "origin")
    legs = CartesianController.from_legs(geometry, controller, platform=platform, point=point)
    return CartesianController(**{name: table.get(name, getattr(legs, name))
                                  for name in _CARTESIAN_KEYS[1:]}, point=point)


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
    known_keys(document, allowed, "the hexapod file", where, noun="table")
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
    known_keys(excitation, AXES, "[excitation]", where, noun="axis name",
               fix="write [excitation.<axis>] tables")
    simulation = dict(known_keys(document.get("simulation", {}), SIMULATION_KEYS, "[simulation]",
                                 where))
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
