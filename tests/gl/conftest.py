"""One headless OpenGL context for every GL test; GL errors fail the test that made them."""

from __future__ import annotations

import pytest

from geoshade.errors import GLUnavailableError


@pytest.fixture(scope="session")
def ctx():
    from geoshade.render.context import get_context

    try:
        return get_context()
    except GLUnavailableError as err:
        pytest.skip(f"no OpenGL >= 4.3 here: {err}")


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
