"""Check every internal link of the built site: each local file and anchor must exist.

    python docs/check_links.py [docs/_build/html]

Parses every HTML page of the build (standard library only; the theme's templates in
``_static/`` are not pages) and checks each ``href`` and
``src`` that points inside the site: the file it names must exist (a folder means its
``index.html``), and an anchor (``page.html#section``, ``#section``) must be the ``id`` or
``name`` of an element of that page. External links (``http:``, ``https:``, ``mailto:``,
``data:`` ...) are not followed: the site must build and check offline. Prints the pages and
links checked and every broken one; exits 1 if any is broken.
"""
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

#: Attributes that hold a link, by element (``None``: any element).
LINK_ATTRIBUTES = {"href": None, "src": None}
#: Link schemes that leave the site.
EXTERNAL = ("http", "https", "mailto", "data", "javascript", "ftp", "tel")


class Page(HTMLParser):
    """The anchors a page defines and the links it makes."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.anchors = set()
        self.links = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if value is None:
                continue
            if name in ("id", "name") and (name == "id" or tag == "a"):
                self.anchors.add(value)
            elif name in LINK_ATTRIBUTES:
                self.links.append((tag, name, value, self.getpos()[0]))

    handle_startendtag = handle_starttag


def parse(path):
    page = Page()
    page.feed(path.read_text(encoding="utf-8", errors="replace"))
    return page


def check(root):
    """``(pages, links checked, [problem, ...])`` for the site under ``root``."""
    root = root.resolve()
    pages = {path: parse(path) for path in sorted(root.rglob("*.html"))
             if "_static" not in path.relative_to(root).parts}  # theme templates, not pages
    problems, checked = [], 0
    for path, page in pages.items():
        for tag, attribute, value, line in page.links:
            parts = urlsplit(value.strip())
            if parts.scheme in EXTERNAL or parts.netloc or value.startswith("//"):
                continue
            if not parts.path and not parts.fragment:
                continue
            checked += 1
            where = f"{path.relative_to(root)}:{line}: <{tag} {attribute}={value!r}>"
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if parts.path.endswith("/") or target.is_dir():
                target = target / "index.html"
            if root not in target.parents and target != root:
                problems.append(f"{where} leaves the site")
                continue
            if not target.exists():
                problems.append(f"{where}: no file {target.relative_to(root)}")
                continue
            fragment = unquote(parts.fragment)
            if fragment and target.suffix == ".html":
                anchors = pages[target].anchors if target in pages else parse(target).anchors
                if fragment not in anchors:
                    problems.append(f"{where}: no anchor #{fragment} in "
                                    f"{target.relative_to(root)}")
    return len(pages), checked, problems


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    root = Path(argv[0] if argv else Path(__file__).parent / "_build" / "html")
    if not (root / "index.html").exists():
        print(f"check_links: no built site at {root} (run `make docs`)", file=sys.stderr)
        return 2
    pages, checked, problems = check(root)
    for problem in problems:
        print(problem)
    print(f"check_links: {pages} pages, {checked} internal links checked, "
          f"{len(problems)} broken")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
