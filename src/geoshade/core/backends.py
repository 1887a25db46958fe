"""The bricks backends of :class:`~geoshade.core.view.CoreView`: where a box's selection maps
are built, kept and drawn. The View keeps what is the same on every path (options, palette,
porosity, annotations, stats) and owns one backend
(:func:`geoshade.core.view.bricks_backend`):

- :class:`WholeBricks`: the box in one visual (one set of selection maps, one texture);
- :class:`BrickedBricks`: a box beyond the GPU's texture limit or memory, drawn in bricks
  (:class:`~geoshade.render.visuals.bricked.visual.BrickedVisual`), pixel-identical;
- :class:`~geoshade.core.distributed.ClusterBricks`: the bricks on the workers of the View's
  cluster, composited by depth (``distributed=True``).

Whole or bricked is decided per box (:meth:`CoreView.backend_kind
<geoshade.core.view.CoreView.backend_kind>`): a new box may change the backend; a cluster
View keeps its own. Each implements :class:`BricksBackend`; the same calls drive all three
(tests/gl/test_core_backends.py).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from geoshade.compute.bricks import fits_message, selection_maps_for
from geoshade.compute.lazy import as_dask
from geoshade.compute.roi import masked_data, outside_value
from geoshade.errors import GPUMemoryError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.render.backend import HoldsVisual


@dataclass
class Prepared:
    """A selection built on the CPU, ready for upload (see
    :meth:`CoreView.prepare_selection <geoshade.core.view.CoreView.prepare_selection>`).

    ``maps`` is None for a bricked box (its bricks build their maps when applied);
    ``porosity`` is the profile along the ``porosity`` option's axis, or None.
    """

    box: Box
    lo: float
    hi: float
    color_range: tuple | None
    maps: object
    prepare_ms: float
    porosity: object = None


def model_matrix(volume: VoxelVolume, box, exaggeration: float = 1.0) -> np.ndarray:
    """4×4 matrix from the box's voxel index space to world coordinates (z multiplied by the
    vertical ``exaggeration``, as in every part: world z = exaggeration × z).

    >>> import numpy as np
    >>> from geoshade.compute.synthetic import synthetic_core
    >>> vol = synthetic_core(8)
    >>> top = model_matrix(vol, vol.resolve_box(None), 3.0) @ [0, 0, 1, 1]
    >>> bool(top[2] == 3.0 * vol.spacing[2] + vol.origin[2])
    True
    """
    m = np.diag([*volume.spacing, 1.0])
    m[:3, 3] = np.asarray(volume.origin) + np.asarray(box.offset) * np.asarray(volume.spacing)
    m[2] *= np.array([1.0, 1.0, float(exaggeration), float(exaggeration)])
    return m


def selection_source(volume: VoxelVolume, o):
    """The data the selection maps are built from: the volume's, with voxels outside the
    options' ROI reading as a value the selection never takes
    (:func:`geoshade.compute.roi.masked_data`, evaluated per slab, chunk or brick)."""
    if o.roi is None:
        return volume.data

    data = volume.data
    if o.scheduler is not None:

        data = as_dask(data)
    lo, hi = o.select
    return masked_data(data, o.roi, lo, hi)


def roi_fill(volume: VoxelVolume, o):
    """The value outside the ROI reads as under ``o``'s selection (None: no ROI)."""
    if o.roi is None:
        return None

    dt, fill = outside_value(volume.dtype, *o.select)
    return (dt.str, repr(fill))


@runtime_checkable
class BricksBackend(Protocol):
    """What a :class:`~geoshade.core.view.CoreView` asks of its bricks backend.

    ``view`` is the owning View: the backend reads its volume, options, method, palette and
    shading and sets its ``maps``, ``prepare_ms`` and ``upload_ms``, never calls its private
    steps.
    """

    #: ``"whole"``, ``"bricked"`` or ``"cluster"``
    name: str
    #: the visual in this process (None on a cluster: the workers hold theirs)
    visual: Any

    def prepare(self, options, progress=None):
        """CPU half of a selection or box change: the selection maps of ``options`` when the
        backend builds them up front (whole), else None (bricks build theirs when applied).
        No GL: any thread."""

    def apply(self, prepared) -> None:
        """GL half: make the View's options' selection current (``prepared``: a
        :class:`Prepared` or None)."""

    def colours(self, palette: np.ndarray) -> None:
        """A new palette (the View's ``palette`` is already set)."""

    def remake(self) -> None:
        """New GPU objects for a new method, culling or trefoil mode."""

    def draw(self, camera, target, count: bool) -> dict:
        """Draw the selected voxels into ``target`` (the GPU's counts with ``count``)."""

    def stats(self) -> dict:
        """What the backend adds to the View's stats (bricks, workers)."""

    def notes(self) -> list[tuple[str, type[Warning]]]:
        """Notes to warn about once per draw (workers lost)."""

    @property
    def gpu_bytes(self) -> int:
        """GPU bytes the selection holds now (on every machine that draws it)."""

    def release(self) -> None:
        """Free the GPU objects (idempotent)."""


def make_visual(view, maps):
    """The visual of ``view``'s method for selection ``maps`` (one box or one brick)."""
    if view.method == "raycast":
        from geoshade.render.visuals.raycast.visual import RaycastVisual

        return RaycastVisual(view.ctx, maps, view.palette)
    from geoshade.render.visuals.voxels.visual import VoxelVisual

    return VoxelVisual(view.ctx, maps, view.palette, method=view.method,
                       cull=view.options.cull, trefoil_mode=view.options.trefoil_mode)


class _Local(HoldsVisual):
    """What the whole and the bricked backends share: one visual in this process."""

    name = ""

    def __init__(self, view):
        self.view = view
        self.visual: Any = None

    def draw(self, camera, target, count: bool) -> dict:
        v = self.view
        model = model_matrix(v.volume, v.options.box, v.options.exaggeration)
        return self.visual.draw(camera, model, v.shading, count=count) or {}

    def stats(self) -> dict:
        return dict(getattr(self.visual, "extra_stats", {}))

    def notes(self) -> list[tuple[str, type[Warning]]]:
        return []


class WholeBricks(_Local):
    """The box in one visual: one set of selection maps (see the module)."""

    name = "whole"

    def prepare(self, options, progress=None):
        v = self.view
        lo, hi = options.select
        clo, chi = options.color_range()
        return selection_maps_for(selection_source(v.volume, options), options.box, lo, hi,
                                  clo, chi, scheduler=v.dask_scheduler(options),
                                  progress=progress)

    def apply(self, prepared) -> None:
        from geoshade.render.context import gpu_memory_bytes
        from geoshade.render.visuals.bricked.visual import tex_limit

        v = self.view
        o = v.options
        if prepared is not None and prepared.maps is not None:
            v.maps, v.prepare_ms = prepared.maps, prepared.prepare_ms
        else:
            t0 = time.perf_counter()
            v.maps = self.prepare(o, v.progress)
            v.prepare_ms = (time.perf_counter() - t0) * 1000
        free = o.gpu_memory_limit or gpu_memory_bytes(v.ctx)
        msg = fits_message(o.box, v.method, v.maps.count, tex_limit(v.ctx),
                           None if free is None else int(free))
        if msg:
            raise GPUMemoryError(msg)
        t0 = time.perf_counter()
        if self.visual is None:
            self.visual = make_visual(v, v.maps)
        else:
            self.visual.upload(v.maps)
        v.ctx.finish()
        v.upload_ms = (time.perf_counter() - t0) * 1000

    def colours(self, palette: np.ndarray) -> None:
        if self.visual is not None:
            self.visual.upload(self.view.maps, palette)

    def remake(self) -> None:
        v = self.view
        o = v.options
        self.release()
        lo, hi = o.select
        self.apply(Prepared(o.box, lo, hi, tuple(o.color_range()), v.maps, v.prepare_ms))


class BrickedBricks(_Local):
    """The box in bricks, each built and drawn in turn within the GPU budget (see the
    module)."""

    name = "bricked"

    def __init__(self, view):
        super().__init__(view)
        self._fill: Any = None

    def prepare(self, options, progress=None):
        return None   # each brick builds its maps when applied

    def apply(self, prepared) -> None:
        from geoshade.render.visuals.bricked.visual import BrickedVisual

        v = self.view
        o = v.options
        box, (lo, hi), crange = o.box, o.select, o.color_range()
        side, budget = v.bricking(box)
        source = selection_source(v.volume, o)
        vis = self.visual
        if vis is not None and vis.box == box and (
                source is v.volume.data or self._fill == roi_fill(v.volume, o)):
            vis.set_range(lo, hi, crange)
        else:
            self.release()
            self._fill = roi_fill(v.volume, o)
            shown = (v.volume if source is v.volume.data
                     else dataclasses.replace(v.volume, data=source))
            self.visual = BrickedVisual(v.ctx, shown, box, lo, hi, crange,
                                        lambda maps: make_visual(v, maps), side, budget,
                                        v.dask_scheduler(o), v.progress, method=v.method)
        v.maps = self.visual.maps
        v.prepare_ms, v.upload_ms = self.visual.prepare_ms, self.visual.upload_ms

    def colours(self, palette: np.ndarray) -> None:
        self.remake()   # every brick's visual holds the palette

    def remake(self) -> None:
        self.release()
        self.apply(None)


__all__ = ["BrickedBricks", "BricksBackend", "Prepared", "WholeBricks", "make_visual",
           "model_matrix", "roi_fill", "selection_source"]
