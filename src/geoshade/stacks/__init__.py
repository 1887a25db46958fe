"""The stacks part: layered geological models as stacks of intervals, ray-cast on the GPU.

>>> import geoshade.stacks as st
>>> from geoshade.compute.stacks import synthetic_layers
>>> model = synthetic_layers(16, 12, 20, seed=0)
>>> img, stats = st.render(model, layout="textures", size=(64, 48))  # doctest: +SKIP
>>> stats["method"], stats["columns"]                                # doctest: +SKIP
('textures', 192)
"""

from __future__ import annotations

from geoshade.stacks.api import (
    DEFAULT_LAYOUT,
    RENDER_LAYOUTS,
    EmptyPictureWarning,
    StacksView,
    adaptive_kernel,
    convert,
    memory_stats,
    render,
)

__all__ = ["DEFAULT_LAYOUT", "RENDER_LAYOUTS", "EmptyPictureWarning", "StacksView",
           "adaptive_kernel", "convert", "memory_stats", "render"]
