"""One page's Python session for tests/test_docs_run.py: a fresh interpreter that runs the
page's ``python`` blocks in one namespace, as a reader pasting them one after the other
into one ``python`` would (later blocks see the names of earlier ones).

The test writes one JSON request per line on this process's stdin::

    {"source": "...", "filename": "docs/page.md", "line": 38, "checks": ["expr", ...]}

and reads one JSON answer per request from the file descriptor given as the first argument
(the process's own stdout and stderr stay the user's: the block's prints, its warnings and
its progress bars go there, and to the answer's ``stdout`` and ``stderr``)::

    {"ok": true, "stdout": "...", "stderr": "...", "error": null, "failed_checks": []}

A block is compiled under the page's name with its own line numbers, so a traceback names
the page and the line a reader sees.
"""
import contextlib
import io
import json
import linecache
import os
import sys
import traceback


class Tee(io.TextIOBase):
    """Write to the real stream and keep a copy (the block's output, for its checks)."""

    def __init__(self, stream):
        self.stream, self.copy = stream, io.StringIO()

    def write(self, text):
        self.copy.write(text)
        return self.stream.write(text)

    def flush(self):
        self.stream.flush()

    def isatty(self):
        return False

    def fileno(self):
        return self.stream.fileno()


def run(request, namespace):
    out, err = Tee(sys.stdout), Tee(sys.stderr)
    error, failed = None, []
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            source = "\n" * (request["line"] - 1) + request["source"] + "\n"
            code = compile(source, request["filename"], "exec")
            # the page's lines for the traceback (a later block of the page adds its own)
            known = linecache.cache.get(request["filename"], (0, None, [], ""))[2]
            lines = source.splitlines(keepends=True)
            merged = [new if new.strip() else (known[i] if i < len(known) else new)
                      for i, new in enumerate(lines)] + known[len(lines):]
            linecache.cache[request["filename"]] = (len(source), None, merged,
                                                    request["filename"])
            exec(code, namespace)
        except BaseException as raised:   # noqa: BLE001 -- a SystemExit fails it too
            # from the block's own frame on: the page's line first, not this driver's
            error = "".join(traceback.format_exception(type(raised), raised,
                                                       raised.__traceback__.tb_next))
        if error is None:
            for check in request["checks"]:
                try:
                    if not eval(check, namespace):
                        failed.append(f"{check}: false")
                except Exception:   # noqa: BLE001 -- the check's own error is its answer
                    failed.append(f"{check}: {traceback.format_exc(limit=0).strip()}")
        out.flush()
        err.flush()
    return {"ok": error is None and not failed, "stdout": out.copy.getvalue(),
            "stderr": err.copy.getvalue(), "error": error, "failed_checks": failed}


def main():
    answers = os.fdopen(int(sys.argv[1]), "w", encoding="utf-8")
    namespace = {"__name__": "__main__"}
    for line in sys.stdin:
        answers.write(json.dumps(run(json.loads(line), namespace)) + "\n")
        answers.flush()


if __name__ == "__main__":
    main()
