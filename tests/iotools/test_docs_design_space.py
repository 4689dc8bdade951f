"""docs/design-space.md keeps its promises: its tables are read from the page and checked
against the code, so that editing one without the other fails here.

The metrics table is :data:`qzs.workflows.design_space.metrics.METRICS` (name, unit, source,
options), and the table of problem-file tables names exactly
:data:`qzs.workflows.design_space.problem.TABLES`.
"""
import re
from pathlib import Path

from qzs.iotools.docs import TOPICS, read_topic
from qzs.workflows.design_space.metrics import METRICS
from qzs.workflows.design_space.problem import TABLES

PAGE = Path(__file__).resolve().parents[2] / "docs" / "design-space.md"


def rows(header):
    """The cells of each row of the page's table whose header row starts with ``header``."""
    text = PAGE.read_text(encoding="utf-8")
    table = text.split(header, 1)[1].split("\n\n", 1)[0]
    lines = [line for line in table.splitlines()[1:]
             if line.startswith("|") and not line.startswith("|---")]
    return [[cell.strip() for cell in line.strip("|").split(" | ")] for line in lines]


def test_the_metrics_table_is_metrics():
    found = {}
    for name, units, source, option, _ in rows("| metric | unit | source | option |"):
        options = tuple(re.findall(r"`([a-z_]+)`", option))
        found[name.strip("`")] = (units, source, options)
    assert found == {m.name: (m.units, m.source, m.options) for m in METRICS.values()}


def test_the_table_of_tables_names_every_table():
    found = [re.sub(r"[\[\]`]", "", row[0]) for row in rows("| table | key | meaning | unit |")]
    assert found == list(TABLES)


def test_the_guide_is_a_topic_with_numbered_sections():
    assert TOPICS["design-space"] == "design-space.md"
    assert read_topic("design-space", "4").startswith("## 4. Uncertainty")
