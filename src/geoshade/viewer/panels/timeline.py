"""The desktop viewer's summary plot (Qt): the View's ``summary`` vectors against time beside
the 3D view, one cursor at the shown report step. Moving the step moves the cursor; a click on
the plot shows the nearest report step with restart data and says so in the status bar. The
picture and the click's step come from :class:`geoshade.viewer.timeline.Timeline` (the notebook
and the browser show the same); the vectors are chosen with the panel's ``summary vectors``
control.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QPixmap
from PySide6.QtWidgets import QLabel, QSizePolicy, QVBoxLayout, QWidget

from geoshade.errors import GeoshadeError
from geoshade.viewer.qt import single_shot, to_qimage
from geoshade.viewer.timeline import Timeline

#: the plot's height in pixels (its width follows the dock's)
PLOT_HEIGHT = 260
#: its least width
PLOT_MIN_WIDTH = 480
#: ms a resize waits before the curves are drawn again at the new width
RESIZE_MS = 150


class PlotLabel(QLabel):
    """The plot's picture at its own size (top left, never scaled: a click's pixel is the
    picture's); a left click goes to ``on_click(px, py)``."""

    def __init__(self, on_click, parent=None):
        super().__init__(parent)
        self.on_click = on_click
        self.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop)
        self.setCursor(Qt.CursorShape.CrossCursor)
        self.setToolTip("click a date: the 3D view shows the nearest report step with "
                        "restart data")

    def mousePressEvent(self, event):  # noqa: N802 (Qt's name)
        if event.button() == Qt.MouseButton.LeftButton and self.pixmap() is not None \
                and not self.pixmap().isNull():
            pos = event.position()
            self.on_click(pos.x(), pos.y())


class TimelinePanel(QWidget):
    """The summary plot of one View (see the module).

    ``host`` has ``apply(**options)``, ``show_error(text)`` and ``say(text)`` (the status
    bar). :meth:`follow` draws the plot again where the step, the vectors or the size changed.
    """

    def __init__(self, timeline: Timeline, host, parent=None):
        super().__init__(parent)
        self.timeline, self.host = timeline, host
        self.view = timeline.view
        #: (vectors, step, size) the plot shows, and whether it shows a picture
        self._shown: tuple | None = None
        self.showing = False
        self.plot = PlotLabel(self.click)
        self.plot.setMinimumSize(PLOT_MIN_WIDTH, PLOT_HEIGHT)
        # the dock decides the width, the picture follows it (never the other way round)
        self.plot.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(2, 2, 2, 2)
        lay.addWidget(self.plot, 1)
        self._resized = single_shot(self, RESIZE_MS, self.follow)

    def size_wanted(self) -> tuple[int, int]:
        return (max(PLOT_MIN_WIDTH, self.plot.width()), PLOT_HEIGHT)

    def follow(self) -> bool:
        """Draw the plot again where what it shows changed (the cursor alone: a few ms).
        True while it shows a picture (some vectors are chosen)."""
        o = self.view.options
        shown = (tuple(getattr(o, "summary", None) or ()), getattr(o, "step", None),
                 self.size_wanted())
        if shown == self._shown:
            return self.showing
        self._shown = shown
        try:
            img = self.timeline.image(shown[2])
        except GeoshadeError as err:
            self.host.show_error(str(err))
            img = None
        self.showing = img is not None
        if img is None:
            self.plot.clear()
        else:
            self.plot.setPixmap(QPixmap.fromImage(to_qimage(img)))
        return self.showing

    def click(self, px: float, py: float) -> int | None:
        """A click at pixel ``(px, py)`` of the plot: the nearest report step with restart
        data is shown, said in the status bar; returns it (None: outside the curves)."""
        at = self.timeline.click(px, py)
        if at is None:
            return None
        self.host.apply(step=at.index)
        self.host.say(at.text)
        return at.index

    def resizeEvent(self, event):  # noqa: N802 (Qt's name)
        super().resizeEvent(event)
        self._resized.start()


def timeline_for(view) -> Timeline | None:
    """The View's :class:`Timeline` where its case has a summary plot (None elsewhere)."""
    try:
        tl = Timeline(view)
    except GeoshadeError:
        return None
    return tl if tl.available else None


__all__ = ["PLOT_HEIGHT", "TimelinePanel", "timeline_for"]
