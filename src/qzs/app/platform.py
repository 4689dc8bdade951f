"""The six-axis platform's tab of the tuning page, computed without any widget (docs/app.md).

Six of the isolator's legs in the shipped cubic Stewart platform
(:data:`qzs.workflows.hexapod.setups.SHIPPED_DEFAULT`, docs/hexapod.md), every leg with the
tab's settings: its geometry, its linear analysis
(:func:`qzs.workflows.hexapod.setups.linear_record`) and the linear 6x6 transmissibility grid
(:func:`qzs.viz.hexapod_matrix.plot_transmissibility_matrix`), drawn to PNG bytes in
memory. Nothing here models the platform: it calls those functions.
"""
import io
from dataclasses import dataclass

import numpy as np

from qzs._validation import known_keys

__all__ = ["PlatformData", "compute_platform", "PLATFORM_PARAMETERS", "GRID_RANGE"]

#: Leg parameters the tab sets (registry names); the rest keep the shipped file's values.
PLATFORM_PARAMETERS = ("pi_kp", "pi_ki", "damping_gain", "viscous_damping")
#: Band of the grid [Hz], log-spaced, and its points [-].
GRID_RANGE = (0.05, 50.0)
GRID_POINTS = 300


@dataclass(frozen=True, kw_only=True)
class PlatformData:
    """What the platform's tab draws.

    Attributes
    ----------
    settings : dict
        The leg parameters applied (registry names -> SI values).
    base_joints, top_joints : ndarray, shape (6, 3)
        The joints at the home pose, both in the base frame [m].
    natural_frequencies : ndarray, shape (6,)
        Undamped modes [Hz]; NaN where the platform is statically unstable.
    mode_axes : tuple of str
        The axis each mode moves most (``x``, ``y``, ``z``, ``rx``, ``ry``, ``rz``).
    stable : bool
        Whether the linearised platform is statically stable.
    notes : tuple of str
        The analysis' notes.
    platform_mass : float
        The platform's mass [kg].
    grid_png : bytes
        The 6x6 linear transmissibility grid as a PNG.
    """

    settings: dict
    base_joints: np.ndarray
    top_joints: np.ndarray
    natural_frequencies: np.ndarray
    mode_axes: tuple
    stable: bool
    notes: tuple
    platform_mass: float
    grid_png: bytes


def compute_platform(settings=None, dpi=75):
    """The platform's geometry, modes and linear transmissibility grid for leg settings.

    Parameters
    ----------
    settings : dict, optional
        Leg parameters by registry name (:data:`PLATFORM_PARAMETERS`, SI units), applied to
        every leg of the shipped cubic platform; validated as ``qzs hexapod --set`` does.
    dpi : float
        Resolution of the grid's PNG [dots per inch].

    Returns
    -------
    PlatformData

    Raises
    ------
    ParameterError
        An unknown name or an invalid value (the API's message).
    """
    import matplotlib.pyplot as plt

    from qzs.viz.hexapod_matrix import plot_transmissibility_matrix
    from qzs.workflows.hexapod.setups import AXES, SHIPPED_DEFAULT, linear_record, load_hexapod

    settings = known_keys(dict(settings or {}), PLATFORM_PARAMETERS, "`settings`",
                          noun="platform setting", options=("settings",))
    setup = load_hexapod(SHIPPED_DEFAULT, settings)
    model, record = linear_record(setup)
    frequency = np.geomspace(*GRID_RANGE, GRID_POINTS)
    stability = "" if model.stable else " (linearly UNSTABLE: see the notes)"
    figure = plot_transmissibility_matrix(
        frequency, linear=model,
        title=f"Linear transmissibility of the {setup.kind} platform, "
              f"{setup.platform.mass:.3g} kg{stability}")
    try:
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=dpi)
    finally:
        plt.close(figure)
    geometry = setup.geometry
    shapes = np.asarray(record["mode_shapes"])
    axes = tuple(AXES[int(np.argmax(np.abs(shapes[:, j])))] for j in range(shapes.shape[1]))
    return PlatformData(
        settings=settings, base_joints=np.asarray(geometry.base_joints),
        top_joints=np.asarray(geometry.top_joints) + np.asarray(geometry.home_position),
        natural_frequencies=np.asarray(record["natural_frequencies"], dtype=float),
        mode_axes=axes, stable=bool(record["stable"]), notes=tuple(record["notes"]),
        platform_mass=float(setup.platform.mass), grid_png=buffer.getvalue())
