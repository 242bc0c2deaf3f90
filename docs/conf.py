"""Sphinx configuration of the hwpts documentation (``make docs``; offline, no intersphinx)."""

import os
import sys

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "src")))

from hwpts import __version__  # noqa: E402

project = "hwpts"
author = "the hwpts developers"
copyright = "2026, the hwpts developers"
version = release = __version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_autosummary/*.md"]
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {
    "members": True, "undoc-members": False, "show-inheritance": True, "ignore-module-all": True,
    "exclude-members": "set_fit_request,set_predict_request,set_score_request,set_output,"
                       "get_metadata_routing,set_params,get_params",
}
autodoc_typehints = "description"
autodoc_member_order = "bysource"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True
myst_heading_anchors = 3
# "ref.python": a name re-exported by a package (hwpts.identification.PWARX and
# hwpts.identification.pwarx.PWARX) is one object found twice; the link goes to either
suppress_warnings = ["myst.header", "myst.xref_missing", "ref.python"]
nitpicky = False
html_theme = "alabaster"
html_theme_options = {"page_width": "1100px", "sidebar_width": "230px"}
html_static_path = []
