"""Names a package exports but imports only on first use (PEP 562), so ``import qzs`` stays lean."""
import importlib
import sys
import threading

__all__ = ["lazy_exports", "import_in_background"]


def lazy_exports(package, exports, public=None):
    """Module-level ``__getattr__`` and ``__dir__`` for a package with lazily loaded names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : dict
        Exported name -> the module that defines it (the layer test reads these as
        imports of the package).
    public : sequence of str, optional
        What ``dir(package)`` lists (its ``__all__``: the public API, none of the names the
        package itself imports to build it); default everything the package holds and
        ``exports``.

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
        if public is not None:
            return sorted(public)
        return sorted(set(namespace) | set(exports))

    return __getattr__, __dir__


def import_in_background(*modules):
    """Import ``modules`` in a daemon thread, while the caller goes on.

    For modules a command will need after a long phase that holds no GIL (a kernel
    integrating): scipy.signal or matplotlib cost 0.3-0.5 s to import, which then overlaps
    the integration instead of following it. Python's per-module import locks make a later
    ``import`` of the same module in the caller wait for the thread's, never import it
    twice. Errors stay in the thread: the caller's own import raises them where it needs
    the module.

    Parameters
    ----------
    *modules : str
        Dotted module names, imported in order.

    Returns
    -------
    threading.Thread
        The started thread. Join it before ending where other code may look the module up
        in ``sys.modules`` rather than import it (it would find it half imported); an
        ``import`` waits by itself.
    """
    def load():
        for name in modules:
            try:
                importlib.import_module(name)
            except Exception:  # noqa: BLE001 - the caller's own import reports it
                return

    thread = threading.Thread(target=load, name="qzs-import", daemon=True)
    thread.start()
    return thread
