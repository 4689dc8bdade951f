"""The validation page's tables, from the records the test suite wrote in this build.

Tests that check a closed form or a published result take the ``validation`` fixture
(tests/conftest.py) and record what they measured. ``make docs`` runs them first
(``pytest -m validation`` with ``QZS_VALIDATION_OUT`` naming a JSON Lines file); the
``validation-records`` directive of validation.md turns that file into one table per test
module, under the module's own one-line docstring. Nothing on the page is typed by hand.

A missing or empty file, or a record whose error exceeds its tolerance, is a build warning
(an error under ``-W``).
"""
import json
import math
import os
from collections import defaultdict
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

logger = logging.getLogger(__name__)

#: Default location of the records, relative to the source folder (``make docs`` writes it).
DEFAULT_RECORDS = "_build/validation.jsonl"
#: Columns and their relative widths.
COLUMNS = (("check", 23), ("reference", 25), ("measured error", 15), ("tolerance", 8),
           ("share", 7), ("test", 22))
#: The page's sections, in reading order: a short title per test module, named by its dotted
#: path under tests/ (``engine.test_kernels`` for tests/engine/test_kernels.py). A module not
#: listed gets a section of its own at the end, titled by its docstring's first clause.
SECTIONS = {
    "model.test_isolator": "Force laws of the model",
    "engine.test_kernels": "The simulator: linear limit, convergence, energy, stick-slip, stops",
    "engine.test_stability": "Integrators' stability limits",
    "engine.test_accuracy": "The accuracy-driven step",
    "model.test_excitation": "Excitations",
    "model.test_controller": "The controller",
    "engine.test_laws_regularised": "The regularised friction option",
    "analysis.test_linear": "The linearised loop, and the paper's natural frequencies",
    "analysis.control_design.test_linear_stability":
        "Controller design: Routh-Hurwitz bounds on the gains",
    "analysis.control_design.test_loop_transfers":
        "Controller design: the sampled loop with a delay",
    "analysis.control_design.test_stability_margins": "Controller design: margins",
    "analysis.control_design.test_describing_functions":
        "Controller design: describing functions",
    "analysis.control_design.test_hunting": "Controller design: hunting at rest",
    "analysis.test_spectral": "Spectral estimation and transmissibility metrics",
    "workflows.response.test_frequency":
        "The steady-state response against Den Hartog and other exact results",
    "analysis.harmonic_balance.test_residual": "Harmonic balance: the residual and its Jacobian",
    "analysis.harmonic_balance.test_solution": "Harmonic balance: one periodic response",
    "analysis.harmonic_balance.test_stability": "Harmonic balance: Floquet exponents",
    "analysis.harmonic_balance.test_curve": "Harmonic balance: folds along the curve",
    "analysis.harmonic_balance.test_continuation":
        "Harmonic balance: continuation in frequency",
    "identify.test_spring": "Fits: the MagSpring",
    "identify.test_friction": "Fits: the friction law",
    "identify.test_transmissibility": "Fits: the transmissibility",
    "identify.test_statistics": "Fits: confidence intervals",
}


def records_path(app):
    return Path(os.environ.get("QZS_VALIDATION_OUT")
                or Path(app.srcdir) / app.config.qzs_validation_records)


def load_records(path):
    """The records of ``path``, once each (a test run twice keeps its last record)."""
    unique = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.strip():
            entry = json.loads(line)
            unique[(entry["test"], entry["check"])] = entry
    return list(unique.values())


def _number(value):
    if isinstance(value, str):
        return value
    if value == 0:
        return "0"
    if 1e-3 <= abs(value) < 1e4:
        return f"{value:.4g}"
    return f"{value:.2e}"


def _share(entry):
    error, tolerance = entry["error"], entry["tolerance"]
    if isinstance(error, str):
        return "-"
    if tolerance == 0:
        return "exact" if error == 0 else "over"
    share = 100 * abs(error) / tolerance
    return "< 0.01 %" if 0 < share < 0.01 else f"{share:.3g} %"


def _paragraph(text, literal=False):
    paragraph = nodes.paragraph()
    paragraph += nodes.literal(text, text) if literal else nodes.Text(text)
    return paragraph


def _title(module, section):
    """The section title of a test module: from :data:`SECTIONS`, else its docstring's."""
    if module in SECTIONS:
        return SECTIONS[module]
    return section.replace("``", "").split(":")[0].rstrip(".")


def _order(module):
    names = list(SECTIONS)
    return (names.index(module) if module in names else len(names), module)


def _table(rows):
    table = nodes.table(classes=["qzs-validation", "colwidths-given"])
    group = nodes.tgroup(cols=len(COLUMNS))
    table += group
    for _, width in COLUMNS:
        group += nodes.colspec(colwidth=width)
    head = nodes.thead()
    group += head
    row = nodes.row()
    for title, _ in COLUMNS:
        row += nodes.entry("", _paragraph(title))
    head += row
    body = nodes.tbody()
    group += body
    for entry in rows:
        row = nodes.row()
        test = entry["test"].split("::", 1)[-1]
        cells = [_paragraph(entry["check"]), _paragraph(entry["reference"]),
                 _paragraph(f"{_number(entry['error'])} ({entry['measure']})"),
                 _paragraph(_number(entry["tolerance"])), _paragraph(_share(entry)),
                 _paragraph(test, literal=True)]
        for cell in cells:
            row += nodes.entry("", cell)
        body += row
    return table


class ValidationRecords(SphinxDirective):
    """``validation-records``: the summary and one table per test module."""

    has_content = False
    option_spec = {"summary-only": directives.flag}

    def run(self):
        path = records_path(self.env.app)
        self.env.note_dependency(str(path))
        if not path.exists() or not path.read_text(encoding="utf-8").strip():
            logger.warning("no validation records at %s: `make docs` writes them "
                           "(QZS_VALIDATION_OUT=... pytest -m validation)", path,
                           location=self.get_location())
            return [_paragraph("No validation records were found in this build.")]
        records = load_records(path)
        for entry in records:
            error = entry["error"]
            if isinstance(error, str) or abs(error) > entry["tolerance"]:
                logger.warning("validation record over its tolerance: %s (%s > %s), %s",
                               entry["check"], error, entry["tolerance"], entry["test"],
                               location=self.get_location())
        by_module = defaultdict(list)
        for entry in records:
            by_module[entry["module"]].append(entry)
        worst = max((e for e in records if not isinstance(e["error"], str) and e["tolerance"]),
                    key=lambda e: abs(e["error"]) / e["tolerance"], default=None)
        summary = (f"{len(records)} checks in {len(by_module)} test modules, recorded by this "
                   f"build's own run of the tests.")
        if worst is not None:
            summary += (f" The closest to its tolerance: {worst['check']} "
                        f"({_share(worst)} of it).")
        result = [_paragraph(summary)]
        if "summary-only" in self.options:
            return result
        for module in sorted(by_module, key=_order):
            rows = sorted(by_module[module], key=lambda e: e["test"])
            section = nodes.section(ids=[nodes.make_id(f"validation-{module}")])
            title = _title(module, rows[0]["section"])
            section += nodes.title(title, title)
            source = f"tests/{module.replace('.', '/')}.py"
            intro = nodes.paragraph()
            intro += nodes.Text(f"{len(rows)} checks, from ")
            intro += nodes.literal(source, source)
            intro += nodes.Text(": " + rows[0]["section"].replace("``", "").rstrip(".") + ".")
            section += intro
            section += _table(rows)
            result.append(section)
        return result


def setup(app):
    app.add_config_value("qzs_validation_records", DEFAULT_RECORDS, "env")
    app.add_directive("validation-records", ValidationRecords)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
