"""The folder tree is the architecture: imports go one way, and nothing imports in a circle.

Every ``import`` in ``src/qzs`` is read from the syntax tree, function-level imports
included (a lazy import must not hide a cycle). Each subpackage is a layer and may import
only from the layers before it in :data:`LAYERS`. The one exception: a result object's
``plot``/``save`` method may hand itself to the figure and file layers above it
(pvlib-style delegation). The test of the checker itself adds an upward import and sees
it fail.
"""
import ast
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"

#: Layers, lowest first. ``base`` are the top-level modules every layer may use.
LAYERS = ("base", "model", "iotools", "analysis", "engine", "identify", "viz", "workflows",
          "app", "cli")
#: Top-level modules that are the base layer.
BASE = {"errors", "_validation", "_version", "_optional", "_lazy", "defaults"}
#: The facade (``qzs/__init__.py``, ``qzs/__main__.py``) may import anything; no module imports it.
FACADE = {"qzs", "qzs.__main__"}
#: Methods that may delegate to a higher layer (result objects: ``.plot()``, ``.save()``).
DELEGATING_METHODS = {"plot", "save"}


def module_name(path):
    parts = list(path.relative_to(SOURCE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer_of(module):
    """The layer of a ``qzs`` module name, or None for the facade."""
    if module in FACADE:
        return None
    first = module.split(".")[1]
    if first in BASE:
        return "base"
    assert first in LAYERS, f"{module}: a module outside every layer ({first!r})"
    return first


def imports(source, module, is_package=False):
    """``(imported qzs module, line, enclosing function name, in a class)`` of a source text."""
    found = []

    def visit(node, function, in_class):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                visit(child, child.name, in_class)
            elif isinstance(child, ast.ClassDef):
                visit(child, function, True)
            else:
                if isinstance(child, ast.Import):
                    for alias in child.names:
                        if alias.name.split(".")[0] == "qzs":
                            found.append((alias.name, child.lineno, function, in_class))
                elif isinstance(child, ast.ImportFrom):
                    base = child.module or ""
                    if child.level:  # relative import: resolve against this module
                        package = module.split(".")
                        package = package if is_package else package[:-1]
                        base = ".".join(package[:len(package) - child.level + 1]
                                        + ([base] if base else []))
                    if base.split(".")[0] == "qzs":
                        for alias in child.names:
                            candidate = f"{base}.{alias.name}"
                            target = candidate if _is_module(candidate) else base
                            found.append((target, child.lineno, function, in_class))
                visit(child, function, in_class)

    tree = ast.parse(source)
    visit(tree, None, False)
    # a lazily exported name is an import too: the modules of a dict of qzs module names
    # (``lazy_exports(__name__, {"name": "qzs.x.y"})``) must keep the same rules
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for value in node.values:
                if (isinstance(value, ast.Constant) and isinstance(value.value, str)
                        and value.value.split(".")[0] == "qzs" and _is_module(value.value)):
                    found.append((value.value, value.lineno, None, False))
    return found


def _is_module(name):
    path = SOURCE.parent.joinpath(*name.split("."))
    return path.with_suffix(".py").exists() or (path / "__init__.py").exists()


def violations(module, source, is_package=False):
    """Upward or facade imports of one module (an empty list when it keeps the rules)."""
    own = layer_of(module)
    if own is None:
        return []
    problems = []
    for target, line, function, in_class in imports(source, module, is_package):
        if target in FACADE:
            problems.append(f"{module}:{line} imports the facade `{target}`; import the "
                            "module that defines the name instead")
            continue
        theirs = layer_of(target)
        if LAYERS.index(theirs) <= LAYERS.index(own):
            continue
        if in_class and function in DELEGATING_METHODS:
            continue
        problems.append(f"{module}:{line} ({own}) imports {target} ({theirs}), a higher layer")
    return problems


def all_modules():
    return {module_name(path): path for path in sorted(SOURCE.rglob("*.py"))}


def test_every_module_is_in_a_layer():
    for module in all_modules():
        if module not in FACADE:
            assert layer_of(module) in LAYERS


def test_imports_go_one_way():
    problems = []
    for module, path in all_modules().items():
        problems += violations(module, path.read_text(), path.name == "__init__.py")
    assert not problems, "\n".join(problems)


def test_no_import_cycles_between_modules():
    """The import graph (function-level imports included, delegations left out) has no cycle."""
    modules = all_modules()
    graph = {}
    for module, path in modules.items():
        edges = set()
        for target, _, function, in_class in imports(path.read_text(), module,
                                                     path.name == "__init__.py"):
            if in_class and function in DELEGATING_METHODS or target == module:
                continue
            if module in FACADE or target in FACADE:
                continue
            edges.add(target)
        graph[module] = edges
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                cycle = trail[trail.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])


@pytest.mark.parametrize("source, upward", [
    ("from qzs.viz.figures import new_figure\n", True),             # module level
    ("def f():\n    from qzs.workflows.studies import run_study\n", True),   # hidden in a function
    ("import qzs.cli\n", True),
    ("from qzs import simulate\n", True),                             # the facade
    ("from qzs.model.isolator import spring_force\n", False),
    ("class R:\n    def plot(self):\n        from qzs.viz import plot_simulation\n", False),
    ("class R:\n    def other(self):\n        from qzs.viz import plot_simulation\n", True),
    ("_EXPORTS = {'plot': 'qzs.viz.simulation'}\n", True),               # a lazy export
    ("_EXPORTS = {'simulate': 'qzs.engine.simulate'}\n", False),
])
def test_the_checker_sees_an_upward_import(source, upward):
    """The check itself: an engine module that imports upward is reported, else not."""
    assert bool(violations("qzs.engine.example", source)) == upward


def test_the_checker_sees_a_relative_upward_import():
    assert violations("qzs.model.example", "from ..viz import figures\n")
