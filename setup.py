"""The build step that ships the documentation pages inside the wheel (``qzs docs``).

Everything else about the package is in pyproject.toml. The repository's docs/ stays the one
copy of the model and workflow pages; building copies the pages named in
``qzs.iotools.docs.TOPICS`` (read from that file's source, without importing qzs)
into the built package as ``qzs/_docs/``. An editable install copies nothing: ``qzs docs``
reads the source tree's docs/ there. A build without the pages (an sdist that lost docs/)
fails here, instead of making a wheel whose ``qzs docs`` cannot work.
"""
import ast
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
DOCUMENTATION = ROOT / "src" / "qzs" / "iotools" / "docs.py"


def shipped_pages():
    """The ``TOPICS`` pages (paths relative to docs/), read from the module's source."""
    for node in ast.parse(DOCUMENTATION.read_text(encoding="utf-8")).body:
        if (isinstance(node, ast.Assign) and len(node.targets) == 1
                and getattr(node.targets[0], "id", None) == "TOPICS"):
            return sorted(set(ast.literal_eval(node.value).values()))
    raise RuntimeError(f"{DOCUMENTATION}: no TOPICS = {{...}} literal")


def copy_pages(docs, destination):
    """Copy the shipped pages from ``docs`` into ``destination``; returns the copies."""
    copies = []
    for page in shipped_pages():
        source = Path(docs) / page
        if not source.is_file():
            raise RuntimeError(f"cannot ship the documentation: {source} is missing (building "
                               "needs the repository's docs/ folder)")
        target = Path(destination) / page
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
        copies.append(str(target))
    return copies


class BuildWithDocs(build_py):
    """setuptools' ``build_py``, plus the documentation pages as ``qzs/_docs/``."""

    def run(self):
        super().run()
        if not getattr(self, "editable_mode", False):
            self._docs = copy_pages(ROOT / "docs", Path(self.build_lib) / "qzs" / "_docs")

    def get_outputs(self, include_bytecode=True):
        return super().get_outputs(include_bytecode) + list(getattr(self, "_docs", []))


if __name__ == "__main__":
    setup(cmdclass={"build_py": BuildWithDocs})
