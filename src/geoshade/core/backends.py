"""How a :class:`~geoshade.core.view.CoreView` draws its selection, along two axes:

- the **source**, where the voxels live (:mod:`geoshade.core.sources`): an array in memory or a
  store (a dask array);
- the **drawing**, where the selection maps are built, kept and drawn
  (:class:`BricksDrawing`): :class:`WholeBricks` (the box in one visual), :class:`BrickedBricks`
  (a box beyond the GPU's texture limit or memory, in bricks:
  :class:`~geoshade.render.visuals.bricked.visual.BrickedVisual`, pixel-identical) or
  :class:`~geoshade.core.distributed.ClusterBricks` (the bricks on the workers of the View's
  cluster, composited by depth, ``distributed=True``).

Whole or bricked is decided per box (:meth:`CoreView.drawing_kind
<geoshade.core.view.CoreView.drawing_kind>`): a new box may change the drawing; a cluster View
keeps its own. A drawing takes the source, the options and the :class:`Look` (the View's
resolved method and palette) and *returns* the :class:`Selection` it made current; it never
holds or writes the View. The same calls drive every drawing (tests/gl/test_backends.py).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from geoshade.compute.voxels.bricks import fits_message, host_cache
from geoshade.core.sources import VolumeSource, roi_fill
from geoshade.errors import GPUMemoryError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.render.backend import HoldsVisual
from geoshade.render.visuals.bricked.visual import BrickedVisual, tex_limit


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


@dataclass(frozen=True)
class Look:
    """What a drawing needs of the View besides the options: the resolved drawing ``method``
    and ``palette`` ((256, 4) uint8) and, for a box drawn in bricks here, ``bricking`` =
    ``(brick side, GPU budget)``."""

    method: str
    palette: np.ndarray
    bricking: tuple | None = None


@dataclass
class Selection:
    """What a drawing made current: the selection ``maps`` (their ``count``), the CPU and
    upload times."""

    maps: Any
    prepare_ms: float
    upload_ms: float


def model_matrix(volume: VoxelVolume, box, exaggeration: float = 1.0) -> np.ndarray:
    """4×4 matrix from the box's voxel index space to world coordinates (z multiplied by the
    vertical ``exaggeration``, as in every part: world z = exaggeration × z).

    >>> import numpy as np
    >>> from geoshade.compute.voxels.synthetic import synthetic_core
    >>> vol = synthetic_core(8)
    >>> top = model_matrix(vol, vol.resolve_box(None), 3.0) @ [0, 0, 1, 1]
    >>> bool(top[2] == 3.0 * vol.spacing[2] + vol.origin[2])
    True
    """
    m = np.diag([*volume.spacing, 1.0])
    m[:3, 3] = np.asarray(volume.origin) + np.asarray(box.offset) * np.asarray(volume.spacing)
    m[2] *= np.array([1.0, 1.0, float(exaggeration), float(exaggeration)])
    return m


@runtime_checkable
class BricksDrawing(Protocol):
    """Where a :class:`~geoshade.core.view.CoreView`'s selection is built, kept and drawn.
    Every call takes what it needs as arguments and returns what it made."""

    #: ``"whole"``, ``"bricked"`` or ``"cluster"``
    name: str
    #: the visual in this process (None on a cluster: the workers hold theirs)
    visual: Any

    def prepare(self, options, progress=None):
        """CPU half of a selection or box change: the selection maps of ``options`` when the
        drawing builds them up front (whole), else None (bricks build theirs when applied).
        No GL: any thread."""

    def apply(self, options, prepared: Prepared | None, look: Look) -> Selection | None:
        """GL half: make the selection of ``options`` current (``prepared``: its maps made
        already, or None); what is drawn now (None: as before)."""

    def colours(self, options, look: Look) -> Selection | None:
        """A new palette (``look.palette``)."""

    def remake(self, options, look: Look) -> Selection | None:
        """New GPU objects for a new method, culling or trefoil mode."""

    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        """Draw the selected voxels into ``target`` (the GPU's counts with ``count``)."""

    def stats(self) -> dict:
        """What the drawing adds to the View's stats (bricks, workers)."""

    def notes(self) -> list[tuple[str, type[Warning]]]:
        """Notes to warn about once per draw (workers lost)."""

    @property
    def gpu_bytes(self) -> int:
        """GPU bytes the selection holds now (on every machine that draws it)."""

    def release(self) -> None:
        """Free the GPU objects (idempotent)."""


def make_visual(ctx, maps, look: Look, options):
    """The visual of ``look``'s method for selection ``maps`` (one box or one brick)."""
    if look.method == "raycast":
        from geoshade.render.visuals.raycast.visual import RaycastVisual

        return RaycastVisual(ctx, maps, look.palette)
    from geoshade.render.visuals.voxels.visual import VoxelVisual

    return VoxelVisual(ctx, maps, look.palette, method=look.method, cull=options.cull,
                       trefoil_mode=options.trefoil_mode)


class _Here(HoldsVisual):
    """What the whole and the bricked drawings share: one visual in this process, the
    selection it shows."""

    name = ""

    def __init__(self, ctx, source: VolumeSource):
        self.ctx, self.source = ctx, source
        self.visual: Any = None
        self.selection: Selection | None = None

    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        model = model_matrix(self.source.volume, options.box, options.exaggeration)
        return self.visual.draw(camera, model, shading, count=count) or {}

    def stats(self) -> dict:
        return dict(getattr(self.visual, "extra_stats", {}))

    def notes(self) -> list[tuple[str, type[Warning]]]:
        return []


class WholeBricks(_Here):
    """The box in one visual: one set of selection maps (see the module)."""

    name = "whole"

    def prepare(self, options, progress=None):
        return self.source.maps(options, progress=progress)

    def apply(self, options, prepared: Prepared | None, look: Look) -> Selection:
        from geoshade.render.context import gpu_memory_bytes

        o = options
        if prepared is not None and prepared.maps is not None:
            maps, prepare_ms = prepared.maps, prepared.prepare_ms
        else:
            t0 = time.perf_counter()
            maps = self.prepare(o)
            prepare_ms = (time.perf_counter() - t0) * 1000
        free = o.gpu_memory or gpu_memory_bytes(self.ctx)
        msg = fits_message(o.box, look.method, maps.count, tex_limit(self.ctx),
                           None if free is None else int(free))
        if msg:
            raise GPUMemoryError(msg)
        t0 = time.perf_counter()
        if self.visual is None:
            self.visual = make_visual(self.ctx, maps, look, o)
        else:
            self.visual.upload(maps)
        self.ctx.finish()
        self.selection = Selection(maps, prepare_ms, (time.perf_counter() - t0) * 1000)
        return self.selection

    def colours(self, options, look: Look) -> None:
        if self.visual is not None and self.selection is not None:
            self.visual.upload(self.selection.maps, look.palette)

    def remake(self, options, look: Look) -> Selection:
        o, sel = options, self.selection
        self.release()
        lo, hi = o.select
        return self.apply(o, Prepared(o.box, lo, hi, tuple(o.color_range()),
                                      None if sel is None else sel.maps,
                                      0.0 if sel is None else sel.prepare_ms), look)


class BrickedBricks(_Here):
    """The box in bricks, each built and drawn in turn within the GPU budget (see the
    module)."""

    name = "bricked"

    def __init__(self, ctx, source: VolumeSource):
        super().__init__(ctx, source)
        self._fill: Any = None

    def prepare(self, options, progress=None):
        return None   # each brick builds its maps when applied

    def apply(self, options, prepared: Prepared | None, look: Look) -> Selection:
        o, src = options, self.source
        vol = src.volume
        box, (lo, hi), crange = o.box, o.select, o.color_range()
        side, budget = look.bricking
        data = src.data(o)
        vis = self.visual
        if vis is not None and vis.box == box and (
                data is vol.data or self._fill == roi_fill(vol, o)):
            vis.set_range(lo, hi, crange)
        else:
            self.release()
            self._fill = roi_fill(vol, o)
            shown = vol if data is vol.data else dataclasses.replace(vol, data=data)
            self.visual = BrickedVisual(self.ctx, shown, box, lo, hi, crange,
                                        lambda maps: make_visual(self.ctx, maps, look, o),
                                        side, budget, src.work, src.progress,
                                        method=look.method,
                                        host_cache_bytes=host_cache(o.memory))
        vis = self.visual
        self.selection = Selection(vis.maps, vis.prepare_ms, vis.upload_ms)
        return self.selection

    def colours(self, options, look: Look) -> Selection:
        return self.remake(options, look)   # every brick's visual holds the palette

    def remake(self, options, look: Look) -> Selection:
        self.release()
        return self.apply(options, None, look)


__all__ = ["BrickedBricks", "BricksDrawing", "Look", "Prepared", "Selection", "WholeBricks",
           "make_visual", "model_matrix", "roi_fill"]
