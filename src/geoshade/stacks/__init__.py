"""The stacks part: layered geological models as stacks of intervals, ray-cast on the GPU.

>>> import geoshade.stacks as st
>>> from geoshade.compute.stacks import synthetic_layers
>>> model = synthetic_layers(16, 12, 20, seed=0)
>>> img, stats = st.render(model, layout="textures", size=(64, 48), frames=1)
>>> stats["method"], stats["columns"]
('textures', 192)
"""

from __future__ import annotations

from geoshade.stacks.api import convert, demo_drape, memory_stats, render, section_plane
from geoshade.stacks.options import (
    DEFAULT_LAYOUT,
    RENDER_LAYOUTS,
    StacksOptions,
    plane_from_section,
)
from geoshade.stacks.pick import pick_stacks  # registers the View's picker
from geoshade.stacks.terrain import apply_top, from_surfaces, read_surfaces, top_from_dem
from geoshade.stacks.view import StacksView, adaptive_kernel

__all__ = ["DEFAULT_LAYOUT", "RENDER_LAYOUTS", "StacksOptions", "StacksView", "adaptive_kernel",
           "apply_top", "convert", "demo_drape", "from_surfaces", "memory_stats", "pick_stacks",
           "plane_from_section", "read_surfaces", "render", "section_plane", "top_from_dem"]
