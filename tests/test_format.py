"""The shared ways of showing numbers (:mod:`qzs._format`), against independent references."""
import cmath
import csv
import io
import json
import math
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from qzs._format import (csv_text, decibels, footnoted, html_figure, html_head, html_table,
                         json_ready, json_text, markdown_table, number)


@pytest.mark.parametrize("ratio, expected", [(10, 20.0), (0.1, -20.0), (1.0, 0.0), (100.0, 40.0),
                                             (math.sqrt(2), 3.0103), (-10.0, 20.0),
                                             (3 + 4j, 20 * math.log10(5)),
                                             (np.float64(0.01), -40.0)])
def test_decibels_of_a_number_is_20_log10_of_its_magnitude(ratio, expected):
    value = decibels(ratio)
    assert type(value) is float
    assert value == pytest.approx(expected, abs=1e-4)


def test_decibels_of_a_number_is_computed_as_math_log10_gives_it():
    for ratio in np.random.default_rng(1).uniform(1e-6, 1e3, 200):
        assert decibels(float(ratio)) == 20 * math.log10(ratio)


def test_decibels_of_an_array_keeps_its_shape_and_matches_numpy_to_the_bit():
    ratio = np.random.default_rng(2).uniform(1e-6, 1e3, (7, 6, 6))
    db = decibels(ratio)
    assert db.shape == ratio.shape
    assert np.array_equal(db, 20 * np.log10(ratio))
    assert np.array_equal(decibels(ratio.tolist()), db)


def test_decibels_of_a_complex_array_is_that_of_its_magnitude():
    rng = np.random.default_rng(3)
    response = rng.normal(size=40) + 1j * rng.normal(size=40)
    expected = [20 * math.log10(abs(z)) for z in response]
    assert decibels(response) == pytest.approx(expected, rel=1e-13)
    assert decibels(response)[5] == pytest.approx(decibels(complex(response[5])), rel=1e-13)
    assert cmath.isclose(10 ** (decibels(response[0]) / 20), abs(response[0]))


def test_zero_is_minus_infinity_without_a_warning_and_nan_stays_nan():
    with np.errstate(all="raise"):
        db = decibels(np.array([0.0, np.nan, np.inf]))
    assert db[0] == -np.inf and np.isnan(db[1]) and db[2] == np.inf
    assert decibels(0.0) == -math.inf and math.isnan(decibels(math.nan))


def test_a_floor_replaces_what_lies_below_it_and_leaves_nan():
    floor = 1e-12
    db = decibels(np.array([0.0, 1e-15, 1e-3, np.nan]), floor)
    assert db[0] == db[1] == pytest.approx(-240.0)
    assert db[2] == pytest.approx(-60.0) and np.isnan(db[3])
    assert decibels(0.0, floor) == pytest.approx(-240.0) and decibels(0.5, floor) == decibels(0.5)


# ---------------------------------------------------------------- numbers as text
@pytest.mark.parametrize("value, text", [(0.123456, "0.123"), (np.float64(1234.5), "1.23e+03"),
                                         (np.float32(2.5), "2.5"), (12345, "12345"),
                                         (np.int64(-7), "-7"), (True, "yes"), (np.False_, "no"),
                                         ("z/z", "z/z")])
def test_number_shows_significant_digits_integers_in_full_and_bools_in_words(value, text):
    assert number(value) == text


def test_number_says_undefined_for_none_and_nan_and_what_it_is_told_for_inf():
    assert number(None) == number(math.nan) == number(np.float64("nan")) == "undefined"
    assert number(math.inf) == "undefined" and number(-math.inf, undefined="—") == "—"
    assert number(math.inf, infinite="infinite") == "infinite"
    assert number(math.nan, unit="Hz", undefined="unstable") == "unstable"


def test_number_appends_the_unit_and_takes_the_digits_asked_for():
    assert number(math.pi, 4, "Hz") == "3.142 Hz"
    assert number(2.0, unit="N/m") == "2 N/m"
    assert float(number(math.e, 10)) == pytest.approx(math.e, rel=1e-9)


# ---------------------------------------------------------------- JSON and CSV
def test_json_ready_gives_what_json_round_trips_with_nan_and_inf_as_null():
    value = {1: np.float64(0.5), "nan": math.nan, "inf": np.float32(np.inf),
             "array": np.array([[1.0, np.nan], [np.inf, -2.0]]), "ints": (np.int64(3), 4),
             "flags": [np.True_, False], "complex": 1 - 2j, "path": Path("a") / "b.nc",
             "nested": {"none": None, "text": np.str_("x")}, "set": {7}}
    expected = {"1": 0.5, "nan": None, "inf": None, "array": [[1.0, None], [None, -2.0]],
                "ints": [3, 4], "flags": [True, False], "complex": [1.0, -2.0],
                "path": str(Path("a") / "b.nc"), "nested": {"none": None, "text": "x"},
                "set": [7]}
    ready = json_ready(value)
    assert json.loads(json.dumps(ready, allow_nan=False)) == expected
    assert json.loads(json_text(value)) == expected
    assert type(ready["ints"][0]) is int and type(ready["1"]) is float
    assert type(ready["flags"][0]) is bool


def test_json_ready_hands_what_it_does_not_know_to_other_or_keeps_it():
    marker = object()
    assert json_ready([marker])[0] is marker
    assert json_ready({"x": [marker]}, other=lambda item: "other") == {"x": ["other"]}


def test_json_text_is_indented_as_asked():
    assert json_text({"a": [1]}, indent=2) == json.dumps({"a": [1]}, indent=2)
    assert "\n " in json_text({"a": 1}, indent=1)


def test_csv_text_has_every_column_in_order_and_leaves_undefined_cells_empty():
    rows = [{"case": "PI", "T": 0.5, "peak": math.nan},
            {"case": "P", "T": np.float64(np.inf), "extra": 3}]
    read = list(csv.reader(io.StringIO(csv_text(rows))))
    assert read == [["case", "T", "peak", "extra"], ["PI", "0.5", "", ""], ["P", "", "", "3"]]


# ---------------------------------------------------------------- report tables
class _Cells(HTMLParser):
    def __init__(self):
        super().__init__()
        self.cells, self.tags = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)

    def handle_endtag(self, tag):
        self.tags.pop()

    def handle_data(self, data):
        if self.tags and self.tags[-1] in ("th", "td"):
            self.cells.append((self.tags[-1], data))


def test_html_table_escapes_headers_and_cells_unless_the_cells_are_html():
    table = html_table(["a < b", "unit [m]"], [["x & y", 2], ["<sup>1</sup>", 3.5]])
    parser = _Cells()
    parser.feed(table)
    assert parser.cells == [("th", "a < b"), ("th", "unit [m]"), ("td", "x & y"), ("td", "2"),
                            ("td", "<sup>1</sup>"), ("td", "3.5")]
    assert table.count("<tr>") == 3 and table.count("\n") == 3
    raw = html_table(["n"], [["&mdash;<sup>1</sup>"]], cells_html=True, separator="")
    assert raw == "<table><tr><th>n</th></tr><tr><td>&mdash;<sup>1</sup></td></tr></table>"


def test_html_head_and_figure_link_the_page_s_parts():
    head = html_head("a & b", "body{}")
    assert head.startswith("<!doctype html>") and head.endswith("<body>")
    assert "<title>a &amp; b</title>" in head and "<style>body{}</style>" in head
    figure = html_figure(Path("out") / "fig 1.png", "Fig <1>", "<b>caption</b>.")
    assert "src='fig 1.png'" in figure and "href='fig 1.svg'" in figure
    assert "alt='Fig &lt;1&gt;'" in figure and "<figcaption><b>caption</b>. Full size" in figure


def test_markdown_table_has_a_header_a_rule_and_a_line_per_row():
    lines = markdown_table(["case", "T [-]"], [["PI", 0.5], ["P", "—"]])
    assert lines[0] == "| case | T [-] |" and set(lines[1]) == {"|", "-"}
    assert lines[1].count("|") == 3
    assert [line.strip("| ").split(" | ") for line in lines[2:]] == [["PI", "0.5"], ["P", "—"]]


def test_footnoted_numbers_each_reason_once_in_the_order_met():
    notes = {}
    marks = [footnoted("—", reason, notes) for reason in ("a", "b", "a", "c")]
    assert marks == ["—<sup>1</sup>", "—<sup>2</sup>", "—<sup>1</sup>", "—<sup>3</sup>"]
    assert list(notes.items()) == [("a", 1), ("b", 2), ("c", 3)]


def test_one_notation_for_dimensionless_units():
    """Console values bare, labels and axes in [-]: never '0.1715 1' nor '[1]'."""
    from qzs._format import number, unit_label, with_unit

    for unit in ("1", "-", "", None):
        assert with_unit("0.1715", unit) == "0.1715"
        assert unit_label("transmissibility", unit) == "transmissibility [-]"
    assert number(0.17154, 4, "1") == "0.1715"
    assert with_unit("0.25", "m") == "0.25 m" and unit_label("stroke", "m") == "stroke [m]"


def test_the_design_space_texts_use_the_one_notation(tmp_path):
    import tomli_w

    from qzs.workflows.design_space.problem import load_problem, plan_text

    path = tmp_path / "p.toml"
    path.write_text(tomli_w.dumps({
        "problem": {"name": "p"}, "variables": {"pi_kp": {"low": 1.0, "high": 100.0}},
        "objectives": [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                       {"metric": "linear_transmissibility_at", "frequency": 12.0}]}))
    text = plan_text(load_problem(path))
    assert "[1]" not in text and "linear_transmissibility_at_1_hz [-]" in text
