"""Tessellation-based marching cubes (the iso paper, Sections 2–3), built on the GPU.

A 3D array of patch-quads (``n_p × m_p × q_p``, each covering ``D × D`` cells of one slice of
cells, ``D = L + 1``) is drawn with no vertex data (every frame in the paper; here once per step,
level and colouring with the mesh cache, see below). The tessellation control shader
(``iso.tesc``) computes the levels ``l_w, l_h`` and the patch indices, the evaluation shader
(``iso.tese``) turns each generated vertex into the indices of one cell, and the geometry shader
(``iso.geom``) classifies the cell (``K``), looks its triangles up in the case table ``T`` (an
integer 2D texture holding :func:`geoshade.compute.mesh.marching_cubes.case_table`, the same array
the
CPU reference uses), places their vertices by Eq. (1) and emits them with gradient normals. The
fragment shader (``iso.frag``) does two-sided Phong.

Beyond the paper:

- outside nodes (inactive, NaN, inf): a cell with one makes no triangles, so the surface stays
  open there as at the grid's boundary (``caps=False``, the default); ``caps=True`` closes it
  (outside nodes below every level, vertices at the edges' midpoints);
- per-patch min/max (``patch_ranges``, RG32F): a patch whose nodes cannot hold the level is
  discarded in the control shader (``skip_patches``, on by default);
- the llvmpipe batching workaround (PLATFORM.md): at most ``patches_per_instance`` patches per
  instance, patch index from ``gl_InstanceID`` and ``gl_VertexID``;
- two field slots (double buffering): the next time step is uploaded into the back slot while the
  front one is drawn; switching steps then only swaps;
- vertices through a positions texture (corner-point grids: the cell centres);
- colour by a property texture (interpolated like the positions);
- transform-feedback capture of the emitted triangles (mesh export, tests);
- the mesh cache (``mesh_cache``, on by default): a frame that generates the surface also
  captures it (transform feedback while rasterising), and later frames of the same step, level
  and colouring draw the captured triangles with ``mesh.vert`` + ``iso.frag`` instead of
  marching again. A new step, level or colouring marches once more. Off, every frame marches
  (the paper). Same picture (tested); costs 84 bytes per triangle on the GPU. Each field slot
  has its own captured mesh (``mesh0``, ``mesh1``): :meth:`IsosurfaceVisual.premarch` marches
  the back slot (the step prepared ahead) without drawing, so a step switch swaps slots *and*
  meshes and its frame draws captured triangles (no march).

GPU memory (exact, from :class:`~geoshade.render.resources.GpuCache`), per slot: the field R32F
``4·nx·ny·nz`` bytes, the patch ranges RG32F ``8·n_p·m_p·q_p``, a property R32F ``4·nx·ny·nz`` if
colouring; once: the table R8I 4096 bytes, the palette 1024 bytes, the positions RGB32F
``12·nx·ny·nz`` (corner-point only), 4-byte placeholders for unused samplers, and with the mesh
cache the captured triangles of each slot (84 bytes each; a slot's buffer is made for the
largest surface it held + 5 %, when a surface does not fit: that march is done again).
With ``refill`` (what :class:`~geoshade.iso.view.IsoView` gives) and the mesh cache, the field
is marched in slabs of slices instead (``slabbed``): one field (and property) texture of at most
:data:`FIELD_SLAB_BYTES` replaces the slots' whole fields; each march writes into it, one slab
at a time, the nodes of the slices that hold a patch able to hold the level (``refill(slot)``
gives the step's arrays), and draws those slices' patches; the slots are drawn from their
captured meshes. Same triangles in the same order as one draw of every patch.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

import moderngl
import numpy as np

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.render import layout
from geoshade.render.camera import Camera
from geoshade.render.context import is_software
from geoshade.render.resources import GpuCache
from geoshade.render.shaders import ProgramSpec, load_program
from geoshade.render.target import neutral_framebuffer

PKG = __package__
#: texture units of the program's samplers
UNIT_FIELD, UNIT_TABLE, UNIT_RANGES, UNIT_POSITIONS, UNIT_PROPERTY, UNIT_PALETTE = range(6)
#: what the transform-feedback capture writes per vertex, interleaved (36 bytes)
CAPTURE_VARYINGS = ("m_pos", "m_normal", "m_value", "m_id")
#: what the mesh cache keeps per vertex (28 bytes): what its re-draw reads, no ids
MESH_VARYINGS = CAPTURE_VARYINGS[:3]
CAPTURE_DTYPE = np.dtype([("pos", "<f4", (3,)), ("normal", "<f4", (3,)), ("value", "<f4"),
                          ("id", "<i4", (2,))])
MESH_DTYPE = np.dtype([("pos", "<f4", (3,)), ("normal", "<f4", (3,)), ("value", "<f4")])
#: default colour of the surface (a water blue), RGBA 0..1
BASE_COLOR = (0.16, 0.45, 0.80, 1.0)
#: bytes of the field texture (and of the property's) when a march goes in slabs of slices
FIELD_SLAB_BYTES = 16 << 20
#: bytes of the staging array a slab across x or y is written through
STAGE_BYTES = 1 << 20


def _glsl_array(kind: str, values) -> str:
    v = [str(int(a)) for a in np.asarray(values).ravel()]
    return f"{kind}[{len(v)}](" + ",".join(v) + ")"


def iso_defines() -> dict:
    """GLSL defines of the iso shaders, emitted from :mod:`geoshade.compute.mesh.marching_cubes`.

    >>> d = iso_defines()
    >>> d["EDGE_A"][:15], d["MAX_VERTICES"]
    ('int[12](0,2,4,6', 15)
    """
    corners = ",".join(f"ivec3({x},{y},{z})" for x, y, z in mc.CORNERS)
    return {
        "UNIT_FIELD": UNIT_FIELD,
        "UNIT_TABLE": UNIT_TABLE,
        "UNIT_RANGES": UNIT_RANGES,
        "UNIT_POSITIONS": UNIT_POSITIONS,
        "UNIT_PROPERTY": UNIT_PROPERTY,
        "UNIT_PALETTE": UNIT_PALETTE,
        "CORNER_OFFSETS": f"ivec3[8]({corners})",
        "EDGE_A": _glsl_array("int", mc.EDGES[:, 0]),
        "EDGE_B": _glsl_array("int", mc.EDGES[:, 1]),
        "OUTSIDE_BELOW": f"{float(mc.OUTSIDE_BELOW):.1e}",
        "MAX_VERTICES": 3 * mc.MAX_TRIANGLES,
    }


#: every program this visual builds: the tessellation marching cubes (drawing and capturing the
#: mesh cache) and the re-draw of a captured mesh
PROGRAMS = [
    ProgramSpec("march", {"vert": "iso.vert", "tesc": "iso.tesc", "tese": "iso.tese",
                          "geom": "iso.geom", "frag": "iso.frag"}, (iso_defines(),),
                MESH_VARYINGS),
    ProgramSpec("capture", {"vert": "iso.vert", "tesc": "iso.tesc", "tese": "iso.tese",
                            "geom": "iso.geom", "frag": "iso.frag"}, (iso_defines(),),
                CAPTURE_VARYINGS),
    ProgramSpec("mesh", {"vert": "mesh.vert", "frag": "iso.frag"},
                ({"UNIT_PALETTE": UNIT_PALETTE},)),
]


def _mat(m) -> bytes:
    return np.asarray(m, "f4").T.tobytes()


_GL_PATCHES, _GL_TRIANGLES, _GL_TRANSFORM_FEEDBACK_BUFFER = 0x000E, 0x0004, 0x8C8E


@functools.lru_cache(maxsize=1)
def _gl() -> dict:
    """The few GL entry points moderngl cannot call for tessellation + transform feedback.

    moderngl's ``VertexArray.transform`` refuses ``PATCHES`` when a geometry shader reads points
    (it does not look at the tessellation stages), so the capture issues the same draw call as
    :meth:`IsoSurfaceVisual.draw` through these.
    """
    u, i = ctypes.c_uint, ctypes.c_int
    protos = {
        "glUseProgram": (u,),
        "glBindVertexArray": (u,),
        "glBindBufferBase": (u, u, u),
        "glBeginTransformFeedback": (u,),
        "glEndTransformFeedback": (),
        "glPauseTransformFeedback": (),
        "glResumeTransformFeedback": (),
        "glDrawArraysInstanced": (u, i, i, i),
    }
    for lib, getter in (("EGL", "eglGetProcAddress"), ("GL", "glXGetProcAddress")):
        path = ctypes.util.find_library(lib)
        if not path:
            continue
        try:
            fn = getattr(ctypes.CDLL(path), getter)
        except (OSError, AttributeError):
            continue
        fn.restype, fn.argtypes = ctypes.c_void_p, [ctypes.c_char_p]
        out = {}
        for name, args in protos.items():
            ptr = fn(name.encode())
            if not ptr:
                break
            out[name] = ctypes.CFUNCTYPE(None, *args)(ptr)
        else:
            return out
    raise RuntimeError("transform feedback: could not resolve the OpenGL entry points")


class IsoSurfaceVisual:
    """GPU state and drawing of the isosurface of a node field ``(nz, ny, nx)``.

    Parameters
    ----------
    ctx : moderngl.Context
    shape_zyx : (nz, ny, nx)
        Nodes of the field (>= 2 per axis).
    patch_level : int
        ``L_max`` of the patches (1..64; the paper's 64); each patch covers ``(L+1)²`` cells.
    skip_patches : bool
        Discard patches whose min/max cannot hold the level (beyond the paper).
    positions : (nz, ny, nx, 3) float, optional
        Model-space positions of the nodes (corner-point grids); default: index space.
    palette : (256, 4) uint8, optional
        Colours for :meth:`draw` ``color_range`` (colour by a property).
    slice_axis : {"z", "y", "x"}
        Axis the slices of patches are stacked along (the paper: z). The ranges given to
        :meth:`upload` must be computed for the same axis.
    mesh_cache : bool
        Keep the triangles of the last generated surface on the GPU and re-draw them while the
        step, level and colouring stay (beyond the paper; off: march every frame).
    caps : bool
        Close the surface along outside nodes (inactive, NaN, inf); default open: a cell with
        an outside corner makes no triangles. The ranges given to :meth:`upload` must be
        computed with the same ``caps``.
    refill : callable, optional
        ``refill(slot) -> (values, prop)``: the arrays of the step in ``slot`` again (as given
        to :meth:`upload`). With it and the mesh cache, one field (and property) texture serves
        both slots: an upload writes it in place (the other slot is drawn from its captured
        mesh), and a march of the other slot (a new level or colouring on it, :meth:`count`,
        :meth:`capture`) asks ``refill`` for its arrays and writes them in.
    """

    def __init__(self, ctx: moderngl.Context, shape_zyx, patch_level: int = 64,
                 skip_patches: bool = True, positions=None, palette=None,
                 slice_axis: str = "z", mesh_cache: bool = True, caps: bool = False,
                 refill=None):
        self.ctx = ctx
        #: ``refill(slot) -> (values, prop)``: the arrays of the step ``slot`` holds, asked
        #: for when a march needs a field that was released; with the mesh cache it also
        #: keeps one field texture on the GPU for both slots
        self.refill = refill
        #: marched in slabs of slices (with ``refill`` and the mesh cache): one field texture
        #: of at most :data:`FIELD_SLAB_BYTES`, written by each march, not two whole fields
        self.slabbed = refill is not None and bool(mesh_cache)
        self._held: tuple | None = None   # (slot, first node, end node, coloured) of the slab
        self._ranges: list = [None, None]   # each slot's patch ranges (what a march skips)
        self._level = 0.0
        self._bound = 0   # the slot the last _bind bound (what _calls marches)
        self._stage = None   # staging array of _write_block
        self.shape = tuple(int(n) for n in shape_zyx)
        if len(self.shape) != 3 or min(self.shape) < 2:
            raise InputError(f"field: expected at least 2 nodes per axis, got {self.shape}")
        max_level = int(ctx.info.get("GL_MAX_TESS_GEN_LEVEL", 64) or 64)
        if not 1 <= int(patch_level) <= max_level:
            raise InputError(f"patch level: expected 1..{max_level}, got {patch_level}")
        self.patch_level = int(patch_level)
        self.skip_patches = bool(skip_patches)
        self.caps = bool(caps)
        nz, ny, nx = self.shape
        self.cells = (nx - 1, ny - 1, nz - 1)
        self.set_slice_axis(slice_axis)
        self.ppi = layout.patches_per_instance(self.patch_level, software=is_software(ctx))
        self.prog = load_program(
            ctx, PKG, {"vert": "iso.vert", "tesc": "iso.tesc", "tese": "iso.tese",
                       "geom": "iso.geom", "frag": "iso.frag"},
            iso_defines(), varyings=MESH_VARYINGS)
        self.vao = ctx.vertex_array(self.prog, [])
        self._capture_prog = None   # (program, vertex array) capturing ids too: capture()
        self.cache = GpuCache(ctx)
        c = self.cache
        c.texture2d("case_table", mc.case_table(), components=1, dtype="i1")
        self.has_positions = positions is not None
        if self.has_positions:
            pos = np.ascontiguousarray(positions, dtype=np.float32)
            if pos.shape != (*self.shape, 3):
                raise InputError(f"positions: expected shape {(*self.shape, 3)}, got "
                                 f"{pos.shape}")
            c.texture3d("positions", pos, components=3, dtype="f4")
        else:
            c.texture3d("positions_unused", np.zeros((1, 1, 1), np.float32), 1, "f4")
        c.texture3d("property_unused", np.zeros((1, 1, 1), np.float32), 1, "f4")
        pal = np.zeros((256, 4), np.uint8) if palette is None else np.asarray(palette, np.uint8)
        if pal.shape != (256, 4):
            raise InputError(f"palette: expected (256, 4) uint8 RGBA, got {pal.shape}")
        c.texture2d("palette", pal.reshape(1, 256, 4))
        self.front = 0
        self.slot_has_property = [False, False]
        self.mesh_cache = bool(mesh_cache)
        #: the property is categories: each triangle takes one real code (color_mode 2)
        self.categorical = False
        #: per slot: (slot, level, coloured, categorical) its "mesh<slot>" buffer holds, and
        #: the triangles in it
        self._mesh_keys: list = [None, None]
        self._mesh_counts = [0, 0]
        self._mesh_guess = 0       # triangles of the last surface generated (sizes the capture)
        self._mesh_draws: dict = {}  # slot -> (program, vertex array) of the cached re-render
        self._mesh_prog = None     # the program of the cached re-render (both slots)

    # --- data ----------------------------------------------------------------------------------
    def set_slice_axis(self, axis: str) -> None:
        """Stack the patch slices along ``axis``; re-upload the ranges of every slot after."""
        if axis not in mc.SLICE_AXES:
            raise InputError(f"slice axis: expected one of x, y, z, got {axis!r}")
        s, r, c = mc.SLICE_AXES[axis]
        self.slice_axis = axis
        self.patch_axes = mc.PATCH_AXES[axis]
        self.patch_cells = (self.shape[c] - 1, self.shape[r] - 1, self.shape[s] - 1)
        self.patch_grid = mc.patch_grid(self.shape, self.patch_level, axis)
        self.n_patches = int(np.prod(self.patch_grid))
        self._mesh_keys = [None, None]
        self._held = None   # slabs along another axis

    def _put3d(self, name: str, data: np.ndarray, components: int) -> None:
        tex = self.cache.get(name)
        arr = np.ascontiguousarray(data, dtype=np.float32)
        d, h, w = arr.shape[:3]
        if tex is not None and tex.size == (w, h, d) and tex.components == components:
            tex.write(arr)  # the array's own buffer: no bytes copy
        else:
            self.cache.texture3d(name, arr, components=components, dtype="f4")

    def upload(self, values: np.ndarray, ranges: np.ndarray, prop=None, slot: int = 0) -> None:
        """Write one time step into ``slot`` (0 or 1); only the textures of that slot change.

        values: (nz, ny, nx) float32 with outside nodes at ``OUTSIDE`` (see ``prepare_values``);
        ranges: ``patch_ranges(values, patch_level, slice_axis, caps)`` (the visual's ``caps``:
        open ranges leave outside nodes out, so with caps on they would skip capped patches);
        prop: (nz, ny, nx) float32 or None. Marched in slabs (``refill``), only the ranges are
        written now: each march writes the slabs of the field it needs.
        """
        if tuple(values.shape) != self.shape:
            raise InputError(f"field step: expected shape {self.shape}, got {values.shape}")
        want = (*self.patch_grid[::-1], 2)
        if tuple(ranges.shape) != want:
            raise InputError(f"patch ranges: expected shape {want} (slice axis "
                             f"{self.slice_axis}), got {ranges.shape}")
        if not self.slabbed:
            self._put3d(f"field{slot}", values, 1)
        self._put3d(f"ranges{slot}", ranges, 2)
        self._ranges[int(slot)] = np.asarray(ranges)   # the caller's (no copy): what to march
        self.set_property(prop, slot)
        self._mesh_keys[slot] = None

    def set_property(self, prop, slot: int) -> None:
        """Replace the colour property of ``slot`` (None: no colouring)."""
        if prop is not None and tuple(prop.shape) != self.shape:
            raise InputError(f"property: expected shape {self.shape}, got {prop.shape}")
        if not self.slabbed:
            if prop is not None:
                self._put3d(f"property{slot}", prop, 1)
            else:
                self.cache.drop(f"property{slot}")
        if self._held is not None and self._held[0] == int(slot):
            self._held = None   # the slab on the GPU is no longer this slot's
        self.slot_has_property[slot] = prop is not None
        self._mesh_keys[slot] = None

    def use_slot(self, slot: int) -> None:
        """Draw from ``slot`` from now on (swap of the double buffer)."""
        if self.cache.get(f"ranges{slot}") is None:
            raise RuntimeError(f"slot {slot} holds no field")
        self.front = int(slot)   # each slot keeps its own captured mesh

    # --- marching in slabs ---------------------------------------------------------------------
    def _slab_cells(self) -> int:
        """Cell slices per slab: the field's slab texture (nodes ``slab + 3``: the cells' and
        the gradients' neighbours) within :data:`FIELD_SLAB_BYTES`."""
        s = mc.SLICE_AXES[self.slice_axis][0]
        plane = 4 * int(np.prod(self.shape)) // self.shape[s]
        return max(1, FIELD_SLAB_BYTES // plane - 3)

    def _runs(self, slot: int) -> list[tuple[int, int]]:
        """Cell-slice ranges ``[c0, c1)`` to march: every slice in one draw with whole field
        textures; marched in slabs, the slices holding a patch that can hold the level (all
        without skipping), in runs of at most :meth:`_slab_cells` slices."""
        q = self.patch_grid[2]
        if not self.slabbed:
            return [(0, q)]
        if self.skip_patches:
            r, s = self._ranges[slot], np.float32(self._level)
            live = ((r[..., 0] < s) & (s <= r[..., 1])).any(axis=(1, 2))
        else:
            live = np.ones(q, bool)
        step, runs = self._slab_cells(), []
        edges = np.flatnonzero(np.diff(np.concatenate([[0], live.astype(np.int8), [0]])))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            runs += [(c, min(int(b), c + step)) for c in range(int(a), int(b), step)]
        return runs

    def _slab_textures(self, slot: int) -> None:
        """The slab field (and property) textures, allocated once (their pages are touched only
        where written)."""
        s = mc.SLICE_AXES[self.slice_axis][0]
        shape = list(self.shape)
        shape[s] = min(shape[s], self._slab_cells() + 3)
        names = ["field", *(["property"] if self.slot_has_property[slot] else [])]
        for name in names:
            tex = self.cache.get(name)
            if tex is None or tex.size != tuple(shape[::-1]):
                self.cache.texture3d(name, np.empty(shape, np.float32), 1, "f4")
                self._held = None

    def _load(self, slot: int, c0: int, c1: int, arrays: list) -> None:
        """Write the nodes of cell slices ``[c0, c1)`` (and their gradients' neighbours) into
        the slab textures, unless they hold them already; the shader's ``field_origin``."""
        s = mc.SLICE_AXES[self.slice_axis][0]
        n0, n1 = max(0, c0 - 1), min(self.shape[s], c1 + 2)
        origin = [0, 0, 0]
        origin[2 - s] = n0   # numpy axis s (z y x) -> texture axis (x y z)
        self._set("field_origin", tuple(origin))
        held = (int(slot), n0, n1, self.slot_has_property[slot])
        if self._held == held:
            return
        if not arrays:
            values, prop = self.refill(int(slot))
            if tuple(values.shape) != self.shape:
                raise InputError(f"field step: expected shape {self.shape}, got "
                                 f"{values.shape}")
            arrays += [values, prop]
        index = [slice(None)] * 3
        index[s] = slice(n0, n1)
        for name, arr in (("field", arrays[0]), ("property", arrays[1])):
            if arr is None or (name == "property" and not self.slot_has_property[slot]):
                continue
            self._write_block(self.cache.get(name), np.asarray(arr)[tuple(index)])
        self._held = held

    def _write_block(self, tex, block: np.ndarray) -> None:
        """``block`` (d, h, w) into ``tex`` from texel 0: as it is when contiguous float32
        (slabs across z), else through a small reused staging array, a few z planes at a time
        (no slab-sized temporary)."""
        d, h, w = block.shape
        if block.dtype == np.float32 and block.flags.c_contiguous:
            tex.write(block, viewport=(0, 0, 0, w, h, d))
            return
        if self._stage is None or self._stage.size < h * w:
            self._stage = np.empty(max(h * w, STAGE_BYTES // 4), np.float32)
        planes = self._stage.size // (h * w)
        for z0 in range(0, d, planes):
            part = block[z0:z0 + planes]
            buf = self._stage[:part.size].reshape(part.shape)
            np.copyto(buf, part, casting="unsafe")
            tex.write(buf, viewport=(0, 0, z0, w, h, part.shape[0]))

    def set_palette(self, palette) -> None:
        self.cache.get("palette").write(np.ascontiguousarray(palette, np.uint8).tobytes())

    @property
    def gpu_bytes(self) -> int:
        return self.cache.nbytes

    # --- drawing -------------------------------------------------------------------------------
    def _set(self, name: str, value, prog=None) -> None:
        p = self.prog if prog is None else prog
        if name in p:
            p[name].value = value

    def _frag_uniforms(self, prog, mvp, mv, normal_matrix, color_range, ortho: bool,
                       shading: dict, base_color) -> None:
        """The uniforms of iso.frag (and mvp) on ``prog``: the live program or the mesh's."""
        for name, m in (("mvp", mvp), ("mv", mv), ("normal_matrix", normal_matrix)):
            if name in prog:
                prog[name].write(_mat(m))
        coloured = color_range is not None and self.slot_has_property[self.front]
        self._set("color_mode", (2 if self.categorical else 1) if coloured else 0, prog)
        self._set("color_range", tuple(float(v) for v in (color_range or (0.0, 1.0))), prog)
        self._set("ortho", int(ortho), prog)
        self._set("base_color", tuple(float(v) for v in base_color), prog)
        for name, value in shading.items():
            self._set(name, value, prog)

    def _uniforms(self, mvp, mv, normal_matrix, level: float, color_range, ortho: bool,
                  shading: dict, base_color) -> None:
        self._frag_uniforms(self.prog, mvp, mv, normal_matrix, color_range, ortho, shading,
                            base_color)
        self._set("cells", self.cells)
        self._set("patch_cells", self.patch_cells)
        self._set("patch_axes", self.patch_axes)
        self._set("patch_grid", self.patch_grid)
        self._set("patch_level", self.patch_level)
        self._set("patches_per_instance", self.ppi)
        self._level = float(np.float32(level))
        self._set("level", self._level)
        self._set("skip_patches", int(self.skip_patches))
        self._set("caps", int(self.caps))
        self._set("geometry_mode", int(self.has_positions))

    def _bind(self, slot: int | None = None) -> None:
        c, s = self.cache, self.front if slot is None else slot
        self._bound = s
        if self.slabbed:
            self._slab_textures(s)
        field, prop = ("field", "property") if self.slabbed else (f"field{s}", f"property{s}")
        c.get(field).use(UNIT_FIELD)
        c.get(f"ranges{s}").use(UNIT_RANGES)
        c.get("case_table").use(UNIT_TABLE)
        (c.get("positions") or c.get("positions_unused")).use(UNIT_POSITIONS)
        prop_tex = c.get(prop) if self.slot_has_property[s] else None
        (prop_tex or c.get("property_unused")).use(UNIT_PROPERTY)
        c.get("palette").use(UNIT_PALETTE)

    def _calls(self, transform_into=None, rasterize: bool = False) -> None:
        """March the bound slot: one draw of every patch, or (in slabs) one draw per run of
        slices whose nodes were just written (:meth:`_runs`, :meth:`_load`), in patch order,
        so the triangles come out in the same order. With ``transform_into``: captured (and
        rasterised only if ``rasterize``), the slabs' triangles one after another."""
        self.ctx.patch_vertices = 1
        per_slice = self.patch_grid[0] * self.patch_grid[1]
        runs, arrays = self._runs(self._bound), []
        gl = None if transform_into is None else _gl()
        if gl is not None and not rasterize:
            self.ctx.enable(moderngl.RASTERIZER_DISCARD)
        active = False
        try:
            for c0, c1 in runs:
                if active:
                    gl["glPauseTransformFeedback"]()
                if self.slabbed:
                    self._load(self._bound, c0, c1, arrays)
                p0, p1 = per_slice * c0, per_slice * c1
                self._set("patch_first", p0)
                self._set("patch_end", p1)
                instances = -(-(p1 - p0) // self.ppi)
                if gl is None:
                    self.vao.render(moderngl.PATCHES, vertices=self.ppi, instances=instances)
                    continue
                # the same draw with transform feedback on (moderngl's transform refuses
                # PATCHES with a geometry shader)
                if active:
                    gl["glResumeTransformFeedback"]()
                else:
                    gl["glUseProgram"](self.prog.glo)
                    gl["glBindVertexArray"](self.vao.glo)
                    gl["glBindBufferBase"](_GL_TRANSFORM_FEEDBACK_BUFFER, 0, transform_into.glo)
                    gl["glBeginTransformFeedback"](_GL_TRIANGLES)
                    active = True
                gl["glDrawArraysInstanced"](_GL_PATCHES, 0, self.ppi, instances)
        finally:
            if active:
                gl["glEndTransformFeedback"]()
                gl["glBindBufferBase"](_GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0)
            if gl is not None and not rasterize:
                self.ctx.disable(moderngl.RASTERIZER_DISCARD)

    def _mesh_program(self, slot: int):
        """(program, vertex array, buffer) of ``slot``'s cached re-draw: one program for both
        slots (linked once), a vertex array per slot's buffer."""
        if self._mesh_prog is None:
            self._mesh_prog = load_program(self.ctx, PKG, {"vert": "mesh.vert",
                                                           "frag": "iso.frag"},
                                           {"UNIT_PALETTE": UNIT_PALETTE})
        if slot not in self._mesh_draws:
            prog = self._mesh_prog
            buf = self.cache.get(f"mesh{slot}")
            vao = self.ctx.vertex_array(prog, [(buf, "3f 3f 1f", "in_pos", "in_normal",
                                                "in_value")])
            self._mesh_draws[slot] = (prog, vao, buf)
        return self._mesh_draws[slot]

    def _drop_mesh_vao(self, slot: int | None = None) -> None:
        for s in (0, 1) if slot is None else (slot,):
            if s in self._mesh_draws:
                _, vao, _ = self._mesh_draws.pop(s)
                vao.release()
        if slot is None and self._mesh_prog is not None:
            self._mesh_prog.release()
            self._mesh_prog = None

    def _mesh_buffer(self, slot: int, triangles: int | None = None):
        """The capture buffer of ``slot``: the one it has (whatever surface it was made for),
        or a first one for the last surface's size; with ``triangles`` (a surface that did
        not fit), one made for that many + 5 %. None while no surface size is known yet.
        Sized by the slot's own surfaces: the driver fills a new buffer at once, so slack
        is memory."""
        name = f"mesh{slot}"
        buf = self.cache.get(name)
        if triangles is None:
            if buf is not None or self._mesh_guess == 0:
                return buf
            triangles = self._mesh_guess
        need = (int(triangles * 1.05) + 64) * 3 * MESH_DTYPE.itemsize
        if buf is None or buf.size < need:
            self._drop_mesh_vao(slot)
            self.cache.drop(name)  # release the old buffer first: never both at once
            if buf is not None:
                self._forget_capture()
            buf = self.cache.buffer(name, reserve=need)
        return buf

    def _forget_capture(self) -> None:
        """An empty transform feedback into a 64-byte buffer: the driver keeps a reference to
        the buffer last captured into (Mesa: for glDrawTransformFeedback) until the next
        capture ends, so a dropped mesh buffer would stay allocated while the new one fills."""
        gl, tiny = _gl(), self.ctx.buffer(reserve=64)
        self.ctx.enable(moderngl.RASTERIZER_DISCARD)
        try:
            gl["glUseProgram"](self.prog.glo)
            gl["glBindVertexArray"](self.vao.glo)
            gl["glBindBufferBase"](_GL_TRANSFORM_FEEDBACK_BUFFER, 0, tiny.glo)
            gl["glBeginTransformFeedback"](_GL_TRIANGLES)
            gl["glEndTransformFeedback"]()
            gl["glBindBufferBase"](_GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0)
        finally:
            self.ctx.disable(moderngl.RASTERIZER_DISCARD)
            tiny.release()

    def _captured(self, slot: int, key, buf, rasterize: bool) -> int:
        """March the bound slot once with transform feedback into ``buf``; keep the mesh
        under ``key`` if it fit. Returns the triangles generated."""
        query = self.ctx.query(primitives=True)
        with query:
            self._calls(transform_into=buf, rasterize=rasterize)
        n = int(query.primitives)
        self._mesh_guess = max(n, 1)
        fits = n * 3 * MESH_DTYPE.itemsize <= buf.size
        self._mesh_keys[slot], self._mesh_counts[slot] = (key, n) if fits else (None, 0)
        if not fits:   # made for this surface now: the next march of the slot captures it
            self._mesh_buffer(slot, n)
        return n

    def _generate(self, key) -> int:
        """March (drawing into the bound framebuffer) and capture the triangles if they fit;
        returns the number of triangles generated."""
        buf = self._mesh_buffer(self.front)
        if buf is None:  # nothing known yet: draw, count, capture next frame
            query = self.ctx.query(primitives=True)
            with query:
                self._calls()
            self._mesh_guess = int(query.primitives)
            return self._mesh_guess
        return self._captured(self.front, key, buf, rasterize=True)

    def _key(self, slot: int, level: float, color_range) -> tuple:
        coloured = color_range is not None and self.slot_has_property[slot]
        return (slot, float(np.float32(level)), coloured, self.categorical)

    def has_mesh(self, slot: int, level: float, color_range=None) -> bool:
        """Whether ``slot``'s captured triangles are those of ``level`` and this colouring."""
        return self.mesh_cache and self._mesh_keys[int(slot)] == self._key(int(slot), level,
                                                                           color_range)

    def premarch(self, slot: int, level: float, color_range=None) -> int | None:
        """March ``slot`` at ``level`` without drawing and keep its triangles, so that the
        first frame after :meth:`use_slot` draws the captured mesh (a step switch without a
        march). Nothing is done without the mesh cache, before any surface size is known, or
        when that slot's mesh is already captured. Returns the triangles captured (None: not
        marched)."""
        slot = int(slot)
        key = self._key(slot, level, color_range)
        if (not self.mesh_cache or self.cache.get(f"ranges{slot}") is None
                or self._mesh_keys[slot] == key):
            return None
        buf = self._mesh_buffer(slot)
        if buf is None:
            return None
        eye = np.eye(4)
        self._uniforms(eye, eye, np.eye(3), level, color_range, False, {}, BASE_COLOR)
        self._bind(slot)
        neutral_framebuffer(self.ctx).use()  # complete, though nothing is drawn
        n = self._captured(slot, key, buf, rasterize=False)
        if self._mesh_keys[slot] != key:  # a larger surface: sized by this march, once more
            n = self._captured(slot, key, self._mesh_buffer(slot), rasterize=False)
        return n if self._mesh_keys[slot] == key else None

    def draw(self, camera: Camera, model: np.ndarray, shading: dict, level: float,
             color_range=None, base_color=BASE_COLOR, count: bool = False) -> dict:
        """Draw into the bound framebuffer; with ``count``, return ``{"triangles": n}``: the
        triangles the geometry shader emitted (a primitives query), or those of the mesh cache
        when it draws the surface captured from an earlier frame."""
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        view = camera.view_matrix()
        mv = view @ model
        mvp = camera.projection_matrix() @ mv
        normal = np.linalg.inv(mv[:3, :3]).T
        key = self._key(self.front, level, color_range)
        if self.mesh_cache and key == self._mesh_keys[self.front]:
            prog, vao, _ = self._mesh_program(self.front)
            self._frag_uniforms(prog, mvp, mv, normal, color_range, camera.ortho, shading,
                                base_color)
            self.cache.get("palette").use(UNIT_PALETTE)
            n = self._mesh_counts[self.front]
            if n:
                vao.render(moderngl.TRIANGLES, vertices=3 * n)
            return {"triangles": n} if count else {}
        self._uniforms(mvp, mv, normal, level, color_range, camera.ortho, shading, base_color)
        self._bind()
        if self.mesh_cache:
            n = self._generate(key)
            return {"triangles": n} if count else {}
        if not count:
            self._calls()
            return {}
        query = ctx.query(primitives=True)
        with query:
            self._calls()
        return {"triangles": int(query.primitives)}

    def count(self, level: float) -> int:
        """Triangles the geometry shader emits at ``level`` (nothing is rasterised)."""
        ctx = self.ctx
        self._uniforms(np.eye(4), np.eye(4), np.eye(3), level, None, False, {}, BASE_COLOR)
        self._bind()
        neutral_framebuffer(ctx).use()  # a complete framebuffer, though nothing is drawn
        ctx.enable(moderngl.RASTERIZER_DISCARD)
        try:
            query = ctx.query(primitives=True)
            with query:
                self._calls()
        finally:
            ctx.disable(moderngl.RASTERIZER_DISCARD)
        return int(query.primitives)

    def capture(self, level: float, color_range=None) -> np.ndarray:
        """The emitted triangles, captured by transform feedback.

        Returns
        -------
        (3 n,) structured array of :data:`CAPTURE_DTYPE`
            ``pos`` (model space), ``normal`` (model space, towards lower values, not normalised),
            ``value`` (the colour property; 0 without one), ``id`` (linear cell index, triangle
            slot); three consecutive rows per triangle, in the GPU's emission order.
        """
        n = self.count(level)
        if n == 0:
            return np.zeros(0, CAPTURE_DTYPE)
        nbytes = n * 3 * CAPTURE_DTYPE.itemsize
        buf = self.cache.buffer("capture", reserve=nbytes)
        if self._capture_prog is None:   # the march program with the ids captured too
            prog = load_program(self.ctx, PKG, {"vert": "iso.vert", "tesc": "iso.tesc",
                                                "tese": "iso.tese", "geom": "iso.geom",
                                                "frag": "iso.frag"},
                                iso_defines(), varyings=CAPTURE_VARYINGS)
            self._capture_prog = (prog, self.ctx.vertex_array(prog, []))
        drawing = self.prog, self.vao
        self.prog, self.vao = self._capture_prog
        try:
            self._uniforms(np.eye(4), np.eye(4), np.eye(3), level, color_range, False, {},
                           BASE_COLOR)
            self._bind()
            self._calls(transform_into=buf)
            return np.frombuffer(buf.read(), CAPTURE_DTYPE).copy()
        finally:
            self.prog, self.vao = drawing
            self.cache.drop("capture")

    def release(self) -> None:
        self._drop_mesh_vao()
        self.vao.release()
        self.prog.release()
        if self._capture_prog is not None:
            self._capture_prog[1].release()
            self._capture_prog[0].release()
            self._capture_prog = None
        self.cache.release()
