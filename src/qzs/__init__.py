"""qzs: simulation and analysis of semi-active quasi-zero-stiffness vibration isolators.

The isolator of Leav et al. (constant-force MagSpring + linear motor, stick-slip
friction, guide hard stops, PI position loop and active damping), simulated
exactly as ``MODEL.md`` specifies, and the tools to judge it by transmissibility.
"""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("qzs")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

from qzs.control import ControllerParameters, closed_loop_natural_frequency  # noqa: E402
from qzs.errors import (  # noqa: E402
    DataError,
    ExcitationError,
    ParameterError,
    SimulationError,
    StabilityError,
)
from qzs.excitation import Chirp, DisplacementRecord, RandomExcitation, Sine  # noqa: E402
from qzs.model import (  # noqa: E402
    InitialState,
    IsolatorParameters,
    friction_force,
    passive_natural_frequency,
    spring_force,
    spring_stiffness,
)
from qzs.results import SimulationResult  # noqa: E402
from qzs.simulate import SOLVERS, largest_stable_step, simulate  # noqa: E402

__all__ = [
    "__version__",
    "Chirp", "Sine", "RandomExcitation", "DisplacementRecord",
    "IsolatorParameters", "ControllerParameters", "InitialState",
    "simulate", "largest_stable_step", "SOLVERS", "SimulationResult",
    "spring_force", "spring_stiffness", "friction_force",
    "passive_natural_frequency", "closed_loop_natural_frequency",
    "ParameterError", "ExcitationError", "StabilityError", "SimulationError", "DataError",
]
