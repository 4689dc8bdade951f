"""Optional dependencies: import them, or say which extra installs them."""
import importlib

from qzs.errors import MissingDependencyError

#: Module -> (distribution on PyPI, qzs extra that installs it).
OPTIONAL = {
    "asammdf": ("asammdf", "rig"),
    "dask": ("dask", "cluster"),
    "distributed": ("distributed", "cluster"),
    "zarr": ("zarr", "cluster"),
    "panel": ("panel", "app"),
    "bokeh": ("bokeh", "app"),
    "pymoo": ("pymoo", "design"),
    "SALib": ("SALib", "design"),
    "fmpy": ("fmpy", "fmu"),
}


def require(module, feature):
    """Import and return ``module``, or raise :class:`MissingDependencyError` naming the extra.

    Parameters
    ----------
    module : str
        Module name, a key of :data:`OPTIONAL`.
    feature : str
        What needs it, for the message (e.g. "reading MF4 logs").
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        package, extra = OPTIONAL[module.split(".")[0]]
        raise MissingDependencyError(package, extra, feature) from None
