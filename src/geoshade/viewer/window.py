"""The desktop viewer window (Qt, PySide6): the 3D view, one panel per data set, the read-out.

>>> from geoshade.viewer.window import run_viewer                       # doctest: +SKIP
>>> run_viewer(demo=True, screenshot="demo.png")                        # doctest: +SKIP
"""

from __future__ import annotations

import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt, QTimer
from PySide6.QtWidgets import (
    QApplication,
    QComboBox,
    QDockWidget,
    QFileDialog,
    QLabel,
    QMainWindow,
    QMenu,
    QProgressBar,
    QScrollArea,
    QSplitter,
    QStackedWidget,
    QToolBar,
    QToolButton,
    QWidget,
)

from geoshade.errors import GeoshadeError, InputError
from geoshade.render.camera import Camera
from geoshade.render.view import Job
from geoshade.styles.options import VIEWS
from geoshade.viewer.app import application
from geoshade.viewer.panels import Panel, panel_for
from geoshade.viewer.panels.picks import PicksPanel
from geoshade.viewer.panels.timeline import TimelinePanel, timeline_for
from geoshade.viewer.qt import FrameWidget, TaskRunner
from geoshade.viewer.session import HELP, Session
from geoshade.viewer.share import read_view, view_text
from geoshade.viewer.views import demo_views, make_view, prepare

#: the side panels' least width in pixels (they widen to their content, see _fit_side)
SIDE_MIN_WIDTH = 300

@dataclass
class Entry:
    """One open data set: its session (View + camera), its panel, what it was opened from
    (a path or a model: a shared view names the path) and its picks (a grid's)."""

    title: str
    session: Session
    panel: Panel
    source: Any = None
    kind: str | None = None
    picks: PicksPanel | None = None
    timeline: TimelinePanel | None = None


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, GeoshadeError):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


class ViewerWindow(QMainWindow):
    """The viewer's main window.

    Parameters
    ----------
    size : (w, h)
        Initial size of the 3D view in pixels.
    view : str
        Named view each data set opens with.
    ortho : bool
        Orthographic projection.
    """

    def __init__(self, size=(800, 600), view: str = "iso", ortho: bool = False):
        super().__init__()
        self.setWindowTitle("geoshade")
        self.view_name, self.ortho = view, bool(ortho)
        self.entries: list[Entry] = []
        self.active: Entry | None = None
        self.errors: list[str] = []
        self.opening = 0
        self._interactive = False
        self._draw_pending = False
        self.last_screenshot: Path | None = None

        self.runner = TaskRunner(self)
        self.runner.state_changed.connect(self._progress)
        self._holding = False   # True while a dock appears (see _show_dock)
        self.frame = FrameWidget(self)
        self.frame.setMinimumSize(160, 120)
        self.panels = QStackedWidget()
        side = QScrollArea()
        side.setWidgetResizable(True)
        side.setWidget(self.panels)
        # panels scroll down, never sideways: the side is as wide as its widest panel
        side.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        side.setMinimumWidth(SIDE_MIN_WIDTH)
        self.side = side
        split = QSplitter()
        split.setChildrenCollapsible(False)
        split.addWidget(self.frame)
        split.addWidget(side)
        split.setStretchFactor(0, 1)
        self.setCentralWidget(split)
        #: docks beside the 3D view, shown where the data set has what they show: a case's
        #: summary plot, a grid's picks (after the first pick); one page per data set each
        self.summary_dock = self._dock("summary", Qt.DockWidgetArea.BottomDockWidgetArea)
        self.picks_dock = self._dock("picks", Qt.DockWidgetArea.RightDockWidgetArea)
        # the picks take the window's whole height (table and history plot), the summary
        # plot the width under the 3D view and the panel
        self.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)
        self._toolbar()
        self.readout = QLabel("")
        self.pick_label = QLabel("")
        self.pick_label.setToolTip("what the last left click picked (cell, value, depth)")
        self.message = QLabel("")
        self.progress = QProgressBar()
        self.progress.setMaximumWidth(200)
        self.progress.hide()
        sb = self.statusBar()
        sb.addWidget(self.readout, 1)
        sb.addWidget(self.pick_label)
        sb.addPermanentWidget(self.message)
        sb.addPermanentWidget(self.progress)
        self.frame.resize(*size)
        self.resize(int(size[0]) + 340, int(size[1]) + 90)
        self._frame_size = (int(size[0]), int(size[1]))

    # --- toolbar ---------------------------------------------------------------------------------
    def _toolbar(self) -> None:
        tb = QToolBar("view")
        self.addToolBar(tb)
        self.data = QComboBox()
        self.data.setToolTip("open data sets")
        self.data.currentIndexChanged.connect(self.select)
        tb.addWidget(self.data)
        tb.addSeparator()
        keys = {v: k for k, v in (("1", "iso"), ("2", "top"), ("3", "bottom"), ("4", "front"),
                                  ("5", "back"), ("6", "left"), ("7", "right"))}
        for name in VIEWS:
            act = tb.addAction(name)
            act.setToolTip(f"{name} view (key {keys[name]})")
            act.triggered.connect(lambda _=False, n=name: self.set_view(n))
        tb.addSeparator()
        shot = tb.addAction("screenshot")
        shot.setShortcut("Ctrl+S")
        shot.setToolTip("save the picture as PNG (S, Ctrl+S)")
        shot.triggered.connect(lambda: self.save_screenshot())
        helpa = tb.addAction("help")
        helpa.setToolTip(HELP)
        helpa.triggered.connect(self.toggle_help)
        # toolbar menus: the window's layout stays as it was
        self.camera_menu = self._menu_button(
            tb, "camera", "save the camera as JSON, or look through a saved one", [
                ("Save camera…", "", "write the camera of the picture as JSON (geoshade ... "
                 "render --camera FILE reproduces the view)", lambda: self.save_camera()),
                ("Load camera…", "", "look through a camera saved here or by --save-camera",
                 lambda: self.load_camera())])
        self.share_menu = self._menu_button(
            tb, "share", "copy the view as JSON, or open a copied one", [
                ("Copy view", "Ctrl+Shift+C", "put the view (file, options, camera) on the "
                 "clipboard as JSON: Open view, geoshade.view(model, **state) or geoshade.show "
                 "reopen it", lambda: self.copy_view()),
                ("Open view", "Ctrl+Shift+V", "open the view on the clipboard (Copy view's "
                 "JSON) beside the others", lambda: self.open_view()),
                ("Open view file…", "", "open a view saved as JSON (Copy view's text in a file)",
                 lambda: self.open_view(path=""))])

    def _menu_button(self, tb, title: str, tip: str, actions) -> QMenu:
        """A toolbar button opening a menu of ``(label, shortcut, tooltip, slot)`` actions."""
        menu = QMenu(title, self)
        for label, shortcut, action_tip, slot in actions:
            act = menu.addAction(label)
            if shortcut:
                act.setShortcut(shortcut)
            act.setToolTip(action_tip)
            act.triggered.connect(slot)
        button = QToolButton()
        button.setText(title)
        button.setToolTip(tip)
        button.setMenu(menu)
        button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
        tb.addWidget(button)
        return menu

    def _dock(self, title: str, area) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable
                         | QDockWidget.DockWidgetFeature.DockWidgetFloatable
                         | QDockWidget.DockWidgetFeature.DockWidgetClosable)
        pages = QStackedWidget()
        scroll = QScrollArea()   # a tall page scrolls: the dock never forces the window taller
        scroll.setWidgetResizable(True)
        scroll.setWidget(pages)
        dock.setWidget(scroll)
        dock.pages = pages
        self.addDockWidget(area, dock)
        dock.hide()
        return dock

    def _show_dock(self, dock: QDockWidget, page: QWidget | None) -> None:
        """Show ``page`` in ``dock`` (None: hide it); a dock that appears widens (or
        heightens) the window by its size, so the 3D view keeps its own (and its camera: a
        pick's line keeps following the options)."""
        if page is None:
            dock.hide()
            return
        dock.pages.setCurrentWidget(page)
        if not dock.isHidden():
            return
        kept = self.frame.size()
        self._holding = True   # the frame's sizes on the way are not the session's
        try:
            side = self.dockWidgetArea(dock) in (Qt.DockWidgetArea.LeftDockWidgetArea,
                                                 Qt.DockWidgetArea.RightDockWidgetArea)
            want = page.sizeHint()
            dock.show()
            self.resize(self.width() + (want.width() if side else 0),
                        self.height() + (0 if side else want.height()))
            self.layout().activate()
            dw, dh = kept.width() - self.frame.width(), kept.height() - self.frame.height()
            if dw or dh:   # what the dock's frame and the splitter took
                self.resize(self.width() + dw, self.height() + dh)
                self.layout().activate()
        finally:
            self._holding = False
        self.frame_resized(self.frame.width(), self.frame.height())

    def _docks(self, entry: Entry) -> None:
        """Show the docks of ``entry`` (the selected data set)."""
        tl = entry.timeline
        self._show_dock(self.summary_dock, tl if tl is not None and tl.showing else None)
        picks = entry.picks
        self._show_dock(self.picks_dock, picks if picks is not None and picks.picks.cells
                        else None)

    # --- opening data ----------------------------------------------------------------------------
    @property
    def session(self) -> Session | None:
        return self.active.session if self.active is not None else None

    def open(self, source, kind: str | None = None, hints: dict | None = None,
             settings: dict | None = None, title: str | None = None,
             select: bool = True) -> None:
        """Read ``source`` (path or model) and add it, in the background (a progress bar runs)."""
        settings = dict(settings or {})
        name = title or (Path(source).name if isinstance(source, (str, Path))
                         else getattr(source, "name", "") or type(source).__name__)

        def compute(progress):
            return prepare(source, kind, hints, progress, **settings)

        def apply(opening):
            view = make_view(opening, size=self._frame_size)
            self.add_view(view, name, select=select, source=source, kind=kind)

        self.opening += 1
        self.runner.submit(Job(f"open {id(source)}", f"opening {name}", compute, apply),
                           then=self._opened, error=self._open_failed)

    def _opened(self) -> None:
        self.opening -= 1

    def _open_failed(self, exc) -> None:
        self.opening -= 1
        self.show_error(_one_line(exc), exc)

    def add_view(self, view, title: str = "", select: bool = True, settings=None,
                 source: Any = None, kind: str | None = None) -> Entry:
        """Show an already made View (GUI thread); ``source``: what it was read from (a
        shared view names its file)."""
        session = Session(view, size=self._frame_size, view_name=self.view_name,
                          ortho=self.ortho)
        panel = panel_for(session, self)
        entry = Entry(title or view.title, session, panel,
                      source=view.model if source is None else source, kind=kind)
        if view.kind == "grid":
            entry.picks = PicksPanel(view, self)
            self.picks_dock.pages.addWidget(entry.picks)
        timeline = timeline_for(view)
        if timeline is not None:
            entry.timeline = TimelinePanel(timeline, self)
            self.summary_dock.pages.addWidget(entry.timeline)
        self.entries.append(entry)
        self.panels.addWidget(panel)
        self._fit_side(panel)
        self.data.addItem(f"{view.kind}: {entry.title}")
        if select or self.active is None:
            self.data.setCurrentIndex(len(self.entries) - 1)
        if settings:
            self.apply(_entry=entry, **settings)
            panel.sync()
        if getattr(view, "loading", False):   # a coarse preview: the full picture next
            self.runner.submit(view.refine_job(), then=lambda: self._refined(entry),
                               error=lambda exc: self.show_error(_one_line(exc), exc))
        return entry

    def _refined(self, entry: Entry) -> None:
        """A progressive View's full picture is built: show it."""
        if entry is self.active:
            self.request_draw()

    def _fit_side(self, panel) -> None:
        """Widen the side (and the window) to the panel's width: nothing clipped or hidden
        behind a scroll bar; the 3D view keeps its size."""
        bar = self.side.verticalScrollBar().sizeHint().width()
        want = max(panel.minimumSizeHint().width(), panel.sizeHint().width()) + bar \
            + 2 * self.side.frameWidth() + 4
        if want > self.side.minimumWidth():
            grow = want - self.side.width()
            self.side.setMinimumWidth(want)
            if grow > 0:
                self.resize(self.width() + grow, self.height())

    def select(self, index: int) -> None:
        if not 0 <= index < len(self.entries):
            return
        self.active = self.entries[index]
        self.pick_label.setText(self.active.session.pick_text)
        self.panels.setCurrentWidget(self.active.panel)
        s = self.active.session
        s.resize(*self._frame_size)
        self.setWindowTitle(f"geoshade — {self.active.session.view.kind}: {self.active.title}")
        if s.ortho != self.ortho:
            s.set_ortho(self.ortho)
        self.active.panel.sync()
        self._docks(self.active)
        self.request_draw()

    # --- changes ---------------------------------------------------------------------------------
    def apply(self, reframe: bool = False, _entry: Entry | None = None, **settings) -> None:
        """Change options of the shown View (what panels call); long jobs go to the worker.

        ``view``, ``ortho`` and ``exaggeration`` change the session's camera (as the browser's
        server does); a new box frames the model again."""
        entry = _entry or self.active
        if entry is None:
            return
        s = entry.session
        camera = {k: settings.pop(k) for k in ("view", "ortho", "exaggeration")
                  if k in settings}
        try:
            if "view" in camera:
                s.reset(str(camera["view"]))
            if "ortho" in camera:
                self.ortho = bool(camera["ortho"])
                s.set_ortho(self.ortho)
            if "exaggeration" in camera and s.exaggeration is not None:
                s.set_exaggeration(float(camera["exaggeration"]))
            jobs = s.view.jobs(**settings)
        except GeoshadeError as err:
            self.show_error(str(err), err)
            entry.panel.sync()
            return
        self.message.setText("")
        reframe = reframe or "box" in settings

        def then():
            if reframe:
                s.reframe()
            entry.panel.applied()
            if entry is self.active:
                self.request_draw()

        for job in jobs:
            self.runner.submit(job, then=then,
                               error=lambda exc: self.show_error(_one_line(exc), exc))
        if not jobs:
            if reframe:
                s.reframe()
            entry.panel.sync()   # what the View made of the change (a ROI fitted, an expression)
            if entry is self.active:
                self.request_draw()

    def set_view(self, name: str) -> None:
        if self.session is not None:
            self.session.reset(name)
            self.active.panel.sync()
            self.request_draw()

    def toggle_help(self) -> None:
        self.frame.show_help = not self.frame.show_help
        self.frame.update()

    def key_action(self, action: str) -> None:
        if action == "screenshot":
            self.save_screenshot()
        elif action == "help":
            self.toggle_help()
        else:
            if action == "ortho":
                self.ortho = self.session.ortho
            self.active.panel.sync()   # the named view, projection and exaggeration
            self.request_draw()

    def pointer_released(self, x: float, y: float, scale=(1.0, 1.0)) -> None:
        """A mouse button went up over the picture: a drag draws the full frame again, a left
        click picks (the read-out goes to the status bar)."""
        s = self.session
        if s is None:
            return
        try:
            what = s.release(x, y, scale)
        except GeoshadeError as err:
            self.show_error(str(err), err)
            return
        if what == "drag":
            self.request_draw()
        elif what == "click":
            self.pick_label.setText(s.pick_text)
            picks = self.active.picks
            if picks is not None and picks.add(s.picked):
                self._show_dock(self.picks_dock, picks)

    # --- drawing ---------------------------------------------------------------------------------
    def frame_resized(self, w: int, h: int) -> None:
        if self._holding:
            return
        self._frame_size = (max(1, w), max(1, h))
        if self.session is not None:
            self.session.resize(*self._frame_size)
            self.request_draw()

    def request_draw(self, interactive: bool = False) -> None:
        """Draw at the next turn of the event loop (requests in between are merged)."""
        # a full frame wins over an interactive one (no GPU counting pass while dragging)
        self._interactive = (self._interactive and interactive) if self._draw_pending \
            else interactive
        if not self._draw_pending:
            self._draw_pending = True
            QTimer.singleShot(0, self._draw_now)

    def _draw_now(self) -> None:
        self._draw_pending = False
        s = self.session
        if s is None:
            return
        try:
            img, stats = s.draw(interactive=self._interactive)
        except GeoshadeError as err:
            self.show_error(str(err), err)
            return
        self.frame.set_image(img)
        self.readout.setText(s.readout())
        self.pick_label.setText(s.pick_text)   # a pick made again follows the options
        self.active.panel.drawn(stats)
        if self.active.picks is not None and not self.picks_dock.isHidden():
            self.active.picks.follow()   # the table and the plot's cursor at the shown step
        tl = self.active.timeline
        if tl is not None:   # the summary plot's cursor at the shown step (once vectors chosen)
            self._show_dock(self.summary_dock, tl if tl.follow() else None)

    def save_screenshot(self, path=None) -> Path | None:
        """Write the current picture as PNG (default: ``geoshade-<part>-<time>.png`` here)."""
        if self.session is None:
            return None
        if self._draw_pending:  # the picture the user asked for, not the one before it
            self._draw_now()
        try:
            p = self.session.screenshot(path)
        except GeoshadeError as err:
            self.show_error(str(err), err)
            return None
        self.last_screenshot = p
        self.message.setText(f"saved {p}")
        return p

    def save_camera(self, path=None) -> Path | None:
        """Write the current camera as JSON (``--camera FILE`` of every render command and
        :meth:`load_camera` read it back); without ``path`` a file dialog asks."""
        if self.session is None:
            return None
        if path is None:
            path, _ = QFileDialog.getSaveFileName(self, "Save camera", "camera.json",
                                                  "camera (*.json)")
            if not path:
                return None
        p = Path(path)
        if p.suffix.lower() != ".json":
            self.show_error(f"{p}: a camera is a JSON file; give a name ending in .json")
            return None
        w, h = self.session.size
        try:
            self.session.camera.with_aspect(w / h).save(p)
        except (GeoshadeError, OSError) as err:
            self.show_error(_one_line(err), err if isinstance(err, GeoshadeError) else None)
            return None
        self.message.setText(f"saved camera {p}")
        return p

    def load_camera(self, path=None) -> bool:
        """Look through the camera of a JSON file (:meth:`save_camera`, ``--save-camera``);
        without ``path`` a file dialog asks. True when the camera changed."""

        if self.session is None:
            return False
        if path is None:
            path, _ = QFileDialog.getOpenFileName(self, "Load camera", "", "camera (*.json)")
            if not path:
                return False
        try:
            cam = Camera.load(path)
        except GeoshadeError as err:
            self.show_error(str(err), err)
            return False
        w, h = self.session.size
        self.session.camera = cam.with_aspect(w / h)
        self.message.setText(f"camera from {path}")
        self.request_draw()
        return True

    # --- views you can share -------------------------------------------------------------------
    def view_text(self) -> str | None:
        """The shown view as JSON (:func:`geoshade.viewer.share.view_text`: the file, the
        part, the options and the camera of the picture), None with nothing shown."""
        if self.active is None:
            return None
        s = self.session
        w, h = s.size
        return view_text(s.view, s.camera.with_aspect(w / h), self.active.source)

    def copy_view(self) -> str | None:
        """Put :meth:`view_text` on the clipboard (and return it)."""
        text = self.view_text()
        if text is None:
            return None
        QApplication.clipboard().setText(text)
        self.message.setText(f"copied the view of {self.active.title} (Open view reopens it)")
        return text

    def open_view(self, text: str | None = None, path=None) -> bool:
        """Open a shared view (:meth:`copy_view`'s JSON) as a new data set: ``text``, else
        the JSON file ``path`` ("": a file dialog asks), else the clipboard's text. A view
        naming no file opens the selected data set again. True when it is opening."""
        try:
            if text is None and path is not None:
                if path == "":
                    path, _ = QFileDialog.getOpenFileName(self, "Open view", "",
                                                          "view (*.json)")
                    if not path:
                        return False
                try:
                    text = Path(path).read_text(encoding="utf-8")
                except (OSError, UnicodeDecodeError) as err:
                    raise InputError(f"{path}: cannot read the view ({err})") from None
            if text is None:
                text = QApplication.clipboard().text()
            shared = read_view(text)
            if shared.file is not None:
                source = shared.file
                if not Path(source).exists():
                    raise InputError(f"view: {source} does not exist here; open the data "
                                     "set, then open the view's state on it")
            elif self.active is not None:
                source = self.active.source
            else:
                raise InputError("view: it names no file and nothing is open to show it on")
        except GeoshadeError as err:
            self.show_error(str(err), err)
            return False
        name = Path(source).name if isinstance(source, str | Path) else \
            (self.active.title if self.active is not None else "data")
        kind = shared.part or (self.active.kind if self.active is not None
                               and source is self.active.source else None)
        self.open(source, kind, None, shared.settings(), title=f"{name} (shared view)")
        return True

    # --- progress, errors, idling ----------------------------------------------------------------
    def _progress(self, label: str, done: int, total: int) -> None:
        if not label:
            self.progress.hide()
            return
        self.progress.show()
        self.progress.setFormat(f"{label} %p%" if total else label)
        self.progress.setRange(0, total if total else 0)  # 0..0: busy indicator
        if total:
            self.progress.setValue(done)

    def say(self, text: str) -> None:
        """One line in the status bar (what a click on the summary plot did)."""
        self.message.setText(text)

    def show_error(self, msg: str, exc: BaseException | None = None) -> None:
        self.errors.append(msg)
        self.message.setText(f"error: {msg}")
        if exc is not None and not isinstance(exc, GeoshadeError):
            traceback.print_exception(exc, file=sys.stderr)

    def idle(self) -> bool:
        """No background job, no pending draw, no debounce timer running."""
        return not (self.runner.busy() or self._draw_pending or self.opening
                    or any(e.panel.pending() for e in self.entries))

    def wait_idle(self, timeout: float = 60.0) -> None:
        """Run the event loop until :meth:`idle` (for scripts and tests)."""
        app = QApplication.instance()
        t_end = time.monotonic() + timeout
        while True:
            app.processEvents()
            if self.idle():
                app.processEvents()
                if self.idle():
                    return
            if time.monotonic() > t_end:
                raise TimeoutError(f"the viewer was still busy after {timeout:g} s")
            time.sleep(0.005)

    def closeEvent(self, event):  # noqa: N802
        for e in self.entries:
            e.panel.stop()
        self.runner.shutdown()
        for e in self.entries:
            if e.timeline is not None:
                e.timeline.timeline.close()
            e.session.view.release()
        self.entries.clear()
        self.active = None
        super().closeEvent(event)


def run_viewer(sources=(), demo=False, screenshot=None, size=(900, 650), view: str = "iso",
               ortho: bool = False, timeout: float = 300.0) -> int:
    """Open the window on ``sources`` and/or the demo data; run until closed.

    Parameters
    ----------
    sources : iterable of dict
        Each ``{"source": path or model, "kind": None, "hints": {}, "settings": {}}``.
    demo : bool or str
        Also open every available part's synthetic data (a kind: that one first).
    screenshot : path, optional
        Draw the first frame, write it there as PNG and return 0 (no event loop for a human).

    Returns
    -------
    int
        The exit status.
    """

    app = application(offscreen=screenshot is not None)
    if screenshot is not None:  # fail before any work if the PNG cannot be written
        out = Path(screenshot)
        if out.suffix.lower() != ".png":
            raise InputError(f"{out}: --screenshot writes PNG; give a name ending in .png")
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            raise InputError(f"{out}: output folder {out.parent} does not exist")
    win = ViewerWindow(size=size, view=view, ortho=ortho)
    first = True
    for spec in sources:
        win.open(spec["source"], spec.get("kind"), spec.get("hints"), spec.get("settings"),
                 select=first)
        first = False
    if demo:
        demos = demo_views()
        order = sorted(demos, key=lambda k: k != demo) if isinstance(demo, str) else list(demos)
        if isinstance(demo, str) and demo not in demos:
            raise InputError(f"--demo: unknown or unavailable part {demo!r}; available: "
                             f"{', '.join(demos)}")
        for kind in order:
            _cls, model, settings = demos[kind]
            win.open(model, kind, None, settings, title=f"demo {kind}", select=first)
            first = False
    win.show()
    if screenshot is None:
        return app.exec()
    try:
        win.wait_idle(timeout)
        if win.errors:
            raise InputError(win.errors[0])
        if win.session is None:
            raise InputError("nothing to show: give a file or --demo")
        if win.session.size != tuple(size) or win.session.image is None:
            win.session.resize(*size)  # the PNG has the size asked for, whatever the layout
            win.session.reframe()      # framed for that size: nothing clipped
            win.session.draw()
        path = win.save_screenshot(screenshot)
        if path is None:
            raise InputError(win.errors[-1])
    finally:
        win.close()
    return 0
