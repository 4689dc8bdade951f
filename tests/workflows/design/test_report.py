"""The design for people: number formats, figures, the summary and the HTML sections."""
import math

from qzs.workflows.design.report import _figure, _fmt, _html, design_text

SECTIONS = ("Chosen gains", "Problem", "Static design", "PI gains", "Linear stability",
            "Hunting at rest", "Damping gain", "Sampled loop",
            "Why active damping did not help much", "Run")


def test_numbers_are_formatted_with_their_unit_and_undefined_ones_say_so():
    assert _fmt(1234.5678) == "1235" and _fmt(1234.5678, 3, "Hz") == "1.23e+03 Hz"
    assert _fmt(0.5, unit="N") == "0.5 N"
    assert _fmt(math.inf) == "infinite" and _fmt(-math.inf) == "infinite"
    assert _fmt(math.nan, unit="Hz") == "undefined" and _fmt(None) == "undefined"


def test_a_missing_figure_is_left_out_and_a_caption_is_escaped(tmp_path):
    assert _figure({}, "margins", "caption") == ""
    shown = _figure({"margins": tmp_path / "margins.png"}, "margins", "Margins < 1.")
    assert "src='margins.png'" in shown and "href='margins.svg'" in shown
    assert "Margins &lt; 1." in shown


def test_the_summary_and_the_report_carry_the_gains_and_every_section_in_order(design):
    text = design_text(design)
    g = design.gains
    assert f"Kp = {_fmt(g['pi_kp'])} N/m, Ki = {_fmt(g['pi_ki'])} N/(m*s)" in text
    assert text.splitlines()[0].startswith("qzs design (quick;")
    page = _html(design, design.to_dict(), {})
    places = [page.index(f"<h2>{title}</h2>") for title in SECTIONS]
    assert places == sorted(places)
    assert page.startswith("<!doctype html>") and page.endswith("</body></html>")
    assert "<figure>" not in page  # no figure written
