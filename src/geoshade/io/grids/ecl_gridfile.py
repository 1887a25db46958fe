"""The old ECLIPSE GRID file (``CASE.GRID``, formatted ``CASE.FGRID``): every cell's corners.

Layout (ECLIPSE File Formats Reference, "GRID file"; resdata's ``rd_grid_alloc_GRID__`` and
``rd_grid_set_cell_GRID``), records as in every ECLIPSE output file (:mod:`ecl_records`):

- ``MAPUNITS``, ``MAPAXES``, ``GRIDUNIT`` (optional), ``DIMENS`` (NX, NY, NZ), ``RADIAL``;
- one ``COORDS`` + ``CORNERS`` pair a cell, i fastest, then j, then k: ``COORDS`` holds I, J, K
  (1-based) and, when longer than 4, the cell's number, active (1/0) and, for 7 items, the host
  cell (an LGR's cell) and the coarsening group; ``CORNERS`` the 8 corners' x, y, z (corner
  ``a + 2b + 4c``: a along i, b along j, c down; the top four first).  With ``GRIDFILE 1`` only
  the active cells are written;
- each local grid refinement after the global cells: ``LGR`` (name, parent), ``DIMENS``,
  ``LGRILG`` (its host box), its cells (``COORDS`` item 6: the host cell in the parent, 1-based);
- a dual-porosity run writes NZ doubled, the fracture cells (K > NZ/2) on the matrix cells'
  corners: told apart as resdata does (even NZ, the second half's corners equal the first's)
  and read as two media (:mod:`geoshade.io.grids.ecl_dual`).

The grid is turned into the corner-point form the rest of geoshade uses: ZCORN straight from
the corners' depths, each pillar through the topmost and the bottommost corner on it
(vertical where they coincide); pillars that no written cell touches take their neighbours'.
Binary files are read with numpy a block of cells at a time (each record's markers, keyword,
count and type checked), not record by record.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import Record, file_format, scan
from geoshade.io.grids.grid_checks import check_grid_size, check_memory
from geoshade.io.grids.lgr import host_box
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid
from geoshade.models.grid import MEDIA, Medium, Refinement

__all__ = ["GRID_FILE_SUFFIXES", "is_ecl_grid", "read_ecl_grid"]

#: suffixes of a GRID file (upper case; ``F``: formatted)
GRID_FILE_SUFFIXES = (".GRID", ".FGRID")
#: the keywords one of which opens a GRID file
_FIRST = {"DIMENS", "MAPUNITS", "MAPAXES", "GRIDUNIT", "RADIAL", "GDORIENT"}
#: cells read at a time on the binary path
_BLOCK_CELLS = 1 << 16


def is_ecl_grid(path) -> bool:
    """Whether ``path`` is an ECLIPSE GRID file (a binary record header, or a formatted
    ``'DIMENS  '`` one, of a GRID keyword) rather than GRDECL text under the same suffix.

    Examples
    --------
    >>> import os, tempfile, numpy as np, resfo
    >>> d = tempfile.mkdtemp()
    >>> resfo.write(os.path.join(d, "A.GRID"), [("DIMENS  ", np.int32([1, 1, 1]))])
    >>> with open(os.path.join(d, "B.grid"), "w") as f:
    ...     _ = f.write("SPECGRID\\n 1 1 1 1 F /\\n")
    >>> is_ecl_grid(os.path.join(d, "A.GRID")), is_ecl_grid(os.path.join(d, "B.grid"))
    (True, False)
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(64)
    except OSError:
        return False
    if len(head) >= 12 and int.from_bytes(head[:4], "big") == 16:
        return head[4:12].decode("latin-1").strip() in _FIRST
    text = head.lstrip()
    if text[:1] == b"'":
        return text[1:9].decode("latin-1").strip() in _FIRST
    return False


def _cell_dtype(nc: int) -> np.dtype:
    """One cell's COORDS + CORNERS records as they lie in a binary file."""
    return np.dtype([("h1", ">i4"), ("k1", "S8"), ("n1", ">i4"), ("t1", "S4"), ("e1", ">i4"),
                     ("m1", ">i4"), ("coords", ">i4", (nc,)), ("m2", ">i4"),
                     ("h2", ">i4"), ("k2", "S8"), ("n2", ">i4"), ("t2", "S4"), ("e2", ">i4"),
                     ("m3", ">i4"), ("corners", ">f4", (24,)), ("m4", ">i4")])


def _cell_blocks(p: Path, start: int, nc: int) -> tuple[int, list, list]:
    """(cells, COORDS pieces, CORNERS pieces) of the run of whole, well-formed cell records of
    a binary file from byte ``start``: every marker, keyword, count and type checked with numpy;
    the run ends at the first record that is not a cell's (an LGR, the file's end)."""
    dt = _cell_dtype(nc)
    size = p.stat().st_size
    count, coords, corners = 0, [], []
    with open(p, "rb") as fh:
        pos = start
        while pos + dt.itemsize <= size:
            n = min(_BLOCK_CELLS, (size - pos) // dt.itemsize)
            fh.seek(pos)
            a = np.fromfile(fh, dtype=dt, count=n)
            ok = ((a["h1"] == 16) & (a["e1"] == 16) & (a["h2"] == 16) & (a["e2"] == 16)
                  & (a["k1"] == b"COORDS  ") & (a["n1"] == nc) & (a["t1"] == b"INTE")
                  & (a["m1"] == 4 * nc) & (a["m2"] == 4 * nc)
                  & (a["k2"] == b"CORNERS ") & (a["n2"] == 24) & (a["t2"] == b"REAL")
                  & (a["m3"] == 96) & (a["m4"] == 96))
            good = int(np.argmin(ok)) if not ok.all() else n
            coords.append(a["coords"][:good].astype(np.int64))
            corners.append(a["corners"][:good].astype(np.float64))
            count += good
            pos += good * dt.itemsize
            if good < n:
                break
    return count, coords, corners


class _Part:
    """The records of one grid of the file (the global grid or an LGR) as they are read."""

    def __init__(self, name: str = "", parent: str = ""):
        self.name, self.parent = name, parent
        self.head: dict[str, Record] = {}
        self.coords: list[np.ndarray] = []
        self.corners: list[np.ndarray] = []

    def what(self) -> str:
        return f"LGR {self.name}: " if self.name else ""


def _walk(p: Path, formatted: bool) -> list[_Part]:
    """The grids of a GRID file with their cells' COORDS and CORNERS."""
    parts = [_Part()]
    pos, prev = 0, ""
    while True:
        jumped = False
        for rec in scan(p, pos, prev):
            kw, cur = rec.keyword, parts[-1]
            if kw == "COORDS" and not formatted and rec.length in (4, 5, 7):
                n, co, cn = _cell_blocks(p, rec.start, rec.length)
                if n:
                    cur.coords += co
                    cur.corners += cn
                    pos = rec.start + n * _cell_dtype(rec.length).itemsize
                    prev, jumped = "CORNERS", True
                    break
            if kw == "COORDS":
                cur.coords.append(np.asarray(rec.read("i"), np.int64)[None, :])
            elif kw == "CORNERS":
                if len(cur.corners) >= len(cur.coords):
                    raise InputError(f"{p}: {cur.what()}CORNERS: at byte {rec.start} without "
                                     "its cell's COORDS before it")
                v = np.asarray(rec.read("f"), np.float64)
                if v.size != 24:
                    raise InputError(f"{p}: {cur.what()}CORNERS: expected 24 values (8 "
                                     f"corners × x, y, z), got {v.size} at byte {rec.start}")
                cur.corners.append(v[None, :])
            elif kw == "LGR":
                names = [bytes(v).decode(errors="replace").strip().upper()
                         for v in rec.read("S")]
                parts.append(_Part(names[0] if names else f"LGR{len(parts)}",
                                   names[1] if len(names) > 1 and names[1] != "GLOBAL" else ""))
            else:
                cur.head.setdefault(kw, rec)
        if not jumped:
            return parts


def _dims(p: Path, part: _Part) -> tuple[int, int, int]:
    if "DIMENS" not in part.head:
        raise InputError(f"{p}: {part.what()}DIMENS: not found; expected an ECLIPSE GRID file")
    d = part.head["DIMENS"].read("i")
    if d.size < 3 or min(int(v) for v in d[:3]) < 1:
        raise InputError(f"{p}: {part.what()}DIMENS: expected 3 positive integers (NX, NY, NZ), "
                         f"got {np.asarray(d[:3]).tolist()}")
    return int(d[0]), int(d[1]), int(d[2])


def _cells(p: Path, part: _Part, dims) -> tuple[np.ndarray, np.ndarray]:
    """(COORDS (n, 4|5|7), CORNERS (n, 8, 3)) of a grid, checked against its DIMENS."""
    nx, ny, nz = dims
    if not part.coords:
        raise InputError(f"{p}: {part.what()}COORDS: no cells; expected a COORDS and a CORNERS "
                         f"record for each of the {nx * ny * nz} cells (or the active ones)")
    widths = {c.shape[1] for c in part.coords}
    if len(widths) > 1 or widths - {4, 5, 7}:
        raise InputError(f"{p}: {part.what()}COORDS: {sorted(widths)} values a cell; expected "
                         "4, 5 or 7 (I J K [number active [host coarsening]])")
    co = np.concatenate(part.coords)
    if sum(len(c) for c in part.corners) != len(co):
        raise InputError(f"{p}: {part.what()}CORNERS: {sum(len(c) for c in part.corners)} "
                         f"records for {len(co)} cells; expected one after each COORDS")
    cn = np.concatenate(part.corners).reshape(-1, 8, 3)
    ijk = co[:, :3] - 1
    bad = (ijk < 0).any(1) | (ijk >= np.array(dims)).any(1)
    if bad.any():
        q = int(np.argmax(bad))
        raise InputError(f"{p}: {part.what()}COORDS: cell {q + 1} is I={co[q, 0]} J={co[q, 1]} "
                         f"K={co[q, 2]}, outside DIMENS {nx}×{ny}×{nz}")
    if not np.isfinite(cn).all() or np.abs(cn).max() > 1e10:
        q = int(np.argmax(~(np.abs(cn) <= 1e10).all(axis=(1, 2))))
        raise InputError(f"{p}: {part.what()}CORNERS: cell I={co[q, 0]} J={co[q, 1]} "
                         f"K={co[q, 2]} has a corner that is not a finite coordinate")
    return co, cn


def _dual(dims, co: np.ndarray, cn: np.ndarray) -> bool:
    """resdata's test: an even NZ, every cell written, the second half on the first's
    corners."""
    nx, ny, nz = dims
    n = nx * ny * nz
    if nz % 2 or len(co) != n:
        return False
    flat = (co[:, 0] - 1) + nx * ((co[:, 1] - 1) + ny * (co[:, 2] - 1))
    order = np.argsort(flat, kind="stable")
    if not np.array_equal(flat[order], np.arange(n)):
        return False
    c = cn[order]
    return bool(np.array_equal(c[: n // 2], c[n // 2:]))


def _pillars(nx: int, ny: int, pid: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(nx+1, ny+1, 6) pillars through the topmost and bottommost of the points on each."""
    npil = (nx + 1) * (ny + 1)
    order = np.lexsort((pts[:, 2], pid))
    sp = pid[order]
    first = np.r_[True, sp[1:] != sp[:-1]]
    last = np.r_[sp[1:] != sp[:-1], True]
    out = np.full((npil, 6), np.nan)
    out[sp[first], :3] = pts[order[first]]
    out[sp[last], 3:] = pts[order[last]]
    flat = np.abs(out[:, 5] - out[:, 2]) == 0
    out[flat, 3:5] = out[flat, 0:2]
    out[flat, 5] = out[flat, 2] + 1.0  # one depth only: a vertical pillar through it
    grid = out.reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2).copy()
    missing = np.isnan(grid[..., 0])
    while missing.any():  # pillars no written cell touches: their neighbours' (inactive cells)
        if missing.all():
            raise InputError("no cell corners to place the pillars")
        for axis in (0, 1):
            for shift in (1, -1):
                src = np.roll(grid, shift, axis)
                ok = ~np.isnan(np.roll(grid[..., 0], shift, axis))
                edge = [slice(None)] * 2
                edge[axis] = 0 if shift == 1 else -1
                ok[tuple(edge)] = False
                take = missing & ok
                grid[take] = src[take]
                missing &= ~take
    return grid


def _corner_point(p: Path, part: _Part, dims, co: np.ndarray, cn: np.ndarray
                  ) -> tuple[CornerPointGrid, np.ndarray]:
    """The corner-point grid of a part's cells, and its ACTNUM (0 where a cell is not
    written)."""
    nx, ny, nz = dims
    check_grid_size(p, f"{part.what()}DIMENS", (nx, ny, nz))
    check_memory(p, f"the corners of {len(co)} cells", len(co) * 8 * 3 * 8 * 3)
    i, j, k = (co[:, q] - 1 for q in range(3))
    act = np.zeros((nx, ny, nz), np.uint8, order="F")
    act[i, j, k] = co[:, 4] != 0 if co.shape[1] >= 5 else 1
    written = np.zeros((nx, ny, nz), bool, order="F")
    written[i, j, k] = True
    a, b, c = (np.arange(8) >> s & 1 for s in (0, 1, 2))
    pid = ((i[:, None] + a) + (nx + 1) * (j[:, None] + b)).ravel()
    coord = _pillars(nx, ny, pid, cn.reshape(-1, 3))
    zcorn = np.zeros((2 * nx, 2 * ny, 2 * nz), np.float32, order="F")
    if not written.all():  # cells not written: flat at their pillars' tops
        zi, zj = np.meshgrid(np.arange(2 * nx), np.arange(2 * ny), indexing="ij")
        top = coord[(zi + 1) // 2, (zj + 1) // 2, 2].astype(np.float32)
        zcorn[:] = top[:, :, None]
    zcorn[2 * i[:, None] + a, 2 * j[:, None] + b, 2 * k[:, None] + c] = cn[:, :, 2]
    grid = CornerPointGrid(coord, zcorn, actnum=act, name=str(p))
    off = _off_pillar(grid, i, j, k, cn)
    if off > 1e-3 * max(1.0, float(np.ptp(cn[:, :, :2]))):
        warnings.warn(f"{p}: {part.what()}CORNERS: corners lie up to {off:.3g} off the straight "
                      "pillars of their columns; drawn on those pillars", stacklevel=3)
    return grid, written


def _off_pillar(grid: CornerPointGrid, i, j, k, cn: np.ndarray) -> float:
    """How far (x, y) the written corners lie from where the corner-point grid puts them."""
    worst, step = 0.0, 1 << 18
    for q in range(0, len(i), step):
        s = slice(q, q + step)
        pts = np.empty((len(i[s]), 8, 3))
        for c in range(8):
            a, b = c & 1, c >> 1 & 1
            pil = grid.coord[i[s] + a, j[s] + b]
            z = cn[s, c, 2]
            dz = pil[:, 5] - pil[:, 2]
            t = np.where(dz != 0, (z - pil[:, 2]) / np.where(dz != 0, dz, 1), 0.0)
            pts[:, c, 0] = pil[:, 0] + t * (pil[:, 3] - pil[:, 0])
            pts[:, c, 1] = pil[:, 1] + t * (pil[:, 4] - pil[:, 1])
        worst = max(worst, float(np.abs(pts[:, :, :2] - cn[s, :, :2]).max(initial=0.0)))
    return worst


def _word(part: _Part, kw: str) -> str:
    if kw not in part.head:
        return ""
    v = part.head[kw].read("S")
    return bytes(v[0]).decode(errors="replace").strip() if len(v) else ""


def read_ecl_grid(path) -> CornerPointGrid:
    """Read an ECLIPSE GRID or FGRID file (see the module text): the global grid, its local
    grid refinements and, for a dual-porosity run, both media.

    Returns
    -------
    CornerPointGrid
        ``meta``: ``format`` "GRID" (or "FGRID"), ``source``, ``mapunits``; ``cells_written``
        when the file holds only some cells (``GRIDFILE 1``: the active ones).

    Raises
    ------
    InputError
        A damaged record, cells outside DIMENS, corners that are not finite (one line).

    Examples
    --------
    >>> import os, tempfile, numpy as np, resfo
    >>> f = os.path.join(tempfile.mkdtemp(), "ONE.GRID")
    >>> corners = np.float32([[x, y, z] for z in (10, 12) for y in (0, 1) for x in (0, 2)])
    >>> resfo.write(f, [("DIMENS  ", np.int32([1, 1, 1])), ("RADIAL  ", ["FALSE"]),
    ...                 ("COORDS  ", np.int32([1, 1, 1, 1, 1])), ("CORNERS ", corners.ravel())])
    >>> g = read_ecl_grid(f)
    >>> g.dims, g.bounds().tolist()
    ((1, 1, 1), [[0.0, 0.0, 10.0], [2.0, 1.0, 12.0]])
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "an ECLIPSE GRID file")
    formatted = file_format(p) == "formatted"
    parts = _walk(p, formatted)
    main = parts[0]
    dims = _dims(p, main)
    co, cn = _cells(p, main, dims)
    nx, ny, nz = dims
    dual = _dual(dims, co, cn)
    if dual:
        half = nx * ny * nz // 2
        flat = (co[:, 0] - 1) + nx * ((co[:, 1] - 1) + ny * (co[:, 2] - 1))
        order = np.argsort(flat, kind="stable")
        co, cn = co[order], cn[order]
        fracture = co[half:]
        co, cn, dims = co[:half], cn[:half], (nx, ny, nz // 2)
    grid, written = _corner_point(p, main, dims, co, cn)
    meta = {"format": "FGRID" if formatted else "GRID", "source": str(p),
            "mapunits": _word(main, "MAPUNITS")}
    if not written.all():
        meta["cells_written"] = int(written.sum())
    mapaxes = main.head["MAPAXES"].read("f") if "MAPAXES" in main.head else None
    kwargs = {}
    if dual:
        fr = np.zeros(dims, np.uint8, order="F")
        fi, fj, fk = fracture[:, 0] - 1, fracture[:, 1] - 1, fracture[:, 2] - 1 - dims[2]
        fr[fi, fj, fk] = fracture[:, 4] != 0 if fracture.shape[1] >= 5 else 1
        media = {name: Medium(name, act) for name, act in
                 zip(MEDIA, (np.asarray(grid.actnum), fr), strict=True)}
        kwargs = {"medium": "matrix", "dual_media": media}
        meta.update(dual="dual porosity", dual_layout=f"NZ {nz} doubled: layers "
                    f"1..{nz // 2} matrix, {nz // 2 + 1}..{nz} fracture")
    out = CornerPointGrid(grid.coord, grid.zcorn, actnum=grid.actnum, mapaxes=mapaxes,
                          units=_word(main, "GRIDUNIT"), name=str(p), meta=meta, **kwargs)
    out.refinements = _refinements(p, parts[1:], out)
    return out


def _refinements(p: Path, parts: list[_Part], grid: CornerPointGrid) -> list[Refinement]:
    """The LGRs of a GRID file: each a grid of its own, its host cells from COORDS item 6."""
    out: list[Refinement] = []
    grids = {"": grid}
    for part in parts:
        what = part.what()
        if part.parent not in grids:
            raise InputError(f"{p}: {what}LGR: parent {part.parent} is not a grid defined "
                             "before it")
        dims = _dims(p, part)
        co, cn = _cells(p, part, dims)
        if co.shape[1] < 7:
            raise InputError(f"{p}: {what}COORDS: {co.shape[1]} values a cell; an LGR's cells "
                             "need 7 (item 6: the host cell)")
        sub, written = _corner_point(p, part, dims, co, cn)
        if not written.all():
            raise InputError(f"{p}: {what}COORDS: {int(written.sum())} of the LGR's "
                             f"{written.size} cells written; expected all")
        host = grids[part.parent]
        hn = np.zeros(dims, np.int64, order="F")
        hn[co[:, 0] - 1, co[:, 1] - 1, co[:, 2] - 1] = co[:, 5] - 1
        if int(hn.min()) < 0 or int(hn.max()) >= host.ncells:
            raise InputError(f"{p}: {what}COORDS: a host cell outside the parent grid's "
                             f"{host.ncells} cells")
        sub.name = f"{p} (LGR {part.name})"
        sub.meta.update(format=grid.meta["format"], source=str(p), lgr=part.name,
                        parent=part.parent)
        out.append(Refinement(part.name, part.parent, hn, host_box(hn.ravel(order="F"),
                                                                   host.dims), sub))
        grids[part.name] = sub
    return out
