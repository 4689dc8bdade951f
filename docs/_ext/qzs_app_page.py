"""workflows/app.md: the interactive page's guide (docs/app.md) when it exists, else a stub.

docs/app.md is written alongside the ``qzs app`` code and cited by path, so it stays where it
is and is not a page of its own (``exclude_patterns``); workflows/app.md includes it, its
image (docs/app.png) relative to it. Until it exists the stub's own text is the page, so the
build does not depend on it.
"""
from pathlib import Path

#: The document that includes the guide, and the guide relative to the source folder.
DOCNAME = "workflows/app"
GUIDE = "app.md"


def include_guide(app, docname, source):
    if docname != DOCNAME or not (Path(app.srcdir) / GUIDE).exists():
        return
    # The guide brings its own title; its image paths stay relative to the guide itself.
    source[0] = f"```{{include}} ../{GUIDE}\n:relative-images:\n```\n"


def setup(app):
    app.connect("source-read", include_guide)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
