"""The version of qzs (a module of its own so that any layer may report it).

The one place the version is written: ``pyproject.toml`` reads it from here
(``[tool.setuptools.dynamic]``), so the installed metadata and ``qzs.__version__`` agree
without asking ``importlib.metadata`` at every start (55 ms of ``import qzs``).
"""
__version__ = "0.1.0"
