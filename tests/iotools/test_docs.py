"""The shipped documentation pages (qzs.iotools.docs) and the build step that ships
them (setup.py): every topic is a page of docs/, the wheel's copy reads the same as the
source tree's, a section is exactly its heading down to the next at its level."""
import re
import runpy
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from qzs.errors import DataError, ParameterError
from qzs.iotools import docs as documentation
from qzs.iotools.docs import (TOPICS, find_section, read_topic, resolve_topic,
                                       section_numbers, topic_names, topics)

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def setup_module_namespace():
    """setup.py's functions, without running setup() (it runs only as __main__)."""
    return runpy.run_path(str(ROOT / "setup.py"), run_name="qzs_setup")


def test_every_topic_is_a_page_of_docs_with_a_title():
    assert set(TOPICS.values()) <= {str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")}
    titles = topics()
    assert list(titles) == list(TOPICS)
    assert titles["model"] == "The qzs isolator model"
    assert all(titles.values())


def test_the_build_step_reads_the_same_topics_without_importing_qzs():
    namespace = setup_module_namespace()
    assert namespace["shipped_pages"]() == sorted(set(TOPICS.values()))


def test_the_shipped_copy_reads_as_the_source_tree(tmp_path, monkeypatch):
    """Pages copied as a wheel has them (qzs/_docs) are the ones read, and read the same."""
    copies = setup_module_namespace()["copy_pages"](DOCS, tmp_path / "qzs" / "_docs")
    assert len(copies) == len(set(TOPICS.values()))
    from_source = read_topic("model", "7")
    (tmp_path / "qzs" / "_docs" / "model.md").write_text("# Shipped\n\n## 7. Seven\n\nx\n")

    class Package:
        @staticmethod
        def files(package):
            assert package == "qzs"
            return tmp_path / "qzs"

    monkeypatch.setattr(documentation, "resources", Package)
    assert read_topic("model", "7") == "## 7. Seven\n\nx\n"
    assert topics()["model"] == "Shipped"
    assert read_topic("workflows/simulate") == read_topic_from(DOCS, "workflows/simulate")
    assert "7. Integrators" in from_source


def read_topic_from(folder, topic):
    return documentation._plain((folder / TOPICS[topic]).read_text(encoding="utf-8"))


def test_a_build_without_the_pages_fails(tmp_path):
    with pytest.raises(RuntimeError,
                       match=r"app.md is missing \(building needs the repository.s docs/"):
        setup_module_namespace()["copy_pages"](tmp_path, tmp_path / "out")


def test_no_pages_anywhere_is_a_clear_error(tmp_path, monkeypatch):
    class Package:
        @staticmethod
        def files(package):
            return tmp_path

    monkeypatch.setattr(documentation, "resources", Package)
    monkeypatch.setattr(documentation, "__file__", str(tmp_path / "a" / "b" / "c" / "d.py"))
    with pytest.raises(DataError, match="documentation pages are missing"):
        read_topic("model")


@pytest.mark.parametrize("name, topic", [("model", "model"), ("model.md", "model"),
                                         ("docs/model.md", "model"),
                                         ("hexapod", "hexapod"),  # the model's, not the workflow
                                         ("workflows/hexapod", "workflows/hexapod"),
                                         ("simulate", "workflows/simulate"),
                                         ("command-line", "workflows/command-line")])
def test_names_resolve(name, topic):
    assert resolve_topic(name) == topic


def test_every_short_name_resolves_to_one_topic():
    names = topic_names()
    assert len(names) == len(set(names))
    assert "sweeps" in names and "simulate" in names
    for name in names:
        assert resolve_topic(name) in TOPICS


@pytest.mark.parametrize("name", ["nope", "", "workflows", "docs"])
def test_an_unknown_topic_lists_the_topics(name):
    with pytest.raises(ParameterError, match="not a documentation topic; choose one of model,"):
        resolve_topic(name)


PAGE = """# Title

## 1. One
text one
```sh
# 2. not a heading: inside a code block
```
### 1.1 Sub
sub text
## 2. Two
two
### 2.1 Deeper
deeper
## 3 Three without a dot
three
"""


@pytest.mark.parametrize("number, first, last", [
    ("1", "## 1. One", "sub text"), ("§1", "## 1. One", "sub text"),
    ("1.1", "### 1.1 Sub", "sub text"), ("2", "## 2. Two", "deeper"),
    ("2.1", "### 2.1 Deeper", "deeper"), ("3", "## 3 Three without a dot", "three"),
    ("§ 3.", "## 3 Three without a dot", "three")])
def test_a_section_runs_to_the_next_heading_of_its_level(number, first, last):
    lines = find_section(PAGE, number).splitlines()
    assert lines[0] == first and lines[-1] == last


def test_headings_in_code_blocks_are_not_sections():
    assert section_numbers(PAGE) == ["1", "1.1", "2", "2.1", "3"]
    assert "not a heading" in find_section(PAGE, "1")


def test_a_missing_section_lists_the_sections():
    with pytest.raises(ParameterError, match=r"no such section; its sections are 1, 1.1, 2"):
        find_section(PAGE, "4")


def test_the_model_page_has_the_sections_the_code_cites():
    """Every "`qzs docs model` §N" / "docs/model.md §N" in the package names a real section."""

    cited = {"model": set(), "hexapod": set()}
    for path in (ROOT / "src" / "qzs").rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        for page, number in re.findall(
                r"(?:docs/|`qzs docs )(model|hexapod)(?:\.md|`) §(\d+(?:\.\d+)?)", text):
            cited[page].add(number)
    for page, numbers in cited.items():
        have = set(section_numbers(read_topic(page)))
        assert numbers and numbers <= have, f"{page}: cited but missing {numbers - have}"


def test_site_only_markup_is_reduced_for_a_terminal():
    text = read_topic("workflows/identification")
    assert "{func}" not in text and "`qzs.read_recording`" in text
    assert "`FrictionFit.to_isolator`" in text          # a role with its own title
    command_line = read_topic("command-line")
    assert "{qzs-command-help}" not in command_line and "`qzs COMMAND --help`" in command_line
    assert command_line.endswith("\n") and not command_line.endswith("\n\n")


@pytest.mark.slow
def test_the_built_wheel_ships_every_page(tmp_path):
    """pip builds a wheel (no build isolation: setuptools of this venv) with qzs/_docs/."""
    tree = tmp_path / "tree"
    tree.mkdir()
    for path in [ROOT / "pyproject.toml", ROOT / "setup.py", ROOT / "MANIFEST.in",
                 ROOT / "README.md", *ROOT.glob("LICENSE*")]:
        shutil.copy(path, tree / path.name)
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info", "_build", "*.nbi", "*.nbc")
    shutil.copytree(ROOT / "src", tree / "src", ignore=ignore)
    shutil.copytree(DOCS, tree / "docs", ignore=ignore)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(tmp_path / "wheel"), str(tree)], check=True,
                   capture_output=True)
    (wheel,) = (tmp_path / "wheel").glob("qzs-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert {f"qzs/_docs/{page}" for page in TOPICS.values()} <= names
    assert not any(name.startswith("qzs/_docs/") and not name.endswith(".md") for name in names)


# ---------------------------------------------------------------- the README outside the repo
README = ROOT / "README.md"
_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)")
_REFERENCE = re.compile(r"^\s*\[[^\]]+\]:\s*(\S+)", re.MULTILINE)
_HTML = re.compile(r"""<(?:a|img)\b[^>]*?\b(?:href|src)\s*=\s*["']([^"']+)""", re.IGNORECASE)


def relative_links(text):
    """Link and image targets of Markdown that only work inside the repository."""
    targets = _LINK.findall(text) + _REFERENCE.findall(text) + _HTML.findall(text)
    return [target for target in targets if not target.startswith(("https://", "http://"))]


def test_the_link_check_sees_relative_links():
    text = ("[a](docs/model.md) ![b](docs/app.png) [c](https://x.org/y) <img src='app.png'>\n"
            "[d]: CONTRIBUTING.md\n")
    assert relative_links(text) == ["docs/model.md", "docs/app.png", "CONTRIBUTING.md",
                                    "app.png"]


def test_the_readme_works_outside_the_repository():
    """PyPI shows the README as the long description: no link or image may be relative, and
    every page it names (`qzs docs TOPIC [SECTION]`) ships inside the package."""
    text = README.read_text(encoding="utf-8")
    assert relative_links(text) == []
    cited = re.findall(r"`qzs docs ([a-z/-]+)(?: (\d+(?:\.\d+)?))?`", text)
    assert len(cited) >= 10
    for topic, section in cited:
        read_topic(topic, section or None)
