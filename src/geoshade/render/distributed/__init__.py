"""Rendering across the workers of a ``dask.distributed`` cluster, composited by depth.

- :mod:`~geoshade.render.distributed.producer` (worker side): the *tile producer* protocol and
  :func:`render_tile` (the producers live beside their View's cluster backend:
  :mod:`geoshade.core.distributed`, :mod:`geoshade.grid.distributed`);
- :mod:`~geoshade.render.distributed.worker`: :class:`RenderActor`, one per worker, holding
  the producers resident in the worker's own headless context between frames;
- :mod:`~geoshade.render.distributed.client`: :class:`DistributedRenderer` (assignment,
  frames, lost workers) and the writing of a composite into a View's target.

The compositing itself (no GL) is :mod:`geoshade.compute.composite`; the Views use it through
their cluster backends (:class:`geoshade.core.distributed.ClusterBricks`,
:class:`geoshade.grid.distributed.ClusterFaces`), which own a renderer and release its scene
with :meth:`DistributedRenderer.release_scene`.
"""

from __future__ import annotations

from geoshade.render.distributed.client import (
    DEFAULT_TIMEOUT_S,
    ClusterLostError,
    DistributedRenderer,
    WorkerLostWarning,
)
from geoshade.render.distributed.producer import TileProducer, render_tile
from geoshade.render.distributed.worker import RenderActor

__all__ = ["DEFAULT_TIMEOUT_S", "ClusterLostError", "DistributedRenderer", "RenderActor",
           "TileProducer", "WorkerLostWarning", "render_tile"]
