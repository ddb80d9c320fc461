"""Sphinx configuration of the ancfdae documentation (``sphinx-build -W docs docs/_build``)."""
import os
import sys

sys.path.insert(0, os.path.abspath(".."))

import ancfdae  # noqa: E402

project = "ancfdae"
author = "the ancfdae authors"
release = version = ancfdae.__version__
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    # The studies page and the integrator guide are markdown, shared with the repository's
    # readers on GitHub; myst-parser renders them here without a second copy in reST.
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "api/generated/*.md"]
templates_path = ["_templates"]
autosummary_generate = True
autodoc_typehints = "none"          # numpydoc's Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
myst_heading_anchors = 3
html_theme = "alabaster"
html_theme_options = {"page_width": "1240px", "sidebar_width": "240px"}
nitpicky = False
suppress_warnings = ["myst.header"]


def _other_guides(app, docname, source):
    """Append every top-level page that index.rst does not name to a "More guides" toctree.

    Other pages (e.g. the integrator guide) are written alongside the code; this keeps each of them
    on the site without a hand-kept list here.
    """
    if docname != "index":
        return
    here = os.path.dirname(os.path.abspath(__file__))
    text = source[0]
    named = {line.strip() for line in text.splitlines()}
    pages = sorted(os.path.splitext(f)[0] for f in os.listdir(here)
                   if f.endswith((".md", ".rst")) and os.path.splitext(f)[0] not in named | {"index"})
    if pages:
        source[0] = text + "\n.. toctree::\n   :maxdepth: 2\n   :caption: More guides\n\n" + "".join(
            f"   {p}\n" for p in pages)


def setup(app):
    """Register the hook that lists the guide pages."""
    app.connect("source-read", _other_guides)
