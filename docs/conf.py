"""Sphinx configuration of the geoshade documentation site.

Build (what ``.ci/run`` runs; the gallery renders with headless EGL)::

    python -m pip install -e ".[docs]"
    python -m sphinx -W --keep-going -b html docs docs/_build/html

The API reference is generated from the code (autosummary over each public package's
``__all__``); the gallery runs every ``examples/plot_*.py`` and fails the build when one raises.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
# the package itself is installed (pip install -e); src/ first makes a plain checkout work too
sys.path.insert(0, str(ROOT / "src"))
# the gallery draws on pictures sized for a web page, never on a display
os.environ.setdefault("MPLBACKEND", "Agg")

import geoshade  # noqa: E402 (after sys.path)

project = "geoshade"
author = "the geoshade authors"
copyright = "2026, the geoshade authors"
version = release = geoshade.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "**.ipynb_checkpoints", "auto_examples/*.ipynb",
                    "auto_examples/*.py", "auto_examples/*.zip", "auto_examples/*.json"]

# --- API reference -------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False  # a module without __all__: only what it defines
autosummary_ignore_module_all = False  # __all__ is the public API
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
autodoc_mock_imports: list[str] = []

numpydoc_show_class_members = False  # autosummary lists members; no second table per class
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()  # the style is checked by review, not the build

# --- Markdown pages of docs/ (ARCHITECTURE, NOTES, DEPENDENCIES) ---------------------------------
myst_heading_anchors = 3
myst_enable_extensions = ["colon_fence"]
suppress_warnings = [
    # the Markdown pages link files of the repository (src/..., benchmarks/...), not pages
    "myst.xref_missing",
    # a page of docs/*.md may go from # to ### (GitHub renders it; so does the site)
    "myst.header",
]

# --- gallery -------------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"__init__\.py|_helpers\.py",
    "plot_gallery": "True",
    "abort_on_example_error": True,  # an example that raises fails the build
    "only_warn_on_example_error": False,
    "image_scrapers": ("matplotlib",),
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "min_reported_time": 1,
    "line_numbers": False,
    "capture_repr": (),
}

# --- HTML ----------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"geoshade {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False


# --- field tables of data classes ----------------------------------------------------------------
# The models and options document their fields as aligned plain-text tables (docs/ARCHITECTURE.md:
# "name: shape dtype meaning"), one entry per line, continuation lines indented under the text:
#
#     data:    (nz, ny, nx) integer or float   values, x varying fastest;
#              a numpy array, a numpy.memmap or a dask array
#     spacing: (3,) float                      voxel size along (x, y, z)
#
# Read as reStructuredText that is a broken definition list; here it becomes a real one (the
# field name as the term), before numpydoc reads the docstring. Only the text before the first
# numpydoc section is looked at.
_ENTRY = re.compile(r"^([A-Za-z_]\w*(?:, [A-Za-z_]\w*)*):\s+(\S.*)$")  # name[, name...]: text
_UNDERLINE = re.compile(r"^\s*-{3,}\s*$")


def _field_table_blocks(lines: list[str]) -> list[tuple[int, int]]:
    """(start, stop) line ranges of field tables in the summary part of ``lines``."""
    end = next((i - 1 for i in range(1, len(lines)) if _UNDERLINE.match(lines[i])), len(lines))
    blocks, i = [], 0
    while i < end:
        if _ENTRY.match(lines[i]) and (i == 0 or not lines[i - 1].strip()):
            j, entries, continued = i, 0, False
            while j < end and lines[j].strip():
                if _ENTRY.match(lines[j]):
                    entries += 1
                elif lines[j][:1].isspace():
                    continued = True
                else:
                    break
                j += 1
            if j >= end or not lines[j].strip():  # the block ends at a blank line
                if entries >= 2 or continued:
                    blocks.append((i, j))
            i = max(j, i + 1)
        else:
            i += 1
    return blocks


def field_tables_as_definition_lists(lines: list[str]) -> None:
    """Rewrite the field tables of a docstring (``lines``, in place) as definition lists.

    >>> doc = ["A volume.", "", "data:  (nz, ny, nx) values;", "       lazy or not",
    ...        "unit:  str   length unit"]
    >>> field_tables_as_definition_lists(doc)
    >>> doc[2:]
    ['``data``', '    (nz, ny, nx) values; lazy or not', '``unit``', '    str length unit']
    """
    for start, stop in reversed(_field_table_blocks(lines)):
        out: list[str] = []
        for line in lines[start:stop]:
            m = _ENTRY.match(line)
            if m:
                term = ", ".join(f"``{n}``" for n in m.group(1).split(", "))
                out += [term, "    " + " ".join(m.group(2).split())]
            else:
                out[-1] += " " + " ".join(line.split())
        lines[start:stop] = out


def _process_docstring(app, what, name, obj, options, lines) -> None:
    if what in ("class", "module", "exception"):
        field_tables_as_definition_lists(lines)


def _check_gl(app, config) -> None:
    """The gallery draws with OpenGL: say so in one line where it is switched off."""
    plot = str(getattr(config, "plot_gallery", "True")).lower()  # -D plot_gallery=0 sets it
    if plot not in ("0", "false", "") and os.environ.get("GEOSHADE_GL", "").lower() == "off":
        raise SystemExit("docs: GEOSHADE_GL=off, but the gallery's examples draw with OpenGL "
                         "(EGL); unset it, or build without running them: -D plot_gallery=0")


def setup(app) -> None:
    # before numpydoc (priority 500), which reads the summary part as plain reST
    app.connect("autodoc-process-docstring", _process_docstring, priority=400)
    app.connect("config-inited", _check_gl)
