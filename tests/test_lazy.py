"""Names a package exports but imports on first use (qzs._lazy.lazy_exports, PEP 562)."""
import math
import sys
import types

import pytest

from qzs._lazy import lazy_exports


def test_a_lazy_name_is_imported_on_first_use_and_kept(monkeypatch):
    package = types.ModuleType("lazy_example")
    monkeypatch.setitem(sys.modules, "lazy_example", package)
    package.__getattr__, package.__dir__ = lazy_exports("lazy_example", {"sqrt": "math"})
    assert "sqrt" not in vars(package) and "sqrt" in dir(package)
    assert package.sqrt is math.sqrt            # through the module's __getattr__
    assert vars(package)["sqrt"] is math.sqrt   # kept: the next use is a plain lookup
    with pytest.raises(AttributeError, match="module 'lazy_example' has no attribute 'cbrt'"):
        package.cbrt


def test_a_module_imported_in_the_background_is_imported_once_and_errors_stay_there(
        monkeypatch):
    """import_in_background: the module is in sys.modules after the thread (and a later import
    gets the same object); a module that fails to import does not raise in the thread's
    caller, and the caller's own import still raises it."""
    import importlib

    from qzs._lazy import import_in_background

    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    monkeypatch.delitem(sys.modules, "tabnanny", raising=False)
    import_in_background("colorsys", "qzs_no_such_module", "tabnanny").join(timeout=30)
    assert "colorsys" in sys.modules
    assert importlib.import_module("colorsys") is sys.modules["colorsys"]
    assert "tabnanny" not in sys.modules  # after a failure the thread stops quietly
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("qzs_no_such_module")


def test_scipy_signal_is_loaded_by_the_first_estimate_not_by_the_workflows_that_import_it():
    """scipy.signal costs about 0.9 s of imports: the design space, sweeps and the command
    line import the spectral functions, but only an estimate loads scipy.signal."""
    import subprocess

    code = ("import sys, numpy as np\n"
            "import qzs.cli, qzs.workflows.design_space, qzs.workflows.sweeps, qzs.analysis.spectral\n"
            "print('scipy.signal' in sys.modules)\n"
            "t = np.arange(4096) / 100.0\n"
            "qzs.analysis.spectral.transmissibility(np.sin(t), 0.5 * np.sin(t), 100.0, fft_length=1024)\n"
            "print('scipy.signal' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.stdout.split() == ["False", "True"], done.stderr


def test_dir_of_qzs_is_its_public_api_and_every_name_resolves():
    """``dir(qzs)`` lists ``qzs.__all__`` and nothing the package imports to build it
    (``TYPE_CHECKING``, ``lazy_exports``, ``_LAZY``, the base modules); every listed name is
    there on first use."""
    import qzs

    listed = dir(qzs)
    assert listed == sorted(qzs.__all__)
    for hidden in ("TYPE_CHECKING", "lazy_exports", "_LAZY", "_lazy", "_validation"):
        assert hidden not in listed
    assert all(hasattr(qzs, name) for name in listed)
    assert "simulate" in listed and "TanhSpring" in listed and "__version__" in listed
