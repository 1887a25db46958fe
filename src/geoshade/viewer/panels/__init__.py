"""The Qt panel beside the 3D view: the View's controls, one group box per declared group.

The controls are the View's (:func:`geoshade.viewer.controls.controls`: made from the options'
declarations and the data), each type rendered once (:mod:`geoshade.viewer.panels.widgets`),
so the panel shows what the browser shows. A part adds only what is not a control: the core's
histogram and porosity profile (:data:`EXTRAS`). A change goes through
:func:`~geoshade.viewer.controls.to_options` to ``host.apply(**options)`` (the window), which
runs the View's :meth:`~geoshade.render.view.View.jobs`, sends long jobs to the worker thread
and redraws; :meth:`Panel.sync` shows the View's settings again.
"""

from __future__ import annotations

import importlib
from typing import Any

from PySide6.QtWidgets import QVBoxLayout, QWidget

from geoshade.errors import GeoshadeError
from geoshade.viewer.controls import controls, to_options
from geoshade.viewer.panels.widgets import StepControl, align_labels, group_box, put_all
from geoshade.viewer.values import control_values

#: kind -> "module:Class" of a part whose panel shows more than its controls
EXTRAS = {"core": "geoshade.viewer.panels.core:CorePanel"}


class Panel(QWidget):
    """The controls of one session's View.

    ``host`` has ``apply(**options)`` (view, ortho and exaggeration change the session's
    camera), ``show_error(text)`` and ``idle()``. ``controls`` holds the widgets by control
    name (``panel.controls["property"]``); ``groups`` the specs they were made from.
    """

    def __init__(self, session, host, parent=None):
        super().__init__(parent)
        self.session, self.view, self.host = session, session.view, host
        self.groups = controls(self.view)
        #: what a check box turns on again: the View's drape picture and wells when it opened
        self.opened: dict[str, Any] = {"drape": getattr(self.view.options, "drape", None),
                                       "wells": getattr(self.view.options, "wells", None)}
        #: the section [axis, fraction, flip] last set (a plane does not say it)
        self.section: list | None = None
        self.controls: dict[str, QWidget] = {}
        self.layout_ = QVBoxLayout(self)
        self.boxes = {g["group"]: group_box(g, self, self.controls) for g in self.groups}
        for box in self.boxes.values():
            self.layout_.addWidget(box)
        align_labels(self.boxes.values())
        self.layout_.addStretch(1)

    # --- what the controls call ------------------------------------------------------------------
    def send(self, values: dict) -> None:
        """A control changed: its values as options, to the host."""
        try:
            options: dict = {}
            for name, value in values.items():
                options.update(to_options(name, value, self.view, self.opened))
        except GeoshadeError as err:
            self.error(str(err))
            return
        if "plane" in values:
            self.section = values["plane"]
        self.host.apply(**options)

    def ready(self) -> bool:
        """Nothing is running or waiting to be drawn (play moves on)."""
        return self.host.idle()

    def error(self, text: str) -> None:
        self.host.show_error(text)
        self.sync()

    # --- from the View to the controls -----------------------------------------------------------
    def settings(self) -> dict:
        """The View's settings with the session's named view, projection and exaggeration."""
        s = {**self.view.settings(), "view": self.session.view_name,
             "ortho": self.session.ortho}
        if self.session.exaggeration is not None:
            s["exaggeration"] = self.session.exaggeration
        return s

    def sync(self, settings: dict | None = None) -> None:
        """Show ``settings`` (default: :meth:`settings`) in the controls, sending nothing."""
        values = control_values(self.groups, settings or self.settings(), self.section)
        put_all(self.controls, values)

    def applied(self) -> None:
        """A long job of this View was applied: show its settings."""
        self.sync()

    def drawn(self, stats: dict) -> None:
        """A frame was drawn: an automatic colour range shows its values as placeholders."""
        pair = self.controls.get("color_range")
        rng = stats.get("color_range")
        if pair is not None and rng is not None and len(rng) == 2:
            for f, v in zip(pair.fields, rng, strict=True):
                f.setPlaceholderText(f"auto {float(v):.6g}")

    def pending(self) -> bool:
        """True while a change waits (none do: each is sent as it is made)."""
        return False

    def stop(self) -> None:
        """Stop playing (the window closes)."""
        for w in self.controls.values():
            if isinstance(w, StepControl):
                w.stop()


def panel_for(session, host) -> Panel:
    """The panel of ``session``'s View (a part's own class where it shows more)."""
    spec = EXTRAS.get(session.view.kind)
    if spec is None:
        panel = Panel(session, host)
    else:
        mod, cls = spec.split(":")
        panel = getattr(importlib.import_module(mod), cls)(session, host)
    panel.sync()
    return panel
