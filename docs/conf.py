"""Sphinx configuration of the appdyn docs (``make docs``: warnings are errors).

The API reference is written at build time from the ``__all__`` of every public package
(`_api.write_api`); the examples gallery runs ``examples/plot_*.py`` with sphinx-gallery;
the performance page's tables are written by ``appdyn bench --docs``.
"""
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
os.environ.setdefault("MPLBACKEND", "Agg")

import appdyn  # noqa: E402
from _api import write_api  # noqa: E402

project = "appdyn"
author = "appdyn maintainers"
copyright = "appdyn maintainers, MIT licence"
release = appdyn.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip", "auto_examples/*.md5",
                    "auto_examples/*.codeobj.json", "auto_examples/*.pickle"]
templates_path = ["_templates"]
# `name` in a docstring links to the object when it resolves, else reads as code
default_role = "py:obj"

# API reference ------------------------------------------------------------------------------
write_api(HERE / "api")
autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "none"        # numpydoc's Parameters section carries types and units
add_module_names = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False
suppress_warnings = ["config.cache"]

# pages written in markdown ------------------------------------------------------------------
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# examples gallery ---------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
}

# HTML ---------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"appdyn {release}"
html_static_path = []
