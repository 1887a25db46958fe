"""Starting Qt for the viewer: one clear line when PySide6 or a display is missing."""

from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path

from geoshade.errors import EXIT_VIEWER, GeoshadeError

#: what to install when PySide6 is missing
INSTALL_HINT = "pip install 'geoshade[viewer]' (PySide6-Essentials)"


class ViewerUnavailableError(GeoshadeError, RuntimeError):
    """The desktop viewer cannot start (no PySide6, no display)."""

    exit_code = EXIT_VIEWER


def require_qt() -> None:
    """Import PySide6 or raise one clear line."""
    try:
        import PySide6.QtWidgets  # noqa: F401
    except ImportError as err:
        raise ViewerUnavailableError(f"the viewer needs PySide6 ({err}); {INSTALL_HINT}") from None


#: the X11 libraries Qt's xcb platform needs beyond libxcb (Debian/Ubuntu package names)
XCB_PACKAGES = ("libxcb-cursor0", "libxcb-icccm4", "libxcb-keysyms1", "libxcb-image0",
                "libxcb-render-util0", "libxcb-randr0", "libxcb-shape0", "libxcb-xinerama0",
                "libxcb-xkb1", "libxkbcommon-x11-0", "libegl1", "libdbus-1-3")
SCREENSHOT_HINT = "or save a picture without a display: geoshade view ... --screenshot OUT.png"


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                or os.environ.get("QT_QPA_PLATFORM") or os.name == "nt"
                or sys.platform == "darwin")


def _xcb_plugin() -> Path | None:
    import PySide6

    p = Path(PySide6.__file__).parent / "Qt" / "plugins" / "platforms" / "libqxcb.so"
    return p if p.is_file() else None


def xcb_problem() -> str | None:
    """Why Qt's xcb platform cannot open a window here (None: it can), without starting Qt:
    the platform plugin is loaded the way Qt will load it (a missing library is named), then an
    X connection to ``$DISPLAY`` is tried."""

    display = os.environ.get("DISPLAY", "")
    if not display:
        return "no display: DISPLAY is not set"
    plugin = _xcb_plugin()
    if plugin is not None:
        try:
            ctypes.CDLL(str(plugin))
        except OSError as err:
            missing = str(err).split(":")[0].strip() or str(err)
            return (f"Qt's xcb platform cannot load ({missing} is missing); install "
                    f"apt-get install -y {' '.join(XCB_PACKAGES)}")
    try:
        xcb = ctypes.CDLL("libxcb.so.1")
    except OSError:
        return f"Qt's xcb platform needs libxcb.so.1; install apt-get install -y libxcb1 " \
               f"{' '.join(XCB_PACKAGES)}"
    xcb.xcb_connect.restype = ctypes.c_void_p
    xcb.xcb_connect.argtypes = [ctypes.c_char_p, ctypes.c_void_p]
    xcb.xcb_connection_has_error.argtypes = [ctypes.c_void_p]
    xcb.xcb_disconnect.argtypes = [ctypes.c_void_p]
    conn = xcb.xcb_connect(display.encode(), None)
    try:
        if not conn or xcb.xcb_connection_has_error(conn):
            return (f"cannot connect to the X display {display} (start an X server, e.g. "
                    "xvfb-run for a virtual one)")
    finally:
        if conn:
            xcb.xcb_disconnect(conn)
    return None


def platform_problem() -> str | None:
    """Why Qt cannot show a window here (None: it can), checked before any QApplication."""
    platform = os.environ.get("QT_QPA_PLATFORM", "").split(":")[0]
    if platform in ("offscreen", "minimal", "vnc", "eglfs") or os.name == "nt" \
            or sys.platform == "darwin":
        return None
    if platform in ("wayland", "wayland-egl") or (
            not platform and os.environ.get("WAYLAND_DISPLAY") and not os.environ.get("DISPLAY")):
        return None  # Qt's wayland platform reports its own errors
    if not has_display():
        return "no display: set DISPLAY, or run under xvfb-run"
    return xcb_problem()


def application(offscreen: bool = False):
    """The QApplication (made once). ``offscreen`` (a screenshot): Qt's offscreen platform when
    no window can be opened here; else one clear line when Qt could not start (Qt itself would
    abort the process)."""
    require_qt()
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    if app is None:
        problem = platform_problem()
        if problem is not None:
            if not offscreen:
                raise ViewerUnavailableError(f"{problem}; {SCREENSHOT_HINT}")
            os.environ["QT_QPA_PLATFORM"] = "offscreen"
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


