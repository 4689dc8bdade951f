"""The documentation pages shipped inside the package: ``qzs docs [TOPIC] [SECTION]``.

The repository's ``docs/`` folder is canonical (the code cites ``docs/model.md`` by section);
no second copy is kept in git. Building a wheel copies the pages named in :data:`TOPICS` into
the package as ``qzs/_docs/<page>`` (``setup.py``, its ``build_py`` step, reads
:data:`TOPICS` from this file), so that an installed qzs can show what its help texts cite
("`qzs docs model` §7"). At run time a page is read from ``qzs/_docs`` if the package has it,
else from the ``docs/`` folder of the source tree (a checkout or an editable install).

A page is printed as its Markdown source, with Sphinx's cross-reference roles (``{func}``,
``{mod}``, ...) reduced to their targets in backquotes, and the blocks only the documentation
site can fill (generated command help, tables of contents) replaced by a line that says
where that content is.
"""
import re
from importlib import resources
from pathlib import Path

from qzs.errors import DataError, ParameterError

__all__ = ["TOPICS", "topics", "topic_names", "resolve_topic", "read_topic", "find_section",
           "section_numbers"]

#: Topic name -> page, relative to ``docs/``. The name is the page's path without ``.md``;
#: a workflow page may be named by its last part alone (``simulate``) where no other topic
#: has that name. ``setup.py`` reads this literal (``ast.literal_eval``) to ship the pages.
TOPICS = {
    "model": "model.md",
    "hexapod": "hexapod.md",
    "response": "response.md",
    "design": "design.md",
    "sweeps": "sweeps.md",
    "design-space": "design-space.md",
    "app": "app.md",
    "fmu": "fmu.md",
    "getting-started": "getting-started.md",
    "workflows/command-line": "workflows/command-line.md",
    "workflows/simulate": "workflows/simulate.md",
    "workflows/paper": "workflows/paper.md",
    "workflows/identification": "workflows/identification.md",
    "workflows/sweeps": "workflows/sweeps.md",
    "workflows/response-design": "workflows/response-design.md",
    "workflows/hexapod": "workflows/hexapod.md",
    "workflows/app": "workflows/app.md",
    "workflows/questions": "workflows/questions.md",
}
#: Where the pages are inside an installed package.
PACKAGE_FOLDER = "_docs"

_ROLE = re.compile(r"\{(?:py:)?(?:func|class|mod|meth|attr|data|ref|doc|exc|obj)\}"
                   r"`~?([^`<]+?)(?:\s*<[^`>]*>)?`")
_DIRECTIVE = re.compile(r"^```\{([a-z-]+)\}[^\n]*\n.*?^```[ \t]*$", re.MULTILINE | re.DOTALL)
_HEADING = re.compile(r"^(#{1,6})\s+(?:§\s*)?(\d+(?:\.\d+)*[a-z]?)\.?\s")
#: What a directive that only the site can fill says in a terminal.
_PLACEHOLDERS = {
    "qzs-command-help": "(In the terminal: `qzs --help` and `qzs COMMAND --help`.)",
    "toctree": "(The pages of this part: `qzs docs` lists them.)",
}


def _root():
    """The folder holding the pages: the package's ``_docs``, else the source tree's docs/."""
    shipped = resources.files("qzs").joinpath(PACKAGE_FOLDER)
    if shipped.is_dir():
        return shipped
    source_tree = Path(__file__).resolve().parents[3] / "docs"
    if (source_tree / TOPICS["model"]).is_file():
        return source_tree
    raise DataError("the documentation pages are missing: this qzs has no qzs/_docs folder "
                    "and no source tree's docs/ beside it; reinstall qzs from a wheel or "
                    "the repository (`pip install .`), whose build ships them.")


def _page(name):
    return _root().joinpath(*TOPICS[name].split("/"))


def _title(text):
    for line in text.splitlines():
        if line.startswith("# "):
            return line[2:].strip()
    return ""


def topics():
    """Every topic with its page's title.

    Returns
    -------
    dict
        Topic name -> the title of its page (its first ``#`` heading), in the order of
        :data:`TOPICS`.
    """
    return {name: _title(_page(name).read_text(encoding="utf-8")) for name in TOPICS}


def topic_names():
    """Every name :func:`resolve_topic` accepts: the topics, and the short names.

    Returns
    -------
    list of str
        The keys of :data:`TOPICS`, then each workflow page's last part that no other topic
        has (``simulate`` for ``workflows/simulate``).
    """
    last = [topic.rsplit("/", 1)[-1] for topic in TOPICS]
    return [*TOPICS, *(name for topic, name in zip(TOPICS, last)
                       if name != topic and last.count(name) == 1 and name not in TOPICS)]


def resolve_topic(name):
    """The topic a name means: itself, or the one topic whose last part it is.

    Parameters
    ----------
    name : str
        A topic name (``model``, ``workflows/simulate``), a workflow page's last part
        (``simulate``), or a page's file name (``model.md``).

    Returns
    -------
    str
        The key of :data:`TOPICS`.

    Raises
    ------
    ParameterError
        No topic has that name; the message lists them.
    """
    wanted = str(name).strip().removesuffix(".md").removeprefix("docs/")
    if wanted in TOPICS:
        return wanted
    matches = [topic for topic in TOPICS if topic.rsplit("/", 1)[-1] == wanted]
    if len(matches) == 1:
        return matches[0]
    raise ParameterError(f"topic {str(name)!r} is not a documentation topic; choose one of "
                         f"{', '.join(TOPICS)} (`qzs docs` lists them with their titles).")


def read_topic(name, section=None):
    """The text of a topic's page, or of one of its numbered sections.

    Parameters
    ----------
    name : str
        The topic (see :func:`resolve_topic`).
    section : str, optional
        A section number as the page numbers its headings (``7``, ``9.5``, with or without
        a leading ``§``); default the whole page.

    Returns
    -------
    str
        The page's Markdown, cross-reference roles reduced to their targets.

    Raises
    ------
    ParameterError
        An unknown topic, or a section the page does not have (the message lists its
        sections).
    """
    topic = resolve_topic(name)
    text = _plain(_page(topic).read_text(encoding="utf-8"))
    if section is None:
        return text
    return find_section(text, section, where=f"`qzs docs {topic}`")


def section_numbers(text):
    """The numbers of a Markdown page's numbered headings, in order (``["1", ..., "9.5"]``).

    Parameters
    ----------
    text : str
        The page's Markdown.

    Returns
    -------
    list of str
    """
    return [match[2] for _, match in _headings(text)]


def find_section(text, number, *, where="the page"):
    """The numbered section of a Markdown page: its heading down to the next at its level.

    Parameters
    ----------
    text : str
        The page's Markdown.
    number : str
        The section's number (``7``, ``§7``, ``9.5``).
    where : str
        How the page is named in the error message.

    Returns
    -------
    str
        The section's lines, its heading first; its subsections included.

    Raises
    ------
    ParameterError
        The page has no section of that number.
    """
    wanted = str(number).strip().lstrip("§").strip().rstrip(".")
    lines = text.splitlines(keepends=True)
    headings = _headings(text)
    for position, (index, match) in enumerate(headings):
        if match[2] == wanted:
            level = len(match[1])
            end = next((later for later, other in headings[position + 1:]
                        if len(other[1]) <= level), len(lines))
            return "".join(lines[index:end]).rstrip() + "\n"
    raise ParameterError(f"section {str(number)!r}: {where} has no such section; its "
                         f"sections are {', '.join(section_numbers(text)) or 'not numbered'}.")


def _headings(text):
    """``(line index, match)`` of every numbered heading outside fenced code blocks."""
    found, fenced = [], False
    for index, line in enumerate(text.splitlines()):
        if line.lstrip().startswith(("```", "~~~")):
            fenced = not fenced
        elif not fenced:
            match = _HEADING.match(line)
            if match:
                found.append((index, match))
    return found


def _plain(text):
    """Markdown for a terminal: roles reduced to their targets, site-only blocks replaced."""
    def directive(match):
        return _PLACEHOLDERS.get(match[1], match[0])

    return _ROLE.sub(r"`\1`", _DIRECTIVE.sub(directive, text)).rstrip("\n") + "\n"
