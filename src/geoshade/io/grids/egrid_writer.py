"""EGRID and INIT writers (binary ECLIPSE output files, through resfo).

:func:`write_egrid` writes the main grid as simulators do and as xtgeo and OPM read it::

    FILEHEAD   100 INTE   version 3, year 2007, version bound 3, corner-point grid, single
                          porosity, irregular corner point (xtgeo's defaults)
    MAPUNITS   1 CHAR     (with MAPAXES) the map's unit
    MAPAXES    6 REAL     (when the grid has them)
    GRIDUNIT   2 CHAR     the length unit and '' (grid coordinates relative to the origin)
    GRIDHEAD   100 INTE   1 (corner point), NX, NY, NZ, 0, ..., [24] 1 reservoir, [25] 1 segment
    COORD      6(NX+1)(NY+1) REAL
    ZCORN      8 NX NY NZ REAL
    ACTNUM     NX NY NZ INTE
    ENDGRID    0 INTE

:func:`write_init` writes a minimal INIT beside it: ``INTEHEAD`` (411 INTE: the unit system at
[2], NX NY NZ and the active cells at [8:12], corner-point grid at [13], phases at [14], the
first report date at [64:67], simulator ECLIPSE 100 at [94]), ``LOGIHEAD`` (121 LOGI, all
false: single porosity), ``DOUBHEAD`` (229 DOUB, zeros), ``PORV`` on every cell when given,
then every static property on the *active* cells (REAL, or INTE for integer properties), as
simulators write them.

The formats store float32 (REAL): COORD and ZCORN keep 7 significant digits there (a GRDECL
keeps every digit). Both writers write to a temporary file in the destination folder and
rename it into place: a failed write leaves nothing.
"""

from __future__ import annotations

import datetime
import os
import tempfile
from pathlib import Path

import numpy as np
import resfo

from geoshade.errors import InputError
from geoshade.io.output import publish
from geoshade.models import CornerPointGrid

#: INTEHEAD's unit system code of a length unit
UNIT_SYSTEMS = {"METRES": 1, "FEET": 2, "CM": 3}
_INTEHEAD, _LOGIHEAD, _DOUBHEAD = 411, 121, 229


def _kw(name: str) -> str:
    return name.upper().ljust(8)


def _atomic(path, write) -> Path:
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{path}: output folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    os.close(fd)
    try:
        write(tmp)
        publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def check_keywords(grid: CornerPointGrid, where: str = "") -> None:
    """Refuse property names that are no ECLIPSE keyword (1 to 8 characters, no blanks)."""
    for name in grid.properties:
        n = str(name)
        if not 1 <= len(n) <= 8 or n != n.strip() or " " in n or not n.isascii():
            raise InputError(f"{where}property {n!r}: an ECLIPSE keyword has 1 to 8 ASCII "
                             "characters and no blanks; rename it before writing")


def egrid_records(grid: CornerPointGrid):
    """The (keyword, array) records of the EGRID of ``grid``, made one at a time."""
    nx, ny, nz = grid.dims
    head = np.zeros(100, np.int32)
    head[[0, 1, 3]] = (3, 2007, 3)
    yield "FILEHEAD", head
    unit = str(grid.units or "").upper()
    if grid.mapaxes is not None:
        yield "MAPUNITS", np.array([(unit or "METRES").ljust(8)])
        yield _kw("MAPAXES"), np.asarray(grid.mapaxes, np.float32)
    if unit:
        yield "GRIDUNIT", np.array([unit[:8].ljust(8), " " * 8])
    gh = np.zeros(100, np.int32)
    gh[:4] = (1, nx, ny, nz)
    gh[24], gh[25] = 1, 1
    yield "GRIDHEAD", gh
    yield _kw("COORD"), np.asarray(grid.coord).transpose(1, 0, 2).reshape(-1).astype(
        np.float32)
    yield _kw("ZCORN"), np.asarray(grid.zcorn).reshape(-1, order="F").astype(np.float32)
    yield _kw("ACTNUM"), np.asarray(grid.actnum).reshape(-1, order="F").astype(np.int32)
    yield _kw("ENDGRID"), np.zeros(0, np.int32)


def write_egrid(grid: CornerPointGrid, path) -> Path:
    """Write ``grid``'s geometry and ACTNUM as a binary EGRID file (atomic).

    Examples
    --------
    >>> import os, tempfile, resfo
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> f = write_egrid(synthetic_grid(4, 3, 2), os.path.join(tempfile.mkdtemp(), "S.EGRID"))
    >>> [kw.strip() for kw, _ in resfo.read(f)]
    ['FILEHEAD', 'MAPUNITS', 'MAPAXES', 'GRIDUNIT', 'GRIDHEAD', 'COORD', 'ZCORN', 'ACTNUM', \
'ENDGRID']
    """

    return _atomic(path, lambda tmp: resfo.write(tmp, egrid_records(grid)))


def _first_date(grid: CornerPointGrid) -> tuple[int, int, int]:
    for d in grid.step_dates:
        try:
            t = datetime.date.fromisoformat(str(d)[:10])
            return t.day, t.month, t.year
        except ValueError:
            continue
    return 0, 0, 0


def init_records(grid: CornerPointGrid, porv=None):
    """The (keyword, array) records of the INIT of ``grid``, made one at a time."""
    nx, ny, nz = grid.dims
    mask = grid.active.reshape(-1, order="F")
    head = np.zeros(_INTEHEAD, np.int32)
    declared = {"METRIC": 1, "FIELD": 2, "LAB": 3, "PVT-M": 4}.get(
        str(grid.meta.get("unit_system") or "").upper())   # the case's (RUNSPEC, INTEHEAD)
    head[2] = declared or UNIT_SYSTEMS.get(str(grid.units or "").upper(), 1)
    head[8:12] = (nx, ny, nz, int(mask.sum()))
    head[13], head[14] = 0, 7
    head[64:67] = _first_date(grid)
    head[94] = 100
    yield "INTEHEAD", head
    yield "LOGIHEAD", np.zeros(_LOGIHEAD, bool)
    yield "DOUBHEAD", np.zeros(_DOUBHEAD, np.float64)
    if porv is not None:
        yield _kw("PORV"), np.asarray(porv).reshape(-1, order="F").astype(np.float32)
    for name, arr in grid.properties.items():
        a = np.asarray(arr).reshape(-1, order="F")[mask]
        a = a.astype(np.int32) if a.dtype.kind in "iub" else a.astype(np.float32)
        yield _kw(str(name)), a


def write_init(grid: CornerPointGrid, path, porv=None) -> Path:
    """Write a minimal INIT file of ``grid``: headers, ``porv`` ((nx, ny, nz) pore volumes on
    every cell, when given) and every static property on the active cells (atomic).

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.io.grids.ecl import read_init
    >>> g = synthetic_grid(4, 3, 2)
    >>> f = write_init(g, os.path.join(tempfile.mkdtemp(), "S.INIT"))
    >>> poro = read_init(f, g)["PORO"]
    >>> bool(np.array_equal(poro[g.active], g.properties["PORO"][g.active]))
    True
    """

    check_keywords(grid, f"{path}: ")
    if porv is not None and np.shape(porv) != grid.dims:
        raise InputError(f"{path}: PORV: expected shape {grid.dims}, got {np.shape(porv)}")
    return _atomic(path, lambda tmp: resfo.write(tmp, init_records(grid, porv)))


__all__ = ["UNIT_SYSTEMS", "check_keywords", "egrid_records", "init_records", "write_egrid",
           "write_init"]
