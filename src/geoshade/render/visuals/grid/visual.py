"""Corner-point grid faces on the GPU: the paper's three approaches, one picture.

All approaches draw the visible faces given to :meth:`GridVisual.set_faces` (a ``FaceSet``),
each split along the same diagonal (corners A–C of :data:`layout.FACE_CORNERS`) and lit with
the triangle's own normal, coloured ``palette[colour index of its cell]``; they differ in what
lives on the GPU and who builds the triangles (bytes: :func:`layout.gpu_plan`):

- **1** (conforming grids): grid nodes, 6 bytes of uint16 x y z + 2 colour bytes each, six
  node indices per face; two passes with the provoking-vertex colour scheme.
- **2**: COORD and ZCORN (16 or 32 bits) in textures, one 8-byte record per cell with a visible
  face; the geometry shader builds the faces.
- **3** ``zcorn_store="grid"`` (the paper): COORD, ZCORN, one colour byte per cell, four ZCORN
  indices per face drawn as ``lines_adjacency``. ``zcorn_store="faces"``: COORD and, per
  visible face, its cell/face number and its four corner depths (12 bytes at 16 bits) plus a
  colour byte; no ZCORN on the GPU.

A new property or time step calls :meth:`set_colors`, which writes only colour data into
existing objects; a new filter/slice calls :meth:`set_faces`; COORD, ZCORN and the approach-1
node positions are never re-sent.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from geoshade.compute.grid.geometry import orientation_sign
from geoshade.errors import InputError
from geoshade.io.paths import give_back_freed
from geoshade.models.grid import CornerPointGrid
from geoshade.render.camera import Camera
from geoshade.render.resources import GpuCache
from geoshade.render.shaders import ProgramSpec, load_program
from geoshade.render.visuals.grid import layout, prepare

PKG = __package__
#: faces whose records are built at a time (approach 3 with faces)
FACE_BATCH = 1 << 20
#: faces whose corner depths a callable ``corners`` gives at a time (a grid out of core)
CORNER_BATCH = 1 << 24
#: up to this many runs of faces of one (2^29-cell bucket, highlight) are drawn as they come
#: (one draw call each, the drawing order kept); more are sorted into one range per key
MAX_DRAW_RUNS = 1024

#: the stage files of each program: approach 1 (without and with its geometry shader), 2, 3 and
#: 3 with faces
STAGES = {"a1": {"vert": "a1.vert", "frag": "grid.frag"},
          "a1gs": {"vert": "a1.vert", "geom": "a1.geom", "frag": "grid.frag"},
          "a2": {"vert": "a2.vert", "geom": "a2.geom", "frag": "grid.frag"},
          "a3": {"vert": "a3.vert", "geom": "a3.geom", "frag": "grid.frag"},
          "a3f": {"vert": "a3f.vert", "geom": "a3f.geom", "frag": "grid.frag"}}


def program_defines(key: str, zcorn_bits: int) -> dict:
    """The defines of program ``key`` (a key of :data:`STAGES`) for 16- or 32-bit ZCORN."""
    d = layout.grid_defines()
    if key in ("a1", "a1gs"):
        return {"UNIT_PALETTE": d["UNIT_PALETTE"], "FAR_PX": d["FAR_PX"],
                "A1_GS": int(key == "a1gs"), "EDGE_QUAD": d["EDGE_QUAD"],
                "EDGE_PAPER": d["EDGE_PAPER"]}
    names = {"TEX_W", "ZCORN_PER_TEXEL", "UNIT_COORD", "UNIT_ZCORN", "EDGE_QUAD",
             "EDGE_PAPER", "FAR_PX", "UNIT_PALETTE"}
    names |= {"a2": {"FACE_CORNERS", "PAPER_MASK_ORDER", "A2_FAULT_SHIFT",
                     "A2_MASK_SHIFT", "A2_COLOR_SHIFT"},
              "a3": {"UNIT_COLOR"}, "a3f": {"FACE_CORNERS", "A3F_FACE_BITS"}}[key]
    return {k: d[k] for k in names} | {"ZCORN_BITS": zcorn_bits}


#: every program this visual builds (approach 1 always has 16-bit nodes)
PROGRAMS = [ProgramSpec(key, stages, tuple(program_defines(key, bits) for bits in
                                           ((16,) if key in ("a1", "a1gs") else (16, 32))))
            for key, stages in STAGES.items()]


@dataclass
class EdgeStyle:
    """Appearance of the cell edges and highlighted faces.

    mode: 'none', 'quad' (distances to the four face edges) or 'paper' (per-triangle heights)
    width: line width in pixels
    color: RGB in 0..1; strength: 0..1 blend of the line over the face
    fade: (lo, hi) on-screen face size in pixels: no lines below lo, full lines above hi
    highlight: RGB mixed into highlighted (fault) faces, with ``highlight_amount``
    """

    mode: str = "none"
    width: float = 1.0
    color: tuple = (0.05, 0.05, 0.05)
    strength: float = 0.85
    fade: tuple = (3.0, 10.0)
    highlight: tuple = (0.9, 0.1, 0.1)
    highlight_amount: float = 0.7


def grid_orientation(grid: CornerPointGrid, samples: int = 4096) -> float:
    """+1 / -1: the sign of d(x, y, depth)/d(i, j, k) over (a sample of) the active cells.

    The faces' corner order is counter-clockwise seen from outside in index space; this sign
    says whether that stays so in the grid's (x, y, depth) space. 0 if undecidable.
    """

    nx, ny, _ = grid.dims
    idx = np.flatnonzero(np.asarray(grid.actnum).ravel(order="F") != 0)
    if idx.size == 0:
        return 0.0
    idx = idx[np.linspace(0, idx.size - 1, min(samples, idx.size)).astype(np.int64)]
    i, j, k = idx % nx, idx // nx % ny, idx // (nx * ny)
    zc = np.asarray(grid.zcorn)
    zc8 = np.stack([zc[2 * i + (c & 1), 2 * j + (c >> 1 & 1), 2 * k + (c >> 2 & 1)]
                    for c in range(8)], 1)
    return orientation_sign(grid.coord, i, j, zc8)


def _set(prog: moderngl.Program, name: str, value) -> None:
    """Set a uniform if the program uses it (the GLSL compiler drops unused ones)."""
    try:
        u = prog[name]
    except KeyError:
        return
    if isinstance(value, np.ndarray) and value.ndim == 2:
        u.write(np.asarray(value, "f4").T.tobytes())
    else:
        u.value = value


class GridVisual:
    """GPU state and drawing of one corner-point grid with one approach.

    Parameters
    ----------
    ctx : moderngl.Context
    grid : CornerPointGrid
    origin : (3,) float
        Local origin (x, y, depth) subtracted before anything goes to float32 on the GPU.
    approach : {1, 2, 3}
    zcorn_bits : {16, 32}
        Depth storage of approaches 2 and 3.
    zcorn_store : {'faces', 'grid'}
        Approach 3: ZCORN of the visible faces with them, or the whole ZCORN (paper).
    quantised : (codes, z0, scale, max_abs_error), optional
        The 16-bit ZCORN (``compute.grid.geometry.zcorn_quantise``); needed for 16 bits.
    palette : (256, 4) uint8
    smear_faults : bool or None
        Approach 1 on a non-conforming grid: average the corner depths that meet at a node
        (the paper's use of approach 1, "when faults and pinch-outs are not critical"); None
        (the default) and True smear (``smeared_nodes`` counts the nodes), False refuses the
        grid with :class:`InputError`.
    """

    def __init__(self, ctx: moderngl.Context, grid: CornerPointGrid, origin, approach: int = 3,
                 zcorn_bits: int = 16, zcorn_store: str = "faces", quantised=None,
                 palette: np.ndarray | None = None, smear_faults: bool | None = None,
                 orientation: float | None = None):
        if approach not in layout.APPROACHES:
            raise InputError(f"approach: expected 1, 2 or 3, got {approach!r}")
        if zcorn_bits not in (16, 32):
            raise InputError(f"zcorn_bits: expected 16 or 32, got {zcorn_bits!r}")
        if zcorn_store not in layout.ZCORN_STORES:
            raise InputError(f"zcorn_store: expected one of {layout.ZCORN_STORES}, "
                             f"got {zcorn_store!r}")
        self.ctx, self.grid, self.approach = ctx, grid, int(approach)
        self.zcorn_bits = int(zcorn_bits) if approach != 1 else 16  # approach 1: u16 nodes
        self.zcorn_store = zcorn_store if approach == 3 else None
        self.origin = np.asarray(origin, np.float64).reshape(3)
        self.dims = grid.dims
        self.cache = GpuCache(ctx)
        self.orientation = grid_orientation(grid) if orientation is None else float(orientation)
        self.smear_faults = smear_faults
        self.node_spread = 0.0
        self.smeared_nodes = 0
        self.zcorn_max_error = 0.0
        self.n_faces = 0
        self.ranges: list[tuple[int, int, int, bool]] = []
        #: approach 3 with faces uploaded in blocks (:meth:`set_staged`): ``(first face,
        #: faces, buffer name)`` of each block's records, in order; empty: one buffer
        self._parts: list[tuple[int, int, str]] = []
        self.vaos: dict[str, moderngl.VertexArray] = {}
        self.programs: dict[str, moderngl.Program] = {}
        #: full per-cell colour indices where the GPU holds one per cell or node (approach 1,
        #: 3 grid) or where they were given so; None: colours come per visible cell only
        self._ci: np.ndarray | None = (np.zeros(grid.ncells, np.uint8)
                                       if approach == 1 or self.zcorn_store == "grid" else None)
        #: approach 3 with faces: the cells with a visible face (int64, ascending) and each
        #: face's place in that list (int32)
        self._cell_list: np.ndarray | None = None
        self._face_slot = np.zeros(0, np.int32)
        self._records: prepare.CellRecords | None = None
        self._quantised = quantised
        if self.zcorn_bits == 16 and approach != 1 and quantised is None:
            raise InputError("16-bit ZCORN needs the quantised ZCORN (zcorn_quantise) or, for "
                             "approach 3 with zcorn_store='faces', its (z0, scale)")
        self.cache.texture2d("palette", np.asarray(
            palette if palette is not None else np.full((256, 4), 200, np.uint8),
            np.uint8).reshape(1, 256, 4))
        self._upload_geometry()

    # --- programs ------------------------------------------------------------------------------
    def _program(self, key: str) -> moderngl.Program:
        if key in self.programs:
            return self.programs[key]
        prog = load_program(self.ctx, PKG, STAGES[key], program_defines(key, self.zcorn_bits))
        self.programs[key] = prog
        return prog

    @property
    def _key(self) -> str:
        if self.approach == 3:
            return "a3f" if self.zcorn_store == "faces" else "a3"
        return f"a{self.approach}"

    # --- uploads -------------------------------------------------------------------------------
    def _upload_geometry(self) -> None:
        g, c = self.grid, self.cache
        o = self.origin
        coord_local = np.asarray(g.coord, np.float64) - np.concatenate([o, o])
        if self.approach == 1:
            nodes = prepare.node_geometry(coord_local, np.asarray(g.zcorn), g.active, o[2])
            self.node_spread = nodes.spread
            if nodes.mismatched_nodes and self.smear_faults is False:
                raise InputError(
                    f"{g.name or 'grid'}: approach 1 needs a conforming grid, but the corners "
                    f"meeting at {nodes.mismatched_nodes} nodes differ (by up to "
                    f"{nodes.spread:.4g}); use approach 2 or 3, or let approach 1 smear the "
                    f"faults (the default without --no-smear-faults) as the paper allows")
            self.smeared_nodes = int(nodes.mismatched_nodes)
            self.nodes = nodes
            self.zcorn_max_error = nodes.z_error
            c.buffer("node_positions", nodes.positions)
            c.buffer("node_colors", prepare.node_colors(self._ci, self.dims))
            return
        c.texture2d("coord", prepare.coord_texture(coord_local), components=3, dtype="f4")
        self._zquant = None
        if self.zcorn_bits == 16 and self._quantised[0] is None:
            # approach 3 with faces: the corners of the drawn faces are quantised when the
            # faces are set (prepare.face_records); no 16-bit copy of the whole ZCORN
            _, z0, scale, _ = self._quantised
            self.zdecode = (float(z0) - o[2], float(scale))
            self._zquant = (float(z0), float(scale))
            # a view of an F-ordered model; None for a grid out of core (corners come with
            # the faces, set_faces(corners=...))
            zflat = (np.asarray(g.zcorn).ravel(order="F") if isinstance(g.zcorn, np.ndarray)
                     else None)
        elif self.zcorn_bits == 16:
            codes, z0, scale, err = self._quantised
            self.zdecode = (float(z0) - o[2], float(scale))
            self.zcorn_max_error = float(err)
            zflat = np.asarray(codes).ravel(order="F").astype(np.uint16, copy=False)
        else:
            # local depths in float32: at most half a float32 spacing of the largest one off
            self.zdecode = (0.0, 1.0)
            zflat = np.asarray(g.zcorn).ravel(order="F")          # a view: F-ordered model
            zmin, zmax = float(zflat.min()), float(zflat.max())
            self.zcorn_max_error = float(np.spacing(np.float32(max(abs(zmin - o[2]),
                                                                   abs(zmax - o[2])))) / 2)
        self._zflat = zflat
        if self.approach == 2 or self.zcorn_store == "grid":
            if self._zquant is not None:
                raise InputError("approach 2 and zcorn_store='grid' need the whole quantised "
                                 "ZCORN (zcorn_quantise)")
            if self.zcorn_bits == 32:
                zflat = (zflat.astype(np.float64) - o[2]).astype(np.float32)
            tex = prepare.to_linear_texture(zflat, layout.ZCORN_PER_TEXEL)
            del zflat
            c.texture2d("zcorn", tex, components=4,
                        dtype="u2" if self.zcorn_bits == 16 else "f4")
        if self.approach == 3 and self.zcorn_store == "grid":
            c.texture2d("cell_colors", prepare.to_linear_texture(self._ci, 1), components=1,
                        dtype="u1")

    def set_faces(self, cells: np.ndarray, face: np.ndarray, highlight=None,
                  corners: np.ndarray | None = None) -> None:
        """The faces to draw (rows of a ``FaceSet``) and which of them to highlight;
        ``corners`` ``(n, 4)``: their corner depths gathered elsewhere (approach 3 with faces,
        a grid out of core whose ZCORN is not in memory)."""
        cells = np.asarray(cells).reshape(-1, 3)
        face = np.asarray(face).ravel()
        hl = (np.zeros(face.size, bool) if highlight is None
              else np.asarray(highlight, bool).ravel())
        if not (cells.shape[0] == face.size == hl.size):
            raise ValueError("cells, face and highlight must have the same length")
        if not self._new_faces(int(face.size)):
            return
        c = self.cache
        dims = self.dims
        if self.approach == 2:
            self._records = prepare.cell_records(cells, face, hl, dims)
            c.buffer("cell_records", self._records.pack(
                self._ci[self._records.cells] if self._ci is not None
                else np.zeros(self._records.cells.size, np.uint8)))
        elif self.approach == 3 and self.zcorn_store == "faces":
            self._set_face_records(cells, face, hl, corners)
        else:
            group = (face < 3).astype(np.int64) if self.approach == 1 else None
            order, self.ranges = prepare.draw_ranges(hl, group, 2 if self.approach == 1 else 1)
            cells, face = cells[order], face[order]
            if self.approach == 1:
                c.buffer("face_indices", prepare.node_triangles(cells, face, dims))
            else:
                c.buffer("face_indices", prepare.zcorn_indices(cells, face, dims))
        self._build_vaos()

    def _new_faces(self, n: int) -> bool:
        """Drop the faces' GPU objects for ``n`` new faces; False when there are none."""
        self.n_faces = n
        self._release_vaos()
        for name in ("face_indices", "cell_records", "face_colors",
                     *(p[2] for p in self._parts[1:]), "face_records"):
            self.cache.drop(name)
        self.ranges = []
        self._parts = []
        self._cell_list = None   # the old faces' lists go with them
        self._face_slot = np.zeros(0, np.int32)
        if n == 0:
            self._records = None
            self._face_slot = np.zeros(0, np.int32)
            return False
        return True

    def set_staged(self, staged: prepare.StagedFaces) -> None:
        """The faces to draw as :class:`~geoshade.render.visuals.grid.prepare.StagedFaces`
        (approach 3 with faces: records built on the CPU, a grid out of core), each staged
        block freed once uploaded.  Drawn as :meth:`set_faces` draws the same faces: in their
        order in up to :data:`MAX_DRAW_RUNS` runs of one key, each block its own GPU buffer
        (made with its records: no whole buffer reserved, which a driver may fill with zeros
        in this process beside the staged blocks), else sorted by key (stable) into one."""
        if not (self.approach == 3 and self.zcorn_store == "faces"):
            raise ValueError("set_staged: staged faces are approach 3 with faces")
        if (staged.quantise is not None) != (self._zquant is not None):
            raise ValueError("set_staged: staged with other depths than the visual's")
        n = staged.n
        if not self._new_faces(n):
            return
        c = self.cache
        words = staged.words
        keys = np.concatenate([b[1] for b in staged.blocks])
        runs = prepare.draw_runs(keys, MAX_DRAW_RUNS)
        # each face's place in the list of cells with a face: per layer where the layers'
        # cells follow each other (no sort of every face's cell), else one sort at the end
        listed = staged.cell_list()
        face_cells = None if listed is not None else np.empty(n, np.uint32)
        slot = (np.empty(n, np.int32 if listed[0].size < 2**31 else np.int64)
                if listed is not None else None)
        blocks = staged.blocks

        def place(at, rec, k, layer, sel=None):
            fc = staged.face_cells(rec, k)
            if slot is not None:
                slot[at:at + fc.size] = staged.slots(fc, layer)
            else:
                face_cells[at:at + fc.size] = fc
            return fc.size

        if runs is not None:   # in their order: a buffer per block
            self.ranges, at = runs, 0
            parts = []
            while blocks:
                rec, k, layer = blocks.pop(0)
                name = "face_records" if not parts else f"face_records@{len(parts)}"
                c.buffer(name, rec)
                parts.append((at, rec.shape[0], name))
                at += place(at, rec, k, layer)
                del rec, k
                if len(blocks) % 4 == 0:   # the uploaded blocks' memory back to the system
                    give_back_freed()
            self._parts = parts
        else:                  # sorted by key, stable: draw_ranges_keyed's order
            buf = c.buffer("face_records", reserve=n * words * 4)
            counts = np.bincount(keys)
            self.ranges = prepare.key_ranges(counts)
            cursor = np.concatenate([[0], np.cumsum(counts)[:-1]])
            while blocks:
                rec, k, layer = blocks.pop(0)
                for kk in np.unique(k).tolist():
                    sel = k == kk
                    part, at = np.ascontiguousarray(rec[sel]), int(cursor[kk])
                    buf.write(part, offset=at * words * 4)
                    cursor[kk] += place(at, part, k[sel], layer)
                del rec, k
        del keys
        if self._zquant is not None:
            self.zcorn_max_error = staged.zerr
        self._face_colours(face_cells, None if slot is None else (listed[0], slot))
        self._build_vaos()

    def _set_face_records(self, cells: np.ndarray, face: np.ndarray, hl: np.ndarray,
                          corners=None) -> None:
        """Approach 3 with faces: the face records and colour bytes, built
        :data:`FACE_BATCH` faces at a time and written straight into the GPU buffers (no
        whole records array on the CPU: a filter that shows 1e8 faces needs their 13 GPU
        bytes each and bounded temporaries, not ~150 bytes a face).

        ``corners``: the faces' ``(n, 4)`` corner depths, or a callable ``corners(sel)``
        giving those of faces ``sel`` (a slice or an index array), asked for
        :data:`CORNER_BATCH` faces at a time (a grid out of core reads them from its ZCORN
        chunks batch by batch).  CPU memory beyond the buffers: the draw order (8 bytes a
        face, only where highlights or 2^29-cell buckets make more than
        :data:`MAX_DRAW_RUNS` runs of faces to draw apart) and the faces' cell numbers
        (4 bytes a face) while the list of cells with a face (8 bytes a cell) and each face's
        place in it (4 bytes a face, kept) are made."""
        n = face.size
        order = None
        big = self.grid.ncells > (1 << layout.A3F_BUCKET_BITS)
        if hl.any() or big:
            # ranges by (2^29-cell bucket, highlight): a range's draw call adds its bucket's
            # base to the 29-bit cell numbers of its records (grids of up to 2^32 cells);
            # one byte a face (up to 2^32 cells): 2 * bucket + highlight
            top = 2 * int(prepare.a3f_buckets(np.array([self.grid.ncells - 1]))[0]) + 1
            key = np.asarray(hl, np.uint8 if top < 1 << 8 else np.uint16 if top < 1 << 16
                             else np.int64).copy()
            if big:
                for f0 in range(0, n, FACE_BATCH):
                    cb = np.asarray(cells[f0:f0 + FACE_BATCH], np.int64)
                    key[f0:f0 + FACE_BATCH] += (2 * prepare.a3f_buckets(
                        prepare.cell_numbers(cb, self.dims))).astype(key.dtype)
            runs = prepare.draw_runs(key, MAX_DRAW_RUNS)   # few runs: the order as it is
            if runs is not None:
                self.ranges = runs
            else:
                order, self.ranges = prepare.draw_ranges_keyed(
                    key, int(key.max(initial=0)) // 2 + 1)
            del key
        else:
            self.ranges = [(0, n, 0, False)]
        words = 3 if self.zcorn_bits == 16 else 5
        c = self.cache
        buf = None
        face_cells = np.empty(n, np.uint32)  # approach 3 with faces: at most 2^32 cells
        err = 0.0
        zc, z0 = None, 0
        per = max(1, CORNER_BATCH // FACE_BATCH) * FACE_BATCH  # whole face batches
        for f0 in range(0, n, FACE_BATCH):  # batches of faces, not cells
            idx = slice(f0, min(n, f0 + FACE_BATCH))
            sel = idx if order is None else order[idx]
            cb, fb = np.asarray(cells[sel], np.int64), np.asarray(face[sel], np.int64)
            if callable(corners):
                if zc is None or f0 >= z0 + len(zc):  # the next batch of corner depths
                    z0, zc = f0, None
                    zc = corners(slice(f0, min(n, f0 + per)) if order is None
                                 else order[f0:f0 + per])
                cz = zc[f0 - z0:idx.stop - z0]
            else:
                cz = None if corners is None else corners[sel]
            rec, e = prepare.face_records(cb, fb, self.dims, self._zflat, self.origin[2],
                                          quantise=self._zquant, corners=cz)
            if buf is None:  # after the first batch's checks
                buf = c.buffer("face_records", reserve=n * words * 4)
            buf.write(np.ascontiguousarray(rec), offset=f0 * words * 4)
            face_cells[idx] = prepare.cell_numbers(cb, self.dims)
            err = max(err, e)
            del rec, cb, fb, cz
        del zc, order
        if self._zquant is not None:
            self.zcorn_max_error = err
        self._face_colours(face_cells)

    def _face_colours(self, face_cells: np.ndarray | None, listed=None) -> None:
        """The list of cells with a face, each face's place in it and the faces' colour bytes
        (approach 3 with faces), from the faces' cell numbers in upload order (consumed), or
        ``listed``: that list and those places, made already."""
        c = self.cache
        if listed is not None:
            self._cell_list, self._face_slot = listed
        else:
            self._cell_list, self._face_slot = prepare.cell_list(face_cells)
        del face_cells, listed
        n = self._face_slot.size
        colours = c.buffer("face_colors", reserve=n)
        for f0 in range(0, n, FACE_BATCH):
            slot = self._face_slot[f0:f0 + FACE_BATCH]
            colours.write(np.ascontiguousarray(self._ci[self._cell_list[slot]])
                          if self._ci is not None else np.zeros(slot.size, np.uint8),
                          offset=f0)

    def color_cells(self) -> np.ndarray | None:
        """The cells whose colours the GPU holds: ``(m,)`` int64 cell numbers, ascending (the
        cells with a visible face, approaches 2 and 3 with faces), or None for every cell
        (approach 1's nodes, approach 3's per-cell texture)."""
        if self.approach == 1 or self.zcorn_store == "grid":
            return None
        if self.approach == 2:
            return (self._records.cells if self._records is not None
                    else np.zeros(0, np.int64))
        if self._cell_list is None:  # no faces
            self._cell_list = np.zeros(0, np.int64)
            self._face_slot = np.zeros(0, np.int32)
        return self._cell_list

    def set_colors(self, ci: np.ndarray, cells: np.ndarray | None = None) -> None:
        """New colour indices: ``(ncells,)`` uint8 in cell-number order, or, with ``cells``
        (the array :meth:`color_cells` returned), one per cell of it.

        Only colour data is written, into the existing objects: node colours (1), cell records
        (2), the per-cell colour texture (3, grid) or the per-face colour bytes (3, faces).
        """
        ci = np.asarray(ci, np.uint8).ravel()
        c = self.cache
        if cells is not None:
            want = self.color_cells()
            if want is None or (cells is not want and not np.array_equal(cells, want)):
                raise ValueError("set_colors: cells must be the array color_cells() returned")
            if ci.size != want.size:
                raise ValueError(f"expected {want.size} colour indices, got {ci.size}")
            if self.approach == 2:
                if self._records is not None:
                    c.get("cell_records").write(self._records.pack(ci))
            elif self._face_slot.size:
                c.get("face_colors").write(np.ascontiguousarray(ci[self._face_slot]))
            return
        if ci.size != self.grid.ncells:
            raise ValueError(f"expected {self.grid.ncells} colour indices, got {ci.size}")
        self._ci = ci
        if self.approach == 1:
            c.get("node_colors").write(prepare.node_colors(ci, self.dims))
        elif self.approach == 2:
            if self._records is not None:
                c.get("cell_records").write(self._records.pack(ci[self._records.cells]))
        elif self.zcorn_store == "grid":
            c.get("cell_colors").write(prepare.to_linear_texture(ci, 1))
        elif self._face_slot.size:
            buf = c.get("face_colors")
            for f0 in range(0, self._face_slot.size, FACE_BATCH):  # batches of faces
                buf.write(np.ascontiguousarray(
                    ci[self._cell_list[self._face_slot[f0:f0 + FACE_BATCH]]]), offset=f0)

    def set_palette(self, palette: np.ndarray) -> None:
        self.cache.get("palette").write(np.asarray(palette, np.uint8).reshape(1, 256, 4))

    # --- VAOs --------------------------------------------------------------------------------
    def _build_vaos(self) -> None:
        c, ctx = self.cache, self.ctx
        if self.approach == 1:
            ib = c.get("face_indices")
            content = [(c.get("node_positions"), "3u2", "pos_code"),
                       (c.get("node_colors"), "2u1", "colors")]
            for key in ("a1", "a1gs"):
                self.vaos[key] = ctx.vertex_array(self._program(key), content, index_buffer=ib,
                                                  index_element_size=4)
        elif self.approach == 2:
            self.vaos["a2"] = ctx.vertex_array(self._program("a2"),
                                               [(c.get("cell_records"), "2u4", "record")])
        elif self.zcorn_store == "grid":
            self.vaos["a3"] = ctx.vertex_array(self._program("a3"), [],
                                               index_buffer=c.get("face_indices"),
                                               index_element_size=4)
        else:
            zfmt = "4u2" if self.zcorn_bits == 16 else "4f4"
            self.vaos["a3f"] = ctx.vertex_array(
                self._program("a3f"),
                [(c.get("face_records"), f"u4 {zfmt}", "face_head", "face_z"),
                 (c.get("face_colors"), "u1", "face_color")])
            prog = self._program("a3f")
            for first, _, name in self._parts[1:]:   # a block's records, its colour bytes
                vao = ctx.vertex_array(prog, [(c.get(name), f"u4 {zfmt}", "face_head",
                                               "face_z")])
                vao.bind(prog["face_color"].location, "i", c.get("face_colors"), "u1",
                         offset=first)
                self.vaos[name] = vao

    def _release_vaos(self) -> None:
        for v in self.vaos.values():
            v.release()
        self.vaos = {}

    # --- accounting ----------------------------------------------------------------------------
    @property
    def gpu_bytes(self) -> int:
        """Exact bytes of every buffer and texture this visual holds."""
        return self.cache.nbytes

    def plan(self) -> dict[str, int]:
        """:func:`layout.gpu_plan` for the current faces (equals :meth:`GpuCache.breakdown`)."""
        cells = self._records.cells.size if self._records is not None else 0
        return layout.gpu_plan(self.approach, self.dims, self.n_faces, cells, self.zcorn_bits,
                               self.zcorn_store or "faces")

    def geometry_objects(self) -> dict[str, object]:
        """The objects a property switch must leave alone (by name)."""
        names = {1: ("node_positions", "face_indices"), 2: ("coord", "zcorn"),
                 3: ("coord", "zcorn", "face_indices", "face_records",
                     *(p[2] for p in self._parts[1:]))}[self.approach]
        return {n: self.cache.get(n) for n in names if self.cache.get(n) is not None}

    # --- drawing -----------------------------------------------------------------------------
    def draw(self, camera: Camera, model: np.ndarray, shading: dict, viewport,
             style: EdgeStyle | None = None, cull: bool = True, count: bool = False,
             piece: int | None = None) -> dict:
        """Draw into the bound framebuffer; with ``count``, return GPU-counted faces.

        ``piece``: only the draw ranges of group ``piece // 2`` with highlight ``piece % 2``
        (a grid drawn in parts on a cluster, :mod:`geoshade.grid.distributed`)."""
        style = style or EdgeStyle()
        ctx = self.ctx
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        if not self.vaos:
            return {"faces_drawn": 0, "triangles": 0} if count else {}
        edge_mode = layout.EDGE_MODES.get(style.mode)
        if edge_mode is None:
            raise InputError(f"edges: expected one of {list(layout.EDGE_MODES)}, got "
                             f"{style.mode!r}")
        mv = camera.view_matrix() @ np.asarray(model, np.float64)
        det = float(np.linalg.det(mv[:3, :3]))
        cull_sign = float(np.sign(det) * self.orientation) if cull else 0.0
        key = self._key
        # the flat values of a triangle come from its first vertex in approach 1, from its last
        # (GL's default) in the others: set every draw, since the context is shared (approach
        # 1's convention left set shifted a later approach-3 picture by 1 at a few pixels)
        ctx.provoking_vertex = (moderngl.FIRST_VERTEX_CONVENTION if self.approach == 1
                                else moderngl.LAST_VERTEX_CONVENTION)
        if self.approach == 1:
            key = "a1gs" if edge_mode != layout.EDGE_NONE else "a1"
            if edge_mode != layout.EDGE_NONE:
                edge_mode = layout.EDGE_PAPER  # a triangle shader sees three corners only
            if cull_sign != 0.0:
                ctx.enable(moderngl.CULL_FACE)
                ctx.front_face = "ccw" if cull_sign > 0 else "cw"
                ctx.cull_face = "back"
        prog, vao = self.programs[key], self.vaos[key]
        values = {
            "mv": mv, "proj": camera.projection_matrix(),
            "viewport": tuple(float(v) for v in viewport), "edge_mode": int(edge_mode),
            "edge_fade": tuple(float(v) for v in style.fade), "cull_sign": cull_sign,
            "ortho": int(camera.ortho), "edge_width": float(style.width),
            "edge_color": (*style.color, float(style.strength)),
            "highlight_color": (*style.highlight, float(style.highlight_amount)),
            "dims": tuple(int(v) for v in self.dims), "highlight": 0,
        }
        if self.approach == 1:
            values.update(pos_lo=tuple(self.nodes.lo.astype(float)),
                          pos_step=tuple(self.nodes.step.astype(float)))
        else:
            values["zdecode"] = self.zdecode
        values.update(shading)
        for name, v in values.items():
            _set(prog, name, v)
        self._bind()
        ranges = (self.ranges if piece is None else
                  [r for r in self.ranges if 2 * r[2] + int(r[3]) == int(piece)])
        query = ctx.query(primitives=True) if count else None
        if query is not None:
            with query:
                self._draw_calls(prog, vao, ranges)
            prims = int(query.primitives)
        else:
            self._draw_calls(prog, vao, ranges)
        ctx.disable(moderngl.CULL_FACE)
        if not count:
            return {}
        return {"faces_drawn": prims // 2, "triangles": prims}

    def _bind(self) -> None:
        c = self.cache
        c.get("palette").use(layout.UNIT_PALETTE)
        for name, unit in (("coord", layout.UNIT_COORD), ("zcorn", layout.UNIT_ZCORN),
                           ("cell_colors", layout.UNIT_COLOR)):
            obj = c.get(name)
            if obj is not None:
                obj.use(unit)

    def _draw_calls(self, prog, vao, ranges) -> None:
        if self.approach == 2:
            vao.render(moderngl.POINTS, vertices=self._records.cells.size)
            return
        for first, cnt, group, hl in ranges:
            _set(prog, "highlight", int(hl))
            if self.approach == 1:
                # group 0: minus faces (colour 1 of node (i, j, k)); group 1: plus faces
                _set(prog, "pass_index", int(group == 1))
                vao.render(moderngl.TRIANGLES, vertices=cnt * 6, first=first * 6)
            elif self.zcorn_store == "grid":
                vao.render(moderngl.LINES_ADJACENCY, vertices=cnt * 4, first=first * 4)
            else:  # approach 3, faces: group = the 2^29-cell bucket of the range
                _set(prog, "cell_base", int(group) << layout.A3F_BUCKET_BITS)
                if not self._parts:
                    vao.render(moderngl.POINTS, vertices=cnt, first=first)
                    continue
                for p0, pn, name in self._parts:   # the range's faces in each block
                    lo, hi = max(first, p0), min(first + cnt, p0 + pn)
                    if lo < hi:
                        self.vaos.get(name, vao).render(moderngl.POINTS, vertices=hi - lo,
                                                        first=lo - p0)

    def release(self) -> None:
        self._release_vaos()
        for p in self.programs.values():
            p.release()
        self.programs = {}
        self.cache.release()
