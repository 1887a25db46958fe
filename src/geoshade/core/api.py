"""Public API of the digital-core view (a thin layer over compute/ and render/)."""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from geoshade.compute.bitmaps import gpu_bytes_estimate
from geoshade.compute.porosity import porosity as _porosity
from geoshade.compute.selection import check_range
from geoshade.errors import GPUMemoryError, InputError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.styles.image import parse_size

#: the methods a user may ask for; ``auto`` is resolved per renderer by :func:`resolve_method`
METHODS = ("auto", "raycast", "trefoil", "gs", "cubes")

#: what ``auto`` picks. Measured with ``geoshade bench core`` (benchmarks/RESULTS.md): on the
#: software rasteriser (llvmpipe) the ray caster re-renders 256³ 20-40× faster
#: than any rasterised method, because all geometry stages run on one thread there. On hardware
#: GPUs the ray caster is kept too (no tessellation/GS amplification, 1.15 B/voxel) until a
#: benchmark on a GPU says otherwise.
AUTO = {"software": "raycast", "hardware": "raycast"}


class EmptySelectionWarning(UserWarning):
    """The range selects no voxel of the box: the picture is an empty scene."""


def resolve_method(method: str, software: bool) -> str:
    if method not in METHODS:
        raise InputError(f"method: unknown method {method!r}; expected one of {', '.join(METHODS)}")
    if method == "auto":
        return AUTO["software" if software else "hardware"]
    return method


def model_matrix(volume: VoxelVolume, box: Box) -> np.ndarray:
    """4×4 matrix from the box's voxel index space to world coordinates."""
    m = np.diag([*volume.spacing, 1.0])
    m[:3, 3] = np.asarray(volume.origin) + np.asarray(box.offset) * np.asarray(volume.spacing)
    return m


def largest_cube_box(method: str, free_bytes: float, tex_limit: int, density: float = 0.5) -> int:
    """Side d of the largest d³ box whose GPU objects fit in ``free_bytes``."""
    lo, hi = 1, max(1, int(tex_limit))
    while lo < hi:
        mid = (lo + hi + 1) // 2
        count = int(mid**3 * density)
        if gpu_bytes_estimate((mid, mid, mid), method, count) <= free_bytes:
            lo = mid
        else:
            hi = mid - 1
    return lo


@dataclass
class Prepared:
    """A selection built on the CPU, ready for upload (see :meth:`CoreView.prepare_selection`)."""

    box: Box
    lo: float
    hi: float
    color_range: tuple | None
    maps: object
    prepare_ms: float


@dataclass
class _State:
    box: Box
    lo: float
    hi: float


class CoreView:
    """A live view of one volume: change range, box, method or camera and draw again.

    Only what changed is redone: a new range or box rebuilds the bit maps and re-uploads them;
    a new camera just draws.
    """

    def __init__(self, volume: VoxelVolume, range=None, box=None, method: str = "auto",
                 size=(1024, 768), colormap: str = "viridis", color_range=None,
                 cull: bool = True, trefoil_mode: str = "eye", ctx=None, palette=None,
                 gpu_memory_limit: float | None = None, progress=None, bricks=None,
                 scheduler=None):
        from geoshade.render.context import get_context, is_software
        from geoshade.styles.palette import palette as make_palette
        from geoshade.styles.shading import shading_uniforms

        if not isinstance(volume, VoxelVolume):
            raise InputError(f"volume: expected a VoxelVolume, got {type(volume).__name__}")
        self.volume = volume
        self.ctx = ctx if ctx is not None else get_context()
        self.software = is_software(self.ctx)
        self.method = resolve_method(method, self.software)
        self.size = parse_size(size)
        self.cull, self.trefoil_mode = bool(cull), trefoil_mode
        self.palette = (np.asarray(palette, np.uint8) if palette is not None
                        else make_palette(colormap))
        if self.palette.shape != (256, 4):
            raise InputError(f"palette: expected (256, 4) uint8 RGBA, got {self.palette.shape}")
        self.shading = shading_uniforms()
        self.color_range = color_range
        self.gpu_memory_limit = gpu_memory_limit
        self.progress = progress
        self.bricks, self.scheduler = bricks, scheduler  # see geoshade.core.bricks (issue 6)
        self.visual = None
        self.target = None
        self.maps = None
        self.prepare_ms = 0.0
        self.upload_ms = 0.0
        lo, hi = self._default_range() if range is None else range
        self.state = _State(volume.resolve_box(box), *check_range(lo, hi, volume.dtype))
        self._rebuild()

    # --- selection ---------------------------------------------------------------------------
    def _default_range(self):
        lo, hi = self.volume.value_limits()
        if not np.isfinite(lo):
            raise InputError(f"{self.volume.name or 'volume'}: float data needs an explicit range")
        return lo, hi

    def prepare_selection(self, range=None, box=None, color_range=None) -> Prepared:
        """CPU half of a new range and/or box: check it and build the bit maps (no GL).

        Safe on a worker thread (a viewer keeps its window alive this way); hand the result to
        :meth:`apply_selection` on the thread that owns the GL context.
        """
        st = self.state
        lo, hi = st.lo, st.hi
        if range is not None:
            lo, hi = check_range(*range, self.volume.dtype)
        bx = st.box if box is None else self.volume.resolve_box(box)
        crange = color_range or self.color_range or (lo, hi)
        t0 = time.perf_counter()
        maps = self._build_maps(bx, lo, hi, *crange)
        return Prepared(bx, lo, hi, tuple(crange), maps, (time.perf_counter() - t0) * 1000)

    def _build_maps(self, box, lo, hi, clo, chi):
        from geoshade.core.bricks import build_maps

        return build_maps(self.volume.data, box, lo, hi, clo, chi,
                          scheduler=getattr(self, "scheduler", None), progress=self.progress)

    def apply_selection(self, prepared) -> None:
        """GL half: make ``prepared`` (from :meth:`prepare_selection`) the current selection."""
        st = self.state
        st.box, st.lo, st.hi = prepared.box, prepared.lo, prepared.hi
        if prepared.color_range is not None:
            self.color_range = tuple(prepared.color_range)
        self.maps, self.prepare_ms = prepared.maps, prepared.prepare_ms
        self._rebuild(maps_ok=True)

    def set_range(self, lo, hi) -> None:
        self.state.lo, self.state.hi = check_range(lo, hi, self.volume.dtype)
        self._rebuild()

    def set_box(self, box) -> None:
        self.state.box = self.volume.resolve_box(box)
        self._rebuild()

    def set_method(self, method: str) -> None:
        method = resolve_method(method, self.software)
        if method != self.method:
            self.method = method
            self._release_visual()
            self._rebuild(maps_ok=True)

    def _check_fits(self, count: int) -> None:
        from geoshade.render.context import gpu_memory_bytes

        box = self.state.box
        limit = int(self.ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048))
        need = gpu_bytes_estimate(box.size, self.method, count)
        free = self.gpu_memory_limit or gpu_memory_bytes(self.ctx)
        too_wide = self.method != "cubes" and max(box.size) > limit
        if too_wide or (free is not None and need > free):
            side = largest_cube_box(self.method, free if free else float("inf"), limit,
                                    density=count / max(box.nvoxels, 1))
            what = (f"exceeds the 3D texture limit of {limit} per axis" if too_wide else
                    f"needs {need / 2**30:.2f} GiB of GPU memory, {free / 2**30:.2f} GiB free")
            raise GPUMemoryError(
                f"box {box.size[0]}×{box.size[1]}×{box.size[2]} with method {self.method} {what}; "
                f"a box of up to {side}³ voxels fits (use --box)")

    def _rebuild(self, maps_ok: bool = False) -> None:
        from geoshade.core.bricks import maybe_bricked

        if maybe_bricked(self, maps_ok):  # boxes beyond the GPU's limits, dask clusters
            return
        st = self.state
        if not maps_ok or self.maps is None:
            clo, chi = self.color_range if self.color_range is not None else (st.lo, st.hi)
            t0 = time.perf_counter()
            self.maps = self._build_maps(st.box, st.lo, st.hi, clo, chi)
            self.prepare_ms = (time.perf_counter() - t0) * 1000
        self._check_fits(self.maps.count)
        t0 = time.perf_counter()
        if self.visual is None:
            self.visual = self._make_visual()
        else:
            self.visual.upload(self.maps)
        self.ctx.finish()
        self.upload_ms = (time.perf_counter() - t0) * 1000

    def _make_visual(self):
        if self.method == "raycast":
            from geoshade.render.visuals.raycast.visual import RaycastVisual

            return RaycastVisual(self.ctx, self.maps, self.palette)
        from geoshade.render.visuals.voxels.visual import VoxelVisual

        return VoxelVisual(self.ctx, self.maps, self.palette, method=self.method, cull=self.cull,
                           trefoil_mode=self.trefoil_mode)

    # --- drawing -----------------------------------------------------------------------------
    def camera(self, view="iso", azimuth=None, elevation=None, zoom=1.0, ortho=False):
        """The camera framed on the box (bounds only: independent of the range)."""
        from geoshade.render.camera import Camera

        w, h = self.size
        return Camera.framed(self.volume.bounds(self.state.box), view=view, azimuth=azimuth,
                             elevation=elevation, zoom=zoom, ortho=ortho, aspect=w / h)

    def draw(self, camera=None, transparent: bool = False, background=(1.0, 1.0, 1.0),
             frames: int = 1, count: bool = True, target=None) -> tuple[np.ndarray, dict]:
        """Render; returns the RGBA image ``(h, w, 4) uint8`` and the stats dict."""
        from geoshade.render.target import Offscreen, time_frames

        if target is None:
            if self.target is None or self.target.size != self.size:
                if self.target is not None:
                    self.target.release()
                self.target = Offscreen(self.ctx, self.size)
            target = self.target
        cam = camera if camera is not None else self.camera()
        cam = cam.with_aspect(target.aspect)
        model = model_matrix(self.volume, self.state.box)
        bg = (*background[:3], 0.0 if transparent else 1.0)

        def frame():
            target.clear(bg)
            self.visual.draw(cam, model, self.shading)

        first_ms, median_ms = time_frames(self.ctx, frame, frames=max(1, frames))
        counts = {}
        if count:
            target.clear(bg)
            counts = self.visual.draw(cam, model, self.shading, count=True)
        img = target.read()
        st = self.state
        stats = {
            "width": target.size[0],
            "height": target.size[1],
            "method": self.method,
            "frame_ms": round(median_ms, 3),
            "first_frame_ms": round(first_ms, 3),
            "gpu_bytes": int(self.visual.gpu_bytes),
            "voxels_selected": int(self.maps.count),
            "voxels_drawn": counts.get("voxels_drawn"),
            "triangles": counts.get("triangles"),
            "box": [*st.box.offset, *st.box.size],
            "range": [st.lo, st.hi],
            "prepare_ms": round(self.prepare_ms, 3),
            "upload_ms": round(self.upload_ms, 3),
            "renderer": self.ctx.info.get("GL_RENDERER"),
            **getattr(self.visual, "extra_stats", {}),
        }
        if self.method != "raycast":
            stats["cull"] = self.cull
        if self.maps.count == 0:
            msg = (f"empty selection: no voxel of box {stats['box']} has a value in "
                   f"[{st.lo:g}, {st.hi:g}]; the picture is an empty scene")
            stats["warning"] = msg
            warnings.warn(msg, EmptySelectionWarning, stacklevel=2)
        return img, stats

    def _release_visual(self) -> None:
        if self.visual is not None:
            self.visual.release()
            self.visual = None

    def release(self) -> None:
        self._release_visual()
        if self.target is not None:
            self.target.release()
            self.target = None


def render(volume: VoxelVolume, range=None, box=None, method: str = "auto", camera=None,
           size=(1024, 768), view: str = "iso", azimuth=None, elevation=None, zoom: float = 1.0,
           ortho: bool = False, transparent: bool = False, colormap: str = "viridis",
           color_range=None, cull: bool = True, trefoil_mode: str = "eye", frames: int = 5,
           count: bool = True, palette=None, ctx=None, progress=None,
           gpu_memory_limit: float | None = None, bricks=None,
           scheduler=None) -> tuple[np.ndarray, dict]:
    """Render the voxels of ``box`` whose values lie in ``range``.

    Parameters
    ----------
    volume : VoxelVolume
    range : (lo, hi)
        Absorption range in the data's own units (inclusive). Default: the whole dtype range.
    box : Box or [x0, y0, z0, nx, ny, nz], optional
        Sub-volume; default the whole volume.
    method : {'auto', 'raycast', 'trefoil', 'gs', 'cubes'}
    camera : Camera, optional
        Default: framed on the box from ``view`` / ``azimuth`` / ``elevation`` / ``zoom``.
    frames : int
        Frames drawn for timing; ``frame_ms`` is the median after the first.
    bricks : None, False or int
        Render in bricks (:mod:`geoshade.core.bricks`): None when the box exceeds the 3D-texture
        limit or the GPU memory, an int to cap the brick side, False never.
    scheduler : None, str or distributed.Client
        Build the selection maps with dask on this scheduler (address or client).

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes voxels_selected voxels_drawn triangles`` and more.

    Examples
    --------
    >>> import geoshade
    >>> vol = geoshade.synthetic_core(16)
    >>> img, st = geoshade.core.render(vol, range=(0, 15000), size="64x64")  # doctest: +SKIP
    """
    view_ = CoreView(volume, range=range, box=box, method=method, size=size, colormap=colormap,
                     color_range=color_range, cull=cull, trefoil_mode=trefoil_mode, ctx=ctx,
                     palette=palette, progress=progress, gpu_memory_limit=gpu_memory_limit,
                     bricks=bricks, scheduler=scheduler)
    try:
        cam = camera or view_.camera(view=view, azimuth=azimuth, elevation=elevation, zoom=zoom,
                                     ortho=ortho)
        return view_.draw(cam, transparent=transparent, frames=frames, count=count)
    finally:
        view_.release()


def porosity(volume: VoxelVolume, range, box=None, axis: str = "z", progress=None,
             scheduler=None):
    """Pore fraction inside ``box`` for values in ``range``: total and a profile along ``axis``.

    >>> import geoshade
    >>> r = geoshade.core.porosity(geoshade.synthetic_core(16), (0, 15000))
    >>> 0 <= r.porosity <= 1
    True
    """
    lo, hi = check_range(*range, volume.dtype)
    if scheduler is not None:  # issue 6: a dask graph on that scheduler (same result)
        from geoshade.compute.lazy import porosity as lazy_porosity

        return lazy_porosity(volume, lo, hi, box=volume.resolve_box(box), axis=axis,
                             scheduler=scheduler, progress=progress)
    return _porosity(volume, lo, hi, box=volume.resolve_box(box), axis=axis, progress=progress)
