"""``geoshade.show(model, ...)``: an interactive view in Jupyter (jupyter_rfb), for users on
remote GPU servers: the kernel draws with the part's View, the browser shows the frames.

Mouse: left drag orbits, right or middle drag pans, the wheel zooms; the keys of the desktop
viewer work while the pointer is over the picture (1-7 or I/T/B/F/K/L/R views, 0 reset, O
ortho, +/- zoom, [ ] exaggeration). Settings change with :meth:`GeoshadeWidget.set`.

>>> import geoshade                                              # doctest: +SKIP
>>> w = geoshade.show(geoshade.synthetic_core(64), range=(0, 19000))  # doctest: +SKIP
>>> w.set(box=[0, 0, 0, 32, 32, 32])                              # doctest: +SKIP
"""

from __future__ import annotations

from geoshade.errors import InputError
from geoshade.viewer.app import ViewerUnavailableError
from geoshade.viewer.session import Session
from geoshade.viewer.views import open_view, run_now

#: jupyter_rfb's event names -> ours (it sends both old ``event_type`` and new ``type`` keys)
_BUTTON_LEFT = 1


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
            self._drag = None  # (x, y, button)
            self._interactive = False

        @property
        def view(self):
            return self.session.view

        @property
        def stats(self) -> dict:
            return self.session.stats

        def readout(self) -> str:
            return self.session.readout()

        def set(self, **options) -> None:
            """Change the View's options (``select=``, ``box=``, ``property=``, ``level=`` …)."""
            run_now(self.view.jobs(**options))
            if "box" in options or "exaggeration" in options:
                self.session.reframe()
            self.request_draw()

        # --- jupyter_rfb ---------------------------------------------------------------------
        def handle_event(self, event: dict) -> None:
            kind = event.get("event_type") or event.get("type")
            s = self.session
            if kind == "resize":
                ratio = float(event.get("pixel_ratio") or event.get("ratio") or 1.0)
                s.resize(round(event["width"] * ratio), round(event["height"] * ratio))
            elif kind == "pointer_down":
                self._drag = (event["x"], event["y"], event.get("button", _BUTTON_LEFT))
                return
            elif kind == "pointer_move":
                if self._drag is None:
                    return
                x0, y0, button = self._drag
                dx, dy = event["x"] - x0, event["y"] - y0
                self._drag = (event["x"], event["y"], button)
                if button == _BUTTON_LEFT:
                    s.orbit(dx, dy)
                else:
                    s.pan(dx, dy)
                self._interactive = True
            elif kind == "pointer_up":
                if self._drag is None:
                    return
                self._drag = None
                self._interactive = False
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
        from geoshade.styles.image import parse_size

        size = parse_size(size)
    cls = widget_class()
    w, h = (int(v) for v in size)
    if w < 1 or h < 1:
        raise InputError(f"size: expected positive width and height, got {size!r}")
    v = open_view(model, kind=kind, size=(w, h), hints=hints, **settings)
    return cls(v, size=(w, h), view_name=view, ortho=ortho)
