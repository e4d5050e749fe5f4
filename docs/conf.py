"""Sphinx configuration of the hybridsub site: the guide (the Markdown pages of docs/, through
myst-parser) and the API reference, generated from the numpydoc docstrings.

Build it with ``python -m sphinx -W --keep-going -b html docs docs/_build/html`` (the ``docs``
extra installs what it needs); ``.ci/run`` builds it with warnings as errors.
"""

import os
import sys

sys.path.insert(0, os.path.abspath(".."))

from hybridsub import __version__  # noqa: E402

project = "hybridsub"
author = "hybridsub contributors"
copyright = "the hybridsub contributors (MIT licence)"
release = version = __version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "figures/*.py"]
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]

autosummary_generate = False
autodoc_typehints = "none"  # the numpydoc Parameters sections carry the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()

html_theme = "alabaster"
html_title = f"hybridsub {release}"
html_static_path: list = []
html_theme_options = {"description": "Subdivision surfaces that keep their sharp features",
                      "github_repo": "hybridsub", "fixed_sidebar": True}
