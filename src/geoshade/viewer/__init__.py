"""The interactive viewer: a thin adapter over the parts' public ``*View`` classes.

Three layers, each usable without the next:

- :mod:`geoshade.viewer.parts` — one *part adapter* per part (core, grid, iso, stacks), free of any
  GUI toolkit: it makes the part's View for a model, forwards settings to the View's setters
  (long CPU work is returned as a :class:`~geoshade.viewer.parts.base.Job`: computed off the GUI
  thread, applied on it), and formats the read-out;
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
    "open_part": ("geoshade.viewer.parts", "open_part"),
    "part_for": ("geoshade.viewer.parts", "part_for"),
    "demo_parts": ("geoshade.viewer.parts", "demo_parts"),
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
