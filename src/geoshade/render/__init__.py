"""The only package that imports moderngl: contexts, shaders, camera, targets, visuals, View.

Importing ``geoshade.render`` (or :mod:`geoshade.render.view`, :mod:`geoshade.render.camera`)
does not import moderngl: the GL modules load when first used, so the parts' Views can check
their options on a machine without OpenGL.
"""

from __future__ import annotations

import importlib

_LAZY = {
    "Camera": ("geoshade.render.camera", "Camera"),
    "View": ("geoshade.render.view", "View"),
    "capabilities": ("geoshade.render.context", "capabilities"),
    "create_context": ("geoshade.render.context", "create_context"),
    "get_context": ("geoshade.render.context", "get_context"),
}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    if name in _LAZY:
        mod, attr = _LAZY[name]
        return getattr(importlib.import_module(mod), attr)
    raise AttributeError(f"module 'geoshade.render' has no attribute {name!r}")
