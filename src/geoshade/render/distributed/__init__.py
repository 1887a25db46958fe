"""Rendering across the workers of a ``dask.distributed`` cluster, composited by depth.

- :mod:`~geoshade.render.distributed.producer` (worker side): the *tile producer* protocol, the
  core's bricks as one (:class:`CoreBricksSpec`), and :func:`render_tile`;
- :mod:`~geoshade.render.distributed.worker`: :class:`RenderActor`, one per worker, holding
  the producers resident in the worker's own headless context between frames;
- :mod:`~geoshade.render.distributed.client`: :class:`DistributedRenderer` (assignment,
  frames, lost workers) and the writing of a composite into a View's target.

The compositing itself (no GL) is :mod:`geoshade.compute.composite`; the core's View over it
is :class:`geoshade.core.distributed.DistributedCoreView`.
"""

from __future__ import annotations

from geoshade.render.distributed.client import (
    DEFAULT_TIMEOUT_S,
    ClusterLostError,
    DistributedRenderer,
    WorkerLostWarning,
)
from geoshade.render.distributed.producer import CoreBricksSpec, TileProducer, render_tile
from geoshade.render.distributed.worker import RenderActor

__all__ = ["DEFAULT_TIMEOUT_S", "ClusterLostError", "CoreBricksSpec", "DistributedRenderer",
           "RenderActor", "TileProducer", "WorkerLostWarning", "render_tile"]
