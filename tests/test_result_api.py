"""Every result class's ``plot()`` and ``save()`` have one signature (issue 31).

``plot(self, path=None, *, title=None, <options>) -> Figure``: ``path`` writes the figure
too, ``title`` replaces the default title, and what only some figures have (``ax`` for a
single-axes figure, ``frequency_scale`` for a frequency axis, ``figure`` to pick one of
several) follows as keyword-only options with defaults; never ``**kwargs``, so an unknown
keyword is an error. ``save(self, path, *, <options>) -> Path``. The classes are found by
reading the source, so a new result class is checked without being listed here.
"""
import ast
import importlib
import inspect
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"


def _methods(name):
    """(module, class) of every class in src/qzs defining the method ``name``."""
    found = []
    for path in sorted(SOURCE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.ClassDef) and any(
                    isinstance(item, ast.FunctionDef) and item.name == name
                    for item in node.body):
                module = ".".join(("qzs", *path.relative_to(SOURCE).with_suffix("").parts))
                found.append((module.removesuffix(".__init__"), node.name))
    return found


def _returns(method):
    annotation = inspect.signature(method).return_annotation
    return str(getattr(annotation, "__name__", annotation)).strip("'\"")


def _options(parameters):
    """The parameters after the shared ones that are not keyword-only with a default."""
    return [p.name for p in parameters
            if p.kind is not p.KEYWORD_ONLY or p.default is inspect.Parameter.empty]


PLOTS, SAVES = _methods("plot"), _methods("save")


def test_the_source_is_read_and_the_result_classes_are_found():
    assert len(PLOTS) >= 10 and len(SAVES) >= 6
    assert ("qzs.engine.result", "SimulationResult") in PLOTS
    assert ("qzs.workflows.design.result", "DesignResult") in SAVES


@pytest.mark.parametrize("module, name", PLOTS)
def test_every_plot_takes_path_then_title_then_keyword_options_and_returns_a_figure(module, name):
    method = getattr(importlib.import_module(module), name).plot
    parameters = list(inspect.signature(method).parameters.values())
    assert [p.name for p in parameters[:3]] == ["self", "path", "title"], parameters
    path, title = parameters[1], parameters[2]
    assert path.kind is path.POSITIONAL_OR_KEYWORD and path.default is None
    assert title.kind is title.KEYWORD_ONLY and title.default is None
    assert _options(parameters[3:]) == []
    assert _returns(method) == "Figure"


@pytest.mark.parametrize("module, name", SAVES)
def test_every_save_takes_path_then_keyword_options_and_returns_the_path(module, name):
    method = getattr(importlib.import_module(module), name).save
    parameters = list(inspect.signature(method).parameters.values())
    assert [p.name for p in parameters[:2]] == ["self", "path"], parameters
    assert parameters[1].kind is parameters[1].POSITIONAL_OR_KEYWORD
    assert parameters[1].default is inspect.Parameter.empty
    assert _options(parameters[2:]) == []
    assert _returns(method) == "Path"


def test_the_rule_refuses_the_spellings_it_replaced():
    """The checks above fail on the signatures issue 31 found (the test can fail)."""
    def old_kwargs(self, **kwargs) -> "Figure": ...
    def old_out(self, out=None, frequency_scale=None) -> "Figure": ...
    def old_dict(self, frequency_scale=None) -> "dict[str, Figure]": ...
    def old_ax(self, ax=None, **kwargs) -> "Figure": ...
    for old in (old_kwargs, old_out, old_dict, old_ax):
        parameters = list(inspect.signature(old).parameters.values())
        assert ([p.name for p in parameters[:3]] != ["self", "path", "title"]
                or _options(parameters[3:]) or _returns(old) != "Figure")
