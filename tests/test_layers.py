"""The folder tree is the architecture: imports go one way, and nothing imports in a circle.

Every ``import`` in ``src/qzs`` is read from the syntax tree, function-level imports
included (a lazy import must not hide a cycle). Each subpackage is a layer and may import
only from the layers before it in :data:`LAYERS`. The one exception: a result object's
``plot``/``save`` method may hand itself to the figure and file layers above it
(pvlib-style delegation). The test of the checker itself adds an upward import and sees
it fail.

The tests mirror the tree (as pvlib's do): every module has its test file at the same path
under tests/ (``tests/engine/test_driver.py`` beside ``src/qzs/engine/driver.py``), every
test file names a module of its folder's package, each package's docstring lists exactly
its modules and subpackages, and no source file is over :data:`MAX_LINES` lines.
"""
import ast
import re
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"



def _layer_table():
    """The names of the layer table in ``qzs/__init__.py``'s docstring, in its order."""
    import re

    text = (SOURCE / "__init__.py").read_text()
    table = text.split('"""')[1].split("=" * 15)[1:]
    return re.findall(r"^``([a-z_]+)``", "".join(table), flags=re.MULTILINE)


#: Top-level modules that are the base layer (the table's first rows).
BASE = {"errors", "_validation", "_version", "_optional", "_lazy", "defaults", "_format"}
#: Layers, lowest first, as the table in ``qzs/__init__.py`` lists them: ``base`` (the
#: top-level modules every layer may use), then each subpackage.
LAYERS = ("base", *(name for name in _layer_table() if name not in BASE))
#: The facade (``qzs/__init__.py``, ``qzs/__main__.py``) may import anything; no module imports it.
FACADE = {"qzs", "qzs.__main__"}
#: Methods that may delegate to a higher layer (result objects: ``.plot()``, ``.save()``).
DELEGATING_METHODS = {"plot", "save"}


def test_the_layer_table_in_the_package_docstring_is_every_module_and_package_once():
    """The table the layers are read from: the base modules first, then every subpackage,
    each once; nothing in src/qzs outside it."""
    names = _layer_table()
    assert len(names) == len(set(names))
    assert set(names[:len(BASE)]) == BASE
    packages = {p.name for p in SOURCE.iterdir() if (p / "__init__.py").exists()}
    modules = {p.stem for p in SOURCE.glob("*.py")} - {"__init__", "__main__"}
    assert set(names[len(BASE):]) == packages
    assert modules == BASE
    assert LAYERS[:4] == ("base", "model", "iotools", "analysis")


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
    ("def f():\n    from qzs.workflows.paper.studies import run_study\n", True),  # in a function
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



# ---------------------------------------------------------------- no private name across packages
def package_of(module, is_package=False):
    """The package a module belongs to (a package's ``__init__`` belongs to itself)."""
    return module if is_package else module.rpartition(".")[0]


def private_imports(source, module, is_package=False):
    """``(line, name, source module)`` of each private name (``_x``, not ``__x__``) a module
    takes from another package: imported (``from qzs.a.b import _x``, relative or inside a
    function too), or read off a module imported from another package (``b._x`` after
    ``from qzs.a import b``). The base layer's private modules (``qzs._validation`` ...,
    :data:`BASE`) are shared by every layer and are not counted."""
    own = package_of(module, is_package)

    def private(name):
        return name.startswith("_") and not name.startswith("__")

    def base_module(name):
        parts = name.split(".")
        return len(parts) == 2 and parts[1] in BASE

    found, modules = [], {}
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative import: resolve against this module
                package = module.split(".")
                package = package if is_package else package[:-1]
                base = ".".join(package[:len(package) - node.level + 1] + ([base] if base else []))
            if base.split(".")[0] != "qzs":
                continue
            for alias in node.names:
                candidate = f"{base}.{alias.name}"
                if _is_module(candidate):  # a module of package `base`
                    modules[alias.asname or alias.name] = candidate
                    theirs = base
                else:  # a name defined in module (or package) `base`
                    theirs = package_of(base, _is_package(base))
                if private(alias.name) and theirs != own and not base_module(candidate):
                    found.append((node.lineno, alias.name, base))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] != "qzs":
                    continue
                if alias.asname:
                    modules[alias.asname] = alias.name
                for i, part in enumerate(parts[1:], start=1):
                    if (private(part) and ".".join(parts[:i]) != own
                            and not base_module(".".join(parts[:i + 1]))):
                        found.append((node.lineno, part, ".".join(parts[:i])))
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                and node.value.id in modules and private(node.attr)):
            target = modules[node.value.id]
            if package_of(target, _is_package(target)) != own:
                found.append((node.lineno, node.attr, target))
    return sorted(set(found))


def _is_package(name):
    return SOURCE.parent.joinpath(*name.split("."), "__init__.py").exists()


def test_no_private_name_is_imported_across_packages():
    """A name with a leading underscore is its package's own: another package that needs it
    gets it public, with a docstring, or the code moves to where it belongs."""
    problems = []
    for module, path in all_modules().items():
        for line, name, source in private_imports(path.read_text(), module,
                                                  path.name == "__init__.py"):
            problems.append(f"src/{module.replace('.', '/')}"
                            f"{'/__init__' if path.name == '__init__.py' else ''}.py:{line} "
                            f"takes the private `{name}` of {source}")
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("module, source, names", [
    # another package's private function, at module level or inside a function
    ("qzs.workflows.design_space.metrics",
     "from qzs.workflows.sweeps.batch import _run_group, run_batch\n", ["_run_group"]),
    ("qzs.workflows.design_space.metrics",
     "def f():\n    from qzs.workflows.sweeps.batch import _run_group\n", ["_run_group"]),
    # relative, to a sibling package
    ("qzs.workflows.design_space.metrics", "from ..sweeps.batch import _run_group\n",
     ["_run_group"]),
    # read off a module of another package
    ("qzs.workflows.design_space.metrics",
     "from qzs.workflows.sweeps import batch\nbatch._run_group()\n", ["_run_group"]),
    ("qzs.workflows.design_space.metrics",
     "import qzs.workflows.sweeps.batch as b\nb._run_group()\n", ["_run_group"]),
    # a subpackage is another package: private names of its parent's modules are not its
    ("qzs.engine.hexapod.accuracy", "from qzs.engine.accuracy import _band\n", ["_band"]),
    # the same package: allowed
    ("qzs.workflows.sweeps.runner", "from qzs.workflows.sweeps.batch import _run_group\n",
     []),
    ("qzs.workflows.sweeps", "from qzs.workflows.sweeps.batch import _run_group\n", []),
    ("qzs.workflows.sweeps.runner", "from .batch import _run_group\n", []),
    # public names, dunders and the base layer's private modules: allowed
    ("qzs.engine.driver", "from qzs.workflows.sweeps.batch import run_batch\n", []),
    ("qzs.engine.driver", "from qzs._version import __version__\n", []),
    ("qzs.engine.driver", "from qzs import _validation\n", []),
    ("qzs.engine.driver", "from qzs._validation import positive\n", []),
])
def test_the_checker_sees_a_private_import(module, source, names):
    """The check itself: a private name taken from another package is reported, else not."""
    assert [name for _, name, _ in private_imports(source, module, _is_package(module))] == names


# ---------------------------------------------------------------- the tests mirror the tree
TESTS = Path(__file__).resolve().parent
#: Modules without a test file of their own, with the reason. Only a module whose whole
#: content is constants or re-exports may be here (checked: it defines no function or class).
UNTESTED = {
    "engine.hexapod.layout": "the six-axis kernels' packed offsets only (that the output "
                             "channels tile them: tests/engine/hexapod/test_result.py)",
}
#: The suites at the top of tests/ that test the package as a whole, not one module.
CROSS_CUTTING = {
    "layers": "this file: the folder tree, the imports between layers, the tests' own tree",
    "docstrings": "every public callable's numpydoc, whatever its module",
    "cli_contract": "exit codes, signals, output paths and --json, the same for every subcommand",
    "cli_doc": "docs/workflows/command-line.md's promises, read from the page, against the parser",
    "docs_run": "README.md and the documentation's pages, every command and snippet run in page "
                "order in one fresh folder, with the outputs they state",
    "bad_inputs": "inputs that used to end in a traceback, through the API and every command",
    "result_api": "every result class's plot() and save(), one signature",
    "trust": "the trusted-bins rule every metric obeys (its check is imported by the studies' "
             "and the experiment's tests)",
    "benchmark_reference": "the benchmarks' C reference model against qzs",
    "typing": "mypy over the annotated public API and over scripts using it (one it must reject)",
    "wheel": "the built wheel and sdist: LICENSE, py.typed, every declared package-data file",
    "cf_compliance": "every kind of NetCDF file qzs writes, through the IOOS compliance "
                     "checker (CF-1.10)",
}
#: The longest a source file of qzs may be [lines] (one concept per module).
MAX_LINES = 1000
#: The longest a module of ``workflows/`` may be [lines] (issue 42: rooms of one concept).
WORKFLOW_MAX_LINES = 800


def source_modules():
    """Every module of qzs but ``__init__`` and ``__main__``, as a path under src/qzs."""
    return sorted(path.relative_to(SOURCE) for path in SOURCE.rglob("*.py")
                  if path.name not in ("__init__.py", "__main__.py"))


def packages():
    """Every package of qzs (qzs itself first), as a path under src/qzs."""
    return sorted(path.parent.relative_to(SOURCE) for path in SOURCE.rglob("__init__.py"))


def package_contents(package):
    """The modules and subpackages of a package, by name (``__main__`` left out)."""
    folder = SOURCE / package
    modules = [path.stem for path in folder.glob("*.py")
               if path.name not in ("__init__.py", "__main__.py")]
    return sorted(modules + [path.parent.name for path in folder.glob("*/__init__.py")])


def mirrored_test(module):
    """tests/<package path>/test_<module name without a leading underscore>.py"""
    return TESTS.joinpath(*module.parent.parts, f"test_{module.stem.lstrip('_')}.py")


def defined_names(path):
    return [node.name for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))]


@pytest.mark.parametrize("module", source_modules(), ids=str)
def test_every_module_has_a_test_file_at_its_mirrored_path(module):
    """tests/engine/test_driver.py beside src/qzs/engine/driver.py, as pvlib does."""
    name = ".".join(module.with_suffix("").parts)
    test = mirrored_test(module).relative_to(TESTS.parent)
    if name in UNTESTED:
        defined = defined_names(SOURCE / module)
        assert not defined, (f"src/qzs/{module} defines {defined}: no longer constants only, "
                             f"so test it in {test} and drop it from UNTESTED")
        assert not (TESTS.parent / test).exists(), f"{test} exists: drop {name} from UNTESTED"
        return
    assert (TESTS.parent / test).exists(), f"src/qzs/{module} has no test file: write {test}"


def test_every_test_file_names_a_module_of_its_mirrored_package():
    """tests/<package>/test_<module>.py or test_<module>_<aspect>.py (a second file of one
    module), test_init.py for a package's ``__init__``; at the top of tests/, the top-level
    modules' files and the cross-cutting suites of :data:`CROSS_CUTTING`."""
    problems = []
    for test in sorted(TESTS.rglob("test_*.py")):
        folder = test.parent.relative_to(TESTS)
        stem = test.stem.removeprefix("test_")
        if not (SOURCE / folder / "__init__.py").exists():
            problems.append(f"{test.relative_to(TESTS.parent)}: no package src/qzs/{folder}")
            continue
        modules = [path.stem.lstrip("_") for path in (SOURCE / folder).glob("*.py")
                   if path.name not in ("__init__.py", "__main__.py")]
        named = (stem == "init" and folder.parts
                 or (not folder.parts and stem in CROSS_CUTTING)
                 or any(stem == m or stem.startswith(m + "_") for m in modules))
        if not named:
            problems.append(f"{test.relative_to(TESTS.parent)}: names no module of "
                            f"src/qzs/{folder}")
    assert not problems, "\n".join(problems)


def listed_modules(docstring):
    """The names a package's docstring lists: the ````name```` entries that start a line
    of its table (between the first and the last rule of ``=`` columns)."""
    lines = (docstring or "").splitlines()
    rules = [i for i, line in enumerate(lines) if re.fullmatch(r"=+( +=+)+", line.strip())]
    if len(rules) < 2:
        return None
    return [match.group(1) for line in lines[rules[0] + 1:rules[-1]]
            if (match := re.match(r"``(\w+)``( |$)", line))]


@pytest.mark.parametrize("package", packages(), ids=lambda p: ".".join(("qzs", *p.parts)))
def test_each_package_docstring_lists_exactly_its_modules(package):
    """The package's docstring has a table, one ``name`` line per module and subpackage,
    in the format of qzs.engine's; a module added, moved or removed changes it."""
    docstring = ast.get_docstring(ast.parse((SOURCE / package / "__init__.py").read_text()))
    listed = listed_modules(docstring)
    assert listed is not None, "no table of modules in the docstring"
    assert len(listed) == len(set(listed)), f"listed twice: {listed}"
    contents = package_contents(package)
    assert sorted(listed) == contents, (f"not listed: {sorted(set(contents) - set(listed))}; "
                                        f"listed but absent: {sorted(set(listed) - set(contents))}")


def test_no_source_file_is_over_the_line_limit():
    lengths = {path.relative_to(SOURCE): len(path.read_text().splitlines())
               for path in sorted(SOURCE.rglob("*.py"))}
    over = [f"src/qzs/{path}: {count} lines" for path, count in lengths.items()
            if count > MAX_LINES]
    assert not over, f"over {MAX_LINES} lines (split by concept):\n" + "\n".join(over)


def test_no_workflow_module_is_over_its_line_limit():
    over = [f"src/qzs/{path.relative_to(SOURCE)}: {count} lines"
            for path in sorted((SOURCE / "workflows").rglob("*.py"))
            if (count := len(path.read_text().splitlines())) > WORKFLOW_MAX_LINES]
    assert not over, (f"over {WORKFLOW_MAX_LINES} lines in workflows/ (split by concept):\n"
                      + "\n".join(over))


def test_the_docstring_reader_sees_only_the_table():
    doc = ("Intro.\n\n``base``\n    not a module\n\n====  ====\n``a``  one\n``bb`` two\n"
           "           more of two\n====  ====\n\n``after``  not either\n")
    assert listed_modules(doc) == ["a", "bb"]
    assert listed_modules("No table.\n``a``  one\n") is None
