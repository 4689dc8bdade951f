"""The package's layout rules that a reader of one file cannot see: each check written once
(unknown keys through ``qzs._validation.known_keys``) and no room in ``workflows/`` over 800
lines (issue 42)."""
import ast
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"
#: The one module that may compare a table's keys with the allowed ones by hand.
KEY_CHECK_HOME = SOURCE / "_validation.py"
#: The most lines a module of ``workflows/`` may have.
WORKFLOW_LINES = 800


def _is_set_of_a_table(node):
    """``set(name)``, ``set(a.b)`` or ``name.keys()``: the keys of a table."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
            and node.func.id in ("set", "frozenset") and len(node.args) == 1:
        return isinstance(node.args[0], (ast.Name, ast.Attribute, ast.Subscript))
    return (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr == "keys" and not node.args)


def hand_written_key_checks(tree):
    """The lines of ``tree`` that take a table's keys minus others: ``set(table) - allowed``,
    ``table.keys() - allowed``, ``set(table).difference(allowed)``."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Sub) \
                and _is_set_of_a_table(node.left):
            found.append(node.lineno)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                and node.func.attr == "difference" and _is_set_of_a_table(node.func.value):
            found.append(node.lineno)
    return found


@pytest.mark.parametrize("text, count", [
    ("unknown = sorted(set(table) - set(ALLOWED))", 1),
    ("extra = set(self.options) - {'a'}", 1),
    ("extra = options.keys() - ALLOWED", 1),
    ("extra = set(spec['x']).difference(ALLOWED)", 1),
    ("unmet = set(range(cases)) - set(met)", 0),  # not a table's keys: the indices of cases
    ("missing = {'done', 'status'} - set(dataset.variables)", 0),  # what must be there
])
def test_the_detector_sees_a_hand_written_key_check(text, count):
    assert len(hand_written_key_checks(ast.parse(text))) == count


def test_no_module_but_validation_checks_a_tables_keys_by_hand():
    """Each check once: an unknown-key check goes through ``known_keys`` (its one message
    format, naming the table, the unknown keys and the allowed ones)."""
    found = {}
    for path in sorted(SOURCE.rglob("*.py")):
        if path == KEY_CHECK_HOME:
            continue
        lines = hand_written_key_checks(ast.parse(path.read_text(encoding="utf-8")))
        if lines:
            found[str(path.relative_to(SOURCE))] = lines
    assert not found, f"use qzs._validation.known_keys at {found}"


def test_no_module_of_workflows_exceeds_800_lines():
    long = {str(path.relative_to(SOURCE)): count
            for path in sorted((SOURCE / "workflows").rglob("*.py"))
            if (count := len(path.read_text(encoding="utf-8").splitlines())) > WORKFLOW_LINES}
    assert not long, f"split these rooms (at most {WORKFLOW_LINES} lines each): {long}"
