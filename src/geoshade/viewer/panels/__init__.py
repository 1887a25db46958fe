"""One Qt panel per part: the controls beside the 3D view.

A panel plugs in by adding its class to :data:`PANELS` (``kind -> "module:Class"``). It gets the
part's View and a *host* (the window) and changes options only through
``host.apply(**options)``, which runs the View's :meth:`~geoshade.render.view.View.jobs`,
sends long jobs to the worker thread and redraws.
"""

from __future__ import annotations

import importlib

from PySide6.QtWidgets import QWidget

#: kind -> "module:Class"
PANELS = {
    "core": "geoshade.viewer.panels.core:CorePanel",
    "grid": "geoshade.viewer.panels.grid:GridPanel",
    "iso": "geoshade.viewer.panels.iso:IsoPanel",
    "stacks": "geoshade.viewer.panels.stacks:StacksPanel",
}


class Panel(QWidget):
    """Base class: ``view`` (the part's View), ``host`` (``apply(**options)``,
    ``request_draw()``).

    Subclasses build their controls in ``__init__`` and may override :meth:`applied` (a long job
    of this part finished), :meth:`drawn` (a frame was drawn) and :meth:`pending` (a debounce
    timer is running).
    """

    def __init__(self, view, host, parent=None):
        super().__init__(parent)
        self.view, self.host = view, host
        self._syncing = False

    def sync(self) -> None:
        """Set the controls from ``view.settings()`` (signals of the controls are ignored)."""

    def applied(self) -> None:
        """A long job of this View was applied (e.g. new selection maps)."""

    def drawn(self, stats: dict) -> None:
        """A frame was drawn with these stats."""

    def pending(self) -> bool:
        """True while a change waits in a debounce timer."""
        return False

    def stop(self) -> None:
        """Stop timers (the window closes)."""


def panel_for(kind: str, view, host) -> Panel:
    mod, cls = PANELS[kind].split(":")
    return getattr(importlib.import_module(mod), cls)(view, host)
