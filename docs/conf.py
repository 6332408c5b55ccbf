"""Sphinx configuration of the cushion-clutch documentation.

Build: ``sphinx-build -W --keep-going -b html docs docs/_build/html`` (warnings are errors; MyST reports
broken internal links as warnings). Sphinx because the command-line reference is generated from the
argparse parser itself (sphinx-argparse), the Python reference from the numpydoc docstrings (autodoc +
napoleon), and the pages stay Markdown (MyST), like the README. ``docs/_ext``: the FMU variable table and the
``{cc}`` role (numbers computed at build time); ``docs/_static/cc.css``: wide tables and code wrap at 1280 px
(``tests/test_site_browser.py`` checks it in headless Chromium).
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))                 # the checkout's package, also without pip install -e
sys.path.insert(0, str(Path(__file__).parent / "_ext"))

from cushion_clutch import __version__  # noqa: E402

project = "cushion-clutch"
author = "cushion-clutch contributors"
copyright = "cushion-clutch contributors, MIT licence"
release = version = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinxarg.ext",
    "fmu_variables",
    "cc_numbers",                             # {cc}`name(args)`: numbers computed at build time
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]           # results pages start at ### (they are generated tables)

napoleon_numpy_docstring = True
napoleon_google_docstring = False
autodoc_member_order = "bysource"
autodoc_typehints = "description"

html_theme = "furo"
html_title = f"cushion-clutch {__version__}"
html_static_path = ["_static"]
html_css_files = ["cc.css"]                  # wide tables and code wrap at 1280 px (tests/test_site_browser.py)
smartquotes = False                          # keep -- in option names as typed


def _relative_paths(app, pagename, templatename, context, doctree) -> None:
    """The checkout's absolute path (in argparse defaults and autodoc signatures: the package's data files)
    written relative to the repository, so that no page names the machine that built it."""
    for key in ("body", "toc", "metatags"):
        if isinstance(context.get(key), str):
            context[key] = context[key].replace(str(ROOT) + "/", "").replace(str(ROOT), ".")


def setup(app):
    app.connect("html-page-context", _relative_paths)
