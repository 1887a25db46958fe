"""geoshade: real-time GPU visualization of very large subsurface data.

``import geoshade`` never imports moderngl: GL parts load lazily, so data, IO and compute work on
machines without OpenGL.

>>> import geoshade
>>> vol = geoshade.synthetic_core(16)
>>> vol.shape_xyz
(16, 16, 16)
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_LAZY = {
    "load": ("geoshade.api", "load"),
    "view": ("geoshade.api", "view"),
    "view_kind": ("geoshade.api", "view_kind"),
    "to_pyvista": ("geoshade.api", "to_pyvista"),
    "from_pyvista": ("geoshade.api", "from_pyvista"),
    "to_xarray": ("geoshade.api", "to_xarray"),
    "from_xarray": ("geoshade.api", "from_xarray"),
    "FieldSeries": ("geoshade.models", "FieldSeries"),
    "CornerPointGrid": ("geoshade.models", "CornerPointGrid"),
    "StackModel": ("geoshade.models", "StackModel"),
    "VoxelVolume": ("geoshade.models", "VoxelVolume"),
    "Box": ("geoshade.models", "Box"),
    "synthetic_core": ("geoshade.compute.voxels.synthetic", "synthetic_core"),
    "core": ("geoshade.core", None),
    "grid": ("geoshade.grid", None),
    "iso": ("geoshade.iso", None),
    "stacks": ("geoshade.stacks", None),
    "render": ("geoshade.render", None),
    "show": ("geoshade.viewer.notebook", "show"),
}


def __getattr__(name: str):
    if name in _LAZY:
        mod, attr = _LAZY[name]
        m = importlib.import_module(mod)
        return m if attr is None else getattr(m, attr)
    raise AttributeError(f"module 'geoshade' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))
