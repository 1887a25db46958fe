"""Qt plumbing of the desktop viewer: the frame widget, the background worker.

The frame widget shows the RGBA picture a part's View drew into the headless context's offscreen
target (a ``QImage`` painted in ``paintEvent``): the same on a local screen, remote X, Xvfb and
Qt's offscreen platform, and no OpenGL call leaves ``geoshade.render``.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QFont, QImage, QPainter
from PySide6.QtWidgets import QWidget

from geoshade.viewer.jobs import JobRunner
from geoshade.viewer.session import HELP

#: Qt's mouse buttons by the names :meth:`Session.press` takes
BUTTONS = {Qt.MouseButton.LeftButton: "left", Qt.MouseButton.RightButton: "right",
           Qt.MouseButton.MiddleButton: "middle"}


def to_qimage(rgba: np.ndarray) -> QImage:
    """An RGBA8888 QImage that owns a copy of ``rgba`` ((h, w, 4) uint8)."""
    a = np.ascontiguousarray(rgba, np.uint8)
    h, w = a.shape[:2]
    return QImage(a.data, w, h, 4 * w, QImage.Format.Format_RGBA8888).copy()


def from_qimage(img: QImage) -> np.ndarray:
    """(h, w, 4) uint8 RGBA of a QImage (for tests and window grabs)."""
    img = img.convertToFormat(QImage.Format.Format_RGBA8888)
    h, w = img.height(), img.width()
    buf = np.frombuffer(img.constBits(), np.uint8, count=img.bytesPerLine() * h)
    return buf.reshape(h, img.bytesPerLine())[:, : 4 * w].reshape(h, w, 4).copy()


class FrameWidget(QWidget):
    """Shows the picture; turns mouse, wheel and keys into calls on ``host``.

    ``host`` has ``session`` (or None), ``request_draw(interactive)``, ``frame_resized(w, h)``,
    ``key_action(action)`` and ``pointer_released(x, y, scale)`` (a drag ends or a click
    picks: :meth:`Session.release`).
    """

    def __init__(self, host, parent=None):
        super().__init__(parent)
        self.host = host
        self.image: QImage | None = None
        self.show_help = False
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMinimumSize(160, 120)
        self.setMouseTracking(False)
        self.setToolTip(HELP.replace("\n", "<br>").join(("<pre>", "</pre>")))

    def set_image(self, rgba: np.ndarray) -> None:
        self.image = to_qimage(rgba)
        self.update()

    def paintEvent(self, event):  # noqa: N802 (Qt's name)
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(255, 255, 255))
        if self.image is not None:
            p.drawImage(self.rect(), self.image)
        if self.show_help:
            p.setFont(QFont("monospace", 9))
            lines = HELP.splitlines()
            box_h = 16 * len(lines) + 12
            p.fillRect(8, 8, self.width() - 16, box_h, QColor(255, 255, 255, 225))
            p.setPen(QColor(20, 20, 20))
            for k, line in enumerate(lines):
                p.drawText(16, 26 + 16 * k, line)
        p.end()

    def resizeEvent(self, event):  # noqa: N802
        self.host.frame_resized(self.width(), self.height())
        super().resizeEvent(event)

    def mousePressEvent(self, event):  # noqa: N802 (Qt's name)
        self.setFocus()
        s = self.host.session
        if s is not None:
            pos = event.position()
            s.press(pos.x(), pos.y(), BUTTONS.get(event.button(), "other"))

    def mouseMoveEvent(self, event):  # noqa: N802
        s = self.host.session
        if s is not None and s.move(event.position().x(), event.position().y()):
            self.host.request_draw(interactive=True)

    def mouseReleaseEvent(self, event):  # noqa: N802
        s = self.host.session
        if s is None:
            return
        # the picture is stretched over the widget: picture pixels per widget pixel
        scale = (s.size[0] / max(1, self.width()), s.size[1] / max(1, self.height()))
        self.host.pointer_released(event.position().x(), event.position().y(), scale)

    def wheelEvent(self, event):  # noqa: N802
        s = self.host.session
        if s is not None:
            s.zoom(event.angleDelta().y() / 120.0)
            self.host.request_draw()

    def keyPressEvent(self, event):  # noqa: N802
        names = {Qt.Key.Key_Home: "home", Qt.Key.Key_F1: "f1"}
        key = names.get(event.key(), event.text())
        if not key or self.host.session is None:
            return super().keyPressEvent(event)
        action = self.host.session.key(key)
        if action is None:
            return super().keyPressEvent(event)
        self.host.key_action(action)


class _Bridge(QObject):
    posted = Signal(object)
    progressed = Signal(object)


class TaskRunner(QObject):
    """The window's :class:`~geoshade.viewer.jobs.JobRunner`: ``compute`` on one worker thread,
    ``apply`` back on the GUI thread, always from its event loop (posted through a queued
    signal, so never inside :meth:`submit`, even when the job is done before :meth:`submit`
    returns); ``state_changed`` drives the progress bar."""

    state_changed = Signal(str, int, int)  # label ("" when idle), done, total

    def __init__(self, parent=None):
        super().__init__(parent)
        self._bridge = _Bridge()
        # queued: a job done before submit() returns (its done-callback then runs on the
        # GUI thread) is applied from the event loop too, never inside submit()
        self._bridge.posted.connect(lambda fn: fn(), Qt.ConnectionType.QueuedConnection)
        self._bridge.progressed.connect(lambda a: self.state_changed.emit(*a))
        self._runner = JobRunner(post=self._bridge.posted.emit,
                                 state=lambda *a: self._bridge.progressed.emit(a),
                                 name="geoshade-viewer")
        self._pool = self._runner._pool   # the worker (tests stand in for it)

    def busy(self) -> bool:
        return self._runner.busy()

    def submit(self, job, then=None, error=None) -> None:
        """Run ``job``; on the GUI thread call ``then()`` after apply, ``error(exc)`` on failure."""
        self._runner.submit(job, then, error)

    def shutdown(self) -> None:
        self._runner.shutdown()


def single_shot(parent, ms: int, fn) -> QTimer:
    """A restartable single-shot timer (debounce)."""
    t = QTimer(parent)
    t.setSingleShot(True)
    t.setInterval(ms)
    t.timeout.connect(fn)
    return t
