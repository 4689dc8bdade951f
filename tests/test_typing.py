"""The public API carries type hints, and mypy holds them to the code and to the code using them.

The rule (CONTRIBUTING.md, "Type hints"): every callable of the flat ``qzs`` namespace, the
public methods and properties of the result classes, and every function the command line
imports from ``qzs.workflows`` has a hint on each parameter and on its return. Checked here
three ways:

* by introspection: no parameter or return of those callables lacks a hint;
* by mypy over the whole package, with the configuration of pyproject.toml's ``[tool.mypy]``
  (an annotated function's body is checked against its hints);
* by mypy over two scripts that use the API as a reader would: one must pass, with
  ``typing.assert_type`` pinning what the main calls return (so that a hint decaying to
  ``Any`` fails), the other must be rejected at exactly the lines marked ``# E: <code>``.

mypy's cache lives in ``.mypy_cache`` at the repository's top (ignored by git): the first run
takes about half a minute, the next ones a second or two.
"""
import ast
import dataclasses
import importlib
import inspect
import re
import textwrap
from pathlib import Path

import pytest

import qzs

mypy_api = pytest.importorskip("mypy.api", reason="mypy is in the test extra: "
                               "pip install -e '.[test]'")

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "src" / "qzs"
CONFIG = ROOT / "pyproject.toml"
CACHE = ROOT / ".mypy_cache"

#: Result classes returned by public functions but not themselves in the flat namespace.
RESULT_CLASSES = {
    "qzs.analysis.linear": ["LinearModel"],
    "qzs.analysis.control_design.stability_margins": ["LoopMargins", "LoopStability"],
    "qzs.analysis.spectral": ["TransmissibilityMetrics"],
    "qzs.analysis.harmonic_balance": ["FrequencyResponseCurve"],
    "qzs.identify": ["SpringFit", "FrictionFit", "TransmissibilityFit"],
    "qzs.iotools.rig": ["Recording", "ChannelMap"],
    "qzs.workflows.response": ["ResponsePoint"],
    "qzs.workflows.experiment.process": ["ExperimentResult"],
    "qzs.workflows.hexapod.setups": ["HexapodSetup"],
    "qzs.workflows.hexapod.study": ["HexapodStudyResult"],
    "qzs.workflows.paper.report": ["Verdict"],
    "qzs.workflows.paper.studies": ["StudyResult"],
    "qzs.workflows.sweeps": ["SweepDefinition"],
}


def cli_workflow_imports():
    """``(module, name)`` of everything the command line imports from ``qzs.workflows``."""
    found = set()
    for path in (SOURCE / "cli").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("qzs.workflows"):
                found.update((node.module, alias.name) for alias in node.names)
    return sorted(found)


def public_objects():
    """Qualified name -> object: the flat namespace, the result classes, the CLI's workflows."""
    objects = {f"qzs.{name}": getattr(qzs, name) for name in qzs.__all__}
    for module, names in RESULT_CLASSES.items():
        objects.update({f"{module}.{name}": getattr(importlib.import_module(module), name)
                        for name in names})
    for module, name in cli_workflow_imports():
        objects[f"{module}.{name}"] = getattr(importlib.import_module(module), name)
    return objects


def public_callables():
    """``(qualified name, function)``: functions, and the public methods and properties of the
    classes (their ``__init__`` unless a dataclass writes it from the annotated fields)."""
    seen = set()
    for qualified, obj in public_objects().items():
        if inspect.isclass(obj):
            if not obj.__module__.startswith("qzs"):
                continue
            members = [("__init__", vars(obj)["__init__"])] if (
                "__init__" in vars(obj) and not dataclasses.is_dataclass(obj)) else []
            members += [(name, member) for name, member in vars(obj).items()
                        if not name.startswith("_")]
            for name, member in members:
                function = (member.fget if isinstance(member, property)
                            else getattr(member, "__func__", member))
                if inspect.isfunction(function) and function not in seen:
                    seen.add(function)
                    yield f"{qualified}.{name}", function
        elif inspect.isfunction(getattr(obj, "py_func", obj)) and obj.__module__.startswith("qzs"):
            function = getattr(obj, "py_func", obj)
            if function not in seen:
                seen.add(function)
                yield qualified, function


def missing_hints(function):
    """The parameters (and ``return``) of ``function`` without a hint."""
    signature = inspect.signature(function)
    missing = [name for index, (name, parameter) in enumerate(signature.parameters.items())
               if parameter.annotation is inspect.Parameter.empty
               and not (index == 0 and name in ("self", "cls"))]
    if signature.return_annotation is inspect.Signature.empty and function.__name__ != "__init__":
        missing.append("return")
    return missing


def run_mypy(*targets):
    """mypy with the project's configuration: ``(report lines, exit status)``."""
    stdout, stderr, status = mypy_api.run(["--config-file", str(CONFIG), "--cache-dir", str(CACHE),
                                           "--no-pretty", "--show-error-codes",
                                           "--hide-error-context", *map(str, targets)])
    assert status in (0, 1), f"mypy crashed (status {status}):\n{stderr}{stdout}"
    return [line for line in stdout.splitlines() if ": error: " in line], status


def test_every_public_callable_has_hints():
    callables = list(public_callables())
    assert len(callables) > 100, f"only {len(callables)} public callables found"
    problems = [f"{name}: no hint on {missing_hints(function)}"
                for name, function in callables if missing_hints(function)]
    assert not problems, "\n".join(problems)


def test_the_checker_of_hints_sees_a_missing_one():
    def documented(value: float, other) -> float:
        return value

    def no_return(value: float):
        return value

    assert missing_hints(documented) == ["other"]
    assert missing_hints(no_return) == ["return"]


def test_type_checkers_see_every_lazy_name_of_qzs():
    """``qzs/__init__.py`` imports its lazy names under ``if TYPE_CHECKING:``; without that, a
    type checker would see ``qzs.transmissibility`` as an unknown attribute."""
    tree = ast.parse((SOURCE / "__init__.py").read_text())
    block = next(node for node in tree.body if isinstance(node, ast.If)
                 and getattr(node.test, "id", None) == "TYPE_CHECKING")
    seen = {alias.asname or alias.name for node in ast.walk(block)
            if isinstance(node, ast.ImportFrom) for alias in node.names}
    assert seen == set(qzs._LAZY)


def test_the_package_ships_its_marker():
    assert (SOURCE / "py.typed").is_file()


def test_mypy_passes_on_the_package():
    """mypy over src/qzs with pyproject's configuration (``python -m mypy`` does the same)."""
    errors, status = run_mypy(SOURCE)
    assert status == 0 and not errors, "\n".join(errors)


USES = '''
    from pathlib import Path
    from typing import assert_type

    import numpy as np
    import xarray as xr

    import qzs
    from qzs.analysis.spectral import TransmissibilityMetrics

    chirp = qzs.Chirp(duration=20.0, f1=5.0)
    isolator = qzs.IsolatorParameters(stiction_force=8.0)
    controller = qzs.ControllerParameters(pi_kp=40.0)
    result = qzs.simulate(chirp, isolator, controller, dt=1e-4, sample_rate=500.0)
    assert_type(result, qzs.SimulationResult)
    assert_type(result.summary(), str)
    assert_type(result.to_xarray(), xr.Dataset)
    assert_type(result.steps_per_second, float)
    assert_type(result.save("run.nc"), Path)
    estimate = qzs.transmissibility(result["base_acceleration"], result.payload_acceleration,
                                    500.0, fft_length=1024)
    assert_type(estimate, qzs.TransmissibilityEstimate)
    assert_type(estimate.to_xarray(), xr.Dataset)
    assert_type(estimate.metrics(), TransmissibilityMetrics)
    assert_type(estimate.metrics().to_dict(), dict[str, float])
    assert_type(qzs.spring_force(-0.06, isolator), float)
    forces = qzs.spring_force(np.linspace(-0.1, 0.1, 5), isolator)
    assert_type(chirp.max_frequency, float)
    assert_type(qzs.largest_stable_step(isolator, controller), float)
    assert_type(qzs.linearize(isolator, controller).damping_ratio, float)
    assert_type(qzs.loop_stability(isolator, controller).message, str)
    assert_type(qzs.loop_margins(isolator, controller).meets(), bool)
    batch = qzs.simulate_batch([(isolator, controller)], chirp, dt=1e-4)
    assert_type(batch, qzs.BatchResult)
    assert_type(batch.to_xarray(), xr.Dataset)
    response = qzs.steady_state_response([2.0, 4.0], isolator=isolator)
    assert_type(response, qzs.SteadyStateResponse)
    assert_type(response.summary(), str)
    config = qzs.load_config("run.toml")
'''

MISUSES = '''
    import qzs

    result = qzs.simulate(qzs.Chirp(duration=20.0), dt="1e-4")  # E: arg-type
    text: int = result.summary()  # E: assignment
    qzs.IsolatorParameters(mass="2 kg")  # E: arg-type
    qzs.transmissibility([0.0, 1.0], [0.0, 1.0])  # E: call-arg
    qzs.simulate(qzs.Sine(), sample_rates=1000.0)  # E: call-arg
    qzs.spring_force(0.01, qzs.ControllerParameters())  # E: call-overload
    result.to_xarray().to_netcdf(result.steps_per_second.upper())  # E: attr-defined
'''


def test_mypy_accepts_a_script_using_the_api(tmp_path):
    script = tmp_path / "uses.py"
    script.write_text(textwrap.dedent(USES))
    errors, status = run_mypy(script)
    assert status == 0 and not errors, "\n".join(errors)


def test_mypy_rejects_a_script_misusing_the_api(tmp_path):
    """Each marked line fails for the reason marked, and no other line does."""
    text = textwrap.dedent(MISUSES)
    script = tmp_path / "misuses.py"
    script.write_text(text)
    expected = {(number, match.group(1)) for number, line in enumerate(text.splitlines(), 1)
                if (match := re.search(r"# E: ([a-z-]+)", line))}
    errors, status = run_mypy(script)
    found = {(int(match.group(1)), match.group(2)) for line in errors
             if (match := re.search(r"misuses\.py:(\d+): error: .*\[([a-z-]+)\]$", line))}
    assert status == 1
    assert found == expected, "\n".join(errors)
