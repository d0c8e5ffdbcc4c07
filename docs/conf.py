"""Sphinx configuration of camdyn's documentation: the README's guide, the pages of docs/,
the derivation notebook (rendered, not executed) and the API reference from the numpydoc
docstrings.  Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html``
(``tests/test_docs.py`` builds it with warnings as errors)."""
from __future__ import annotations

import shutil
from pathlib import Path

import camdyn  # installed from this checkout: pip install -e ".[docs]"

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

project = "camdyn"
author = "the camdyn developers"
copyright = "camdyn developers, BSD-3-Clause"  # noqa: A001
release = version = camdyn.__version__

extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.mathjax"]
source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]

# the notebooks are rendered as committed (no outputs stored): running them is tests/test_notebooks.py's job
nb_execution_mode = "off"
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
# a class exported at the top level is documented twice (camdyn.Scene and camdyn.model.scene.Scene):
# a type hint "Scene" then has two targets, both the same class ("more than one target found")
suppress_warnings = ["ref.python"]
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_google_docstring = False
napoleon_numpy_docstring = True

html_theme = "alabaster"
html_title = f"camdyn {release}"
html_static_path: list[str] = []

# The derivation notebook lives in notebooks/ (where Jupyter users open it); Sphinx reads only
# files under docs/, so the build copies it into docs/_generated/ (git-ignored) when it changed.
NOTEBOOKS = {"01-derivation.ipynb": "derivation.ipynb"}
generated = HERE / "_generated"
generated.mkdir(exist_ok=True)
for source, target in NOTEBOOKS.items():
    src, dst = ROOT / "notebooks" / source, generated / target
    if not dst.exists() or dst.read_bytes() != src.read_bytes():
        shutil.copyfile(src, dst)
