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
