"""Names a package exports but imports only on first use (PEP 562), so ``import qzs`` stays lean."""
import importlib
import sys

__all__ = ["lazy_exports"]


def lazy_exports(package, exports):
    """Module-level ``__getattr__`` and ``__dir__`` for a package with lazily loaded names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : dict
        Exported name -> the module that defines it (the layer test reads these as
        imports of the package).

    Returns
    -------
    __getattr__, __dir__ : callable
        To assign at the package's top level.
    """
    namespace = sys.modules[package].__dict__

    def __getattr__(name):
        if name in exports:
            value = getattr(importlib.import_module(exports[name]), name)
            namespace[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(namespace) | set(exports))

    return __getattr__, __dir__
