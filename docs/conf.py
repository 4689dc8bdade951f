"""Sphinx configuration of the qzs documentation site (``make docs``).

The site is built warning-free (``sphinx-build -W``) from:

* the Markdown guides in this folder (model.md, sweeps.md, response.md, design.md,
  hexapod.md), parsed by MyST, under the names that code and help texts cite;
* the API reference, generated from the docstrings (numpydoc, autosummary): the pages of
  api/ are written at build time from the ``__all__`` of every public module
  (``_ext/qzs_api.py``);
* tutorials/*.ipynb, stored without outputs and executed by myst-nb on every build;
* gallery_src/*.py, the figure gallery, executed by sphinx-gallery;
* validation.md, whose tables are the records of the test suite's closed-form checks
  (``_ext/qzs_validation.py``; ``make docs`` runs those tests first).
"""
import os
import sys
from pathlib import Path

import qzs

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

project = "qzs"
author = "the qzs developers"
copyright = "the qzs developers; model after Leav, Eriksson, Cazzolato, Robertson and Ding"
release = qzs.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_nb",
    "sphinx_gallery.gen_gallery",
    "qzs_api",
    "qzs_validation",
    "qzs_app_page",
]

root_doc = "index"
highlight_language = "text"         # formula blocks are text; code blocks say their language
templates_path = ["_templates"]
exclude_patterns = [
    "_build", "**.ipynb_checkpoints", "Thumbs.db", ".DS_Store",
    # the gallery's sources (sphinx-gallery turns them into gallery/*.rst) ...
    "gallery_src",
    # ... and the notebooks and scripts it writes beside its pages for download
    "gallery/*.ipynb", "gallery/*.md",
    # included by workflows/app.md when it exists (qzs_app_page), not a page of its own
    "app.md",
    # validation records written by the test run of `make docs`
    "_build/validation*",
]

# ------------------------------------------------------------------ MyST and notebooks
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath", "amsmath"]
myst_heading_anchors = 3            # model.md#5-controller and the like
myst_links_external_new_tab = False

nb_execution_mode = os.environ.get("QZS_DOCS_EXECUTE", "force")   # every build runs them
# The notebooks' kernels inherit this process's environment: a backend forced here (Agg)
# would leave them without inline figures. sphinx-gallery sets its own backend.
os.environ.pop("MPLBACKEND", None)
nb_execution_timeout = 180          # [s] per cell; each tutorial takes well under a minute
nb_execution_raise_on_error = True  # a failing cell fails the build
nb_execution_show_tb = True
nb_merge_streams = True

# ------------------------------------------------------------------ API reference
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": False}
autodoc_typehints = "none"          # types are in the numpydoc sections, with units
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()  # tests/test_docstrings.py checks the house style

# ------------------------------------------------------------------ the gallery
sphinx_gallery_conf = {
    "examples_dirs": "gallery_src",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_memory": False,
    "show_signature": False,
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "run_stale_examples": True,
    "matplotlib_animations": False,
    "min_reported_time": 1,
    "write_computation_times": False,
}

# ------------------------------------------------------------------ HTML
html_theme = "pydata_sphinx_theme"
html_title = f"qzs {release}"
html_static_path = ["_static"]
html_css_files = ["qzs.css"]
html_show_sourcelink = False
html_copy_source = False
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_depth": 3,
    "show_prev_next": True,
    "secondary_sidebar_items": ["page-toc"],
    "header_links_before_dropdown": 8,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
# Wide pages (code, figures, tables) without the section navigation on the left.
html_sidebars = {"index": [], "validation": [], "tutorials/*": [], "gallery/*": []}
