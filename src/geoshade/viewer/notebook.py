"""``geoshade.show(model, ...)``: an interactive view in Jupyter (jupyter_rfb), for users on
remote GPU servers: the kernel draws with the part's View, the browser shows the frames.

Mouse: a left click picks (what is there, its value and depth: :attr:`GeoshadeWidget.pick_text`,
also the last line of :meth:`GeoshadeWidget.readout`), left drag orbits, right or middle drag
pans, the wheel zooms; the keys of the desktop
viewer work while the pointer is over the picture (1-7 or I/T/B/F/K/L/R views, 0 reset, O
ortho, +/- zoom, [ ] exaggeration). Settings change with :meth:`GeoshadeWidget.set`.

``w.workbench()`` shows the picture with a side panel (:mod:`geoshade.viewer.notebook_panel`):
the View's controls, a case's summary plot with one time cursor, the picks (a grid cell's
properties at the shown step, its history). ``w.state()`` is the view as JSON values (options
and camera; ``w.view_text()`` the text the desktop viewer's *Copy view* gives):
``geoshade.show(model, **w.state())`` opens the same picture again.

>>> import geoshade                                              # doctest: +SKIP
>>> w = geoshade.show(geoshade.synthetic_core(64), range=(0, 19000))  # doctest: +SKIP
>>> w.set(box=[0, 0, 0, 32, 32, 32])                              # doctest: +SKIP
"""

from __future__ import annotations

import asyncio
import contextlib
from pathlib import Path

from geoshade.errors import InputError
from geoshade.styles.image import parse_size
from geoshade.viewer.app import ViewerUnavailableError
from geoshade.viewer.loading import Refiner
from geoshade.viewer.notebook_panel import NotebookPanel
from geoshade.viewer.session import Session
from geoshade.viewer.share import view_text
from geoshade.viewer.views import open_view, run_now

#: jupyter_rfb's mouse buttons (1 left, 2 right, 3 middle) by the names Session.press takes
_BUTTONS = {1: "left", 2: "right", 3: "middle"}


def _widget_base():
    try:
        from jupyter_rfb import RemoteFrameBuffer
    except ImportError as err:
        raise ViewerUnavailableError(f"geoshade.show needs jupyter_rfb ({err}); pip install "
                                     "'geoshade[viewer]'") from None
    return RemoteFrameBuffer


def _make_class():
    base = _widget_base()

    class GeoshadeWidget(base):
        """A jupyter_rfb widget showing one part's View.

        Attributes
        ----------
        session : geoshade.viewer.session.Session
        view : the part's View (``session.view``)
        """

        def __init__(self, view, size=(640, 480), view_name: str = "iso", ortho: bool = False,
                     **kwargs):
            w, h = (int(v) for v in size)
            super().__init__(css_width=f"{w}px", css_height=f"{h}px", **kwargs)
            self.session = Session(view, size=(w, h), view_name=view_name, ortho=ortho)
            self._ratio = 1.0  # picture pixels per pointer (CSS) pixel
            self._interactive = False
            #: the side panel (:meth:`workbench`), made when first shown
            self.panel: NotebookPanel | None = None
            #: what the View was read from (a path: the shared view names it)
            self.source = None
            #: a progressive View's full picture, built while its coarse preview is shown
            self.refiner = Refiner(view)
            if self.refiner.loading:
                self.refiner.start()
                self._poll_later()

        def _poll_later(self) -> None:
            """Look for the finished full picture again soon (in the kernel's event loop)."""
            with contextlib.suppress(RuntimeError):   # no loop: poll_loading() by hand
                asyncio.get_event_loop().call_later(0.2, self.poll_loading)

        def poll_loading(self) -> bool:
            """Show the full picture once it is built (True then); else redraw the progress
            line and look again later."""
            if self.refiner.poll():
                self.request_draw()
                return True
            if self.refiner.busy():
                self.request_draw()
                self._poll_later()
            return False

        @property
        def view(self):
            return self.session.view

        @property
        def stats(self) -> dict:
            return self.session.stats

        def readout(self) -> str:
            """The frame's read-out and, on a second line, the last pick."""
            s = self.session
            loading = self.refiner.line()
            return (s.readout() + (f"\n{loading}" if loading else "")
                    + (f"\n{s.pick_text}" if s.pick_text else ""))

        @property
        def picked(self):
            """The last left click's :class:`~geoshade.render.pick.Pick` (None: nothing)."""
            return self.session.picked

        @property
        def pick_text(self) -> str:
            return self.session.pick_text

        def state(self) -> dict:
            """The view as plain JSON values: every option not at its default and the camera
            of the picture (:meth:`View.state`); ``geoshade.show(model, **w.state())`` and
            ``geoshade.view(model, **w.state())`` draw the same picture."""
            w, h = self.session.size
            return self.view.state(self.session.camera.with_aspect(w / h))

        def view_text(self) -> str:
            """The view as the desktop viewer's *Copy view* gives it (its *Open view* opens
            it): the file, the part and :meth:`state` as JSON."""
            w, h = self.session.size
            return view_text(self.view, self.session.camera.with_aspect(w / h), self.source)

        def workbench(self):
            """The picture with its side panel (an ``ipywidgets.HBox``): the controls, the
            summary plot with its time cursor, the picks (see the module)."""
            import ipywidgets

            if self.panel is None:
                self.panel = NotebookPanel(self)
            return ipywidgets.HBox([self, self.panel.box])

        def set(self, **options) -> None:
            """Change the View's options (``select=``, ``box=``, ``property=``, ``level=`` …)."""
            jobs = self.view.jobs(**options)
            refine = [j for j in jobs if j.key == getattr(self.view, "refine_key", str)()]
            run_now([j for j in jobs if j not in refine])
            for job in refine:   # while loading: a new preview now, the old load superseded
                self.refiner.start(job)
                self._poll_later()
            if "box" in options or "exaggeration" in options:
                self.session.reframe()
            self.request_draw()
            if self.panel is not None:   # the controls, summary cursor and picks follow
                self.panel.changed()

        # --- jupyter_rfb ---------------------------------------------------------------------
        def handle_event(self, event: dict) -> None:
            kind = event.get("event_type") or event.get("type")
            s = self.session
            if kind == "resize":
                ratio = float(event.get("pixel_ratio") or event.get("ratio") or 1.0)
                self._ratio = ratio
                s.resize(round(event["width"] * ratio), round(event["height"] * ratio))
            elif kind == "pointer_down":
                s.press(event["x"], event["y"], _BUTTONS.get(event.get("button", 1), "other"))
                return
            elif kind == "pointer_move":
                if not s.move(event["x"], event["y"]):
                    return
                self._interactive = True
            elif kind == "pointer_up":
                what = s.release(event["x"], event["y"], (self._ratio, self._ratio))
                self._interactive = False
                if what == "click" and self.panel is not None:
                    self.panel.picked(s.picked)   # a grid cell: kept in the picks
                if what != "drag":
                    return
            elif kind == "wheel":
                s.zoom(-float(event.get("dy", 0.0)) / 100.0)
            elif kind == "key_down":
                action = s.key(str(event.get("key", "")))
                if action in (None, "help"):
                    return
                if action == "screenshot":
                    s.screenshot()
                    return
            else:
                return
            self.request_draw()

        def get_frame(self):
            img, _ = self.session.draw(interactive=self._interactive)
            return img[..., :3]

        def close(self, *args, **kwargs):
            super().close(*args, **kwargs)
            if self.panel is not None:
                self.panel.close()
            self.refiner.close()
            self.session.view.release()

    return GeoshadeWidget


_CLASS = None


def widget_class():
    """The ``GeoshadeWidget`` class (made on first use: jupyter_rfb is an optional extra)."""
    global _CLASS
    if _CLASS is None:
        _CLASS = _make_class()
    return _CLASS


def show(model, kind: str | None = None, size=(640, 480), view: str = "iso",
         ortho: bool = False, hints: dict | None = None, **settings):
    """An interactive view of ``model`` for Jupyter.

    Parameters
    ----------
    model : path or model
        Anything :func:`geoshade.load` reads (fields over time with ``kind='iso'``), or a
        VoxelVolume, CornerPointGrid, FieldSeries or StackModel.
    kind : {'core', 'grid', 'iso', 'stacks'}, optional
        Force a part.
    size : (w, h)
        Picture size in pixels (the widget follows the notebook's resizes).
    view, ortho
        Initial named view and projection.
    hints : dict
        Reader hints for a path (``shape``, ``dtype``, ...).
    **settings
        The part's options, e.g. ``select=(0, 9000), box=[...]`` (core), ``property="PORO"``
        (grid), ``level=0.5, step=3`` (iso), ``hide=[2]`` (stacks).

    Returns
    -------
    GeoshadeWidget
        A ``jupyter_rfb.RemoteFrameBuffer``; the last expression of a cell displays it.

    Examples
    --------
    >>> import geoshade                                                # doctest: +SKIP
    >>> geoshade.show("snow.tif", select=(6237, 20000))                 # doctest: +SKIP
    """
    if isinstance(size, str):

        size = parse_size(size)
    cls = widget_class()
    w, h = (int(v) for v in size)
    if w < 1 or h < 1:
        raise InputError(f"size: expected positive width and height, got {size!r}")
    v = open_view(model, kind=kind, size=(w, h), hints=hints, **settings)
    widget = cls(v, size=(w, h), view_name=view, ortho=ortho)
    widget.source = model if isinstance(model, str | Path) else None
    return widget
