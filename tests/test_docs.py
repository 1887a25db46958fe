"""The documentation site's cheap checks, without building it (``.ci/run`` builds it with
``python -m sphinx -W``): the configuration loads, every gallery example has a title and will
run, every public module and top-level name is in the API reference, every guide page is linked.
"""

from __future__ import annotations

import ast
import re
import runpy
import tomllib
from pathlib import Path

import pytest

import geoshade

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXAMPLES = ROOT / "examples"
#: packages and modules under geoshade that are not public API: the GL layer (reached through
#: the parts and geoshade.view), the CLI and the viewer (documented in the user guide)
INTERNAL = {"render", "cli", "viewer"}


@pytest.fixture(scope="module")
def conf() -> dict:
    return runpy.run_path(str(DOCS / "conf.py"))


def _api_text() -> str:
    return "\n".join(p.read_text() for p in sorted((DOCS / "api").glob("*.rst")))


def _public_modules() -> list[str]:
    src = Path(geoshade.__file__).parent
    names = [p.name for p in src.iterdir() if p.is_dir() and (p / "__init__.py").is_file()]
    names += [p.stem for p in src.glob("*.py") if p.stem != "__init__"]
    return sorted(f"geoshade.{n}" for n in names if not n.startswith("_") and n not in INTERNAL)


def test_conf_loads_with_the_extensions_and_a_gallery_that_fails_on_errors(conf):
    assert conf["release"] == geoshade.__version__
    assert {"numpydoc", "sphinx.ext.autodoc", "sphinx.ext.autosummary",
            "sphinx_gallery.gen_gallery", "myst_parser"} <= set(conf["extensions"])
    gallery = conf["sphinx_gallery_conf"]
    assert Path(gallery["examples_dirs"]) == EXAMPLES
    assert gallery["abort_on_example_error"] is True
    assert gallery["only_warn_on_example_error"] is False
    assert conf["autosummary_generate"] is True


def test_field_tables_become_definition_lists(conf):
    lines = ["A grid.", "", "coord: (n, 6) float   pillars,", "       F-order",
             "nx, ny: int   cells", "", "Examples", "--------", "name: not a table"]
    conf["field_tables_as_definition_lists"](lines)
    assert lines == ["A grid.", "", "``coord``", "    (n, 6) float pillars, F-order",
                     "``nx``, ``ny``", "    int cells", "", "Examples", "--------",
                     "name: not a table"]


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.py")), ids=lambda p: p.name)
def test_every_example_is_run_by_the_gallery_and_has_a_title(conf, path):
    pattern = conf["sphinx_gallery_conf"]["filename_pattern"]
    assert re.search(pattern, str(path)), f"{path.name} does not match {pattern!r}: never run"
    tree = ast.parse(path.read_text())
    doc = ast.get_docstring(tree, clean=False)
    assert doc, f"{path.name}: no docstring (sphinx-gallery takes the title from it)"
    lines = doc.strip("\n").splitlines()
    assert len(lines) >= 4, f"{path.name}: a title, its underline and a paragraph"
    title, underline = lines[0], lines[1]
    assert title.strip() and re.fullmatch(r"=+", underline), f"{path.name}: title underline"
    assert len(underline) >= len(title), f"{path.name}: underline shorter than the title"
    assert "plt.show()" in path.read_text(), f"{path.name}: shows no figure for the gallery"


def test_the_gallery_has_its_readme_and_examples():
    assert (EXAMPLES / "README.rst").is_file() or (EXAMPLES / "README.txt").is_file()
    assert len(list(EXAMPLES.glob("plot_*.py"))) >= 6


def test_every_public_module_is_in_the_api_reference():
    listed = set(re.findall(r"^\s+(geoshade(?:\.\w+)*)\s*$", _api_text(), flags=re.M))
    missing = [m for m in _public_modules() if m not in listed]
    assert not missing, f"docs/api/index.rst does not list {missing}"
    for m in listed:  # and nothing listed is gone
        __import__(m)


def test_every_top_level_name_is_in_the_api_reference():
    text = (DOCS / "api" / "geoshade.rst").read_text()
    missing = [n for n in geoshade._LAZY if f"``geoshade.{n}``" not in text]
    assert not missing, f"docs/api/geoshade.rst does not describe geoshade.{missing}"


def test_every_guide_page_is_in_the_guide_toctree():
    index = (DOCS / "guide" / "index.rst").read_text()
    entries = set(re.findall(r"^   (\w+)\s*$", index, flags=re.M))
    pages = {p.stem for p in (DOCS / "guide").glob("*.rst")} - {"index"}
    assert pages == entries
    assert {"install", "core", "grid", "iso", "stacks", "viewer", "scale", "interop"} <= pages


def test_the_docs_extra_and_ci_build_with_warnings_as_errors():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    docs = {re.match(r"[A-Za-z0-9_.\-]+", r).group(0).lower()
            for r in meta["optional-dependencies"]["docs"]}
    assert {"sphinx", "numpydoc", "sphinx-gallery", "pydata-sphinx-theme"} <= docs
    ci = (ROOT / ".ci" / "run").read_text()
    assert 'python -m pip install -e ".[docs]"' in ci
    build = [line for line in ci.splitlines() if "-m sphinx" in line]
    assert build and " -W " in build[0] and "GEOSHADE_GL=off" not in build[0]


def test_gallery_with_gl_off_is_one_line(conf, monkeypatch):
    from types import SimpleNamespace

    monkeypatch.setenv("GEOSHADE_GL", "off")
    with pytest.raises(SystemExit, match=r"GEOSHADE_GL=off.*-D plot_gallery=0"):
        conf["_check_gl"](None, SimpleNamespace(plot_gallery="True"))
    conf["_check_gl"](None, SimpleNamespace(plot_gallery="0"))  # without the gallery: fine
    monkeypatch.delenv("GEOSHADE_GL")
    conf["_check_gl"](None, SimpleNamespace(plot_gallery="True"))
