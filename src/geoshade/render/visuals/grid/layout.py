"""One definition of every table, bit layout and constant the grid shaders share with Python.

The shaders declare these names with ``#pragma geoshade define NAME``; :func:`grid_defines`
emits their values, so a layout is never written down twice. No GL here: the benchmark computes
GPU bytes from :func:`gpu_plan` without a context, and the visual allocates exactly that plan.

Cell corners are numbered ``c = a + 2b + 4c'`` with ``a, b, c'`` in {0, 1} along i, j, k (the
:class:`~geoshade.models.grid.CornerPointGrid` convention: corner ``c`` of cell ``(i, j, k)`` has
depth ``zcorn[2i+a, 2j+b, 2k+c']`` on pillar ``(i+a, j+b)``). Faces are numbered as in
``FaceSet.face``: 0..5 = I+ J+ K+ I- J- K-.

>>> FACE_CORNERS[3], FACE_CORNERS[0]
((0, 4, 6, 2), (7, 5, 1, 3))
>>> [PAPER_MASK_BIT[f] for f in range(6)]
[1, 3, 5, 0, 2, 4]
"""

from __future__ import annotations

import math

import numpy as np

# --- faces ------------------------------------------------------------------------------------
#: corners (A, B, C, D) of each face, counter-clockwise seen from outside the cell in (i, j, k)
#: index space; A–C is the diagonal every approach splits the face along (triangles ABC and
#: CDA). A is corner 0 for the minus faces and corner 7 for the plus faces: the grid node that
#: approach 1 uses as the provoking vertex (node (i, j, k) resp. (i+1, j+1, k+1)).
FACE_CORNERS = {0: (7, 5, 1, 3), 1: (7, 3, 2, 6), 2: (7, 6, 4, 5),
                3: (0, 4, 6, 2), 4: (0, 1, 5, 4), 5: (0, 2, 3, 1)}
FACE_CORNER_TABLE = np.array([FACE_CORNERS[f] for f in range(6)], np.int64)  # (6, 4)
#: the paper's approach-2 visibility mask, Table 2: bits (-X, X, -Y, Y, -Z, Z)
PAPER_MASK_ORDER = (3, 0, 4, 1, 5, 2)
PAPER_MASK_BIT = {f: PAPER_MASK_ORDER.index(f) for f in range(6)}
#: faces whose provoking node is (i, j, k) (pass 1 of approach 1) and (i+1, j+1, k+1) (pass 2)
MINUS_FACES, PLUS_FACES = (3, 4, 5), (0, 1, 2)

# --- approach 2 record (Table 2, 8 bytes per visible cell) -------------------------------------
#: word 0: cell number i + j*nx + k*nx*ny; word 1: bits 0..15 the paper's reserved bytes (we keep
#: the fault-face mask in bits 0..5, same bit order as the visibility mask), bits 16..23 the
#: visibility mask, bits 24..31 the colour index
A2_FAULT_SHIFT, A2_MASK_SHIFT, A2_COLOR_SHIFT = 0, 16, 24

# --- approach 3, ``faces`` storage (12 bytes per face at 16 bits, 20 at 32) ---------------------
#: word 0 = cell number << 3 | face; then the depths of corners A, B, C, D
A3F_FACE_BITS = 3
A3F_MAX_CELLS = 1 << (32 - A3F_FACE_BITS)
#: cell-number bits a face record holds; larger grids draw in ranges of 2^A3F_BUCKET_BITS
#: cells, each with its ``cell_base`` uniform (Python-side only: tests shrink it)
A3F_BUCKET_BITS = 32 - A3F_FACE_BITS

# --- textures used as big 1D arrays (2D so that 1e8-cell grids fit the texture size limits) ----
#: texels per row of the linear textures (COORD, ZCORN, per-cell colours); the height is
#: ceil(texels / TEX_W) and must stay within GL_MAX_TEXTURE_SIZE (16384 on llvmpipe)
TEX_W = 16384
#: ZCORN values per texel (RGBA16UI at 16 bits, RGBA32F at 32 bits: the paper's Table 3 density)
ZCORN_PER_TEXEL = 4
#: texture units
UNIT_PALETTE, UNIT_COORD, UNIT_ZCORN, UNIT_COLOR = 0, 1, 2, 3

# --- approach 1 (Table 1, 8 bytes per grid node) ------------------------------------------------
#: positions: x, y, z as uint16 in the local box (6 bytes); colours: colour 1 (cell (i, j, k)),
#: colour 2 (cell (i-1, j-1, k-1)) as uint8 (2 bytes, their own buffer so that a new property
#: re-uploads only them)
A1_POS_BYTES, A1_COLOR_BYTES, A1_INDEX_BYTES, A1_INDICES_PER_FACE = 6, 2, 4, 6

#: edge modes (uniform ``edge_mode``): none; distances to the four quad edges (strip per face);
#: the paper's per-triangle heights with the diagonal skipped (two triangles per face)
EDGE_NONE, EDGE_QUAD, EDGE_PAPER = 0, 1, 2
EDGE_MODES = {"none": EDGE_NONE, "quad": EDGE_QUAD, "paper": EDGE_PAPER}
#: a distance larger than any screen (stands for "no such edge")
FAR_PX = 1.0e6

PALETTE_BYTES = 256 * 4
APPROACHES = (1, 2, 3)
ZCORN_STORES = ("faces", "grid")


def _glsl_int_array(a) -> str:
    a = np.asarray(a).ravel()
    return f"int[{a.size}](" + ",".join(str(int(v)) for v in a) + ")"


def grid_defines() -> dict:
    """GLSL ``#define`` values of the grid shaders.

    >>> d = grid_defines()
    >>> d["FACE_CORNERS"][:13], d["TEX_W"]
    ('int[24](7,5,1', 16384)
    """
    return {
        "FACE_CORNERS": _glsl_int_array(FACE_CORNER_TABLE),
        "PAPER_MASK_ORDER": _glsl_int_array(PAPER_MASK_ORDER),
        "A2_FAULT_SHIFT": A2_FAULT_SHIFT,
        "A2_MASK_SHIFT": A2_MASK_SHIFT,
        "A2_COLOR_SHIFT": A2_COLOR_SHIFT,
        "A3F_FACE_BITS": A3F_FACE_BITS,
        "TEX_W": TEX_W,
        "ZCORN_PER_TEXEL": ZCORN_PER_TEXEL,
        "UNIT_PALETTE": UNIT_PALETTE,
        "UNIT_COORD": UNIT_COORD,
        "UNIT_ZCORN": UNIT_ZCORN,
        "UNIT_COLOR": UNIT_COLOR,
        "EDGE_QUAD": EDGE_QUAD,
        "EDGE_PAPER": EDGE_PAPER,
        "FAR_PX": FAR_PX,
    }


# --- GPU memory plan ----------------------------------------------------------------------------
def linear_texture_shape(n_texels: int) -> tuple[int, int]:
    """(width, height) of a linear texture holding ``n_texels`` (rows of :data:`TEX_W`).

    >>> linear_texture_shape(10), linear_texture_shape(16385)
    ((10, 1), (16384, 2))
    """
    n = max(int(n_texels), 1)
    w = min(n, TEX_W)
    return w, -(-n // w)


def gpu_plan(approach: int, dims, n_faces: int, n_cells_drawn: int = 0,
             zcorn_bits: int = 16, zcorn_store: str = "faces") -> dict[str, int]:
    """Bytes of every GPU object of one grid visual, by name — what the visual allocates.

    Parameters
    ----------
    approach : {1, 2, 3}
    dims : (nx, ny, nz)
    n_faces : int
        Visible faces drawn (``FaceSet`` size after the fault option).
    n_cells_drawn : int
        Cells with at least one visible face (approach 2 stores one record per such cell).
    zcorn_bits : {16, 32}
        Depth storage of approaches 2 and 3.
    zcorn_store : {'faces', 'grid'}
        Approach 3 only: ``grid`` is the paper's (whole ZCORN, one colour byte per cell, four
        ZCORN indices per face); ``faces`` keeps only the depths of the visible faces with them.

    Examples
    --------
    The paper's shell of a (1000, 1000, 100) grid, approach 1 (827 MB in the paper):

    >>> faces = 2 * 1000 * 1000 + 4 * 1000 * 100
    >>> round(sum(gpu_plan(1, (1000, 1000, 100), faces).values()) / 2**20)
    827
    """
    nx, ny, nz = (int(v) for v in dims)
    ncells = nx * ny * nz
    plan = {"palette": PALETTE_BYTES}
    if approach == 1:
        nodes = (nx + 1) * (ny + 1) * (nz + 1)
        plan["node_positions"] = nodes * A1_POS_BYTES
        plan["node_colors"] = nodes * A1_COLOR_BYTES
        plan["face_indices"] = n_faces * A1_INDICES_PER_FACE * A1_INDEX_BYTES
        return plan
    if zcorn_bits not in (16, 32):
        raise ValueError(f"zcorn_bits must be 16 or 32, got {zcorn_bits}")
    zbytes = zcorn_bits // 8
    pillars = (nx + 1) * (ny + 1)
    w, h = linear_texture_shape(2 * pillars)  # RGB32F, top and bottom texel per pillar
    plan["coord"] = w * h * 12
    if approach == 2 or zcorn_store == "grid":
        w, h = linear_texture_shape(math.ceil(8 * ncells / ZCORN_PER_TEXEL))
        plan["zcorn"] = w * h * ZCORN_PER_TEXEL * zbytes
    if approach == 2:
        plan["cell_records"] = n_cells_drawn * 8
    elif approach == 3 and zcorn_store == "grid":
        w, h = linear_texture_shape(ncells)
        plan["cell_colors"] = w * h
        plan["face_indices"] = n_faces * 4 * 4
    elif approach == 3 and zcorn_store == "faces":
        plan["face_records"] = n_faces * (4 + 4 * zbytes)
        plan["face_colors"] = n_faces
    else:
        raise ValueError(f"approach {approach!r} / zcorn_store {zcorn_store!r} unknown")
    return plan
