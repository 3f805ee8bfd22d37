"""Sphinx configuration of the modalviewer documentation (``make docs``).

The Markdown pages are read by MyST; the API reference (``api.rst``) is written at build
time from ``modalviewer.__all__`` by ``_ext/api_page.py``; the performance tables are
made from ``benchmarks/results/*.json`` by the ``benchmark_tables`` extension.  The build
runs with ``-W``: every warning is an error, and the few suppressed below say why.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

# Importing the viewer's classes for autodoc must not need a display.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import api_page  # noqa: E402

import modalviewer  # noqa: E402

project = "modalviewer"
release = version = modalviewer.__version__
copyright = "modalviewer"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "docstrings",
    "benchmark_tables",
    # The gallery runs examples/gallery/*.py and shows the PNGs each writes with the
    # viewer's own renderer.  sphinx-gallery would need a custom image scraper for
    # those files (it collects matplotlib figures) and rewrites the scripts into its
    # own page layout; the small extension in _ext/gallery.py runs each script in a
    # temporary folder and re-runs only scripts whose text changed.
    "gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated", "_ext"]

# MyST: anchors for headings down to ####, spelled as GitHub spells them, so the pages'
# links such as how-it-works.md#how-the-eigenproblems-are-solved work on GitHub and in the
# HTML alike.
myst_heading_anchors = 4
myst_enable_extensions = ["colon_fence", "attrs_inline"]

# autodoc and napoleon: the docstrings are numpy style (Parameters / Returns sections).
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"undoc-members": False}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
# The dataclasses list their fields in an "Attributes" section and autodoc documents the
# same fields as members; as :ivar: fields the section does not describe them a second time
# (which Sphinx reports as duplicate object descriptions).
napoleon_use_ivar = True

html_theme = "furo"
html_title = f"modalviewer {release}"


_HTML_ANCHOR = re.compile(r'<a id="([\w-]+)"></a>')


def _html_anchors(app, docname, source) -> None:
    """The pages mark a few list items with ``<a id="..."></a>`` for links such as
    viewer-guide.md#sessions (GitHub keeps the id); MyST does not see ids in raw HTML, so
    for the HTML build each becomes MyST's inline anchor ``[]{#...}``."""
    source[0] = _HTML_ANCHOR.sub(r"[]{#\1}", source[0])


def _changelog_link(app, docname, source) -> None:
    """docs/index.md links ../CHANGELOG.md, the file GitHub shows; in the HTML build the
    link goes to the page changelog.md, which includes that file."""
    if docname == "index":
        source[0] = source[0].replace("](../CHANGELOG.md)", "](changelog.md)")


def _api_outdated(app, env, added, changed, removed) -> list[str]:
    """The API page is read again on every build: autodoc does not notice edited docstrings,
    and the exported names may have changed."""
    return ["api"] if "api" in env.found_docs and "api" not in changed else []


def setup(app):
    app.connect("source-read", _html_anchors)
    app.connect("source-read", _changelog_link)
    app.connect("env-get-outdated", _api_outdated)


# The API reference's list of names, from modalviewer.__all__ at build time.
api_page.write_api_page(DOCS / "_generated" / "api.inc")
