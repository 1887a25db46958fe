"""Public API of the stacks part: convert to stacks, render with the geologist's tools."""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from geoshade.compute.stacks import LAYOUT_NAMES, LAYOUTS, gpu_intervals, memory_table
from geoshade.errors import InputError
from geoshade.models.stacks import EMPTY, BoreholeLogs, StackModel
from geoshade.models.volume import VoxelVolume
from geoshade.styles.image import parse_size

#: what a user may pass as ``layout`` (``dense``: the dense 3D-texture baseline)
RENDER_LAYOUTS = (*LAYOUTS, "dense")
DEFAULT_LAYOUT = "ssbo"


class EmptyPictureWarning(UserWarning):
    """Nothing is left to draw (every material hidden, or no borehole column)."""


# ==============================================================================================
# conversion
# ==============================================================================================
def convert(source, variable: str | None = None, empty=None, boreholes="auto",
            strict_boreholes: bool = False, progress=None) -> StackModel:
    """A :class:`StackModel` from a file, a labelled volume, an array or a model.

    Parameters
    ----------
    source : path, VoxelVolume, (nz, ny, nx) array or StackModel
        ``.nc`` (GeoTOP), ``.npy``/``.npz``/TIFF/zarr labels (z up), ``.stacks.npz`` (returned
        as read).
    variable : str, optional
        netCDF variable (``lithok`` or ``strat``).
    empty : number, optional
        The label meaning empty (NaN always does for float labels).
    boreholes : "auto", path, BoreholeLogs or None
        Borehole logs to place into the model's columns; ``auto`` uses a ``boreholes*.parquet``
        next to a GeoTOP file when there is one.

    Examples
    --------
    >>> import numpy as np, geoshade.stacks as st
    >>> a = np.zeros((6, 3, 4), np.int8); a[:4] = 2; a[:2] = 1
    >>> m = st.convert(a, empty=0)
    >>> m.shape, m.nintervals, m.max_intervals
    ((4, 3), 36, 3)
    """
    if isinstance(source, StackModel):
        return source
    logs_path = None
    if isinstance(source, (str, Path)):
        from geoshade.io import load

        hints = {"variable": variable} if variable else {}
        obj = load(source, **hints)
        if isinstance(obj, StackModel):
            return obj
        source = obj
    if isinstance(source, VoxelVolume):
        meta = source.meta or {}
        legend = meta.get("legend")
        logs_path = meta.get("boreholes")
        data, spacing, origin = source.data, source.spacing, source.origin
        name, crs, unit = source.name, meta.get("crs", ""), source.unit
        variable = meta.get("variable", variable)
    else:
        data = np.asarray(source)
        legend, spacing, origin, name, crs, unit = None, (1.0, 1.0, 1.0), (0.0,) * 3, "", "", ""
    from geoshade.compute.stacks import place_boreholes, voxels_to_stacks

    model = voxels_to_stacks(data, empty=empty, spacing=spacing, origin=origin, legend=legend,
                             crs=crs, unit=unit, name=name, progress=progress)
    if variable:
        model.meta["variable"] = variable
    logs = None
    if isinstance(boreholes, BoreholeLogs):
        logs = boreholes
    elif boreholes is not None and boreholes != "auto":
        logs = _read_logs(boreholes, variable, model)
    elif boreholes == "auto" and logs_path:
        logs = _read_logs(logs_path, variable, model)
    if logs is not None:
        model = place_boreholes(model, logs, strict=strict_boreholes)
        model.meta["boreholes_source"] = str(logs.name)
    return model


def _read_logs(path, variable, model: StackModel) -> BoreholeLogs:
    from geoshade.io.geotop import read_boreholes

    var = variable if variable in ("lithok", "strat") else "lithok"
    return read_boreholes(path, var, model.legend)


def memory_stats(model: StackModel, octree: bool = True, progress=None) -> dict:
    """Table 1 of the paper: bytes of the dense voxels (4 B/voxel), a real octree, the stacks.

    Examples
    --------
    >>> import numpy as np, geoshade.stacks as st
    >>> s = st.memory_stats(st.convert(np.ones((8, 2, 2), np.int8)))
    >>> s["bytes_voxels"], s["bytes_stacks"], s["octree_nodes"]
    (128, 48, 25)
    """
    t = memory_table(model)
    if octree:
        from geoshade.compute.octree import octree_memory, octree_of_stacks

        counts = octree_of_stacks(model, progress=progress)
        full = octree_memory(counts)
        six = octree_memory(counts, max_depth=6)
        t.update(bytes_octree=full["bytes"], octree_nodes=full["nodes"],
                 octree_side=full["side"], bytes_octree_6_levels=six["bytes"])
    return t


# ==============================================================================================
# rendering
# ==============================================================================================
def adaptive_kernel(shape) -> int:
    """The paper's adaptive normal kernel: k in 5..9 by the grid size (5 up to 256 columns a
    side, 7 up to 512, 9 beyond).

    >>> adaptive_kernel((200, 250)), adaptive_kernel((400, 500)), adaptive_kernel((800, 1000))
    (5, 7, 9)
    """
    n = max(shape)
    return 5 if n <= 256 else 7 if n <= 512 else 9


def _check_codes(model: StackModel, codes, what: str) -> list[int]:
    out = []
    for c in codes or ():
        try:
            ci = int(c)
        except (TypeError, ValueError):
            raise InputError(f"{what}: expected integer material codes, got {c!r}") from None
        if ci not in set(model.legend.codes.tolist()):
            present = np.unique(model.codes[model.codes != EMPTY]).tolist()
            raise InputError(f"{what}: unknown material code {ci}; the model has codes "
                             f"{present[:30]}{' …' if len(present) > 30 else ''}")
        out.append(ci)
    return out


def _plane(model: StackModel, section) -> tuple[float, float, float, float] | None:
    """World plane ``(nx, ny, nz, d)`` -> index space; refuses a plane that misses the model."""
    if section is None:
        return None
    if isinstance(section, str):
        try:
            section = [float(v) for v in section.split(",")]
        except ValueError:
            raise InputError(f"section: expected NX,NY,NZ,D numbers, got {section!r}") from None
    s = np.asarray(section, float).ravel()
    if s.size != 4 or not np.isfinite(s).all():
        raise InputError(f"section: expected 4 numbers NX,NY,NZ,D, got {list(s)}")
    n, d = s[:3], s[3]
    if not np.linalg.norm(n) > 0:
        raise InputError("section: the normal NX,NY,NZ must not be zero")
    lo_lv, hi_lv = model.occupied_levels()
    og, sp = np.asarray(model.origin), np.asarray(model.spacing)
    lo = og + np.array([0, 0, lo_lv]) * sp
    hi = og + np.array([*model.shape, hi_lv]) * sp
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    side = corners @ n - d
    if (side <= 0).all() or (side >= 0).all():
        raise InputError(
            f"section: the plane {','.join(f'{v:g}' for v in s)} misses the model (x "
            f"{lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}, z {lo[2]:g}..{hi[2]:g}); it must "
            "cross the box")
    n_idx = n * sp
    return (*(float(v) for v in n_idx), float(d - n @ og))


class StacksView:
    """A live view of one stack model: change layout, opacity, section, boreholes, drape,
    exaggeration or camera and draw again; only what changed is redone (a new opacity
    re-uploads the palette alone, a new layout re-packs the stacks).

    Examples
    --------
    >>> view = StacksView(model, layout="textures", size=(320, 240))   # doctest: +SKIP
    >>> view.set_hidden([1000]); img, stats = view.draw()             # doctest: +SKIP
    >>> view.release()                                                 # doctest: +SKIP
    """

    def __init__(self, model: StackModel, layout: str = DEFAULT_LAYOUT, size=(1024, 768),
                 walk: str = "exact", walk_from: str = "auto", exaggeration: float = 1.0,
                 kernel: int | None = None, smooth: float = 0.8, lighting: bool = True,
                 brick_skip: bool = True, ctx=None):
        from geoshade.render.context import get_context
        from geoshade.styles.shading import shading_uniforms

        if not isinstance(model, StackModel):
            raise InputError(f"model: expected a StackModel, got {type(model).__name__}")
        self.model = model
        self.ctx = ctx if ctx is not None else get_context()
        self.size = parse_size(size)
        self.gpu = gpu_intervals(model)
        self.shading = shading_uniforms()
        self._check_layout(layout)
        if walk not in ("exact", "paper"):
            raise InputError(f"walk: expected exact or paper, got {walk!r}")
        if walk_from not in ("auto", "top", "bottom"):
            raise InputError(f"walk_from: expected auto, top or bottom, got {walk_from!r}")
        self.layout, self.walk, self.walk_from = layout, walk, walk_from
        self.kernel = adaptive_kernel(model.shape) if kernel is None else int(kernel)
        self.smooth, self.lighting = float(smooth), bool(lighting)
        self.brick_skip = bool(brick_skip)
        self.opacity = np.ones(len(model.legend), float)
        self.section = None
        self.boreholes = False
        self.drape = None
        self.drape_mix = 1.0
        self.exaggeration = 1.0
        self.set_exaggeration(exaggeration)
        self.visual = None
        self.target = None
        self.upload_ms = 0.0
        self._make_visual()

    # --- settings ------------------------------------------------------------------------------
    @staticmethod
    def _check_layout(layout: str) -> None:
        if layout not in RENDER_LAYOUTS:
            raise InputError(f"layout: unknown layout {layout!r}; expected one of "
                             f"{', '.join(RENDER_LAYOUTS)}")

    def _make_visual(self) -> None:
        from geoshade.render.visuals.stacks.visual import StacksVisual

        if self.visual is not None:
            self.visual.release()
            self.visual = None
        t0 = time.perf_counter()
        self.visual = StacksVisual(self.ctx, self.gpu, self.palette(), layout=self.layout,
                                   walk=self.walk)
        if self.drape is not None:
            self.visual.set_drape(*self.drape)
        self.ctx.finish()
        self.upload_ms = (time.perf_counter() - t0) * 1000

    def set_layout(self, layout: str) -> None:
        self._check_layout(layout)
        if layout != self.layout:
            self.layout = layout
            self._make_visual()

    def set_walk(self, walk: str) -> None:
        if walk not in ("exact", "paper"):
            raise InputError(f"walk: expected exact or paper, got {walk!r}")
        if walk != self.walk:
            self.walk = walk
            self._make_visual()

    def palette(self) -> np.ndarray:
        """``(P + 1, 4) uint8``: entry 0 empty, then the legend, alpha scaled by the opacity."""
        rgba = self.model.legend.rgba.astype(float)
        rgba[:, 3] *= self.opacity
        pal = np.zeros((len(self.model.legend) + 1, 4), np.uint8)
        pal[1:] = np.clip(np.round(rgba), 0, 255).astype(np.uint8)
        return pal

    def set_opacity(self, opacity: dict | None = None, hide=()) -> None:
        """Per-material opacity (code -> 0..1; 1 = the legend's) and hidden codes (opacity 0).

        Raises InputError for a code the model's legend does not have.
        """
        op = np.ones(len(self.model.legend), float)
        opacity = opacity or {}
        codes = _check_codes(self.model, list(opacity), "opacity")
        for c, a in zip(codes, opacity.values(), strict=True):
            a = float(a)
            if not 0.0 <= a <= 1.0:
                raise InputError(f"opacity: code {c}: expected 0..1, got {a:g}")
            op[int(self.model.legend.index_of(np.array([c]))[0]) - 1] = a
        for c in _check_codes(self.model, hide, "hide"):
            op[int(self.model.legend.index_of(np.array([c]))[0]) - 1] = 0.0
        self.opacity = op
        self.visual.set_palette(self.palette())

    def set_hidden(self, codes) -> None:
        """Hide these material codes (and show every other one at the legend's opacity)."""
        self.set_opacity(None, hide=codes)

    def set_section(self, section) -> None:
        """Cut away ``n·p > d`` of the world plane ``(nx, ny, nz, d)`` (None: no cut)."""
        self.section = _plane(self.model, section)

    def set_boreholes(self, only: bool) -> None:
        self.boreholes = bool(only)

    def set_drape(self, image=None, mix: float = 1.0) -> None:
        """Drape an image on the top surface: a path (PNG/JPEG/GeoTIFF), an RGBA array, or None.

        A georeferenced GeoTIFF lands where its tags say; other images cover the whole grid.
        """
        self.drape_mix = float(mix)
        if image is None:
            self.drape = None
            self.visual.set_drape(None)
            return
        extent = None
        if isinstance(image, (str, Path)):
            from geoshade.io.image import read_image

            image, extent = read_image(image)
        img = np.asarray(image)
        if img.ndim != 3 or img.shape[2] != 4:
            raise InputError(f"drape: expected an (h, w, 4) RGBA image, got shape {img.shape}")
        rect = None
        if extent is not None:
            (x0, y0, _), (dx, dy, _) = self.model.origin, self.model.spacing
            rect = ((extent[0] - x0) / dx, (extent[1] - y0) / dy,
                    (extent[2] - extent[0]) / dx, (extent[3] - extent[1]) / dy)
        self.drape = (img.astype(np.uint8), rect)
        self.visual.set_drape(*self.drape)

    def set_exaggeration(self, factor: float) -> None:
        f = float(factor)
        if not (np.isfinite(f) and f > 0):
            raise InputError(f"exaggeration: expected a positive number, got {factor!r}")
        self.exaggeration = f

    # --- geometry ------------------------------------------------------------------------------
    def zlo(self) -> float:
        return float(np.floor(self.model.occupied_levels()[0]))

    def model_matrix(self) -> np.ndarray:
        """4×4: index space (columns, levels) -> display world (vertical exaggeration)."""
        (dx, dy, dz), (x0, y0, z0), f = self.model.spacing, self.model.origin, self.exaggeration
        m = np.diag([dx, dy, dz * f, 1.0])
        m[:3, 3] = (x0, y0, z0 * f)
        return m

    def bounds(self) -> np.ndarray:
        """(2, 3) display-world bounds of the box (model only: independent of the settings)."""
        lo, hi = self.visual.box(self.zlo())
        m = self.model_matrix()
        return np.stack([m[:3, :3] @ lo + m[:3, 3], m[:3, :3] @ hi + m[:3, 3]])

    def camera(self, view="iso", azimuth=None, elevation=None, zoom=1.0, ortho=False):
        from geoshade.render.camera import Camera

        w, h = self.size
        return Camera.framed(self.bounds(), view=view, azimuth=azimuth, elevation=elevation,
                             zoom=zoom, ortho=ortho, aspect=w / h)

    def params(self):
        from geoshade.render.visuals.stacks.visual import RayParams

        g = self.gpu
        col = np.repeat(np.arange(g.count.size), g.count)
        prev = np.zeros(g.n, np.float32)
        if g.n:
            prev[1:] = np.where(col[1:] == col[:-1], g.end[:-1], 0.0)
        thick = (g.end - prev)[g.mat > 0]
        mean = float(thick.mean()) if thick.size else 1.0
        ref = mean * self.model.spacing[2] * self.exaggeration
        return RayParams(section=self.section, boreholes_only=self.boreholes, ref_length=ref,
                         walk_from=self.walk_from, kernel=self.kernel, sigma=self.smooth,
                         lighting=self.lighting, drape_mix=self.drape_mix,
                         brick_skip=self.brick_skip)

    # --- drawing ------------------------------------------------------------------------------
    def draw(self, camera=None, transparent: bool = False, background=(1.0, 1.0, 1.0),
             frames: int = 1, legend: bool = False, target=None) -> tuple[np.ndarray, dict]:
        """Render; returns the RGBA image ``(h, w, 4) uint8`` and the stats dict."""
        from geoshade.render.target import Offscreen, time_frames

        if target is None:
            if self.target is None or self.target.size != self.size:
                if self.target is not None:
                    self.target.release()
                self.target = Offscreen(self.ctx, self.size)
            target = self.target
        cam = (camera if camera is not None else self.camera()).with_aspect(target.aspect)
        bg = (*background[:3], 0.0 if transparent else 1.0)
        model, params, zlo = self.model_matrix(), self.params(), self.zlo()

        def frame():
            target.clear(bg)
            self.visual.draw(cam, model, params, self.shading, target, zlo=zlo)

        first_ms, median_ms = time_frames(self.ctx, frame, frames=max(1, frames))
        img = target.read()
        if transparent:
            a = img[..., 3:4].astype(float)
            img[..., :3] = np.where(a > 0, np.clip(img[..., :3] / np.maximum(a, 1) * 255, 0,
                                                   255), 0).astype(np.uint8)
        shown = self._shown_codes()
        if legend:
            from geoshade.stacks.legend import draw_legend

            img = draw_legend(img, self.model.legend, shown,
                              title=str(self.model.meta.get("variable", "")))
        w, h = target.size
        m = self.model
        stats = {
            "width": w, "height": h, "method": self.layout,
            "layout_name": LAYOUT_NAMES[self.layout], "walk": self.walk,
            "walk_from": self.walk_from, "frame_ms": round(median_ms, 3),
            "first_frame_ms": round(first_ms, 3), "gpu_bytes": int(self.visual.gpu_bytes),
            "layout_bytes": int(self.visual.layout_bytes),
            "layout_wasted_bytes": int(self.visual.plan["wasted"]),
            "columns": m.ncols, "intervals": m.nintervals, "max_intervals": m.max_intervals,
            "gpu_intervals": self.gpu.n, "gpu_max_intervals": self.gpu.max_count,
            "mrays_per_s": round(w * h / max(median_ms, 1e-9) / 1000.0, 3),
            "borehole_columns": int(m.borehole.sum()), "boreholes_only": self.boreholes,
            "hidden": [int(c) for c, a in zip(m.legend.codes, self.opacity, strict=True)
                       if a == 0],
            "section": None if self.section is None else list(self.section),
            "exaggeration": self.exaggeration, "kernel": self.kernel, "smooth": self.smooth,
            "drape": self.drape is not None, "brick_skip": self.brick_skip,
            "upload_ms": round(self.upload_ms, 3),
            "renderer": self.ctx.info.get("GL_RENDERER"),
        }
        if not shown or (self.boreholes and not m.borehole.any()):
            msg = ("nothing to draw: the model has no borehole column"
                   if self.boreholes and not m.borehole.any()
                   else "nothing to draw: every material is hidden")
            stats["warning"] = msg
            warnings.warn(msg, EmptyPictureWarning, stacklevel=2)
        return img, stats

    def _shown_codes(self) -> list[int]:
        m = self.model
        cols = m.column_ids()
        use = m.codes != EMPTY
        if self.boreholes:
            use &= m.borehole[cols]
        present = np.unique(m.codes[use])
        if present.size == 0:
            return []
        alpha = self.opacity[m.legend.index_of(present) - 1] * \
            m.legend.rgba[m.legend.index_of(present) - 1, 3]
        return [int(c) for c in present[alpha > 0]]

    def release(self) -> None:
        if self.visual is not None:
            self.visual.release()
            self.visual = None
        if self.target is not None:
            self.target.release()
            self.target = None


def render(model, layout: str = DEFAULT_LAYOUT, hide=(), opacity=None, section=None,
           boreholes: bool = False, drape=None, exaggeration: float = 1.0, camera=None,
           size=(1024, 768), view: str = "iso", azimuth=None, elevation=None,
           zoom: float = 1.0, ortho: bool = False, transparent: bool = False,
           legend: bool = False, walk: str = "exact", walk_from: str = "auto",
           kernel: int | None = None, smooth: float = 0.8, lighting: bool = True,
           frames: int = 5, ctx=None) -> tuple[np.ndarray, dict]:
    """Ray-cast a stack model with the geologist's tools of Section 4.3.

    Parameters
    ----------
    model : StackModel, or anything :func:`convert` takes
    layout : {'textures', 'r-supertexels', 'l-supertexels', 'texture3d', 'ssbo', 'dense'}
        The GPU layout (Section 4.2); ``dense`` is the dense 3D-texture baseline.
    hide : codes
        Materials not drawn.
    opacity : dict code -> 0..1
        Attenuated materials (the opacity of a layer of the model's mean interval thickness).
    section : (nx, ny, nz, d) or "NX,NY,NZ,D"
        World plane; the side ``n·p > d`` is cut away. A plane that misses the model is an error.
    boreholes : bool
        Draw the borehole columns only.
    drape : path or (h, w, 4) array
        Image on the top surface (PNG/JPEG/GeoTIFF).
    exaggeration : float
        Vertical exaggeration.
    walk : {'exact', 'paper'}
        Exact interval walk (default) or the paper's coarse/fine sampling.
    walk_from : {'auto', 'top', 'bottom'}
        Where a stack walk starts (``auto``: the paper's box-equator rule).
    kernel : int
        k of the k×k×k normal kernel (default: adaptive 5..9).
    smooth : float
        Gaussian smoothing of the colour pass in pixels (0: off).
    frames : int
        Frames timed; ``frame_ms`` is the median after the first.

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes columns intervals max_intervals mrays_per_s``
        and more.

    Examples
    --------
    >>> import geoshade.stacks as st
    >>> from geoshade.compute.stacks import synthetic_layers
    >>> img, stats = st.render(synthetic_layers(16, 12, 20), size=(64, 48))  # doctest: +SKIP
    >>> stats["method"], img.shape                                           # doctest: +SKIP
    ('ssbo', (48, 64, 4))
    """
    model = convert(model)
    view_ = StacksView(model, layout=layout, size=size, walk=walk, walk_from=walk_from,
                       exaggeration=exaggeration, kernel=kernel, smooth=smooth,
                       lighting=lighting, ctx=ctx)
    try:
        view_.set_opacity(opacity, hide=hide)
        view_.set_section(section)
        view_.set_boreholes(boreholes)
        if drape is not None:
            view_.set_drape(drape)
        cam = camera or view_.camera(view=view, azimuth=azimuth, elevation=elevation,
                                     zoom=zoom, ortho=ortho)
        return view_.draw(cam, transparent=transparent, frames=frames, legend=legend)
    finally:
        view_.release()
