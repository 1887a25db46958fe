"""Block-centred geometry (``DX/DY/DZ/TOPS``, ``DXV/DYV/DZV/DEPTHZ``) as corner-point COORD + ZCORN.

Most textbook and benchmark decks (the SPE cases) give cell sizes instead of corners.  ECLIPSE,
OPM (``EclipseGrid``) and ResInsight turn them into a corner-point grid; this module does the
same, with OPM's arithmetic, so that the corners equal those of the EGRID OPM Flow writes for the
same deck (tested to float32, the precision of an EGRID).  The conversions are pure numpy (no
loop over cells; :func:`fill_layers` and :func:`fill_tops` step over layers, each a whole-layer
array operation).  They live in ``io`` rather than ``compute`` because the readers need them and
``io`` may not import ``compute``.

Rules
-----
``DX DY DZ TOPS`` (or ``DXV DYV DZV`` instead of ``DX DY DZ``, each scattered along its axis)

- **sizes**: a cell array holds ``nx·ny·nz`` values, or fewer but at least ``nx·ny`` (the top
  layer); a cell without a value takes the value of the cell above it (OPM: "for layers below
  the top layer the value from the layer above is used").  ``BOX``, ``EQUALS``, ``MULTIPLY``,
  ``ADD`` and ``COPY`` set parts of them as for any cell array (OPM itself reads only the raw
  keyword, so a deck using them must be compared with its expanded equivalent).
- **TOPS** of a cell without a value = TOPS + DZ of the cell above.  A given TOPS within 1e-6 of
  that sum is set to it (OPM's rule: cells meant to touch do touch, bit for bit).  A given TOPS
  that differs more is kept (ECLIPSE: each cell's top is its TOPS; a gap between layers stays a
  gap).  OPM uses only the top layer's TOPS and stacks DZ below it; the two agree wherever the
  deeper TOPS are consistent.
- **ZCORN**: the four top corners of a cell are at its TOPS, the four bottom ones at TOPS + DZ.
- **COORD** (OPM's pillars): pillar ``(I, J)`` runs from ``x`` = the sum of DX along row
  ``min(J, ny-1)`` of the top layer up to ``I`` (``y`` likewise from DY along column
  ``min(I, nx-1)``), at depth TOPS of cell ``(min(I, nx-1), min(J, ny-1))``, to the same sums
  over the bottom layer, at that depth plus the thickness of column ``(max(I-1, 0),
  max(J-1, 0))``.  When DX and DY do not change with depth the pillars are vertical and only
  their ``x, y`` matter.

``DXV DYV DZV DEPTHZ``

- **DEPTHZ** gives the depth of the top of the grid at each of the ``(nx+1)·(ny+1)`` pillars (i
  fastest); the layers follow it: a corner of layer ``k`` is ``DEPTHZ + sum(DZV[:k])`` deep at its
  top and that plus ``DZV[k]`` at its bottom.  The top surface is bilinear within a cell.
- **COORD**: vertical pillars at ``x = sum(DXV[:I])``, ``y = sum(DYV[:J])``, from DEPTHZ to
  DEPTHZ + ``sum(DZV)``.

Both: the depths along each corner column are then made monotone (a corner above the one before
it is moved down to it), as OPM's ``ZcornMapper::fixupZCORN`` does.

Layout: as :class:`~geoshade.models.CornerPointGrid` (COORD ``(nx+1, ny+1, 6)`` float64, ZCORN
``(2nx, 2ny, 2nz)`` float32, F-order); cell arrays here are ``(nx, ny, nz)`` float64.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.grid_checks import check_memory

#: the cell-array keywords of block-centred geometry
CELL_KEYWORDS = ("DX", "DY", "DZ", "TOPS")
#: the vector keywords: one value per column (DXV), row (DYV) or layer (DZV)
VECTOR_KEYWORDS = ("DXV", "DYV", "DZV")
#: all keywords of block-centred geometry
KEYWORDS = frozenset((*CELL_KEYWORDS, *VECTOR_KEYWORDS, "DEPTHZ"))
#: a given TOPS this close to TOPS + DZ of the cell above is set to that sum (OPM)
Z_TOLERANCE = 1e-6


def fill_layers(values: np.ndarray) -> np.ndarray:
    """A cell array with every NaN cell given the value of the cell above it (in place).

    Examples
    --------
    >>> a = np.full((2, 1, 3), np.nan); a[:, 0, 0] = (1, 2); a[1, 0, 2] = 5
    >>> fill_layers(a)[:, 0, :].tolist()
    [[1.0, 1.0, 1.0], [2.0, 2.0, 5.0]]
    """
    for k in range(1, values.shape[2]):  # one whole-layer operation per layer
        gap = np.isnan(values[:, :, k])
        if gap.any():
            values[:, :, k][gap] = values[:, :, k - 1][gap]
    return values


def fill_tops(tops: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """TOPS of every layer (in place): a NaN cell gets TOPS + DZ of the cell above; a given
    value within :data:`Z_TOLERANCE` of that sum is set to it; others are kept.

    Examples
    --------
    >>> tops = np.array([[[100.0, np.nan, 130.0000001, 200.0]]])
    >>> fill_tops(tops, np.full((1, 1, 4), 15.0))[0, 0].tolist()
    [100.0, 115.0, 130.0, 200.0]
    """
    for k in range(1, tops.shape[2]):
        below = tops[:, :, k - 1] + dz[:, :, k - 1]
        t = tops[:, :, k]
        snap = np.isnan(t) | (np.abs(t - below) < Z_TOLERANCE)
        t[snap] = below[snap]
    return tops


def _corner_depths(top: np.ndarray, bottom: np.ndarray) -> np.ndarray:
    """ZCORN ``(2nx, 2ny, 2nz)`` float32 from the depths (float64) of the 4 top and 4 bottom
    corners of every cell, each ``(nx, ny, nz, 2, 2)`` indexed ``[i, j, k, a, b]`` (a: i side,
    b: j side).  Rounded to float32 here: rounding keeps the order of depths, so making them
    monotone afterwards gives what it gives on float64 rounded."""
    nx, ny, nz = top.shape[:3]
    z = np.empty((nx, 2, ny, 2, nz, 2), np.float32)  # [i, a, j, b, k, c] -> (2nx, 2ny, 2nz)
    z[..., 0] = top.transpose(0, 3, 1, 4, 2)
    z[..., 1] = bottom.transpose(0, 3, 1, 4, 2)
    return z.reshape(2 * nx, 2 * ny, 2 * nz)


def monotone_zcorn(zcorn: np.ndarray) -> tuple[np.ndarray, float]:
    """ZCORN made monotone down every corner column (OPM's ``fixupZCORN``): each depth at least
    the one above it, or at most where depths decrease downwards (the direction is read from
    the first corner column).  Returns a new F-order array of the same dtype and the largest
    move.

    Examples
    --------
    >>> z = np.array([0.0, 10.0, 9.0, 20.0]).reshape(1, 1, 4).repeat(2, 0).repeat(2, 1)
    >>> fixed, moved = monotone_zcorn(z)
    >>> fixed[0, 0].tolist(), moved
    ([0.0, 10.0, 10.0, 20.0], 1.0)
    """
    down = zcorn[0, 0, 0] <= zcorn[0, 0, -1]
    fixed = np.empty(zcorn.shape, zcorn.dtype, order="F")
    (np.maximum if down else np.minimum).accumulate(zcorn, axis=2, out=fixed)
    moved = 0.0
    for c in range(zcorn.shape[2]):  # one corner layer at a time: no third array
        moved = max(moved, float(np.abs(fixed[:, :, c] - zcorn[:, :, c]).max(initial=0.0)))
    return fixed, moved


def dtops_geometry(dx: np.ndarray, dy: np.ndarray, dz: np.ndarray,
                   tops: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """COORD and ZCORN from complete ``DX DY DZ TOPS`` cell arrays ``(nx, ny, nz)``.

    Returns ``(coord, zcorn, moved)``: COORD ``(nx+1, ny+1, 6)`` float64, ZCORN float32
    ``(2nx, 2ny, 2nz)`` F-order, and the largest depth :func:`monotone_zcorn` moved.

    Examples
    --------
    >>> one = np.ones((2, 1, 2))
    >>> tops = np.array([[[10.0, 11.0]], [[20.0, 21.0]]])
    >>> coord, zcorn, _ = dtops_geometry(100 * one, 50 * one, one, tops)
    >>> coord[:, 0, :3].tolist()               # pillars along j = 0: x, y, top depth
    [[0.0, 0.0, 10.0], [100.0, 0.0, 20.0], [200.0, 0.0, 20.0]]
    >>> zcorn[:, 0, :].tolist()                # the two cells' corners: a step at the fault
    [[10.0, 11.0, 11.0, 12.0], [10.0, 11.0, 11.0, 12.0], [20.0, 21.0, 21.0, 22.0], \
[20.0, 21.0, 21.0, 22.0]]
    """
    nx, ny, nz = dz.shape
    # sums along i (j) in the top and bottom layers, sequential as OPM adds them
    sx = np.zeros((nx + 1, ny, 2))
    sx[1:] = np.cumsum(dx[:, :, [0, nz - 1]], axis=0)
    sy = np.zeros((nx, ny + 1, 2))
    sy[:, 1:] = np.cumsum(dy[:, :, [0, nz - 1]], axis=1)
    thick = np.cumsum(dz, axis=2)[:, :, -1]
    big_i, big_j = np.arange(nx + 1), np.arange(ny + 1)
    ci, cj = np.minimum(big_i, nx - 1), np.minimum(big_j, ny - 1)  # the cell a pillar takes
    pi, pj = np.maximum(big_i - 1, 0), np.maximum(big_j - 1, 0)  # the column of its thickness
    coord = np.empty((nx + 1, ny + 1, 6))
    coord[:, :, 0] = sx[:, cj, 0]
    coord[:, :, 3] = sx[:, cj, 1]
    coord[:, :, 1] = sy[ci, :, 0]
    coord[:, :, 4] = sy[ci, :, 1]
    coord[:, :, 2] = tops[np.ix_(ci, cj)][:, :, 0]
    coord[:, :, 5] = coord[:, :, 2] + thick[np.ix_(pi, pj)]
    top = np.broadcast_to(tops[..., None, None], (nx, ny, nz, 2, 2))
    bottom = np.broadcast_to((tops + dz)[..., None, None], (nx, ny, nz, 2, 2))
    zcorn, moved = monotone_zcorn(_corner_depths(top, bottom))
    return coord, zcorn, moved


def depthz_geometry(dxv: np.ndarray, dyv: np.ndarray, dzv: np.ndarray,
                    depthz: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """COORD and ZCORN from ``DXV (nx,) DYV (ny,) DZV (nz,)`` and ``DEPTHZ (nx+1, ny+1)``.

    Returns ``(coord, zcorn, moved)`` as :func:`dtops_geometry`.

    Examples
    --------
    >>> coord, zcorn, _ = depthz_geometry(np.array([10.0]), np.array([20.0]), np.array([1.0, 2.0]),
    ...                                   np.array([[100.0, 101.0], [102.0, 103.0]]))
    >>> coord[1, 1].tolist()
    [10.0, 20.0, 103.0, 10.0, 20.0, 106.0]
    >>> zcorn[:, :, 0].tolist(), zcorn[1, 1].tolist()
    ([[100.0, 101.0], [102.0, 103.0]], [103.0, 104.0, 104.0, 106.0])
    """
    nx, ny, nz = dxv.size, dyv.size, dzv.size
    x = np.concatenate([[0.0], np.cumsum(dxv)])
    y = np.concatenate([[0.0], np.cumsum(dyv)])
    z = np.concatenate([[0.0], np.cumsum(dzv)])
    coord = np.empty((nx + 1, ny + 1, 6))
    coord[:, :, 0] = coord[:, :, 3] = x[:, None]
    coord[:, :, 1] = coord[:, :, 4] = y[None, :]
    coord[:, :, 2] = depthz
    coord[:, :, 5] = depthz + z[nz]
    # corner (a, b) of cell (i, j) sits on pillar (i + a, j + b)
    corners = np.stack([np.stack([depthz[a:a + nx, b:b + ny] for b in (0, 1)], -1)
                        for a in (0, 1)], -2)  # (nx, ny, 2, 2) [i, j, a, b]
    top = corners[:, :, None] + z[None, None, :nz, None, None]
    bottom = top + dzv[None, None, :, None, None]
    zcorn, moved = monotone_zcorn(_corner_depths(top, bottom))
    return coord, zcorn, moved


def index_space_geometry(dims) -> tuple[np.ndarray, np.ndarray]:
    """COORD and ZCORN (float32) of unit cells in IJK index space: cell ``(i, j, k)`` spans
    ``x`` i..i+1, ``y`` j..j+1 and depth k..k+1 (for a grid whose geometry is missing).

    Examples
    --------
    >>> coord, zcorn = index_space_geometry((2, 1, 3))
    >>> coord[2, 1].tolist(), zcorn[0, 0].tolist()
    ([2.0, 1.0, 0.0, 2.0, 1.0, 3.0], [0.0, 1.0, 1.0, 2.0, 2.0, 3.0])
    """
    nx, ny, nz = (int(v) for v in dims)
    coord = np.zeros((nx + 1, ny + 1, 6))
    coord[:, :, 0] = coord[:, :, 3] = np.arange(nx + 1)[:, None]
    coord[:, :, 1] = coord[:, :, 4] = np.arange(ny + 1)[None, :]
    coord[:, :, 5] = nz
    depth = (np.arange(2 * nz, dtype=np.float32) + 1) // 2  # 0 1 1 2 2 ... nz
    zcorn = np.asfortranarray(np.broadcast_to(depth, (2 * nx, 2 * ny, 2 * nz)))
    return coord, zcorn


class BlockCentredKeywords:
    """Reading the block-centred keywords, for :class:`geoshade.io.grids.grdecl.GridBuilder`.

    Cell arrays go to :attr:`block` as ``(nx, ny, nz)`` float64 (NaN where not given, so the
    edit keywords of decks work on them as on properties); vectors and DEPTHZ as 1D/2D float64.
    """

    root: Path
    dims: tuple[int, int, int] | None
    box: tuple | None
    block: dict[str, np.ndarray]

    def need_dims(self, kw, src) -> tuple[int, int, int]:  # pragma: no cover - GridBuilder's
        raise NotImplementedError

    def block_array(self, name: str) -> np.ndarray:
        """The ``(nx, ny, nz)`` array of a cell keyword (created NaN)."""
        arr = self.block.get(name)
        if arr is None:
            nx, ny, nz = self._size()
            check_memory(self.root, f"{name} ({nx * ny * nz} values)", 8 * nx * ny * nz)
            arr = self.block[name] = np.full((nx, ny, nz), np.nan, order="F")
        return arr

    def _size(self) -> tuple[int, int, int]:
        if self.dims is None:  # pragma: no cover - need_dims() came first
            raise InputError(f"{self.root}: block-centred keywords before SPECGRID/DIMENS")
        return self.dims

    def _block_cells(self, kw, src):
        """DX, DY, DZ, TOPS: nx·ny·nz values, or at least nx·ny (the rest from the layer
        above); inside a BOX exactly the box's cells."""
        nx, ny, nz = self.need_dims(kw, src)
        arr = self.block_array(kw)
        if self.box is not None:
            shape = tuple(s.stop - s.start for s in self.box)
            flat = np.empty(int(np.prod(shape)))
            text = ", ".join(f"{s.start + 1}-{s.stop}" for s in self.box)
            src.values(kw, flat.size, flat, f"(BOX {text})")
            arr[self.box] = flat.reshape(shape, order="F")
            return
        flat = np.full(nx * ny * nz, np.nan)
        got = src.values(kw, flat.size, flat, "(nx·ny·nz)", strict=False)
        if not nx * ny <= got <= flat.size:
            what = ("a non-numeric value or a repeat running past the grid" if got < 0 else
                    f"{got} values")
            raise InputError(f"{src.path}: {kw}: expected {nx * ny * nz} values (nx·ny·nz), or "
                             f"at least the top layer's {nx * ny} (nx·ny), got {what}")
        flat[got:] = np.nan  # the layers below take the values of the one above
        arr[...] = flat.reshape((nx, ny, nz), order="F")

    def _block_vector(self, kw, src):
        """DXV (nx values), DYV (ny), DZV (nz); DEPTHZ ((nx+1)·(ny+1), i fastest)."""
        nx, ny, nz = self.need_dims(kw, src)
        n, what = {"DXV": (nx, "(nx)"), "DYV": (ny, "(ny)"), "DZV": (nz, "(nz)"),
                   "DEPTHZ": ((nx + 1) * (ny + 1), "((nx+1)·(ny+1))")}[kw]
        flat = np.empty(n)
        src.values(kw, n, flat, what)
        self.block[kw] = flat if kw != "DEPTHZ" else flat.reshape(ny + 1, nx + 1).T.copy()

    def block_gaps(self) -> list[str]:
        """The keywords block-centred geometry still needs ([] when complete or none read)."""
        have = set(self.block)
        if not have or {"DXV", "DYV", "DZV", "DEPTHZ"} <= have:
            return []
        return [k for k in CELL_KEYWORDS if k not in have and f"{k}V" not in have]

    def block_geometry(self, path) -> tuple[np.ndarray, np.ndarray, str, float]:
        """COORD, ZCORN (float32), a name of the geometry and the largest depth made monotone
        (the keywords must be complete: :meth:`block_gaps`)."""
        nx, ny, nz = self._size()
        check_memory(path, f"ZCORN of the block-centred grid ({8 * nx * ny * nz} values)",
                     80 * nx * ny * nz)  # two float32 ZCORNs and the cell arrays made whole
        have = set(self.block)
        if {"DXV", "DYV", "DZV", "DEPTHZ"} <= have:
            vec = {k: self.block[k] for k in ("DXV", "DYV", "DZV", "DEPTHZ")}
            for k, v in vec.items():
                _check_values(path, k, v, k != "DEPTHZ")
            coord, zcorn, moved = depthz_geometry(vec["DXV"], vec["DYV"], vec["DZV"],
                                                  vec["DEPTHZ"])
            return coord, zcorn, "block-centred (DXV, DYV, DZV, DEPTHZ)", moved
        arrays = {}
        for axis, k in enumerate(("DX", "DY", "DZ")):
            arr = self.block.get(k)
            if arr is None:  # DXV scattered along its axis
                shape = [1, 1, 1]
                shape[axis] = -1
                arr = np.broadcast_to(self.block[f"{k}V"].reshape(shape), self._size()).copy()
            else:
                arr = fill_layers(arr)
            _check_values(path, k, arr, True)
            arrays[k] = arr
        tops = self.block["TOPS"]
        _check_values(path, "TOPS", tops[:, :, :1], False)
        tops = fill_tops(tops, arrays["DZ"])
        coord, zcorn, moved = dtops_geometry(arrays["DX"], arrays["DY"], arrays["DZ"], tops)
        used = ", ".join(k if k in self.block else f"{k}V" for k in ("DX", "DY", "DZ"))
        return coord, zcorn, f"block-centred ({used}, TOPS)", moved


def _check_values(path, kw: str, arr: np.ndarray, size: bool) -> None:
    """Every value given and finite (a size also >= 0); else one line naming the first cell."""
    bad = ~np.isfinite(arr)
    if size:
        bad |= arr < 0
    if not bad.any():
        return
    where = np.argwhere(bad)[0]
    first = arr[tuple(where)]
    cell = " ".join(f"{n}={int(v) + 1}" for n, v in zip("ijk", where, strict=False))
    if arr.ndim == 1:
        cell = f"entry {int(where[0]) + 1}"
    elif kw == "DEPTHZ":
        cell = f"pillar i={int(where[0]) + 1} j={int(where[1]) + 1}"
    else:
        cell = f"cell {cell}"
    if np.isnan(first):
        raise InputError(f"{path}: {kw}: no value for {cell}; expected a value for every cell "
                         "of the top layer at least (BOX, EQUALS or the array)")
    want = "a finite size >= 0" if size else "a finite depth"
    raise InputError(f"{path}: {kw}: value {first:g} at {cell}; expected {want}")


__all__ = ["CELL_KEYWORDS", "KEYWORDS", "VECTOR_KEYWORDS", "BlockCentredKeywords",
           "depthz_geometry", "dtops_geometry", "fill_layers", "fill_tops",
           "index_space_geometry", "monotone_zcorn"]
