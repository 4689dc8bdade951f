"""The linear analysis of a six-axis set-up as data, text and a figure (``qzs hexapod
linear``): its stiffness, damping and mass matrices, modes and static leg forces
(:func:`qzs.analysis.hexapod_linear.hexapod_linearize`), and the linear 6x6 transmissibility
grid. Re-exported by :mod:`qzs.workflows.hexapod.setups`.
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from qzs._format import number
from qzs.defaults import AXES
from qzs.errors import ParameterError
from qzs.workflows.hexapod.platform_setup import HexapodSetup

if TYPE_CHECKING:
    from qzs.analysis.hexapod_linear import HexapodLinearModel

__all__ = ["linear_record", "linear_text", "plot_linear_transmissibility", "STIFFNESS_UNITS"]


#: Units of the stiffness matrix's blocks (translation rows/columns first).
STIFFNESS_UNITS = (("N/m", "N/rad"), ("N", "N*m/rad"))
#: How the reports name the frame points.
_FRAME_WORDS = {"center_of_mass": "payload's centre of mass", "origin": "top frame origin",
                "cube_center": "cube's centre"}


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
