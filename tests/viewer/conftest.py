"""Viewer tests: Qt's offscreen platform (no display, no window waits for a human)."""

from __future__ import annotations

import os

import pytest

# before any QApplication exists: Qt draws into memory, no X server or Wayland needed
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")


@pytest.fixture(scope="session")
def qapp(ctx):
    """Qt's application (offscreen); the views draw into the shared context ``ctx``."""
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
