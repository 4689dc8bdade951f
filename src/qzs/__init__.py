"""qzs: simulation and analysis of semi-active quasi-zero-stiffness vibration isolators."""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("qzs")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

from qzs.errors import (  # noqa: E402
    DataError,
    ExcitationError,
    ParameterError,
    SimulationError,
    StabilityError,
)

__all__ = [
    "__version__",
    "DataError",
    "ExcitationError",
    "ParameterError",
    "SimulationError",
    "StabilityError",
]
