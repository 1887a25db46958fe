"""Shared pytest fixtures: the one headless OpenGL context (``ctx``), real data folder.

A test that uses ``ctx`` is marked ``gl`` automatically and skipped with the reason where no
OpenGL context can be created (the root ``conftest.py`` says how); GL errors fail the test that
made them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from geoshade.errors import GLUnavailableError

#: the real data sets (``<repo>/../shared/data``); absent on a machine with only the project
SHARED_DATA = (Path(__file__).resolve().parents[1] / ".." / "shared" / "data").resolve()


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path of ``<repo>/../shared/data``; skips the test when that folder is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real data folder {SHARED_DATA} is absent (see shared/data/README.md)")
    return SHARED_DATA


@pytest.fixture(scope="session")
def ctx():
    """The process-wide headless context (``geoshade.render.context.get_context``)."""
    from geoshade.render.context import get_context

    try:
        return get_context()
    except GLUnavailableError as err:
        pytest.skip(str(err).split(". ")[0])


@pytest.fixture(autouse=True)
def _gl_error_check(request):
    if "ctx" not in request.fixturenames:
        yield
        return
    context = request.getfixturevalue("ctx")
    _ = context.error  # clear
    yield
    assert context.error == "GL_NO_ERROR", "the test left a GL error"


@pytest.fixture
def shading():
    from geoshade.styles.shading import shading_uniforms

    return shading_uniforms()


@pytest.fixture(autouse=True)
def _bare_renders(monkeypatch):
    """Views render without annotations unless a test asks for them (``annotations=True``):
    the exact-oracle comparisons use the bare render, as ``--no-annotations`` and
    ``annotations=False`` give it. The CLI passes ``annotations`` explicitly, so CLI pictures
    keep theirs."""
    import geoshade.styles.options as options

    monkeypatch.setattr(options, "ANNOTATIONS_DEFAULT", False)
