"""Dual-porosity and dual-permeability ECLIPSE cases (``DUALPORO``, ``DUALPERM``): a matrix and a
fracture medium on one geometry.

How the files lay them out (ECLIPSE File Formats Reference; resdata's ``rd_grid.cpp``
"About dual porosity"; ResInsight reads them through resdata):

- **EGRID**: ``FILEHEAD`` item 6 (index 5) is 1 (dual porosity) or 2 (dual permeability);
  ``GRIDHEAD`` NZ is the geometric layers; ``ACTNUM`` holds 0 (inactive), 1 (matrix active), 2
  (fracture active) or 3 (both).  A grid written with the deck's doubled NZ instead (the second
  half of the layers repeating the first half's corners, ACTNUM 0/1 per half: the matrix, then
  the fracture) is read as the same two media.
- **INIT and restart arrays**: the matrix's active cells, then the fracture's (resdata's
  ``rd_grid_get_nactive`` + ``rd_grid_get_nactive_fracture``); arrays of every cell (PORV) hold
  the matrix's cells then the fracture's (:class:`~geoshade.io.grids.ecl_restart.CellMap`).
  ``INTEHEAD`` carries the deck's NZ (doubled) or the grid's, and the active cells of both
  media or of the matrix; ``LOGIHEAD`` item 15 (index 14) is true.

The grid shows the matrix (``grid.medium``); :meth:`CornerPointGrid.select_medium` gives the
fracture's cells, properties and report steps.
"""

from __future__ import annotations

import numpy as np

from geoshade.models import CornerPointGrid
from geoshade.models.grid import MEDIA, Medium

__all__ = ["DUAL_KINDS", "dual_kind", "split_media"]

#: FILEHEAD item 6 (index 5) -> the kind of case
DUAL_KINDS = {1: "dual porosity", 2: "dual permeability"}
#: FILEHEAD index of the dual-porosity flag, LOGIHEAD index of "dual porosity"
FILEHEAD_DUALP, LOGIHEAD_DUALP = 5, 14


def dual_kind(filehead) -> str:
    """"dual porosity", "dual permeability" or "" from an EGRID's FILEHEAD (None: "").

    Examples
    --------
    >>> head = np.zeros(100, np.int32); head[5] = 2
    >>> dual_kind(head), dual_kind(None)
    ('dual permeability', '')
    """
    if filehead is None or len(filehead) <= FILEHEAD_DUALP:
        return ""
    return DUAL_KINDS.get(int(filehead[FILEHEAD_DUALP]), "")


def _doubled(grid: CornerPointGrid, raw: np.ndarray | None) -> bool:
    """Whether the grid has the deck's doubled NZ: ACTNUM 0/1, an even NZ, and the second half
    of the layers on the first half's corners."""
    nz = grid.dims[2]
    if nz % 2 or (raw is not None and raw.size and int(raw.max()) > 1):
        return False
    z = np.asarray(grid.zcorn)
    return bool(np.array_equal(z[:, :, :nz], z[:, :, nz:]))


def split_media(grid: CornerPointGrid, raw: np.ndarray | None, kind: str, path
                ) -> CornerPointGrid:
    """``grid`` as a dual grid: ``dual_media`` matrix and fracture from ACTNUM's values
    ``raw`` (see the module text), ``medium`` "matrix", ``meta["dual"]`` ``kind``.

    Examples
    --------
    >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1, 2)], float)
    >>> zc = np.repeat([[[0.0, 1.0]]], 4, 0).repeat(2, 1)
    >>> g = CornerPointGrid(coord, zc)
    >>> d = split_media(g, np.array([3, 1], np.int32).reshape(2, 1, 1), "dual porosity", "G")
    >>> d.media, d.nactive, d.select_medium("fracture").nactive
    (('matrix', 'fracture'), 2, 1)
    """
    nx, ny, nz = grid.dims
    if raw is None:
        raw = np.full((nx, ny, nz), 3, np.int32)
    zcorn, actnum = grid.zcorn, raw
    if _doubled(grid, raw):
        half = nz // 2
        zcorn = np.asarray(grid.zcorn)[:, :, :2 * half]
        matrix = np.asarray(raw[:, :, :half] != 0, np.uint8)
        fracture = np.asarray(raw[:, :, half:] != 0, np.uint8)
        layout = f"NZ {nz} doubled: layers 1..{half} matrix, {half + 1}..{nz} fracture"
    else:
        matrix = np.asarray((actnum & 1) != 0, np.uint8)
        fracture = np.asarray((actnum & 2) != 0, np.uint8)
        layout = "ACTNUM 1 matrix, 2 fracture, 3 both"
    media = {name: Medium(name, act) for name, act in zip(MEDIA, (matrix, fracture),
                                                           strict=True)}
    meta = {**grid.meta, "dual": kind, "dual_layout": layout}
    return CornerPointGrid(grid.coord, np.asfortranarray(zcorn), actnum=matrix,
                           mapaxes=grid.mapaxes, units=grid.units, name=grid.name, meta=meta,
                           medium="matrix", dual_media=media)
