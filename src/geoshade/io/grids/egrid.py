"""EGRID and FEGRID files: the global grid, its local grid refinements and its dual media.

An EGRID is a chain of sections (ECLIPSE File Formats Reference; resdata's ``rd_grid.cpp``;
OPM's ``EGrid.cpp``), every record header checked first (:mod:`ecl_records`):

- the **global grid**: ``FILEHEAD`` (item 6, index 5: 0 single porosity, 1 dual porosity, 2
  dual permeability), ``MAPUNITS``, ``MAPAXES``, ``GRIDUNIT``, ``GRIDHEAD`` (type 1, NX, NY,
  NZ), ``COORD``, ``ZCORN``, ``ACTNUM``, ``ENDGRID``;
- one section per **local grid refinement**: ``LGR`` (its name), ``LGRPARNT`` (the parent's
  name, blank for the global grid), ``GRIDHEAD`` (type, NX, NY, NZ, LGR number), ``COORD``,
  ``ZCORN``, ``ACTNUM`` and ``HOSTNUM`` (each refined cell's host cell in the parent, 1-based,
  i fastest), ``ENDGRID``, ``ENDLGR`` (:mod:`geoshade.io.grids.lgr`);
- non-neighbour connections (``NNCHEAD``, ``NNC1`` …): not read.

A dual-porosity or dual-permeability grid (FILEHEAD) is read with both media
(:mod:`geoshade.io.grids.ecl_dual`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_dual import dual_kind, split_media
from geoshade.io.grids.ecl_records import Record, file_format, scan
from geoshade.io.grids.grid_checks import check_grid_size, warn_inverted
from geoshade.io.grids.lgr import read_refinements
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid

__all__ = ["egrid_sections", "grid_from_records", "read_egrid"]

#: EGRID keywords of a grid section that are read, and the kinds of values they must hold
GRID_KEYWORDS = {"GRIDHEAD": "i", "COORD": "f", "ZCORN": "f", "ACTNUM": "i", "MAPAXES": "f",
                 "GRIDUNIT": "S", "MAPUNITS": "S", "FILEHEAD": "i", "LGR": "S",
                 "LGRPARNT": "S", "HOSTNUM": "i"}


def egrid_sections(path: Path) -> tuple[dict[str, Record], list[dict[str, Record]], str, bool]:
    """The records of an EGRID by section: (the global grid's records by keyword, each LGR
    section's records by keyword, the last keyword of the global section, whether its ENDGRID
    was found).  Every header of the file is checked before any array is read."""
    main: dict[str, Record] = {}
    lgrs: list[dict[str, Record]] = []
    cur: dict[str, Record] | None = None
    last, ended = "", False
    for rec in scan(path):
        kw = rec.keyword
        if not ended:
            ended = kw == "ENDGRID"
            if kw in GRID_KEYWORDS:
                main.setdefault(kw, rec)
            last = kw
        elif kw == "LGR":
            cur = {"LGR": rec}
            lgrs.append(cur)
        elif kw in ("ENDLGR", "NNCHEAD", "NNCHEADA"):
            cur = None
        elif cur is not None and (kw in GRID_KEYWORDS or kw == "ENDGRID"):
            cur.setdefault(kw, rec)
    return main, lgrs, last, ended


def word(recs: dict[str, Record], kw: str) -> str:
    """The first string of record ``kw`` stripped ("" when there is none)."""
    if kw not in recs:
        return ""
    v = recs[kw].read("S")
    return bytes(v[0]).decode(errors="replace").strip() if len(v) else ""


def grid_head(p: Path, recs: dict[str, Record], what: str = "") -> tuple[int, int, int]:
    """(NX, NY, NZ) of a section's GRIDHEAD, checked (one line naming ``what``)."""
    if "GRIDHEAD" not in recs:
        raise InputError(f"{p}: {what}GRIDHEAD: not found; expected an EGRID file")
    head = recs["GRIDHEAD"].read("i")
    if head.size < 4:
        raise InputError(f"{p}: {what}GRIDHEAD: expected at least 4 integers (type, NX, NY, NZ), "
                         f"got {head.size}")
    if int(head[0]) != 1:
        raise InputError(f"{p}: {what}GRIDHEAD: grid type {int(head[0])} is not supported; "
                         "expected 1 (corner point)")
    nx, ny, nz = (int(v) for v in head[1:4])
    if min(nx, ny, nz) < 1:
        raise InputError(f"{p}: {what}GRIDHEAD: grid size {nx}×{ny}×{nz} is not positive")
    return nx, ny, nz


def grid_from_records(p: Path, recs: dict[str, Record], formatted: bool, what: str = ""
                      ) -> tuple[CornerPointGrid, np.ndarray | None]:
    """The corner-point grid of one EGRID section, and its ACTNUM values as the file has them
    (0..3 in a dual-porosity grid; None without ACTNUM).  ``what`` prefixes the keyword in
    messages (``"LGR LGR1: "``)."""
    nx, ny, nz = grid_head(p, recs, what)
    n = nx * ny * nz
    per = 16 if formatted else 32  # 8 ZCORN values of 4 bytes (formatted: 2 at least) a cell
    if per * n > p.stat().st_size:
        raise InputError(f"{p}: {what}GRIDHEAD: a {nx}×{ny}×{nz} grid needs {8 * n:.3g} ZCORN "
                         f"values ({per * n:.3g} bytes); the file has {p.stat().st_size} bytes")
    for kw, want, how in (("COORD", 6 * (nx + 1) * (ny + 1), "(6·(nx+1)·(ny+1))"),
                          ("ZCORN", 8 * n, "(2·nx·2·ny·2·nz)"), ("ACTNUM", n, "(nx·ny·nz)")):
        if kw not in recs:
            if kw == "ACTNUM":
                continue
            raise InputError(f"{p}: {what}{kw}: not found; expected {want} values {how}")
        if recs[kw].length != want:
            raise InputError(f"{p}: {what}{kw}: expected {want} values {how} for GRIDHEAD "
                             f"{nx}×{ny}×{nz}, got {recs[kw].length}")
    check_grid_size(p, f"{what}GRIDHEAD", (nx, ny, nz))
    coord = np.asarray(recs["COORD"].read("f"), np.float64).reshape(ny + 1, nx + 1, 6)
    zcorn = _native(recs["ZCORN"].read("f")).reshape((2 * nx, 2 * ny, 2 * nz), order="F")
    raw = actnum = None
    if "ACTNUM" in recs:
        raw = _native(recs["ACTNUM"].read("i")).reshape((nx, ny, nz), order="F")
        actnum = np.asarray(raw != 0, np.uint8)
    mapaxes = recs["MAPAXES"].read("f") if "MAPAXES" in recs else None
    grid = CornerPointGrid(coord=coord.transpose(1, 0, 2), zcorn=zcorn, actnum=actnum,
                           mapaxes=mapaxes, units=word(recs, "GRIDUNIT"),
                           name=f"{p}" + (f" ({what.rstrip(': ')})" if what else ""),
                           meta={"format": "FEGRID" if formatted else "EGRID", "source": str(p),
                                 "mapunits": word(recs, "MAPUNITS")})
    return grid, raw


def _native(a: np.ndarray) -> np.ndarray:
    """The file's big-endian array in native byte order, swapped in place (no copy)."""
    if a.dtype.byteorder in ("=", "|") or a.dtype.isnative:
        return a
    a.byteswap(inplace=True)
    return a.view(a.dtype.newbyteorder("="))


def read_egrid(path) -> CornerPointGrid:
    """Read an EGRID or FEGRID file: the global grid (COORD, ZCORN, ACTNUM, MAPAXES, GRIDUNIT),
    its local grid refinements (``grid.refinements``) and, for a dual-porosity/permeability
    case, both media (``grid.dual_media``, ``grid.medium`` "matrix").

    Non-neighbour connections are not read.

    Returns
    -------
    CornerPointGrid
        COORD float64 (the file's float32 values), ZCORN float32, ACTNUM uint8, properties
        empty, ``meta`` with ``format`` "EGRID" (or "FEGRID"), ``source``, ``mapunits``
        (``dual``: "dual porosity" / "dual permeability" for such a case).

    Examples
    --------
    >>> import numpy as np, os, tempfile, resfo
    >>> f = os.path.join(tempfile.mkdtemp(), "ONE.EGRID")
    >>> head = np.zeros(100, np.int32); head[:4] = (1, 1, 1, 1)
    >>> coord = np.array([0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1],
    ...                  np.float32)
    >>> zc = np.array([0, 0, 0, 0, 1, 1, 1, 1], np.float32)
    >>> resfo.write(f, [("GRIDHEAD", head), ("COORD   ", coord), ("ZCORN   ", zc),
    ...                 ("ACTNUM  ", np.ones(1, np.int32)), ("ENDGRID ", np.zeros(0, np.int32))])
    >>> read_egrid(f).dims
    (1, 1, 1)
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "an ECLIPSE EGRID file")
    formatted = file_format(p) == "formatted"
    main, sections, last, ended = egrid_sections(p)
    grid_head(p, main)
    if not ended:
        nx, ny, nz = grid_head(p, main)
        per = 16 if formatted else 32
        if per * nx * ny * nz <= p.stat().st_size:
            raise InputError(f"{path}: ENDGRID: not found after the main grid; the file is "
                             f"truncated (it ends after {last})")
    grid, raw = grid_from_records(p, main, formatted)
    grid.name = str(p)
    kind = dual_kind(main["FILEHEAD"].read("i") if "FILEHEAD" in main else None)
    if kind:
        grid = split_media(grid, raw, kind, p)
    if sections:
        grid.refinements = read_refinements(
            p, sections, grid, lambda recs, what: grid_from_records(p, recs, formatted, what)[0])
    warn_inverted(grid, p)
    return grid
