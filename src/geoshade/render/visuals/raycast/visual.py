"""The ``raycast`` voxel method: an exact voxel ray caster, beyond the paper.

It draws the same picture as the rasterised methods of
:mod:`geoshade.render.visuals.voxels.visual` (Phong-lit unit cubes of the selected voxels, each
coloured ``palette[color_index]``), but makes no triangles for voxels: the box's back faces are
drawn as proxy geometry and every fragment walks its ray through the voxels with a 3D DDA
(Amanatides & Woo) until the first selected voxel, leaving in one step the largest empty cube the
skip map (:mod:`geoshade.compute.voxels.skipmap`) proves empty around it.

GPU memory (exact, from :class:`~geoshade.render.resources.GpuCache`):

=============  ======================================  ==================================
name           texture                                 bytes
=============  ======================================  ==================================
voxel_bits     R32UI ``ceil(nx/32) × ny × nz``         ``nx·ny·nz / 8`` (rows padded)
color_index    R8UI ``nx × ny × nz``                   ``nx·ny·nz``
bricks         RGB32UI ``ceil(n/8)`` per axis          ``12 · nx·ny·nz / 512``
palette        RGBA8 ``256 × 1``                       1024
=============  ======================================  ==================================

about 1.149 bytes per box voxel, the same as
:func:`geoshade.compute.voxels.bitmaps.gpu_bytes_breakdown` ``(shape, "raycast")``.

Near and far planes clip as they clip triangles: a ray starts where it enters the box or crosses
the near plane, whichever comes later. A selected voxel cut by the near plane shows its far face
from inside, as the cubes method draws it.
"""

from __future__ import annotations

import moderngl
import numpy as np

from geoshade.compute.voxels.bitmaps import SelectionMaps, words_per_row
from geoshade.compute.voxels.skipmap import skip_map
from geoshade.errors import GPUMemoryError, InputError
from geoshade.render import layout
from geoshade.render.camera import Camera
from geoshade.render.resources import GpuCache, unclipped
from geoshade.render.shaders import ProgramSpec, load_program

PKG = __package__
#: the layout defines the shaders declare (values from :func:`layout.voxel_defines`)
_LAYOUT_DEFINES = ("BITS_PER_WORD", "BRICK", "UNIT_BITS", "UNIT_COLOR", "UNIT_PALETTE",
                   "UNIT_BRICKS")
_PROXY_VERTICES = 36
#: every program this visual builds: with and without the seen-voxel counter
PROGRAMS = [
    ProgramSpec("raycast", {"vert": "raycast.vert", "frag": "raycast.frag"},
                tuple({**{k: layout.voxel_defines()[k] for k in _LAYOUT_DEFINES},
                       "COUNT_SEEN": count, "COUNT_BINDING": layout.SSBO_COUNT}
                      for count in (0, 1))),
]


def _mat_bytes(m) -> bytes:
    return np.asarray(m, "f4").T.tobytes()


class RaycastVisual:
    """GPU state and drawing of one selection with the exact voxel ray caster.

    Parameters
    ----------
    ctx : moderngl.Context
        An OpenGL >= 4.3 context.
    maps : SelectionMaps
        The selection (bit map and colour indices; the skip map is built from the bit map).
    palette : (256, 4) uint8
        RGBA palette indexed by the colour index map.
    brick_skip : bool
        Skip empty space with the skip map (default). Switch off only to measure what skipping
        gains.

    Examples
    --------
    >>> vis = RaycastVisual(ctx, maps, palette)                       # doctest: +SKIP
    >>> target.clear(); vis.draw(camera, np.eye(4), shading)          # doctest: +SKIP
    {}
    >>> vis.draw(camera, np.eye(4), shading, count=True)              # doctest: +SKIP
    {'voxels_drawn': 1234, 'triangles': 0}
    """

    method = "raycast"

    def __init__(self, ctx: moderngl.Context, maps: SelectionMaps, palette: np.ndarray,
                 brick_skip: bool = True):
        if palette is None:
            raise InputError("palette: expected a (256, 4) uint8 array, got None")
        self.ctx = ctx
        self.brick_skip = bool(brick_skip)
        self.cache = GpuCache(ctx)
        self._programs: dict[bool, tuple[moderngl.Program, moderngl.VertexArray]] = {}
        self.maps: SelectionMaps | None = None
        try:
            self.prog = self._program(count=False)[0]
            self.upload(maps, palette)
        except BaseException:
            self.release()
            raise

    # ------------------------------------------------------------------------------------------
    def _program(self, count: bool) -> tuple[moderngl.Program, moderngl.VertexArray]:
        """The program (and its buffer-less VAO) with or without the seen-voxel counter."""
        if count not in self._programs:
            defs = layout.voxel_defines()
            defines = {k: defs[k] for k in _LAYOUT_DEFINES}
            defines.update(COUNT_SEEN=int(count), COUNT_BINDING=layout.SSBO_COUNT)
            prog = load_program(self.ctx, PKG, {"vert": "raycast.vert", "frag": "raycast.frag"},
                                defines)
            self._programs[count] = (prog, self.ctx.vertex_array(prog, []))
        return self._programs[count]

    def upload(self, maps: SelectionMaps, palette: np.ndarray | None = None) -> None:
        """(Re)upload a new selection (new range or box); the programs are kept.

        Parameters
        ----------
        maps : SelectionMaps
            The new selection.
        palette : (256, 4) uint8, optional
            A new palette (None: keep the current one).
        """
        nx, ny, nz = (int(n) for n in maps.shape_xyz)
        want = {"bits": (nz, ny, words_per_row(nx)), "color": (nz, ny, nx)}
        for name, shape in want.items():
            got = np.shape(getattr(maps, name))
            if tuple(got) != shape:
                raise InputError(f"maps.{name}: expected shape {shape} for a {nx}×{ny}×{nz} box, "
                                 f"got {got}")
        c = self.cache
        if palette is not None:
            pal = np.asarray(palette, np.uint8)
            if pal.size != 256 * 4:
                raise InputError(f"palette: expected (256, 4) uint8, got shape {pal.shape}")
            c.texture2d("palette", pal.reshape(1, 256, 4))
        c.texture3d("voxel_bits", np.asarray(maps.bits, np.uint32), dtype="u4")
        c.texture3d("color_index", np.asarray(maps.color, np.uint8), dtype="u1")
        skip = skip_map(maps.bits, nx)
        c.texture3d("bricks", skip, components=skip.shape[-1], dtype="u4")
        self.maps = maps

    @property
    def gpu_bytes(self) -> int:
        """Exact bytes of the textures (and buffers) this visual holds on the GPU."""
        return self.cache.nbytes

    # ------------------------------------------------------------------------------------------
    def _set_uniforms(self, prog: moderngl.Program, camera: Camera, model: np.ndarray,
                      shading: dict, brick_offset=(0, 0, 0)) -> np.ndarray:
        model = np.asarray(model, float)
        mv = camera.view_matrix() @ model
        inv_mv = np.linalg.inv(mv)
        prog["inv_pmv"].write(_mat_bytes(np.linalg.inv(camera.projection_matrix() @ mv)))
        prog["viewport"].value = tuple(float(v) for v in self.ctx.viewport)
        prog["brick_offset"].value = tuple(int(v) for v in brick_offset)
        prog["mv"].write(_mat_bytes(mv))
        prog["proj"].write(_mat_bytes(camera.projection_matrix()))
        prog["normal_matrix"].write(_mat_bytes(np.linalg.inv(mv[:3, :3]).T))
        prog["box_size"].value = tuple(int(n) for n in self.maps.shape_xyz)
        prog["eye_ocs"].value = tuple(float(v) for v in inv_mv[:3, 3])
        prog["view_dir_ocs"].value = tuple(float(v) for v in -inv_mv[:3, 2])
        prog["ortho"].value = bool(camera.ortho)
        prog["near_far"].value = tuple(float(v) for v in camera.near_far())
        prog["brick_skip"].value = self.brick_skip
        for name, value in shading.items():
            prog[name].value = value
        return mv

    def _bind(self) -> None:
        c = self.cache
        c.get("voxel_bits").use(layout.UNIT_BITS)
        c.get("color_index").use(layout.UNIT_COLOR)
        c.get("palette").use(layout.UNIT_PALETTE)
        c.get("bricks").use(layout.UNIT_BRICKS)

    def draw(self, camera: Camera, model: np.ndarray, shading: dict, count: bool = False,
             brick_offset=(0, 0, 0)) -> dict:
        """Draw into the bound framebuffer (depth test on, writes depth).

        Parameters
        ----------
        camera : Camera
            View and projection.
        model : (4, 4) array
            Maps voxel index space (voxel ``(x, y, z)`` spans ``[x, x+1]×[y, y+1]×[z, z+1]``) to
            world space.
        shading : dict
            Uniform name -> value (``light_dir``, ``material``).
        brick_offset : 3 ints
            For a brick of a bricked box: where this visual's maps start in the index space of
            ``model`` (then the whole box's matrix). The ray is built from the pixel in that
            space, so the bricks walk exactly the voxels the whole box would.
        count : bool
            Count on the GPU the distinct voxels hit by at least one pixel's ray (before the depth
            test against other geometry). A bit set of one bit per box voxel is allocated for this
            call only.

        Returns
        -------
        dict
            ``{}``, or with ``count`` ``{"voxels_drawn": N, "triangles": 0}``.
        """
        ctx = self.ctx
        prog, vao = self._program(bool(count))
        mv = self._set_uniforms(prog, camera, model, shading, brick_offset)
        self._bind()
        ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.disable(moderngl.BLEND)
        # back faces only; a mirroring model turns the winding over
        ctx.front_face = "ccw" if np.linalg.det(mv[:3, :3]) > 0 else "cw"
        ctx.cull_face = "front"
        seen = None
        if count:
            nx, ny, nz = (int(n) for n in self.maps.shape_xyz)
            nbytes = 4 + 4 * words_per_row(nx) * ny * nz
            limit = ctx.info.get("GL_MAX_SHADER_STORAGE_BLOCK_SIZE") or nbytes
            if nbytes > limit:
                ctx.cull_face, ctx.front_face = "back", "ccw"
                ctx.disable(moderngl.CULL_FACE)
                raise GPUMemoryError(f"count: the seen-voxel bit set of {nbytes / 2**20:.1f} MiB "
                                     f"exceeds this GPU's SSBO limit of {limit / 2**20:.1f} MiB; "
                                     "count on a smaller box")
            seen = self.cache.buffer("seen_voxels", reserve=nbytes)
            seen.clear()
            seen.bind_to_storage_buffer(layout.SSBO_COUNT)
        try:
            with unclipped(ctx):  # every pixel of the box gets its ray (far corners included)
                vao.render(moderngl.TRIANGLES, vertices=_PROXY_VERTICES)
        finally:
            ctx.cull_face, ctx.front_face = "back", "ccw"
            ctx.disable(moderngl.CULL_FACE)
        if seen is None:
            return {}
        try:
            ctx.memory_barrier()
            n = int(np.frombuffer(seen.read(size=4), np.uint32)[0])
        finally:
            self.cache.drop("seen_voxels")
        return {"voxels_drawn": n, "triangles": 0}

    def release(self) -> None:
        """Release the programs, vertex arrays and every GPU object of the cache."""
        for prog, vao in self._programs.values():
            vao.release()
            prog.release()
        self._programs.clear()
        self.cache.release()
