"""Rasterised voxel methods: ``trefoil`` (the paper), ``gs`` and ``cubes`` (its baselines).

All three draw the same picture: Phong-lit unit cubes of the selected voxels, each with the
colour ``palette[color_index]``. They differ in what lives on the GPU and who makes triangles:

- ``trefoil``: no vertex buffer; patch-quads tessellated into voxel threads (TCS/TES), the
  geometry shader emits the visible trefoil strip. GPU memory: bit maps + colour-index map.
- ``gs``: one stored point (4-byte linear index) per selected voxel into the same geometry shader.
- ``cubes``: whole cubes, 36 vertices × 8 bytes per voxel, built on the CPU (with the cull on,
  only voxels with an exposed face).
"""

from __future__ import annotations

import moderngl
import numpy as np

from geoshade.compute.voxels.bitmaps import SelectionMaps, unpack_bits
from geoshade.compute.voxels.visibility import exposed_mask
from geoshade.render import layout
from geoshade.render.camera import Camera
from geoshade.render.context import is_software
from geoshade.render.resources import GpuCache
from geoshade.render.shaders import ProgramSpec, load_program

PKG = __package__
METHODS = ("trefoil", "gs", "cubes")

_D = layout.voxel_defines()
_TREFOIL = ("PATCH_L", "BITS_PER_WORD", "UNIT_PATCH_BITS", "UNIT_BITS", "UNIT_COLOR",
            "UNIT_PALETTE", "TREFOIL_S", "TREFOIL_N")
#: every program this visual builds (one per method; trefoil's patches per instance differ on
#: software and hardware rasterisers)
PROGRAMS = [
    ProgramSpec("cubes", {"vert": "cubes.vert", "frag": "voxel.frag"},
                ({"UNIT_PALETTE": _D["UNIT_PALETTE"]},)),
    ProgramSpec("trefoil", {"vert": "trefoil.vert", "tesc": "trefoil.tesc",
                            "tese": "trefoil.tese", "geom": "trefoil.geom", "frag": "voxel.frag"},
                tuple({**{k: _D[k] for k in _TREFOIL},
                       "PATCHES_PER_INSTANCE": layout.patches_per_instance(software=sw)}
                      for sw in (True, False))),
    ProgramSpec("gs", {"vert": "points.vert", "geom": "trefoil.geom", "frag": "voxel.frag"},
                ({k: _D[k] for k in _TREFOIL if k not in ("PATCH_L", "UNIT_PATCH_BITS")},)),
]

# the 36 corners of a cube's 12 triangles, per face (0 +x, 1 +y, 2 +z, 3 -x, 4 -y, 5 -z), CCW
# seen from outside; corner v = (v & 1, v >> 1 & 1, v >> 2 & 1)
_FACE_QUADS = {0: (1, 3, 7, 5), 1: (2, 6, 7, 3), 2: (4, 5, 7, 6),
               3: (0, 4, 6, 2), 4: (0, 1, 5, 4), 5: (0, 2, 3, 1)}
_CUBE_CORNERS = np.array([[f, q[a]] for f, q in _FACE_QUADS.items()
                          for a in (0, 1, 2, 0, 2, 3)], dtype=np.int64)


def cube_vertices(sel: np.ndarray, color: np.ndarray) -> np.ndarray:
    """The ``cubes`` vertex buffer: ``(count*36, 4) uint16`` rows ``x, y, z, face | ci << 8``.

    ``sel``: (nz, ny, nx) bool voxels to draw; ``color``: (nz, ny, nx) uint8 colour indices.
    """
    z, y, x = np.nonzero(sel)
    ci = color[z, y, x].astype(np.uint16)
    v = _CUBE_CORNERS[:, 1]
    out = np.empty((x.size, 36, 4), np.uint16)
    out[..., 0] = x[:, None] + (v & 1)
    out[..., 1] = y[:, None] + (v >> 1 & 1)
    out[..., 2] = z[:, None] + (v >> 2 & 1)
    out[..., 3] = _CUBE_CORNERS[:, 0].astype(np.uint16)[None, :] | (ci[:, None] << 8)
    return out.reshape(-1, 4)


class VoxelVisual:
    """GPU state and drawing of one selection with one rasterised method."""

    def __init__(self, ctx: moderngl.Context, maps: SelectionMaps, palette: np.ndarray,
                 method: str = "trefoil", cull: bool = True, trefoil_mode: str = "eye",
                 skip_empty_patches: bool = True):
        if method not in METHODS:
            raise ValueError(f"method {method!r} not one of {METHODS}")
        self.ctx, self.method, self.cull = ctx, method, bool(cull)
        self.trefoil_mode = {"eye": layout.TREFOIL_EYE, "paper": layout.TREFOIL_PAPER}[trefoil_mode]
        self.skip_empty = bool(skip_empty_patches)
        self.maps = maps
        self.cache = GpuCache(ctx)
        self.ppi = layout.patches_per_instance(software=is_software(ctx))
        defines = layout.voxel_defines()
        if method == "cubes":
            self.prog = load_program(ctx, PKG, {"vert": "cubes.vert", "frag": "voxel.frag"},
                                     {"UNIT_PALETTE": defines["UNIT_PALETTE"]})
        else:
            stages = ({"vert": "trefoil.vert", "tesc": "trefoil.tesc", "tese": "trefoil.tese"}
                      if method == "trefoil" else {"vert": "points.vert"})
            stages.update(geom="trefoil.geom", frag="voxel.frag")
            if method == "trefoil":
                defines["PATCHES_PER_INSTANCE"] = self.ppi
            used = {"PATCH_L", "BITS_PER_WORD", "UNIT_PATCH_BITS", "UNIT_BITS", "UNIT_COLOR",
                    "UNIT_PALETTE", "TREFOIL_S", "TREFOIL_N", "PATCHES_PER_INSTANCE"}
            if method == "gs":
                used -= {"PATCH_L", "UNIT_PATCH_BITS", "PATCHES_PER_INSTANCE"}
            self.prog = load_program(ctx, PKG, stages, {k: defines[k] for k in used})
        self.vao = None
        self.upload(maps, palette)

    # ------------------------------------------------------------------------------------------
    def upload(self, maps: SelectionMaps, palette: np.ndarray | None = None) -> None:
        """(Re)upload a new selection (new range or box); the programs are kept."""
        self.maps = maps
        nx, ny, nz = maps.shape_xyz
        c = self.cache
        if palette is not None:
            c.texture2d("palette", np.asarray(palette, np.uint8).reshape(1, 256, 4))
        if self.method == "cubes":
            sel = unpack_bits(maps.bits, nx).astype(bool)
            draw = exposed_mask(sel) if self.cull else sel
            verts = cube_vertices(draw, maps.color)
            self.n_cubes = int(draw.sum())
            if self.vao is not None:
                self.vao.release()
                self.vao = None
            if verts.size:
                buf = c.buffer("cube_vertices", verts)
                self.vao = self.ctx.vertex_array(self.prog, [(buf, "4u2", "corner_face_color")])
            else:
                c.drop("cube_vertices")
            return
        c.texture3d("voxel_bits", maps.bits, dtype="u4")
        c.texture3d("color_index", maps.color, dtype="u1")
        if self.method == "trefoil":
            c.texture3d("patch_bits", maps.patch_bits, dtype="u4")
            if self.vao is None:
                self.vao = self.ctx.vertex_array(self.prog, [])
        else:
            sel = unpack_bits(maps.bits, nx).astype(bool)
            if nx * ny * nz >= 2**32:
                raise ValueError("gs method: box has >= 2^32 voxels; use trefoil or raycast")
            lin = np.flatnonzero(sel.ravel()).astype(np.uint32)
            if self.vao is not None:
                self.vao.release()
                self.vao = None
            self.n_points = int(lin.size)
            if lin.size:
                buf = c.buffer("voxel_points", lin)
                self.vao = self.ctx.vertex_array(self.prog, [(buf, "u4", "voxel_linear")])
            else:
                c.drop("voxel_points")

    @property
    def gpu_bytes(self) -> int:
        return self.cache.nbytes

    # ------------------------------------------------------------------------------------------
    def _set_uniforms(self, camera: Camera, model: np.ndarray, shading: dict) -> None:
        p = self.prog
        view = camera.view_matrix()
        mv = view @ model
        normal = np.linalg.inv(mv[:3, :3]).T
        set_mat = lambda name, m: p[name].write(np.asarray(m, "f4").T.tobytes())  # noqa: E731
        set_mat("mv", mv)
        set_mat("proj", camera.projection_matrix())
        set_mat("normal_matrix", normal)
        for name, value in shading.items():
            p[name].value = value
        if self.method == "cubes":
            return
        nx, ny, nz = self.maps.shape_xyz
        p["box_size"].value = (nx, ny, nz)
        eye_ocs = (np.linalg.inv(model) @ np.append(camera.eye, 1.0))[:3]
        p["eye_ocs"].value = tuple(float(v) for v in eye_ocs)
        p["trefoil_mode"].value = self.trefoil_mode
        # Eq. (1): b_p = 1 when the z of the p-th column of the normal matrix is >= 0
        nz_cols = normal[2, :]
        p["frame_b"].value = tuple(int(v >= 0) for v in nz_cols)
        p["cull_hidden"].value = int(self.cull)
        if self.method == "trefoil":
            p["patch_grid"].value = tuple(int(v) for v in self.maps.patch_shape)
            p["skip_empty"].value = int(self.skip_empty)

    def _bind(self) -> None:
        c = self.cache
        c.get("palette").use(layout.UNIT_PALETTE)
        if self.method != "cubes":
            c.get("voxel_bits").use(layout.UNIT_BITS)
            c.get("color_index").use(layout.UNIT_COLOR)
        if self.method == "trefoil":
            c.get("patch_bits").use(layout.UNIT_PATCH_BITS)

    def draw(self, camera: Camera, model: np.ndarray, shading: dict, count: bool = False) -> dict:
        """Draw into the bound framebuffer. With ``count``, return GPU-counted primitives."""
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        ctx.provoking_vertex = moderngl.LAST_VERTEX_CONVENTION
        if self.vao is None:
            return {"voxels_drawn": 0, "triangles": 0} if count else {}
        self._set_uniforms(camera, model, shading)
        self._bind()
        query = ctx.query(primitives=True) if count else None
        if query is not None:
            with query:
                self._draw_calls()
            prims = int(query.primitives)
        else:
            self._draw_calls()
            return {}
        if self.method == "cubes":
            return {"voxels_drawn": prims // 12, "triangles": prims}
        # a trefoil strip is 8 triangles, 2 of them degenerate
        return {"voxels_drawn": prims // 8, "triangles": prims // 8 * 6}

    def _draw_calls(self) -> None:
        if self.method == "cubes":
            self.vao.render(moderngl.TRIANGLES)
        elif self.method == "gs":
            self.vao.render(moderngl.POINTS, vertices=self.n_points)
        else:
            n_patches = int(np.prod(self.maps.patch_shape))
            self.ctx.patch_vertices = 1
            instances = -(-n_patches // self.ppi)
            self.vao.render(moderngl.PATCHES, vertices=self.ppi, instances=instances)

    def release(self) -> None:
        if self.vao is not None:
            self.vao.release()
        self.prog.release()
        self.cache.release()
