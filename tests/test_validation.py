"""The shared argument checks of :mod:`qzs._validation`: what they accept, return and say."""
import ast
import math
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from qzs._validation import (Structured, choice, finite_rows, integer, interval, known_keys,
                             non_negative_real, optional, positive_real, real)
from qzs.errors import DataError, ParameterError, ProblemError

NOT_NUMBERS = [True, np.True_, "1.0", None, [1.0], 1 + 2j]


@pytest.mark.parametrize("check", [real, positive_real, non_negative_real])
@pytest.mark.parametrize("value, expected", [(2, 2.0), (0.5, 0.5), (np.float32(0.25), 0.25),
                                             (np.int64(3), 3.0), (Fraction(1, 4), 0.25),
                                             (np.array(1.5), 1.5)])
def test_a_positive_real_number_comes_back_as_a_python_float(check, value, expected):
    number = check("x", value)
    assert type(number) is float and number == expected


@pytest.mark.parametrize("check", [real, positive_real, non_negative_real])
@pytest.mark.parametrize("value", NOT_NUMBERS + ["1e-4", "2", np.array([1.0])])
def test_every_check_of_a_real_number_refuses_text_and_non_numbers_alike(check, value):
    # Before: `positive("dt", "1e-4")` returned 0.0001 where `positive_real` refused it.
    with pytest.raises(ParameterError) as info:
        check("dt", value, fix="e.g. 1e-3 [s]")
    shown = f"the boolean {value!r}" if isinstance(value, (bool, np.bool_)) else repr(value)
    assert str(info.value) == f"`dt` must be a number, got {shown}; e.g. 1e-3 [s]."


@pytest.mark.parametrize("value, minimum, maximum, strict, requirement", [
    (math.nan, None, None, False, "must be finite"),
    (math.inf, 0.0, None, False, "must be finite"),
    (-0.5, 0.0, None, False, "must be non-negative"),
    (0.0, 0.0, None, True, "must be positive"),
    (0.5, 1.0, None, True, "must be > 1"),
    (0.5, 1.0, None, False, "must be >= 1"),
    (2.0, 0.0, 1.0, False, "must lie in [0, 1]"),
    (1.0, 0.0, 1.0, True, "must lie in (0, 1)"),
    (np.int64(-2), 0.0, None, False, "must be non-negative")])
def test_real_refuses_non_finite_values_and_values_out_of_bounds_naming_the_bound(
        value, minimum, maximum, strict, requirement):
    with pytest.raises(ParameterError) as info:
        real("gain", value, minimum=minimum, maximum=maximum, strict=strict)
    assert str(info.value) == f"`gain` {requirement}, got {float(value)!r}."


@pytest.mark.parametrize("value, minimum, strict", [(0.0, 0.0, False), (1.0, 1.0, False),
                                                    (1e-300, 0.0, True), (-5.0, None, False)])
def test_real_accepts_the_bound_itself_unless_strict(value, minimum, strict):
    assert real("gain", value, minimum=minimum, strict=strict) == value


@pytest.mark.parametrize("value", [0, -1.0, np.float64(-0.0), math.inf])
def test_positive_real_is_real_with_its_bound_message_for_message(value):
    with pytest.raises(ParameterError) as shorthand:
        positive_real("sample_rate", value)
    with pytest.raises(ParameterError) as spelled:
        real("sample_rate", value, minimum=0.0, strict=True)
    assert str(shorthand.value) == str(spelled.value)
    assert str(shorthand.value).startswith("`sample_rate` must be ")


def test_the_checks_raise_the_error_class_asked_for():
    for check in (lambda: real("x", "a", error=DataError),
                  lambda: non_negative_real("x", math.nan, error=DataError),
                  lambda: positive_real("x", 0.0, error=DataError),
                  lambda: integer("x", 0, 1, DataError),
                  lambda: choice("x", "c", ("a", "b"), DataError)):
        with pytest.raises(DataError):
            check()


def test_a_structured_error_gets_the_name_the_value_and_the_reason_as_attributes():
    error = Structured(build=lambda key, value, reason: ProblemError("robust", key, value, reason))
    with pytest.raises(ProblemError) as info:
        integer("samples", 2.5, 1, error, fix="e.g. 64")
    assert (info.value.table, info.value.key, info.value.value) == ("robust", "samples", 2.5)
    assert info.value.fix == "must be an integer >= 1; e.g. 64"
    with pytest.raises(ProblemError) as info:
        real("low", "1", error=error)
    assert (info.value.key, info.value.value, info.value.fix) == ("low", "1", "must be a number")


def test_choice_names_the_options_the_value_and_the_fix():
    assert choice("solver", "rk4", ("rk4", "euler")) == "rk4"
    with pytest.raises(ParameterError) as info:
        choice("solver", "rk5", ("rk4", "euler"), fix="see docs/model.md")
    assert str(info.value) == ("`solver` must be one of 'rk4', 'euler', got 'rk5'; "
                               "see docs/model.md.")


def test_optional_lets_none_through_and_checks_the_rest():
    assert optional(positive_real)("corner", None) is None
    assert optional(positive_real)("corner", 2) == 2.0
    with pytest.raises(ParameterError, match="`corner` must be positive, got -1.0"):
        optional(positive_real)("corner", -1.0)


@pytest.mark.parametrize("value", [True, 1.0, -1, "3"])
def test_integer_refuses_bools_floats_and_values_below_the_minimum(value):
    with pytest.raises(ParameterError) as info:
        integer("jitter_samples", value, 0)
    shown = "the boolean True" if value is True else repr(value)
    assert str(info.value) == f"`jitter_samples` must be an integer >= 0, got {shown}."
    assert integer("jitter_samples", np.int64(4), 0) == 4
    with pytest.raises(ParameterError, match=r"must be an integer in \[1, 8\], got 9"):
        integer("harmonics", 9, 1, maximum=8)


def test_an_interval_is_two_ordered_finite_numbers_above_its_minimum():
    assert interval("mass_range", (6, 6.5), "kg") == (6.0, 6.5)
    assert interval("mass_range", np.array([2.0, 2.0]), "kg") == (2.0, 2.0)
    for value in [(7.0, 6.0), (1.0,), (1.0, math.nan), "ab", (-1.0, 1.0), 3.0]:
        with pytest.raises(ParameterError, match="`mass_range`"):
            interval("mass_range", value, "kg")
    with pytest.raises(ParameterError) as info:
        interval("rate_range", (0.0, 10.0), "Hz", minimum=1e-9)
    assert str(info.value) == ("`rate_range` must satisfy 1e-09 <= low <= high (finite, in Hz), "
                               "got (0.0, 10.0); e.g. (1, 2) Hz.")
    with pytest.raises(ParameterError) as info:
        interval("band", "ab", "Hz", example="(1, 20)")
    assert str(info.value) == ("`band` must be two numbers (low, high) in Hz, got 'ab'; "
                               "e.g. (1, 20).")


def test_finite_rows_names_the_rows_with_non_finite_samples_and_refuses_other_shapes():
    rows = np.zeros((30, 5))
    assert finite_rows("base", rows, DataError).shape == (30, 5)
    rows[[3, 7]] = [[np.nan] * 5, [np.inf] + [0.0] * 4]
    with pytest.raises(DataError, match=r"`base` has non-finite .* in 2 of 30 rows \(\[3, 7\]\); "
                                        r"trim them"):
        finite_rows("base", rows, DataError, "trim them")
    rows[:] = np.nan
    with pytest.raises(DataError, match=r"30 of 30 rows \(\[0, 1, .*, 9\], \.\.\.\)"):
        finite_rows("base", rows, DataError)
    with pytest.raises(ParameterError, match=r"`base` must be a 2-D array.*shape \(5,\)"):
        finite_rows("base", np.zeros(5), ParameterError)


def test_an_integer_range_includes_both_bounds_and_nothing_beyond():
    """``minimum <= value <= maximum``, as documented: both bounds accepted, one beyond each
    refused."""
    assert [integer("harmonics", v, 1, maximum=8) for v in (1, 8)] == [1, 8]
    for beyond in (0, 9):
        with pytest.raises(ParameterError, match=r"must be an integer in \[1, 8\]"):
            integer("harmonics", beyond, 1, maximum=8)


def test_a_repeated_or_decreasing_time_is_refused_at_its_sample():
    """Strictly increasing: a repeated time (a step of 0) is refused as a decreasing one is,
    naming the first such sample and how many there are; an increasing one passes."""
    from qzs._validation import strictly_increasing

    strictly_increasing("time", np.array([0.0, 0.1, 0.2]), DataError)
    with pytest.raises(DataError, match=r"duplicated at sample 2 .*1 such steps"):
        strictly_increasing("time", np.array([0.0, 0.1, 0.1, 0.2]), DataError)
    with pytest.raises(DataError, match=r"duplicated at sample 2 .*2 such steps"):
        strictly_increasing("time", np.array([0.0, 0.1, 0.1, 0.2, 0.15]), DataError)
    with pytest.raises(DataError, match=r"decreasing at sample 1 \(t = 0.05 s after t = 0.1"):
        strictly_increasing("time", np.array([0.1, 0.05, 0.2]), DataError)


@pytest.mark.parametrize("value", [-3, np.int64(-1), 2 ** 63, 1.0, True, "1"])
def test_a_seed_is_a_whole_number_a_file_can_hold(value):
    """numpy's generators refuse a negative seed (a ValueError traceback after the search
    began); one above 2**63 - 1 ran and then failed as a file attribute (int64)."""
    from qzs._validation import seed

    with pytest.raises(ParameterError) as info:
        seed("--seed", value)
    message = str(info.value)
    assert message.startswith("`--seed` must be an integer in [0, 9223372036854775807]"), message
    assert repr(value) in message and "e.g. 1" in message


@pytest.mark.parametrize("value", [0, 1, np.int64(7), 2 ** 63 - 1])
def test_a_seed_comes_back_as_an_int(value):
    from qzs._validation import seed

    assert seed("seed", value) == value and type(seed("seed", value)) is int


def test_known_keys_names_the_table_the_unknown_keys_and_the_allowed_ones():
    table = {"a": 1, "b": 3}
    assert known_keys(table, ("a", "b"), "[t]", required=("a",)) is table
    with pytest.raises(ParameterError) as info:
        known_keys({"a": 1, "zz": 2, "yy": 3}, ("b", "a"), "[t]", "'f.toml': ",
                   options=("t",), fix="drop them")
    assert str(info.value) == ("'f.toml': unknown key(s) ['yy', 'zz'] in [t]; allowed are "
                               "['a', 'b']; drop them.")
    assert info.value.options == ("t",)


def test_known_keys_names_a_missing_required_key_and_refuses_a_non_table():
    with pytest.raises(ParameterError, match=r"^missing axis\(s\) \['y'\] in `e`; required are "
                                             r"\['x', 'y'\], allowed are \['x', 'y', 'z'\]\.$"):
        known_keys({"x": 1}, ("z",), "`e`", required=("x", "y"), noun="axis")
    with pytest.raises(ParameterError, match=r"^\[t\] must be a table, got 3\.$"):
        known_keys(3, ("a",), "[t]")


def test_known_keys_raises_the_error_asked_for():
    from qzs.errors import ExcitationError

    with pytest.raises(ExcitationError) as info:
        known_keys({"f0": 1.0}, ("frequency",), "a sine", noun="option", error=ExcitationError,
                   options=("f0",))
    assert info.value.options == ("f0",)
    build = Structured(build=lambda key, value, reason: ProblemError("t", key, value, reason))
    with pytest.raises(ProblemError) as info:
        known_keys({"a": 1, "q": 7}, ("a",), "[t]", error=build)
    assert (info.value.table, info.value.key, info.value.value) == ("t", "q", 7)
    assert info.value.fix == "unknown key(s) ['q'] in [t]; allowed are ['a']"


#: The package's sources, and the one module that may compare a table's keys with the
#: allowed ones by hand (:func:`known_keys`).
SOURCE = Path(__file__).resolve().parents[1] / "src" / "qzs"
KEY_CHECK_HOME = SOURCE / "_validation.py"


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


def test_known_keys_names_the_key_its_message_is_about_when_keys_are_both_unknown_and_missing():
    """An unknown key and a missing one: the message is about the unknown key, so the error's
    key and value are that key's (the missing one has no value to show)."""
    build = Structured(build=lambda key, value, reason: ProblemError("t", key, value, reason))
    with pytest.raises(ProblemError) as info:
        known_keys({"q": 7}, ("a",), "[t]", required=("b",), error=build)
    assert (info.value.key, info.value.value) == ("q", 7)
    assert info.value.fix.startswith("unknown key(s) ['q'] in [t]")
