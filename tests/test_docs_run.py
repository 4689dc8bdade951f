"""The documentation runs as written: every ```sh and ```python block of README.md and the
documentation's pages, in the site's order, in one fresh folder, as a reader following them.

The pages are README.md, then the site's pages in its toctree order from docs/index.md
(a page's ``{include}`` at its place; workflows/app is docs/app.md when it exists, as
``docs/_ext/qzs_app_page.py`` builds it). Every page of docs/ and docs/workflows/ must be
reached, so a new page is never left out silently.

- An ``sh`` block runs in one ``bash`` in the folder, command by command as typed into a
  terminal (a line ending in ``\\`` continues; a variable set or a ``cd`` holds for the
  block's later commands), with this environment's ``qzs`` and ``python`` first on PATH, a
  HOME of its own (inside the folder's parent) and ``MPLBACKEND=Agg`` (no window: a figure
  a page shows is drawn, and closed). A command that exits with anything but 0 fails.
- The ``python`` blocks of one page run in ONE interpreter session (a fresh ``python`` per
  page, tests/docs_run_session.py): the pages are written so, a later block using the
  names of an earlier one (identification's ``recording``, hexapod's ``setup``). A block
  that raises fails, with the traceback naming the page and its line.

What a block cannot do in a test, and what it states, is written in the page's source, in
HTML comments right above the block (invisible on the site), never in a list here:

``<!-- docs-run: skip (why) -->``
    the block is not run;
``<!-- docs-run: skip `PREFIX` (why) -->``
    its commands that start with ``PREFIX`` are not run (``qzs app``: it serves until
    Ctrl-C);
``<!-- docs-run: replace `OLD` with `NEW` (why) -->``
    the block runs with ``OLD`` replaced by ``NEW`` (a Dask cluster's address);
``<!-- docs-run: writes PATH[, PATH ...] -->``
    the files or folders the page says the block writes: each must exist afterwards,
    written (or rewritten) by the block;
``<!-- docs-run: prints `TEXT` -->``
    the block's output holds ``TEXT``;
``<!-- docs-run: check `EXPRESSION` -->``
    (``python`` blocks) the page's session finds ``EXPRESSION`` true after the block;
``<!-- docs-run: save FILE -->``
    (above any other block, such as a ```toml file the page shows) the reader saves the
    block as ``FILE`` at this point of the page, as the page's later commands expect.

A marker that names no command, no text or nothing to check fails the test, and so does
an unknown marker: a stale marker never hides a command. The page tests carry the marker
``docs_run``: ``make docs`` runs them (they take minutes), ``make test`` leaves them out; the
tests of the reader itself run in both. ``QZS_DOCS_RUN_OUT`` names a JSON Lines file to
which each block's seconds (each command's, for ``sh``) and the end of its output are
appended.
"""
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: The Python session's driver.
SESSION = Path(__file__).with_name("docs_run_session.py")
#: The longest one block may take [s] before it counts as hung.
BLOCK_TIMEOUT = 900
#: JSON Lines file for each block's seconds (unset: none written).
TIMES_OUT = "QZS_DOCS_RUN_OUT"

#: The languages of the blocks that run.
RUN = ("sh", "python")
FENCE = re.compile(r"^(?P<fence>`{3,}|~{3,})(?P<info>[^`\n]*)$")
MARKER = re.compile(r"^<!--\s*docs-run:\s*(?P<body>.*?)\s*-->\s*$")
TOCTREE = re.compile(r"^(`{3,}|:{3,})\{toctree\}")
INCLUDE = re.compile(r"^(`{3,}|:{3,})\{include\}\s+(?P<path>\S+)")


# ---------------------------------------------------------------- reading the pages
@dataclass
class Block:
    """One ``sh`` or ``python`` block of a page, with the markers above it."""
    path: Path
    line: int                        # the first line of the block's code, 1-based
    language: str
    code: str
    skip: str | None = None          # why the whole block is not run
    skip_commands: list = field(default_factory=list)   # (prefix, why)
    replace: list = field(default_factory=list)         # (old, new, why)
    writes: list = field(default_factory=list)
    prints: list = field(default_factory=list)
    checks: list = field(default_factory=list)
    save: str | None = None          # a file block: saved under this name

    @property
    def where(self):
        return f"{shown(self.path)}:{self.line}"


def shown(path):
    """A page's path as the messages give it: from the repository's root."""
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def quoted(text, where):
    """The ``code`` spans of a marker, in order."""
    found = re.findall(r"`([^`]+)`", text)
    if not found:
        raise ValueError(f"{where}: the marker names nothing in `backquotes`: {text!r}")
    return found


def reason(text, where):
    match = re.search(r"\(([^()]*(?:\([^()]*\)[^()]*)*)\)\s*$", text)
    if not match or not match.group(1).strip():
        raise ValueError(f"{where}: the marker gives no (reason): {text!r}")
    return match.group(1).strip()


def apply_marker(block, body, where):
    """Read one ``docs-run:`` marker into ``block``; an unknown one is an error."""
    verb, _, rest = body.partition(" ")
    if verb == "skip" and not rest.lstrip().startswith("`"):
        block.skip = reason(rest, where)
    elif verb == "skip":
        block.skip_commands.append((quoted(rest, where)[0], reason(rest, where)))
    elif verb == "replace":
        parts = quoted(rest, where)
        if len(parts) < 2 or " with " not in rest:
            raise ValueError(f"{where}: a docs-run marker is `replace `OLD` with `NEW` (why)`: "
                             f"{body!r}")
        block.replace.append((parts[0], parts[1], reason(rest, where)))
    elif verb == "writes":
        paths = [path.strip() for path in rest.split(",") if path.strip()]
        if not paths:
            raise ValueError(f"{where}: `writes` names no file: {body!r}")
        block.writes.extend(paths)
    elif verb == "prints":
        block.prints.extend(quoted(rest, where))
    elif verb == "check":
        if block.language != "python":
            raise ValueError(f"{where}: `check` is for python blocks: {body!r}")
        block.checks.extend(quoted(rest, where))
    elif verb == "save":
        if block.language in RUN or not rest.strip():
            raise ValueError(f"{where}: `save FILE` is for a block that is not run: {body!r}")
        block.save = rest.strip()
    else:
        raise ValueError(f"{where}: unknown docs-run marker {verb!r}: {body!r}")


def blocks_of(path):
    """The ``sh`` and ``python`` blocks of a Markdown file, ``{include}`` s followed."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found, markers, index = [], [], 0
    while index < len(lines):
        line = lines[index]
        marker = MARKER.match(line.strip())
        include = INCLUDE.match(line)
        fence = FENCE.match(line)
        if marker:
            markers.append((index + 1, marker.group("body")))
        elif include:
            found.extend(blocks_of((path.parent / include.group("path")).resolve()))
        if fence and not marker:
            end = next((k for k in range(index + 1, len(lines))
                        if lines[k].startswith(fence.group("fence"))
                        and not lines[k].strip("`~")), len(lines))
            language = fence.group("info").strip()
            if language in RUN or markers:
                block = Block(path, index + 2, language, "\n".join(lines[index + 1:end]))
                for number, body in markers:
                    apply_marker(block, body, f"{shown(path)}:{number}")
                if language not in RUN and block.save is None:
                    raise ValueError(f"{shown(path)}:{markers[0][0]}: a docs-run marker "
                                     f"above a ```{language} block, which does not run")
                found.append(block)
            markers, index = [], end + 1
            continue
        if line.strip() and not marker:
            if markers:
                raise ValueError(f"{shown(path)}:{markers[0][0]}: a docs-run "
                                 f"marker not right above a block")
        index += 1
    return found


def toctree_entries(path):
    """The documents a page's ``{toctree}`` s list, in order, as paths of .md files
    (notebooks, the gallery and the API pages are built by other means, not pages here)."""
    lines, entries = path.read_text(encoding="utf-8").splitlines(), []
    for index, line in enumerate(lines):
        match = TOCTREE.match(line)
        if not match:
            continue
        for entry in lines[index + 1:]:
            if entry.startswith(match.group(1)):
                break
            entry = entry.strip()
            if not entry or entry.startswith(":"):
                continue
            target = re.search(r"<([^>]+)>$", entry)
            name = target.group(1) if target else entry
            page = (path.parent / f"{name}.md").resolve()
            if page.exists():
                entries.append(page)
    return entries


def site_pages():
    """README.md, then docs/index.md and every page below it, depth first."""
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        from qzs_app_page import DOCNAME, GUIDE
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    pages = [ROOT / "README.md"]

    def visit(page):
        pages.append(page)
        if page == DOCS / f"{DOCNAME}.md" and (DOCS / GUIDE).exists():
            pages.append(DOCS / GUIDE)    # the site shows the guide on that page
        for entry in toctree_entries(page):
            if entry not in pages:
                visit(entry)

    visit(DOCS / "index.md")
    return pages


PAGES = site_pages()


# ---------------------------------------------------------------- running them
def commands(block):
    """The block's commands: continued lines joined, comments and blank lines left out,
    with the line each starts on."""
    found, current, start = [], "", None
    for offset, line in enumerate(block.code.splitlines()):
        if start is None:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            start = block.line + offset
        current += line.strip() if current else line
        if line.rstrip().endswith("\\"):
            current = current.rstrip()[:-1].rstrip() + " "
            continue
        found.append((start, current.strip()))
        current, start = "", None
    return found


def prepared(block):
    """The block's code with its ``replace`` markers applied (each must match)."""
    code = block.code
    for old, new, _ in block.replace:
        assert old in code, f"{block.where}: `replace` names {old!r}, not in the block"
        code = code.replace(old, new)
    return code


def environment(home):
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env["HOME"] = str(home)
    env["MPLBACKEND"] = "Agg"
    env.pop("PYTHONPATH", None)
    return env


def snapshot(folder, names):
    """Each path's newest modification time (a folder: of anything in it), or None."""
    times = {}
    for name in names:
        path = folder / name
        if not path.exists():
            times[name] = None
        elif path.is_dir():
            times[name] = max([p.stat().st_mtime_ns for p in path.rglob("*")]
                              + [path.stat().st_mtime_ns])
        else:
            times[name] = path.stat().st_mtime_ns
    return times


def run_shell(block, folder, env):
    """Run the block's commands in one bash, one after the other as typed into a terminal
    (a variable set or a ``cd`` holds for the commands after it; a command that fails does
    not stop the next); the failures (none: an empty list), the output and each command's
    seconds."""
    code = prepared(block)
    substituted = Block(block.path, block.line, block.language, code)
    used = {prefix: False for prefix, _ in block.skip_commands}
    run = []
    for line, command in commands(substituted):
        skipped = [prefix for prefix in used if command.startswith(prefix)]
        for prefix in skipped:
            used[prefix] = True
        if not skipped:
            run.append((line, command))
    failures = [f"{block.where}: `skip` names `{prefix}`, which starts no command"
                for prefix, hit in used.items() if not hit]
    with tempfile.TemporaryDirectory(prefix="qzs-docs-run-sh-") as scratch:
        scratch = Path(scratch)
        script = [f"exec 3>{shlex.quote(str(scratch / 'status'))}"]
        for k, (_, command) in enumerate(run):
            out, err = (shlex.quote(str(scratch / f"{k}.{name}")) for name in ("out", "err"))
            script += ["__docs_run_start=$(date +%s%N)",
                       f"{{ {command}\n}} >{out} 2>{err} </dev/null",
                       f"echo {k} $? $__docs_run_start $(date +%s%N) >&3"]
        try:
            subprocess.run(["bash", "-o", "pipefail", "-c", "\n".join(script)], cwd=folder,
                           env=env, timeout=BLOCK_TIMEOUT, stdin=subprocess.DEVNULL,
                           capture_output=True)
        except subprocess.TimeoutExpired:
            pass
        status = {int(k): (int(rc), (int(end) - int(begin)) / 1e9) for k, rc, begin, end in
                  (entry.split() for entry in (scratch / "status").read_text().splitlines())}
        output, times = "", []
        for k, (line, command) in enumerate(run):
            if k not in status:
                failures.append(f"{shown(block.path)}:{line}: `{command}` did not finish "
                                f"within the block's {BLOCK_TIMEOUT} s")
                break
            rc, seconds = status[k]
            stdout, stderr = ((scratch / f"{k}.{name}").read_text(errors="replace")
                              for name in ("out", "err"))
            output += stdout + stderr
            times.append((line, round(seconds, 2)))
            if rc != 0:
                failures.append(f"{shown(block.path)}:{line}: `{command}` exited {rc}\n"
                                f"--- stdout\n{stdout[-3000:]}--- stderr\n{stderr[-3000:]}")
    return failures, output, times


class Session:
    """The page's Python interpreter (tests/docs_run_session.py), started at its first
    ``python`` block."""

    def __init__(self, folder, env, log):
        read, self.write = os.pipe()
        self.log = open(log, "w", encoding="utf-8")
        self.process = subprocess.Popen(
            [sys.executable, str(SESSION), str(self.write)], cwd=folder, env=env,
            stdin=subprocess.PIPE, stdout=self.log, stderr=subprocess.STDOUT, text=True,
            pass_fds=(self.write,))
        os.close(self.write)
        self.answers = os.fdopen(read, "r", encoding="utf-8")

    def run(self, block):
        request = {"source": prepared(block), "filename": shown(block.path),
                   "line": block.line, "checks": block.checks}
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        answer = self.answers.readline()
        if not answer:
            self.process.wait(timeout=60)
            return {"ok": False, "stdout": "", "stderr": Path(self.log.name).read_text(),
                    "error": f"the session ended (exit {self.process.returncode})",
                    "failed_checks": []}
        return json.loads(answer)

    def close(self):
        self.process.stdin.close()
        try:
            self.process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.answers.close()
        self.log.close()


def run_python(block, session):
    answer = session.run(block)
    failures = []
    if answer["error"]:
        failures.append(f"{block.where}: the block raised\n{answer['error']}"
                        f"--- its output\n{(answer['stdout'] + answer['stderr'])[-3000:]}")
    failures += [f"{block.where}: check {text}" for text in answer["failed_checks"]]
    return failures, answer["stdout"] + answer["stderr"]


def run_page(page, folder, home):
    """Run a page's blocks in ``folder``; the failures, one text each (none: all ran)."""
    env, session, failures = environment(home), None, []
    times = None
    try:
        for block in blocks_of(page):
            if block.skip:
                continue
            before = snapshot(folder, block.writes)
            start = time.perf_counter()
            if block.save is not None:
                (folder / block.save).parent.mkdir(parents=True, exist_ok=True)
                (folder / block.save).write_text(block.code + "\n", encoding="utf-8")
                found, output = [], ""
            elif block.language == "sh":
                found, output, times = run_shell(block, folder, env)
            else:
                if session is None:
                    session = Session(folder, env, home / f"{page.stem}-session.log")
                found, output = run_python(block, session)
            seconds = time.perf_counter() - start
            after = snapshot(folder, block.writes)
            for name in block.writes:
                if after[name] is None:
                    found.append(f"{block.where}: the page says it writes {name}; it is "
                                 "not there")
                elif before[name] is not None and after[name] <= before[name]:
                    found.append(f"{block.where}: the page says it writes {name}; the "
                                 "block left the one before it unchanged")
            found += [f"{block.where}: the page says it prints {text!r}; the output "
                      f"was\n{output[-3000:]}" for text in block.prints if text not in output]
            failures += found
            if os.environ.get(TIMES_OUT):
                with open(os.environ[TIMES_OUT], "a", encoding="utf-8") as record:
                    record.write(json.dumps({"block": block.where,
                                             "seconds": round(seconds, 2), "ok": not found,
                                             "commands": times,
                                             "output": output[-4000:]}) + "\n")
            times = None
    finally:
        if session is not None:
            session.close()
    return failures


# ---------------------------------------------------------------- the pages
@pytest.fixture(scope="module")
def reader_folder(tmp_path_factory):
    """One fresh folder for every page (and a home beside it)."""
    base = tmp_path_factory.mktemp("docs-run")
    (base / "folder").mkdir()
    (base / "home").mkdir()
    return base / "folder", base / "home"


@pytest.mark.docs_run
@pytest.mark.parametrize("page", [p for p in PAGES if blocks_of(p)],
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_the_page_runs_as_written(page, reader_folder):
    """The page's blocks, after every page before it, in the same folder."""
    failures = run_page(page, *reader_folder)
    assert not failures, "\n\n".join(failures)


# ---------------------------------------------------------------- the reader itself
def test_every_page_is_read_in_the_sites_order():
    """README first, the site's pages in toctree order, and none of docs/ nor
    docs/workflows/ left out."""
    names = [str(page.relative_to(ROOT)) for page in PAGES]
    assert names[:3] == ["README.md", "docs/index.md", "docs/getting-started.md"]
    assert names.index("docs/workflows/simulate.md") < names.index("docs/sweeps.md")
    assert names.index("docs/workflows/app.md") + 1 == names.index("docs/app.md")
    every = set(DOCS.glob("*.md")) | set((DOCS / "workflows").glob("*.md"))
    assert sorted(map(str, every - set(PAGES))) == []


def test_every_marker_is_read_and_names_something():
    """Parsing every page raises on a malformed marker; each skip says why."""
    blocks = [block for page in PAGES for block in blocks_of(page)]
    assert len(blocks) > 40
    for block in blocks:
        assert block.skip is None or block.skip
        assert all(why for _, why in block.skip_commands)


@pytest.fixture
def page_of(tmp_path):
    """Write a page of the test's own, tmp_path/page.md; return its path."""
    def write(text):
        path = tmp_path / "page.md"
        path.write_text(text, encoding="utf-8")
        return path

    return write


def run_probe(page, tmp_path):
    (tmp_path / "folder").mkdir()
    (tmp_path / "home").mkdir()
    return run_page(page, tmp_path / "folder", tmp_path / "home")


def test_a_broken_command_fails(page_of, tmp_path):
    page = page_of("```sh\necho one > one.txt\nqzs no-such-command\n```\n")
    failures = run_probe(page, tmp_path)
    assert len(failures) == 1 and "`qzs no-such-command` exited 2" in failures[0]
    assert (tmp_path / "folder" / "one.txt").read_text() == "one\n"


def test_a_broken_snippet_fails_naming_its_line_and_later_blocks_see_earlier_names(
        page_of, tmp_path):
    page = page_of("```python\nvalue = 41\n```\n\ntext\n\n```python\nprint(value + 1)\n"
                   "print(undefined_name)\n```\n")
    failures = run_probe(page, tmp_path)
    assert len(failures) == 1
    assert f"{page.name}\", line 9" in failures[0] and "NameError" in failures[0]
    assert "42" in failures[0]


def test_the_markers_check_what_a_page_states(page_of, tmp_path):
    page = page_of(
        "<!-- docs-run: writes made.txt, never.txt -->\n"
        "<!-- docs-run: prints `hello` -->\n"
        "```sh\necho bye > made.txt\n```\n\n"
        "<!-- docs-run: check `x == 2` -->\n"
        "<!-- docs-run: replace `x = 1` with `x = 3` (the probe's substitution) -->\n"
        "```python\nx = 1\n```\n\n"
        "<!-- docs-run: skip (never runs) -->\n```sh\nfalse\n```\n\n"
        "<!-- docs-run: save conf/a.toml -->\n```toml\nkey = 1\n```\n\n"
        "<!-- docs-run: writes copied.toml -->\n```sh\ncp conf/a.toml copied.toml\n```\n\n"
        "<!-- docs-run: skip `qzs app` (serves until Ctrl-C) -->\n"
        "<!-- docs-run: skip `qzs nothing` (names no command) -->\n"
        "```sh\nqzs app --no-browser\n```\n")
    failures = run_probe(page, tmp_path)
    assert any("writes never.txt; it is not there" in text for text in failures)
    assert not any("writes made.txt" in text for text in failures)
    assert any("prints 'hello'" in text for text in failures)
    assert any("check x == 2: false" in text for text in failures)
    assert any("`qzs nothing`, which starts no command" in text for text in failures)
    assert len(failures) == 4


@pytest.mark.parametrize("marker", ["<!-- docs-run: skip -->", "<!-- docs-run: hide -->",
                                    "<!-- docs-run: skip `qzs app` -->",
                                    "<!-- docs-run: replace `a` (why) -->"])
def test_a_malformed_or_stray_marker_is_an_error(page_of, marker):
    """A malformed marker, one that is not right above a block, and one above a block
    that is not run (other than `save`)."""
    with pytest.raises(ValueError, match="docs-run|marker"):
        blocks_of(page_of(f"{marker}\n```sh\necho\n```\n"))
    with pytest.raises(ValueError, match="not right above"):
        blocks_of(page_of("<!-- docs-run: skip (why) -->\n\ntext\n\n```sh\necho\n```\n"))
    with pytest.raises(ValueError, match="which does not run"):
        blocks_of(page_of("<!-- docs-run: skip (why) -->\n```toml\na = 1\n```\n"))


def test_the_commands_of_a_block_join_continued_lines():
    block = Block(ROOT / "README.md", 10, "sh",
                  "# a comment\nqzs simulate --a 1 \\\n    --b 2   # note\n\nqzs params\n")
    assert commands(block) == [(11, "qzs simulate --a 1 --b 2   # note"), (14, "qzs params")]
    assert shlex.split(commands(block)[0][1], comments=True)[-1] == "2"


def test_a_blocks_commands_share_one_shell(page_of, tmp_path):
    """A variable set by one command (docs/fmu.md's FMI_HEADERS) or a `cd` holds for the
    next; a failing command does not stop those after it, and is named with its line."""
    page = page_of("<!-- docs-run: writes sub/seen.txt, after.txt -->\n"
                   "```sh\nNAME=value\nmkdir -p sub && cd sub\nfalse\necho \"$NAME\" > seen.txt\n"
                   "cd .. && echo done > after.txt\n```\n")
    failures = run_probe(page, tmp_path)
    assert len(failures) == 1 and ":5: `false` exited 1" in failures[0], failures
    assert (tmp_path / "folder" / "sub" / "seen.txt").read_text() == "value\n"
