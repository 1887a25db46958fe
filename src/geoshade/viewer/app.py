"""Starting Qt for the viewer: one clear line when PySide6 or a display is missing."""

from __future__ import annotations

import os
import sys

from geoshade.errors import GeoshadeError

#: what to install when PySide6 is missing
INSTALL_HINT = "pip install 'geoshade[viewer]' (PySide6-Essentials)"


class ViewerUnavailableError(GeoshadeError, RuntimeError):
    """The desktop viewer cannot start (no PySide6, no display)."""

    exit_code = 3


def require_qt() -> None:
    """Import PySide6 or raise one clear line."""
    try:
        import PySide6.QtWidgets  # noqa: F401
    except ImportError as err:
        raise ViewerUnavailableError(f"the viewer needs PySide6 ({err}); {INSTALL_HINT}") from None


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                or os.environ.get("QT_QPA_PLATFORM") or os.name == "nt"
                or sys.platform == "darwin")


def application(offscreen: bool = False):
    """The QApplication (made once). ``offscreen``: Qt's offscreen platform when no display."""
    require_qt()
    if offscreen and not has_display():
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    if app is None:
        if not has_display():
            raise ViewerUnavailableError(
                "no display: set DISPLAY, run under xvfb-run, or save a picture with "
                "--screenshot OUT.png (Qt's offscreen platform)")
        _quiet_qt()
        app = QApplication(["geoshade"])
    return app


def _quiet_qt() -> None:
    """Drop Qt's notice that the offscreen platform ignores window size hints (harmless)."""
    from PySide6.QtCore import qInstallMessageHandler

    def handler(mode, context, message):
        if "propagateSizeHints" not in message:
            sys.stderr.write(f"{message}\n")

    qInstallMessageHandler(handler)


