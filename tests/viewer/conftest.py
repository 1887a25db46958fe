"""Viewer tests: Qt's offscreen platform (no display, no window waits for a human)."""

from __future__ import annotations

import os

import pytest

# before any QApplication exists: Qt draws into memory, no X server or Wayland needed
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


@pytest.fixture(scope="session")
def gl():
    """The shared headless context; skips where there is no OpenGL 4.3."""
    from geoshade.errors import GLUnavailableError
    from geoshade.render.context import get_context

    try:
        return get_context()
    except GLUnavailableError as err:
        pytest.skip(f"no OpenGL >= 4.3 here: {err}")


@pytest.fixture(scope="session")
def qapp(gl):
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (pip install "
                        "'geoshade[viewer]')")
    from geoshade.viewer.app import application

    return application(offscreen=True)


@pytest.fixture
def window(qapp):
    from geoshade.viewer.window import ViewerWindow

    win = ViewerWindow(size=(200, 150))
    win.show()
    yield win
    win.close()
