"""The package qzs.analysis.harmonic_balance: its docstring's table lists exactly its modules,
and the public names are imported from the package as they were from the single module."""
import importlib
import pkgutil
import re

import qzs.analysis
import qzs.analysis.harmonic_balance as package


def test_the_docstring_lists_exactly_the_modules():
    listed = re.findall(r"^``(\w+)``\s", package.__doc__, flags=re.MULTILINE)
    modules = [info.name for info in pkgutil.iter_modules(package.__path__)]
    assert sorted(listed) == sorted(modules)
    assert len(listed) == len(set(listed))


def test_the_public_names_are_the_packages_and_the_analysis_layers():
    for name in package.__all__:
        value = getattr(package, name)
        home = getattr(value, "__module__", None)
        if home is not None:  # a class or function: defined in one of the modules
            assert home.startswith(package.__name__ + "."), name
            assert getattr(importlib.import_module(home), name) is value
    for name in ("SmoothModel", "HarmonicBalanceSolution", "FrequencyResponseCurve",
                 "periodic_response", "frequency_response_curve", "floquet_exponents",
                 "smooth_right_hand_side"):
        assert getattr(qzs.analysis, name) is getattr(package, name)
    assert package.DEFAULT_HARMONICS == 40 and package.FRICTION_VELOCITY == 1e-3
