"""numba kernels for corner-point grids of 1e8 cells and more: one pass, no temporaries.

The numpy versions in :mod:`geoshade.compute.grid.faces` and
:mod:`geoshade.models.grid` build a dozen ``(nx, ny, nk)`` boolean arrays per k-slab; at 1e8
cells that is tens of seconds and hundreds of MB in flight.  These kernels read ZCORN and the
shown mask once, cell by cell, and write only the result:

- :func:`active_depth_range`: min/max corner depth of the active cells (the camera's framing);
- :func:`faces_in_slab`: the visible faces of one k-slab in exactly the order of
  :func:`geoshade.compute.grid.faces.visible_faces` (face code, then k, j, i), so the two paths
  are interchangeable and tested equal, face for face.

The kernels are serial and release the GIL (``nogil``): the caller runs slabs on threads
(:func:`geoshade.compute.grid.faces.visible_faces`).  numba's ``parallel=True`` compiled for
~30 s on this 2-core machine, once per argument layout, for no gain over threads.

numba is imported and the kernels compiled (cached on disk) on first use only: small grids keep
the numpy path (:data:`MIN_CELLS`), which saves numba's start-up.
"""

from __future__ import annotations

from functools import cache

import numpy as np

#: grids with fewer cells than this use the numpy paths (numba's start-up costs ~0.5 s)
MIN_CELLS = 1 << 21


@cache
def _kernels() -> dict:
    from geoshade.compute.grid import kernels_numba as k

    return {"depth_range": k.depth_range, "slab_faces": k.slab_faces,
            "drawing_rows": k.drawing_rows, "place_faces": k.place_faces,
            "in_drawing_order": k.in_drawing_order, "color_codes": k.color_codes,
            "face_words": k.face_words, "cell_numbers": k.cell_numbers}


def use_kernels(ncells: int) -> bool:
    """True when a grid of ``ncells`` is large enough for the numba kernels."""
    return ncells >= MIN_CELLS


def active_depth_range(zcorn: np.ndarray, active: np.ndarray, maxabs: float
                       ) -> tuple[float, float] | None:
    """(min, max) corner depth of the active cells over values with ``|z| <= maxabs``; None
    when there is none.  One parallel pass over ZCORN, no temporaries.

    Examples
    --------
    >>> z = np.arange(16, dtype=np.float32).reshape(2, 2, 4, order="F")
    >>> active_depth_range(z, np.array([[[0, 1]]], np.uint8), 1e10)
    (8.0, 15.0)
    """
    lo, hi = _kernels()["depth_range"](_f(zcorn, np.float32), _f(active, np.uint8),
                                       float(maxabs))
    return (float(lo), float(hi)) if lo <= hi else None


def faces_in_slab(zcorn: np.ndarray, shown: np.ndarray, k0: int, k1: int, tol: float = 0.0):
    """Visible faces of the shown cells of layers ``[k0, k1)``: ``(cells (n, 3) int32,
    face (n,) uint8, fault (n,) bool, neighbour_shown (n,) bool)`` in the order of
    :func:`geoshade.compute.grid.faces.visible_faces` (face code, then k, j, i).

    ``shown`` is the whole ``(nx, ny, nz)`` mask (neighbours outside the slab are read from it),
    ``zcorn`` the whole ZCORN.
    """
    return _kernels()["slab_faces"](_f(zcorn, np.float32), _f(shown, np.uint8), float(tol),
                                    int(k0), int(k1))


def drawing_rows(cells: np.ndarray, face: np.ndarray, step: int, ny: int,
                 counts: np.ndarray | None = None) -> tuple[np.ndarray, bool]:
    """``(rows, in_order)``: each face's row of the drawing order (k-slab, face code, k, j;
    int64) and whether the faces are in drawing order already (rows non-decreasing, i
    increasing inside a row); with ``counts`` (int64, one per row of the grid), the faces of
    each row are counted into it and no rows are returned (an empty array).  One compiled
    pass.

    Examples
    --------
    >>> cells = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.int32)
    >>> rows, ok = drawing_rows(cells, np.zeros(3, np.uint8), 1, 2)
    >>> rows.tolist(), ok
    ([0, 0, 1], True)
    >>> counts = np.zeros(12, np.int64)
    >>> drawing_rows(cells, np.zeros(3, np.uint8), 1, 2, counts)[1], counts[:2].tolist()
    (True, [2, 1])
    """
    c = np.ascontiguousarray(cells, np.int32)
    f = np.ascontiguousarray(face, np.uint8)
    rows = np.empty(f.size if counts is None else 0, np.int64)
    ok = _kernels()["drawing_rows"](c, f, int(step), int(ny), rows,
                                    np.zeros(0, np.int64) if counts is None else counts)
    return rows, bool(ok)


def place_faces(part: tuple, step: int, ny: int, cursor: np.ndarray, out: tuple) -> None:
    """Copy one part's ``(cells, face, fault, neighbour_shown[, corners])`` into the columns
    ``out`` (the same, corners ``(n, 4)`` or ``(0, 4)``) at the places of their drawing rows
    (``cursor``: each row's next place, advanced in place): one compiled pass."""
    c = np.ascontiguousarray(part[0], np.int32)
    corners = (np.ascontiguousarray(part[4], np.float32) if len(part) > 4
               else np.zeros((0, 4), np.float32))
    _kernels()["place_faces"](c, np.ascontiguousarray(part[1], np.uint8),
                              np.ascontiguousarray(part[2], np.bool_),
                              np.ascontiguousarray(part[3], np.bool_), corners, int(step),
                              int(ny), cursor, *out)


def in_drawing_order(cells: np.ndarray, face: np.ndarray, step: int, ny: int) -> bool:
    """Whether the faces are in drawing order (see :func:`drawing_rows`): one compiled pass,
    nothing allocated.

    >>> in_drawing_order(np.array([[1, 0, 0], [0, 0, 0]], np.int32), np.zeros(2, np.uint8), 1, 1)
    False
    """
    return bool(_kernels()["in_drawing_order"](np.ascontiguousarray(cells, np.int32),
                                               np.ascontiguousarray(face, np.uint8),
                                               int(step), int(ny)))


def color_codes(values: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """uint8 ``round((v - lo) / (hi - lo) * 255)`` clipped, NaN 0 (one compiled pass, no
    float64 temporaries: ``render/visuals/grid/prepare.color_index`` for many values).

    >>> color_codes(np.array([0.0, 0.5, 1.0, 2.0, np.nan], np.float32), 0.0, 1.0).tolist()
    [0, 128, 255, 255, 0]
    """
    v = np.ascontiguousarray(values).reshape(-1)
    out = np.empty(v.size, np.uint8)
    _kernels()["color_codes"](v, float(lo), float(hi) - float(lo), out)
    return out.reshape(np.shape(values))


def face_words(numbers: np.ndarray, face: np.ndarray, corners: np.ndarray, low_bits: int,
               face_bits: int, z_offset: float, quantise: tuple[float, float] | None
               ) -> tuple[np.ndarray, float]:
    """``render/visuals/grid/prepare.face_records`` from gathered corners in one compiled
    pass: ``(n, 3)`` uint32 with ``quantise=(z0, scale)`` (and the largest error), else
    ``(n, 5)``; the same bits."""
    n = int(np.asarray(face).size)
    words = 3 if quantise is not None else 5
    out = np.empty((n, words), np.uint32)
    z0, scale = quantise if quantise is not None else (0.0, 0.0)
    err = _kernels()["face_words"](np.ascontiguousarray(numbers, np.int64),
                                   np.ascontiguousarray(face, np.uint8),
                                   np.ascontiguousarray(corners, np.float32).reshape(-1, 4),
                                   int(low_bits), int(face_bits), float(z0), float(scale),
                                   float(z_offset), out, out.view(np.float32))
    return out, float(err)


def cell_numbers(cells: np.ndarray, nx: int, ny: int) -> np.ndarray:
    """``i + nx (j + ny k)`` (int64) of ``(n, 3)`` cells, one compiled pass (no ``(n, 3)``
    int64 copy).

    >>> cell_numbers(np.array([[1, 2, 1]], np.int32), 4, 3).tolist()
    [21]
    """
    out = np.empty(len(cells), np.int64)
    _kernels()["cell_numbers"](np.ascontiguousarray(cells, np.int32), int(nx), int(ny), out)
    return out


def _f(a, dtype) -> np.ndarray:
    """``a`` as an F-ordered array of ``dtype`` (bool viewed as uint8): one compiled signature
    per kernel; the models' arrays are F-ordered already, so nothing is copied."""
    a = np.asarray(a)
    if a.dtype == bool and dtype == np.uint8:
        a = a.view(np.uint8)
    return np.asfortranarray(a, dtype)
