"""``qzs docs`` (qzs.cli.docs): the topic list, a page, one section; bad names are exit 2."""
import pytest

from qzs.cli import main
from qzs.iotools.docs import TOPICS, read_topic


def test_without_a_topic_it_lists_every_topic_with_its_title(capsys):
    assert main(["docs"]) == 0
    out = capsys.readouterr().out
    for topic in TOPICS:
        assert f"  {topic} " in out
    assert "The qzs isolator model" in out


def test_a_topic_prints_its_page(capsys):
    assert main(["docs", "model"]) == 0
    assert capsys.readouterr().out == read_topic("model")


@pytest.mark.parametrize("argv", [["docs", "model", "7"], ["docs", "model", "§7"],
                                  ["docs", "model", "--section", "7"],
                                  ["docs", "--section", "7", "model", "7"]])
def test_a_section_prints_just_that_section(capsys, argv):
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert out.startswith("## 7. Integrators")
    assert "## 8." not in out and "## 6." not in out


@pytest.mark.parametrize("argv, words", [
    (["docs", "nope"], ["'nope'", "choose one of model,"]),
    (["docs", "model", "99"], ["'99'", "its sections are 1, 2,"]),
    (["docs", "--section", "7"], ["--section 7", "name the topic too"]),
    (["docs", "model", "7", "--section", "8"], ["--section 8", "given twice"])])
def test_bad_names_are_one_line_and_exit_2(capsys, argv, words):
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("qzs: error: ")
    assert captured.err.count("\n") == 1
    assert all(word in captured.err for word in words), captured.err


def help_texts(parser, path="qzs"):
    """``(command, text)`` of every description, epilog and option help of the parser."""
    import argparse

    yield path, parser.description or ""
    yield path, parser.epilog or ""
    for action in parser._actions:
        yield path, action.help or ""
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from help_texts(sub, f"{path} {name}")


def test_help_texts_cite_what_an_installed_qzs_can_open():
    """No help text sends a reader to a repository path; every cited page and section exists."""
    import re

    from qzs.cli import build_parser

    cited = 0
    for command, text in help_texts(build_parser()):
        assert "docs/" not in text, f"{command}: {text}"
        for topic, section in re.findall(r"`qzs docs ([a-z/-]+)`(?: §(\d+(?:\.\d+)?))?", text):
            read_topic(topic, section or None)
            cited += 1
    assert cited >= 5
