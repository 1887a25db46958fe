"""The stack ray caster: one ray caster over the five GPU layouts of Section 4.2.

Two passes (deferred shading, Graciano et al. Fig. 3):

1. ``proxy.vert`` + ``raycast.frag``: the box's back faces as proxy geometry; each fragment casts
   its ray through the stacks (``fetch.glsl`` holds the layout-specific stack identification
   and iteration, chosen by the ``LAYOUT`` define) and writes the composited, unlit colour and
   the depth of its first contribution into a G-buffer (RGBA8 + depth) of the target's size.
2. ``fullscreen.vert`` + ``shade.frag``: hybrid image-space normals, Gaussian smoothing, Lambert
   light; blended (premultiplied) over the target, with depth.

GPU memory (exact, from the objects): the layout's textures/buffers (the paper's Table 3
"consumed" bytes, see :func:`geoshade.compute.stacks.layout_plan`), the palette (``4·(P+1)``
bytes), the drape image, the air-skipping map (4 bytes per 8×8 columns) and the G-buffer
(8 bytes per pixel).
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from geoshade.compute.stacks import LAYOUTS, GpuIntervals
from geoshade.errors import InputError
from geoshade.render.camera import Camera
from geoshade.render.resources import GpuCache, unclipped
from geoshade.render.shaders import ProgramSpec, load_program
from geoshade.render.target import neutral_framebuffer
from geoshade.render.visuals.stacks.layouts import dense_levels, pack

PKG = __package__
#: LAYOUT define of each layout (6: the dense 3D-texture baseline)
LAYOUT_IDS = {name: i + 1 for i, name in enumerate(LAYOUTS)} | {"dense": 6}
WALKS = {"exact": 0, "paper": 1}
WALK_FROM = {"auto": 0, "top": 1, "bottom": 2}
#: texture units and SSBO bindings (one definition: emitted as GLSL defines)
UNITS = {"UNIT_INDEX": 0, "UNIT_INTERVALS": 1, "UNIT_PALETTE": 2, "UNIT_DRAPE": 3,
         "UNIT_BRICKS": 4, "UNIT_TOPS": 5, "SSBO_INDEX": 0, "SSBO_INTERVALS": 1,
         "SSBO_DRAPE": 2}
#: columns per side of the bricks of the air-skipping map (max stack top per brick)
BRICK = 8
SHADE_UNITS = {"UNIT_GCOLOR": 0, "UNIT_GDEPTH": 1, "UNIT_GNORMAL": 2}
#: bytes per pixel of the G-buffer: RGBA8 colour, 32-bit depth, RGBA16F smooth-top normal
GBUFFER_BYTES = 16
#: a column without material in the smooth top's texture
NO_TOP = -1e30
#: every program this visual builds: the ray caster for each layout and walk, the deferred
#: shading pass with and without light and smoothing
PROGRAMS = [
    ProgramSpec("raycast", {"vert": "proxy.vert", "frag": "raycast.frag"},
                tuple({"LAYOUT": layout_id, "WALK": walk, "BRICK": BRICK, **UNITS}
                      for layout_id in LAYOUT_IDS.values() for walk in WALKS.values())),
    ProgramSpec("shade", {"vert": "fullscreen.vert", "frag": "shade.frag"},
                tuple({**SHADE_UNITS, "SHADE_LIGHT": light, "SHADE_SMOOTH": smooth}
                      for light in (0, 1) for smooth in (0, 1))),
]
_PROXY_VERTICES = 36


def _mat(m) -> bytes:
    return np.asarray(m, "f4").T.tobytes()


@dataclass
class RayParams:
    """Per-frame settings of the ray caster (index space unless said otherwise).

    section:        (4,) float or None   keep ``dot(n, p) <= d``; ``(nx, ny, nz, d)``
    boreholes_only: bool                 draw only borehole columns
    ref_length:     float                display path length at which opacity a gives a
    walk_from:      str                  ``auto`` (the paper's equator rule), ``top``, ``bottom``
    kernel:         int                  k of the k×k×k normal kernel (< 3: no normals)
    sigma:          float                Gaussian smoothing of the colours, pixels (0: off)
    lighting:       bool                 Lambert light (False: the transfer-function colours)
    drape_mix:      float                weight of the draped image (0..1)
    brick_skip:     bool                 skip 8×8-column bricks the ray passes above (beyond
                                         the paper; the exact walk of the stack layouts)
    smooth_top:     bool                 the top of the stacks interpolated between column
                                         centres (terrain; exact walk, stack layouts)
    top_normals:    bool                 shade the smooth top with its interpolated gradient
                                         normal (False: the hybrid normals of its depth)
    """

    section: tuple | None = None
    boreholes_only: bool = False
    ref_length: float = 1.0
    walk_from: str = "auto"
    kernel: int = 5
    sigma: float = 1.0
    lighting: bool = True
    drape_mix: float = 1.0
    brick_skip: bool = True
    smooth_top: bool = False
    top_normals: bool = True


def column_tops(g: GpuIntervals) -> np.ndarray:
    """``(ny, nx, 2) float32``: each column's top (the end of its last interval as the fp16
    layouts hold it, :data:`NO_TOP` without one) and the highest top of the 3×3 columns around
    it (the smooth top never rises above it there).

    >>> from geoshade.models.stacks import StackModel
    >>> from geoshade.compute.stacks import gpu_intervals
    >>> t = column_tops(gpu_intervals(StackModel([0, 2, 2, 4], [0, 3, 0, 5], [1, -1, 1, -1],
    ...                                          (3, 1), 8)))
    >>> t[0, :, 0].tolist(), t[0, :, 1].tolist()
    ([3.0, -1.0000000150474662e+30, 5.0], [3.0, 5.0, 5.0])
    """
    nx, ny = g.shape
    top = np.full(nx * ny, NO_TOP, np.float32)
    has = g.count > 0
    top[has] = g.end.astype(np.float16).astype(np.float32)[(g.first + g.count - 1)[has]]
    top = top.reshape(ny, nx)
    pad = np.full((ny + 2, nx + 2), NO_TOP, np.float32)
    pad[1:-1, 1:-1] = top
    dil = np.max(np.stack([pad[1 + a:ny + 1 + a, 1 + b:nx + 1 + b]
                           for a in (-1, 0, 1) for b in (-1, 0, 1)]), axis=0)
    return np.ascontiguousarray(np.stack([top, dil], axis=2))


def brick_tops(g: GpuIntervals, brick: int = BRICK, smooth: bool = False) -> np.ndarray:
    """(ceil(ny/brick), ceil(nx/brick)) float32: the highest stack top of each brick of columns
    (-1 where all its columns are empty), from the fp16 heights the layouts hold; ``smooth``:
    of the 3×3-column maxima (the smooth top near a brick's edge follows its neighbours).

    >>> from geoshade.compute.stacks import gpu_intervals, synthetic_layers
    >>> t = brick_tops(gpu_intervals(synthetic_layers(20, 10, 30, seed=0)))
    >>> t.shape, bool((t > 0).all())
    ((2, 3), True)
    """
    nx, ny = g.shape
    top = np.full(nx * ny, -1.0, np.float32)
    has = g.count > 0
    top[has] = g.end.astype(np.float16).astype(np.float32)[(g.first + g.count - 1)[has]]
    if smooth:
        t = column_tops(g)[..., 1].ravel()
        top = np.where(t > NO_TOP, t, -1.0).astype(np.float32)
    by, bx = -(-ny // brick), -(-nx // brick)
    pad = np.full((by * brick, bx * brick), -1.0, np.float32)
    pad[:ny, :nx] = top.reshape(ny, nx)
    return np.ascontiguousarray(pad.reshape(by, brick, bx, brick).max(axis=(1, 3)))


class StacksVisual:
    """GPU state and drawing of one stack model with one layout.

    Parameters
    ----------
    ctx : moderngl.Context
    gpu : GpuIntervals
        The model in the GPU form (:func:`geoshade.compute.stacks.gpu_intervals`).
    palette : (P + 1, 4) uint8
        RGBA per palette index, entry 0 = empty; alpha = opacity (0 hides a material).
    layout : str
        One of :data:`geoshade.compute.stacks.LAYOUTS`, or ``dense`` (the baseline).
    walk : {'exact', 'paper'}

    Raises
    ------
    GPUMemoryError
        The layout exceeds a texture or buffer limit of this GPU (one line that says which).

    Examples
    --------
    >>> vis = StacksVisual(ctx, gpu_intervals(model), palette, layout="ssbo")  # doctest: +SKIP
    >>> vis.draw(camera, model_matrix, RayParams(), shading, target)           # doctest: +SKIP
    """

    def __init__(self, ctx: moderngl.Context, gpu: GpuIntervals, palette: np.ndarray,
                 layout: str = "ssbo", walk: str = "exact"):
        if layout not in LAYOUT_IDS:
            raise InputError(f"layout: unknown layout {layout!r}; expected one of "
                             f"{', '.join(LAYOUTS)}")
        if walk not in WALKS:
            raise InputError(f"walk: expected one of {', '.join(WALKS)}, got {walk!r}")
        self.ctx, self.layout, self.walk = ctx, layout, walk
        self.cache = GpuCache(ctx)
        self.gpu = gpu
        self._programs: dict = {}
        self._gbuf = None
        self.smooth_top = False
        try:
            self._upload(gpu)
            self.set_palette(palette)
            self.set_drape(None)
            self.cache.buffer("drape_count", np.zeros(1, np.uint32))
            self._program()
            self._shade_program()
        except BaseException:
            self.release()
            raise

    # --- data ---------------------------------------------------------------------------------
    def limits(self) -> dict:
        info = self.ctx.info
        return {"max_texture_size": int(info.get("GL_MAX_TEXTURE_SIZE", 16384)),
                "max_3d_texture_size": int(info.get("GL_MAX_3D_TEXTURE_SIZE", 2048)),
                "max_ssbo_bytes": int(info.get("GL_MAX_SHADER_STORAGE_BLOCK_SIZE", 128 << 20))}

    def _upload(self, g: GpuIntervals) -> None:
        packed = pack(self.layout, g, self.limits())
        self.plan, self.ztop = packed["plan"], packed["ztop"]
        a, c = packed["arrays"], self.cache
        if self.layout == "textures":
            c.texture2d("indices", a["indices"], components=2, dtype="u4")
            c.texture2d("intervals", a["intervals"], components=2, dtype="f2")
        elif self.layout == "ssbo":
            c.buffer("indices", a["indices"])
            c.buffer("intervals", a["intervals"])
        elif self.layout == "texture3d":
            c.texture3d("intervals", a["intervals"], components=2, dtype="f2")
        elif self.layout == "dense":
            c.texture3d("intervals", a["dense"], components=1, dtype="u2")
        else:
            c.texture2d("intervals", a["intervals"], components=2, dtype="f2")
        c.texture2d("brick_tops", brick_tops(g), components=1, dtype="f4")
        # the thinnest non-empty interval (the paper's Nyquist rate along z)
        col = np.repeat(np.arange(g.count.size), g.count)
        prev = np.zeros(g.n, np.float32)
        if g.n:
            prev[1:] = np.where(col[1:] == col[:-1], g.end[:-1].astype(np.float16), 0.0)
        thick = g.end.astype(np.float16).astype(np.float32) - prev
        ok = (g.mat > 0) & (thick > 0)
        self.thinnest = float(thick[ok].min()) if ok.any() else 1.0

    def set_palette(self, palette: np.ndarray) -> None:
        """New colours/opacities (``(P + 1, 4) uint8``, entry 0 = empty); nothing else moves."""
        pal = np.ascontiguousarray(palette, np.uint8)
        if pal.ndim != 2 or pal.shape[1] != 4 or pal.shape[0] < 1:
            raise InputError(f"palette: expected (P + 1, 4) uint8, got shape {pal.shape}")
        pal = pal.copy()
        pal[0] = 0
        self.cache.texture2d("palette", pal.reshape(1, -1, 4))

    def set_drape(self, image: np.ndarray | None, rect=None) -> None:
        """The image draped on the top surface (``(h, w, 4) uint8``, row 0 north), or None.

        ``rect``: index-space ``(x0, y0, width, height)`` it covers (default: the whole grid).
        """
        nx, ny = self.gpu.shape
        if image is None:
            img = np.zeros((1, 1, 4), np.uint8)
            self.drape_on = False
        else:
            img = np.ascontiguousarray(np.asarray(image, np.uint8)[::-1])
            self.drape_on = True
        tex = self.cache.texture2d("drape", img)
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.drape_rect = tuple(float(v) for v in (rect if rect is not None else (0, 0, nx, ny)))

    @property
    def layout_bytes(self) -> int:
        """Consumed bytes of the layout (Table 3), equal to its allocated objects."""
        return int(self.plan["consumed"])

    @property
    def gpu_bytes(self) -> int:
        """Every texture and buffer of this visual: layout, palette, drape, G-buffer."""
        gb = 0 if self._gbuf is None else GBUFFER_BYTES * self._gbuf[0][0] * self._gbuf[0][1]
        return self.cache.nbytes + gb

    # --- programs -----------------------------------------------------------------------------
    def _program(self):
        key = (self.layout, self.walk)
        if key not in self._programs:
            defines = {"LAYOUT": LAYOUT_IDS[self.layout], "WALK": WALKS[self.walk],
                       "BRICK": BRICK, **UNITS}
            prog = load_program(self.ctx, PKG, {"vert": "proxy.vert", "frag": "raycast.frag"},
                                defines)
            self._programs[key] = (prog, self.ctx.vertex_array(prog, []))
        return self._programs[key]

    def _shade_program(self, light: bool = True, smooth: bool = True):
        key = ("shade", bool(light), bool(smooth))
        if key not in self._programs:
            defines = {**SHADE_UNITS, "SHADE_LIGHT": int(light), "SHADE_SMOOTH": int(smooth)}
            prog = load_program(self.ctx, PKG, {"vert": "fullscreen.vert",
                                                "frag": "shade.frag"}, defines)
            self._programs[key] = (prog, self.ctx.vertex_array(prog, []))
        return self._programs[key]

    def _gbuffer(self, size):
        if self._gbuf is not None and self._gbuf[0] == tuple(size):
            return self._gbuf
        self._release_gbuffer()
        color = self.ctx.texture(tuple(size), 4, dtype="f1")
        normal = self.ctx.texture(tuple(size), 4, dtype="f2")
        depth = self.ctx.depth_texture(tuple(size))
        depth.compare_func = ""
        for t in (color, normal, depth):
            t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        fbo = self.ctx.framebuffer(color_attachments=[color, normal], depth_attachment=depth)
        self._gbuf = (tuple(size), color, depth, fbo, normal)
        return self._gbuf

    def _release_gbuffer(self):
        if self._gbuf is not None:

            neutral_framebuffer(self.ctx).use()
            for o in self._gbuf[1:][::-1]:
                o.release()
            self._gbuf = None

    # --- drawing ------------------------------------------------------------------------------
    @staticmethod
    def _set(prog, name, value) -> None:
        if name in prog:
            u = prog[name]
            if isinstance(value, bytes):
                u.write(value)
            else:
                u.value = value

    def _bind(self, smooth: bool = False) -> None:
        c = self.cache
        if self.layout == "ssbo":
            c.get("indices").bind_to_storage_buffer(UNITS["SSBO_INDEX"])
            c.get("intervals").bind_to_storage_buffer(UNITS["SSBO_INTERVALS"])
        else:
            if c.get("indices") is not None:
                c.get("indices").use(UNITS["UNIT_INDEX"])
            c.get("intervals").use(UNITS["UNIT_INTERVALS"])
        c.get("palette").use(UNITS["UNIT_PALETTE"])
        c.get("drape").use(UNITS["UNIT_DRAPE"])
        c.get("brick_tops_smooth" if smooth else "brick_tops").use(UNITS["UNIT_BRICKS"])
        c.get("drape_count").bind_to_storage_buffer(UNITS["SSBO_DRAPE"])
        if smooth:
            c.get("tops").use(UNITS["UNIT_TOPS"])

    def _smooth_textures(self) -> None:
        """The smooth top's textures (made at its first use): column tops and 3×3 maxima (RG32F,
        8 bytes per column) and the air-skipping map of the maxima."""
        if self.cache.get("tops") is None:
            self.cache.texture2d("tops", column_tops(self.gpu), components=2, dtype="f4")
            self.cache.texture2d("brick_tops_smooth", brick_tops(self.gpu, smooth=True),
                                 components=1, dtype="f4")

    def drape_pixels(self) -> int:
        """Pixels of the last picture whose colour took something from the drape (0 without
        one, or when none shows: off the model, hidden, mixed at 0, seen from below)."""
        if not self.drape_on:
            return 0
        return int(np.frombuffer(self.cache.get("drape_count").read(), np.uint32)[0])

    def box(self, zlo: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The ray-casting box ``(lo, hi)`` in index space."""
        nx, ny = self.gpu.shape
        return np.array([0.0, 0.0, zlo]), np.array([nx, ny, max(self.ztop, zlo + 1e-3)])

    def draw(self, camera: Camera, model: np.ndarray, params: RayParams, shading: dict,
             target, zlo: float = 0.0) -> None:
        """Render into ``target`` (an :class:`~geoshade.render.target.Offscreen`), both passes.

        ``model`` maps index space (x, y in columns, z in levels) to display world space.
        """
        ctx = self.ctx
        w, h = target.size
        _, gcolor, gdepth, gfbo, gnormal = self._gbuffer((w, h))
        prog, vao = self._program()
        model = np.asarray(model, float)
        mv = camera.view_matrix() @ model
        inv_mv = np.linalg.inv(mv)
        proj = camera.projection_matrix()
        nx, ny = self.gpu.shape
        lo, hi = self.box(zlo)
        lin = model[:3, :3]
        S = self._set
        S(prog, "mv", _mat(mv))
        S(prog, "proj", _mat(proj))
        S(prog, "to_world", _mat(lin))
        S(prog, "box_lo", tuple(lo))
        S(prog, "box_hi", tuple(hi))
        S(prog, "grid", (nx, ny))
        S(prog, "zbox", (float(lo[2]), float(hi[2])))
        S(prog, "eye_ocs", tuple(float(v) for v in inv_mv[:3, 3]))
        S(prog, "view_dir_ocs", tuple(float(v) for v in -inv_mv[:3, 2]))
        S(prog, "ortho", bool(camera.ortho))
        S(prog, "near_far", tuple(float(v) for v in camera.near_far()))
        S(prog, "section_on", params.section is not None)
        S(prog, "section", tuple(float(v) for v in (params.section or (0, 0, 1, 0))))
        S(prog, "boreholes_only", bool(params.boreholes_only))
        S(prog, "ref_length", float(params.ref_length))
        S(prog, "walk_from", WALK_FROM[params.walk_from])
        S(prog, "coarse_len", float(min(np.linalg.norm(lin[:, 0]), np.linalg.norm(lin[:, 1]))))
        S(prog, "nyquist", (1.0, 1.0, float(self.thinnest)))
        S(prog, "drape_on", bool(self.drape_on))
        S(prog, "drape_rect", self.drape_rect)
        S(prog, "drape_mix", float(params.drape_mix))
        S(prog, "brick_skip", bool(params.brick_skip))
        smooth = bool(params.smooth_top and self.walk == "exact" and self.layout != "dense"
                      and not params.boreholes_only)
        if smooth:
            self._smooth_textures()
        self.smooth_top = smooth
        S(prog, "smooth_top", smooth)
        S(prog, "top_normals", bool(params.top_normals))
        S(prog, "level_scale", tuple(float(v) for v in np.linalg.norm(lin, axis=0)))
        plan = self.plan
        S(prog, "slots", int(plan.get("slots") or 1))
        S(prog, "super_size", tuple(plan["super"] or (1, 1)))
        if self.layout == "textures":
            S(prog, "iv_width", int(plan["objects"]["intervals"][0]))
        zspan = hi[2] - lo[2]
        if self.layout == "dense":
            S(prog, "dense_levels", dense_levels(self.gpu))
        steps = nx + ny + 8
        if self.layout == "dense":
            steps += int(np.ceil(zspan)) + 2
        if self.walk == "paper":
            steps = 4 * (nx + ny + int(np.ceil(zspan / max(self.thinnest, 1e-3)))) + 64
        S(prog, "max_steps", int(steps))
        self._bind(smooth)
        self.cache.get("drape_count").write(np.zeros(1, np.uint32).tobytes())

        gfbo.use()
        gfbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.disable(moderngl.BLEND)
        ctx.front_face = "ccw" if np.linalg.det(mv[:3, :3]) > 0 else "cw"
        ctx.cull_face = "front"
        try:
            with unclipped(ctx):  # every pixel of the model's box gets its ray
                vao.render(moderngl.TRIANGLES, vertices=_PROXY_VERTICES)
        finally:
            ctx.cull_face, ctx.front_face = "back", "ccw"
            ctx.disable(moderngl.CULL_FACE)

        sprog, svao = self._shade_program(params.lighting, params.sigma > 0)
        axes = lin / np.maximum(np.linalg.norm(lin, axis=0), 1e-30)
        view_axes = camera.view_matrix()[:3, :3] @ axes
        S(sprog, "proj", _mat(proj))
        S(sprog, "inv_proj", _mat(np.linalg.inv(proj)))
        S(sprog, "ortho", bool(camera.ortho))
        S(sprog, "viewport", (float(w), float(h)))
        S(sprog, "kernel", int(params.kernel))
        S(sprog, "axes", _mat(view_axes))
        S(sprog, "voxel_len", float(np.linalg.norm(lin, axis=0).min()))
        S(sprog, "sigma", float(params.sigma))
        S(sprog, "view_rot", _mat(camera.view_matrix()[:3, :3]))
        for name, value in shading.items():
            S(sprog, name, value)
        target.fbo.use()
        gcolor.use(SHADE_UNITS["UNIT_GCOLOR"])
        gdepth.use(SHADE_UNITS["UNIT_GDEPTH"])
        gnormal.use(SHADE_UNITS["UNIT_GNORMAL"])
        ctx.enable(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA
        try:
            svao.render(moderngl.TRIANGLES, vertices=3)
        finally:
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            ctx.disable(moderngl.BLEND)

    def read_gbuffer(self) -> tuple[np.ndarray, np.ndarray]:
        """The last pass-1 colour ``(h, w, 4) uint8`` and depth ``(h, w) float32``, row 0 top."""
        (w, h), color, depth, _, _ = self._gbuf
        c = np.frombuffer(color.read(), np.uint8).reshape(h, w, 4)[::-1].copy()
        d = np.frombuffer(depth.read(), np.float32).reshape(h, w)[::-1].copy()
        return c, d

    def release(self) -> None:
        """Release the programs, the G-buffer and every GPU object of the cache."""
        for prog, vao in self._programs.values():
            vao.release()
            prog.release()
        self._programs.clear()
        self._release_gbuffer()
        self.cache.release()
