"""Sphinx configuration of frirom's documentation (bash scripts/docs.sh builds it)."""

import os
from pathlib import Path

import frirom

ROOT = Path(__file__).resolve().parents[1]

project = "frirom"
author = "the frirom developers"
copyright = "2026, the frirom developers"
release = frirom.__version__
version = release

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "ford.md", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json"]
root_doc = "index"

myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
autodoc_typehints = "none"
autodoc_member_order = "bysource"

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MPLBACKEND", "Agg")

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "within_subsection_order": "FileNameSortKey",
}

html_theme = "alabaster"
html_static_path = ["_static"]
html_title = f"frirom {release}"


def _escape_bars(app, what, name, obj, options, lines):
    """Docstrings write magnitudes and norms as |x| and ||x||, which reStructuredText
    reads as substitution references; escape the bars outside tables."""
    for i, line in enumerate(lines):
        if "|" in line and not line.lstrip().startswith(("| ", "+")):
            lines[i] = line.replace("|", r"\|")


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
