"""The notebook widget's side panel (ipywidgets): the View's controls, the summary plot with
one time cursor, and the picks -- what the desktop viewer shows around its 3D view.

``geoshade.show(case).workbench()`` puts it beside the picture. Its parts are the toolkit-free
ones every viewer shows: the controls (:func:`geoshade.viewer.controls.controls`, rendered by
:mod:`geoshade.viewer.notebook_controls`; a change goes through
:func:`~geoshade.viewer.controls.to_options` to the widget's ``set``), the summary plot
(:class:`geoshade.viewer.timeline.Timeline`: the ``summary`` vectors, the cursor at the shown
step; a click on the plot -- a jupyter_rfb frame, as the picture is -- or the *show step* list
under it moves the step), and the picks (:class:`geoshade.viewer.picks.Picks`: a list, the
chosen cell's table as HTML, its history plot).
"""

from __future__ import annotations

import functools
import io
from typing import Any

import numpy as np
from PIL import Image as PILImage

from geoshade.errors import GeoshadeError
from geoshade.models.steps import dated_steps, step_label
from geoshade.viewer.controls import controls, to_options
from geoshade.viewer.notebook_controls import make_controls, put_all
from geoshade.viewer.picks import HISTORY_SIZE, Picks
from geoshade.viewer.timeline import Timeline
from geoshade.viewer.values import control_values

#: the summary plot's size in the notebook
PLOT_SIZE = (640, 300)
#: settings that move the session's camera, not the View's options
CAMERA = ("view", "ortho", "exaggeration")


def png(rgba: np.ndarray) -> bytes:
    """PNG bytes of an (h, w, 4) uint8 picture (what an ipywidgets Image shows)."""
    buf = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(rgba, np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def _timeline(view) -> Timeline | None:
    try:
        tl = Timeline(view)
    except GeoshadeError:
        return None
    return tl if tl.available else None


@functools.cache
def _frame_class():
    from jupyter_rfb import RemoteFrameBuffer

    class PlotFrame(RemoteFrameBuffer):
        """The summary plot's picture in the notebook; a left click on it goes to
        ``on_click(px, py)`` in the picture's pixels (the frame may be shown scaled)."""

        def __init__(self, size: tuple[int, int], on_click):
            super().__init__(css_width=f"{size[0]}px", css_height=f"{size[1]}px")
            self.on_click = on_click
            self.image: np.ndarray | None = None
            #: the frame's size on the page in CSS pixels (its last resize event)
            self.shown = (float(size[0]), float(size[1]))

        def show(self, img: np.ndarray) -> None:
            self.image = img
            self.request_draw()

        def get_frame(self):
            return None if self.image is None else np.ascontiguousarray(self.image[..., :3])

        def handle_event(self, event: dict) -> None:
            kind = event.get("event_type", event.get("type"))
            if kind == "resize":
                self.shown = (float(event["width"]), float(event["height"]))
            elif kind == "pointer_down" and event.get("button") == 1 \
                    and self.image is not None:
                h, w = self.image.shape[:2]
                self.on_click(float(event["x"]) * w / max(self.shown[0], 1.0),
                              float(event["y"]) * h / max(self.shown[1], 1.0))

    return PlotFrame


class NotebookPanel:
    """The side panel of a notebook widget (see the module); ``box`` is the ipywidgets box.

    Attributes
    ----------
    controls : dict
        The controls by name (:class:`~geoshade.viewer.notebook_controls.NotebookControl`).
    timeline : Timeline or None
        The summary plot (None: the case has no summary).
    picks : Picks or None
        The picks (None: not a grid).
    status : ipywidgets.Label
        The last line said (an error, what a click on the plot did).
    """

    def __init__(self, widget):
        import ipywidgets as W  # noqa: N812

        self.widget = widget
        self.view = widget.view
        self._quiet = False   # True while a list shows a value: nothing is sent
        self.groups = controls(self.view)
        self.section: list | None = None
        self.opened: dict[str, Any] = {"drape": getattr(self.view.options, "drape", None),
                                       "wells": getattr(self.view.options, "wells", None)}
        self.status = W.Label("")
        self.accordion, self.controls = make_controls(self.groups, self.send, self.say)
        parts = [self.status, self.accordion]
        self.timeline = _timeline(self.view)
        self._plot_key: tuple | None = None
        if self.timeline is not None:
            #: the plot (a jupyter_rfb frame: a click on it moves the step)
            self.plot = _frame_class()(PLOT_SIZE, self.click)
            n = int(getattr(self.view, "nsteps", 0) or 0)
            dates, reports = dated_steps(self.view.model)   # a grid's or a field's
            self.goto = W.Dropdown(options=[(step_label(k, dates, reports), k)
                                            for k in range(n)],
                                   description="show step",
                                   tooltip="show this report step (the cursor "
                                   "moves to its date)")
            self.goto.observe(lambda ch: self._goto(ch["new"]), names="value")
            self.summary_box = W.VBox([W.HTML("<b>summary</b>"), self.plot, self.goto])
            parts.append(self.summary_box)
        self.picks = Picks(self.view) if self.view.kind == "grid" else None
        self._picks_key: tuple | None = None
        if self.picks is not None:
            self.pick_list = W.Select(options=[], rows=4, description="picks")
            self.pick_list.observe(lambda ch: self._chosen(ch["new"]), names="value")
            self.remove = W.Button(description="remove")
            self.remove.on_click(lambda _b: self._forget(all_=False))
            self.clear = W.Button(description="clear")
            self.clear.on_click(lambda _b: self._forget(all_=True))
            self.table = W.HTML(self.picks.html())
            names = self.picks.history_names()
            self.history = W.Dropdown(options=names, description="history of")
            self.history.observe(lambda ch: self._history(ch["new"]), names="value")
            self.history_plot = W.Image(format="png")
            self.picks_box = W.VBox([W.HTML("<b>picks</b> (left-click the grid)"),
                                     self.pick_list, W.HBox([self.remove, self.clear]),
                                     self.table, *([self.history, self.history_plot]
                                                   if names else [])])
            parts.append(self.picks_box)
        self.box = W.VBox(parts, layout={"width": f"{PLOT_SIZE[0] + 20}px"})
        self.sync()
        self.follow()

    # --- controls -------------------------------------------------------------------------------
    def send(self, values: dict) -> None:
        """A control changed: its values as options, to the widget."""
        try:
            options: dict = {}
            for name, value in values.items():
                options.update(to_options(name, value, self.view, self.opened))
            if "plane" in values:
                self.section = values["plane"]
            self.apply(**options)
        except GeoshadeError as err:
            self.say(f"error: {err}")
            self.sync()
            return
        self.say("")

    def apply(self, **options) -> None:
        """Change the View's options (the named view, projection and exaggeration move the
        session's camera, as in the desktop viewer), then show everything again."""
        s = self.widget.session
        camera = {k: options.pop(k) for k in CAMERA if k in options}
        if "view" in camera:
            s.reset(str(camera["view"]))
        if "ortho" in camera:
            s.set_ortho(bool(camera["ortho"]))
        if "exaggeration" in camera and s.exaggeration is not None:
            s.set_exaggeration(float(camera["exaggeration"]))
        if options:
            self.widget.set(**options)   # follows: the widget calls changed()
        else:
            self.widget.request_draw()
            self.changed()

    def say(self, text: str) -> None:
        self.status.value = text

    def settings(self) -> dict:
        s = self.widget.session
        out = {**self.view.settings(), "view": s.view_name, "ortho": s.ortho}
        if s.exaggeration is not None:
            out["exaggeration"] = s.exaggeration
        return out

    def sync(self) -> None:
        """Show the View's settings in the controls, sending nothing."""
        put_all(self.controls, control_values(self.groups, self.settings(), self.section))

    def changed(self) -> None:
        """The View changed (a control, ``set``, a click on the plot): show it again."""
        self.sync()
        self.follow()

    # --- the summary plot -----------------------------------------------------------------------
    def follow(self) -> None:
        """The summary plot's cursor and the picks at the shown step (drawn again only where
        what they show changed)."""
        o = self.view.options
        if self.timeline is not None:
            key = (tuple(getattr(o, "summary", None) or ()), o.step)
            if key != self._plot_key:
                self._plot_key = key
                try:
                    img = self.timeline.image(PLOT_SIZE)
                except GeoshadeError as err:
                    self.say(f"error: {err}")
                    img = None
                self.summary_box.layout.display = None if img is not None else "none"
                if img is not None:
                    self.plot.show(img)
                if o.step is not None and self.goto.value != o.step:
                    self._quiet = True   # the list shows the step; it sends nothing
                    try:
                        self.goto.value = int(o.step)
                    finally:
                        self._quiet = False
        if self.picks is not None:
            p = self.picks
            key = (tuple(p.cells), p.current, p.step(), p.history_name)
            if key != self._picks_key:
                self._picks_key = key
                self.table.value = p.html()
                if p.history_name is not None and self.history.value != p.history_name:
                    self._quiet = True   # the list shows the property plotted
                    try:
                        self.history.value = p.history_name
                    finally:
                        self._quiet = False
                img = p.history_image(HISTORY_SIZE)
                self.history_plot.value = png(img) if img is not None else b""
                self.history_plot.layout.display = None if img is not None else "none"

    def click(self, px: float, py: float) -> int | None:
        """A click at pixel ``(px, py)`` of the summary plot: the nearest report step with
        restart data is shown and said (returned; None outside the curves)."""
        if self.timeline is None:
            return None
        at = self.timeline.click(px, py)
        if at is None:
            return None
        self.apply(step=at.index)
        self.say(at.text)
        return at.index

    def _goto(self, k) -> None:
        if k is not None and not self._quiet and k != self.view.options.step:
            self.apply(step=int(k))
            self.say(f"showing {step_label(int(k), *dated_steps(self.view.model))}")

    def close(self) -> None:
        """Let the summary plot and its frame go (the widget closes)."""
        if self.timeline is not None:
            self.timeline.close()
            self.plot.close()

    # --- picks ----------------------------------------------------------------------------------
    def picked(self, pick) -> None:
        """A left click picked ``pick`` on the picture: a grid cell is kept and shown."""
        if self.picks is None:
            return
        try:
            kept = self.picks.add(pick)
        except GeoshadeError as err:
            self.say(f"error: {err}")
            return
        if kept:
            self._list()
            self.follow()

    def _list(self) -> None:
        p = self.picks
        self._quiet = True
        try:
            self.pick_list.options = [(lab, k) for k, lab in enumerate(p.labels())]
            self.pick_list.value = p.current
        finally:
            self._quiet = False

    def _chosen(self, k) -> None:
        if k is not None and not self._quiet:
            self.picks.choose(int(k))
            self.follow()

    def _forget(self, all_: bool) -> None:
        if all_:
            self.picks.clear()
        else:
            self.picks.remove()
        self._list()
        self.follow()

    def _history(self, name) -> None:
        if name and not self._quiet:
            self.picks.history_name = name
            self.follow()


__all__ = ["PLOT_SIZE", "NotebookPanel", "png"]
