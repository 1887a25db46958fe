"""The interactive viewer: a thin adapter over the parts' public ``*View`` classes.

Three layers, each usable without the next:

- :mod:`geoshade.viewer.views` — free of any GUI toolkit: opens a model with the part's View
  (:func:`geoshade.view`; the CPU work of opening on a worker thread, the upload on the GUI
  thread) with the defaults a viewer wants; the front ends then use the View's own public API
  (``settings()``, ``jobs(**changes)`` -- long CPU work as a :class:`~geoshade.render.view.Job`
  computed off the GUI thread and applied on it --, ``readout()``, ``camera()``);
- :mod:`geoshade.viewer.session` — camera interaction (orbit, zoom, pan in pixels), named views,
  vertical exaggeration, draw, read-out, screenshot; shared by the desktop window and Jupyter;
- :mod:`geoshade.viewer.window` (Qt, PySide6) and :mod:`geoshade.viewer.notebook`
  (jupyter_rfb) — the two front ends; :mod:`geoshade.viewer.panels` holds one Qt panel per part.

Nothing here calls OpenGL: the Views draw into the shared headless context's offscreen target
and the front ends show the RGBA image they return.

>>> import geoshade.viewer
>>> sorted(geoshade.viewer.PART_KINDS)
['core', 'grid', 'iso', 'stacks']
"""

from __future__ import annotations

import importlib

#: the part kinds the viewer knows, in the order of the data selector
PART_KINDS = ("core", "grid", "iso", "stacks")

_LAZY = {
    "Session": ("geoshade.viewer.session", "Session"),
    "open_view": ("geoshade.viewer.views", "open_view"),
    "demo_views": ("geoshade.viewer.views", "demo_views"),
    "show": ("geoshade.viewer.notebook", "show"),
    "run_viewer": ("geoshade.viewer.window", "run_viewer"),
}


def __getattr__(name: str):
    if name in _LAZY:
        mod, attr = _LAZY[name]
        return getattr(importlib.import_module(mod), attr)
    raise AttributeError(f"module 'geoshade.viewer' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))
