"""``IsoView``: a live isosurface of a field over time; ``render``, ``export_mesh``, ``animate``."""

from __future__ import annotations

import concurrent.futures
import time
import warnings
from pathlib import Path

import numpy as np

from geoshade.compute import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.iso.api import (
    DEFAULT_PATCH_LEVEL,
    METHOD,
    EmptySurfaceWarning,
    OutsideValuesWarning,
    PreparedStep,
    check_level,
    choose_slice_axis,
    empty_reason,
    geometry,
    prepare_step,
    prepare_step_property,
    world_bounds,
)
from geoshade.models.field import FieldSeries, TriangleMesh
from geoshade.styles.image import parse_size


class IsoView:
    """A live view of the isosurface ``S = level`` of a field, step by step.

    Only what changed is redone: a new camera re-draws the triangles captured when the surface
    was last marched (mesh cache), a new level marches once on the GPU; a new step uploads only
    that step's field (and colour property) into the back one of two texture slots, then swaps.
    While a step is shown, the next one is read and prepared in a background thread and uploaded
    after the frame, so stepping forward is a swap.

    Parameters
    ----------
    field : FieldSeries
    level : float
        ``S*``. A node is below the level when ``S < S*``.
    step : int, optional
        Initial step (default: the last one).
    color_by : str, optional
        Name of a ``field.properties`` quantity to colour the surface by (e.g. ``"PRESSURE"``).
    color_range : (lo, hi), optional
        Colour range of ``color_by`` (default: its finite range at the initial step, then kept,
        so colours compare across steps).
    colormap : str
        Matplotlib colour map for ``color_by``.
    size : (w, h) or "WxH"
    patch_level : int
        ``L`` of the patch-quads (1..64); the paper uses 64.
    skip_patches : bool
        Skip patches whose min/max cannot hold the level (beyond the paper).
    slice_axis : {"auto", "z", "y", "x"}
        Axis the slices of patch-quads are stacked along (the paper: z). "auto" picks, at the
        initial step and level, the axis that leaves the fewest cells in patches that can hold
        the level (beyond the paper; kept for later steps and levels).
    prefetch : bool
        Prepare the next step in a background thread.
    z_scale : float
        Vertical exaggeration of the world (thin reservoirs); 1 = true geometry.
    mesh_cache : bool
        Re-draw the triangles captured when the surface was last marched while the step, level
        and colouring stay (beyond the paper, default); False marches every frame (the paper).
    ctx : moderngl.Context, optional

    Examples
    --------
    >>> from geoshade.compute.displacement import displacement_field
    >>> f = displacement_field((24, 16, 16), steps=3)
    >>> view = IsoView(f, 0.5, step=0, size=(64, 48))        # doctest: +SKIP
    >>> img, stats = view.draw()                              # doctest: +SKIP
    >>> view.set_step(1); img, stats = view.draw()            # doctest: +SKIP
    >>> view.release()                                        # doctest: +SKIP
    """

    def __init__(self, field: FieldSeries, level, step=None, color_by=None, color_range=None,
                 colormap: str = "viridis", size=(1024, 768),
                 patch_level: int = DEFAULT_PATCH_LEVEL, skip_patches: bool = True,
                 slice_axis: str = "auto", prefetch: bool = True, z_scale: float = 1.0,
                 base_color=None, mesh_cache: bool = True, ctx=None):
        from geoshade.render.context import get_context
        from geoshade.render.visuals.isosurface.visual import BASE_COLOR, IsoSurfaceVisual
        from geoshade.styles.palette import palette as make_palette
        from geoshade.styles.shading import shading_uniforms

        if not isinstance(field, FieldSeries):
            raise InputError(f"field: expected a FieldSeries, got {type(field).__name__}")
        self.field = field
        self.level = check_level(level)
        if color_by is not None and color_by not in field.properties:
            have = ", ".join(field.properties) or "none"
            raise InputError(f"{field.source or field.name}: cannot colour by {color_by!r}; "
                             f"the field has: {have}")
        self.color_by = color_by
        self.size = parse_size(size)
        self.patch_level = int(patch_level)
        self.ctx = ctx if ctx is not None else get_context()
        self.model, positions = geometry(field, z_scale)
        self.z_scale = float(z_scale)
        self.bounds = world_bounds(field, z_scale)
        self.shading = shading_uniforms()
        self.base_color = tuple(base_color) if base_color is not None else BASE_COLOR
        first = field.check_step(field.nsteps - 1 if step is None else step)
        pv0 = mc.prepare_values(field.step(first), field.active)
        self.slice_axis = choose_slice_axis(pv0, self.level, self.patch_level, slice_axis)
        self._first = prepare_step(field, first, self.patch_level, color_by, self.slice_axis,
                                   prepared=pv0)
        self.visual = IsoSurfaceVisual(self.ctx, field.shape, patch_level=self.patch_level,
                                       skip_patches=skip_patches, positions=positions,
                                       palette=make_palette(colormap),
                                       slice_axis=self.slice_axis, mesh_cache=mesh_cache)
        self.target = None
        self._slots: list[PreparedStep | None] = [None, None]
        self._executor = (concurrent.futures.ThreadPoolExecutor(1, "geoshade-iso-prefetch")
                          if prefetch and field.nsteps > 1 else None)
        self._future: tuple[int, concurrent.futures.Future] | None = None
        self.switch_ms = 0.0
        self.swapped = False
        self.color_range = None
        self.set_step(first)
        if color_by is not None:
            self.color_range = (self._default_color_range() if color_range is None
                                else tuple(float(v) for v in color_range))

    # --- steps ---------------------------------------------------------------------------------
    @property
    def step(self) -> int:
        return self._slots[self.visual.front].step

    @property
    def info(self) -> PreparedStep:
        """What the shown step's preparation found (range, NaN count, times)."""
        return self._slots[self.visual.front]

    def _default_color_range(self) -> tuple[float, float]:
        prop = self.field.property_step(self.color_by, self.step)
        finite = prop[np.isfinite(prop)]
        if finite.size == 0:
            return (0.0, 1.0)
        return (float(finite.min()), float(finite.max()))

    def _prepare(self, k: int) -> PreparedStep:
        if self._first is not None and self._first.step == k:
            prep, self._first = self._first, None
            return prep
        return prepare_step(self.field, k, self.patch_level, self.color_by, self.slice_axis)

    def _upload(self, prep: PreparedStep, slot: int) -> None:
        self.visual.upload(prep.values, prep.ranges, prep.prop, slot=slot)
        # the slot keeps the small facts, not the arrays (they live on the GPU now)
        self._slots[slot] = PreparedStep(prep.step, None, prep.ranges, None, prep.vmin,
                                         prep.vmax, prep.nonfinite, prep.inactive,
                                         prep.prepare_ms)

    def _service_prefetch(self, wait: bool = False) -> None:
        """Upload a finished background preparation into the back slot."""
        if self._future is None:
            return
        k, fut = self._future
        if not (wait or fut.done()):
            return
        self._future = None
        prep = fut.result()
        back = 1 - self.visual.front
        if self._slots[self.visual.front] is not None and self.step == k:
            return
        self._upload(prep, back)

    def _schedule(self, k: int) -> None:
        if self._executor is None or not 0 <= k < self.field.nsteps:
            return
        if any(s is not None and s.step == k for s in self._slots):
            return
        if self._future is not None:
            if self._future[0] == k:
                return
            self._future[1].cancel()
            self._future = None
        self._future = (k, self._executor.submit(self._prepare, k))

    def set_step(self, step) -> None:
        """Show step ``step``: swap to it if it was prepared ahead, else prepare and upload it."""
        k = self.field.check_step(step)
        t0 = time.perf_counter()
        front = self.visual.front
        self.swapped = False
        if self._future is not None and self._future[0] == k:
            self._service_prefetch(wait=True)
        cur = self._slots[front]
        if cur is None or cur.step != k:
            back = 1 - front
            if self._slots[back] is None or self._slots[back].step != k:
                self._upload(self._prepare(k), back)
            else:
                self.swapped = True
            self.visual.use_slot(back)
        self.ctx.finish()
        self.switch_ms = (time.perf_counter() - t0) * 1000
        self._schedule(k + 1)

    def wait_prefetch(self) -> None:
        """Block until the step prepared ahead (if any) is uploaded into the back slot."""
        self._service_prefetch(wait=True)

    def set_color_by(self, name=None, color_range=None) -> None:
        """Colour by another property (``None``: the plain surface colour).

        Only the shown step's property is uploaded now; the step prepared ahead is prepared
        again with the new property.
        """
        if name is not None and name not in self.field.properties:
            have = ", ".join(self.field.properties) or "none"
            raise InputError(f"{self.field.source or self.field.name}: cannot colour by "
                             f"{name!r}; the field has: {have}")
        self.color_by = name
        front = self.visual.front
        back = 1 - front
        self._slots[back] = None  # prepared with the old property
        if self._future is not None:
            self._future[1].cancel()
            self._future = None
        info = self._slots[front]
        prop = None
        if name is not None:
            prop = prepare_step_property(self.field, name, info.step)
        self.visual.set_property(prop, front)
        self.color_range = None
        if name is not None:
            self.color_range = (self._default_color_range() if color_range is None
                                else tuple(float(v) for v in color_range))
        self._schedule(info.step + 1)

    def set_level(self, level) -> None:
        """A new ``S*`` (nothing is uploaded: the next frame marches the new surface)."""
        self.level = check_level(level)

    # --- drawing -------------------------------------------------------------------------------
    def camera(self, view="iso", azimuth=None, elevation=None, zoom=1.0, ortho=False):
        """A camera framed on the field's bounds (independent of the step and the level)."""
        from geoshade.render.camera import Camera

        w, h = self.size
        return Camera.framed(self.bounds, view=view, azimuth=azimuth, elevation=elevation,
                             zoom=zoom, ortho=ortho, aspect=w / h)

    def empty_reason(self) -> str | None:
        info = self.info
        return empty_reason(self.level, info.vmin, info.vmax)

    def draw(self, camera=None, transparent: bool = False, background=(1.0, 1.0, 1.0),
             frames: int = 1, count: bool = True, warn: bool = True) -> tuple[np.ndarray, dict]:
        """Render; returns the RGBA image ``(h, w, 4) uint8`` and the stats dict.

        Stats: ``width height method frame_ms gpu_bytes cells triangles`` (``triangles``
        counted on the GPU by a primitives query), plus ``first_frame_ms level step time nsteps
        value_range cells_marched patch_level skip_patches nonfinite inactive step_switch_ms
        prefetched color_by color_range renderer`` and ``warning`` when something was off.
        """
        from geoshade.render.target import Offscreen, time_frames

        if self.target is None or self.target.size != self.size:
            if self.target is not None:
                self.target.release()
            self.target = Offscreen(self.ctx, self.size)
        target = self.target
        cam = camera if camera is not None else self.camera()
        cam = cam.with_aspect(target.aspect)
        bg = (*background[:3], 0.0 if transparent else 1.0)
        reason = self.empty_reason()
        crange = self.color_range if self.color_by is not None else None

        def frame():
            target.clear(bg)
            if reason is None:
                self.visual.draw(cam, self.model, self.shading, self.level, crange,
                                 self.base_color)

        def counted() -> int:
            target.clear(bg)
            if reason is not None:
                return 0
            return self.visual.draw(cam, self.model, self.shading, self.level, crange,
                                    self.base_color, count=True)["triangles"]

        triangles = None
        if count and frames <= 1:  # one frame: the counted draw is the timed one
            t0 = time.perf_counter()
            triangles = counted()
            self.ctx.finish()
            first_ms = median_ms = (time.perf_counter() - t0) * 1000
        else:
            first_ms, median_ms = time_frames(self.ctx, frame, frames=max(1, frames))
            if count:
                triangles = counted()
        img = target.read()
        info, f = self.info, self.field
        marched = (0 if reason is not None else
                   mc.live_patch_cells(info.ranges, f.shape, self.level, self.patch_level,
                                       self.slice_axis)
                   if self.visual.skip_patches else f.cells)
        stats = {
            "width": target.size[0], "height": target.size[1], "method": METHOD,
            "frame_ms": round(median_ms, 3), "gpu_bytes": int(self.visual.gpu_bytes),
            "cells": int(f.cells), "triangles": triangles,
            "first_frame_ms": round(first_ms, 3), "level": self.level, "step": info.step,
            "time": f.times[info.step], "nsteps": f.nsteps, "name": f.name,
            "value_range": [info.vmin, info.vmax], "cells_marched": int(marched),
            "patch_level": self.patch_level, "skip_patches": self.visual.skip_patches,
            "mesh_cache": self.visual.mesh_cache,
            "slice_axis": self.slice_axis,
            "nonfinite": info.nonfinite, "inactive": info.inactive,
            "step_switch_ms": round(self.switch_ms, 3), "prefetched": self.swapped,
            "prepare_ms": round(info.prepare_ms, 3), "color_by": self.color_by,
            "color_range": list(crange) if crange else None,
            "renderer": self.ctx.info.get("GL_RENDERER"),
        }
        where = f"{f.name or 'field'} at step {info.step} ({f.times[info.step]})"
        notes = []
        if reason is not None:
            notes.append((f"{where}: {reason}; nothing to draw", EmptySurfaceWarning))
        if info.nonfinite:
            notes.append((f"{where}: {info.nonfinite:,} nodes are NaN or infinite; they are "
                          "treated as outside the surface", OutsideValuesWarning))
        if notes:
            stats["warning"] = "; ".join(m for m, _ in notes)
            if warn:
                for msg, cat in notes:
                    warnings.warn(msg, cat, stacklevel=2)
        self._service_prefetch()
        return img, stats

    # --- mesh ----------------------------------------------------------------------------------
    def mesh(self) -> TriangleMesh:
        """The triangles the GPU emits now, captured by transform feedback, in world coordinates.

        Vertices shared by neighbouring cells are computed bit-identically on the GPU and welded
        here; degenerate triangles (a vertex exactly on a node) are kept, so ``n_faces`` equals
        the GPU's triangle count. Normals point towards lower values (out of the displacing
        fluid); ``values`` holds the colour property when colouring. True geometry: the view's
        ``z_scale`` is not applied.
        """
        cap = (self.visual.capture(self.level, self.color_range if self.color_by else None)
               if self.empty_reason() is None else np.zeros(0, _capture_dtype()))
        pos = np.ascontiguousarray(cap["pos"], dtype=np.float32)
        key = pos.view(np.dtype((np.void, 12))).ravel()
        uniq, first, inverse = np.unique(key, return_index=True, return_inverse=True)
        faces = inverse.reshape(-1, 3).astype(np.int64)
        m = np.diag([1.0, 1.0, 1.0 / self.z_scale, 1.0]) @ self.model
        verts = pos[first].astype(np.float64) @ m[:3, :3].T + m[:3, 3]
        nrm = np.zeros((len(uniq), 3))
        np.add.at(nrm, inverse.ravel(), cap["normal"].astype(np.float64))
        nrm = nrm @ np.linalg.inv(m[:3, :3])  # covectors: n_world = M^-T n_model
        ln = np.linalg.norm(nrm, axis=1, keepdims=True)
        nrm = np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 0).astype(np.float32)
        values = cap["value"][first] if self.color_by else None
        f = self.field
        return TriangleMesh(verts, faces, normals=nrm, values=values,
                            name=f"{f.name} = {self.level:g}, step {self.step}")

    def export_mesh(self, path) -> Path:
        """Write :meth:`mesh` to ``path`` (``.ply``, ``.obj`` or ``.stl``), atomically."""
        from geoshade.io.mesh import write_mesh

        return write_mesh(path, self.mesh())

    def release(self) -> None:
        if self._executor is not None:
            if self._future is not None:
                self._future[1].cancel()
            self._executor.shutdown(wait=True)
            self._executor = None
        self.visual.release()
        if self.target is not None:
            self.target.release()
            self.target = None

    def __enter__(self) -> IsoView:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def _capture_dtype():
    from geoshade.render.visuals.isosurface.visual import CAPTURE_DTYPE

    return CAPTURE_DTYPE
