"""The installed version of qzs (a module of its own so that any layer may report it)."""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("qzs")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"
