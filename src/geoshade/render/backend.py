"""What every drawing of a View shares: the GPU bytes it holds and its release.

A View (core, grid) uses a drawing (``core/backends.py``, ``grid/backends.py``, the cluster
ones in ``core/distributed.py`` and ``grid/distributed.py``) of a data source. A drawing in
this process holds one visual (:class:`HoldsVisual`); one on a cluster holds a
:class:`~geoshade.render.distributed.client.DistributedRenderer` (:class:`HoldsRenderer`).
"""

from __future__ import annotations

from typing import Any


class HoldsVisual:
    """A drawing whose pictures come from ``self.visual`` (None before the first build)."""

    visual: Any = None

    @property
    def gpu_bytes(self) -> int:
        """Bytes the visual holds on the GPU (0 without one)."""
        return 0 if self.visual is None else int(self.visual.gpu_bytes)

    def release(self) -> None:
        """Free the visual's GPU objects."""
        if self.visual is not None:
            self.visual.release()
            self.visual = None


class HoldsRenderer:
    """A drawing whose pictures are drawn on a cluster by ``self.renderer``."""

    renderer: Any = None

    @property
    def gpu_bytes(self) -> int:
        """Bytes the workers hold for the scene, as they last said (0 without a renderer)."""
        return 0 if self.renderer is None else int(self.renderer.gpu_bytes)

    def release(self) -> None:
        """Free the workers' GPU objects and actors (the View closes its cluster)."""
        if self.renderer is not None:
            self.renderer.release_scene()
            self.renderer.close()
            self.renderer = None


__all__ = ["HoldsRenderer", "HoldsVisual"]
