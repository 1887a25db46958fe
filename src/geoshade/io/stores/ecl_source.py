"""An ECLIPSE/OPM case as a grid-store source: EGRID + INIT + restarts read in pieces at record
offsets (big records are read in pieces, :func:`read_values`), never whole; the ``source`` of the
``eclipse`` row of :mod:`geoshade.io.formats` (``geoshade grid ingest``)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl import case_files
from geoshade.io.grids.ecl_records import Record, RecordError, data_bytes, item_bytes, scan
from geoshade.io.grids.ecl_restart import NOT_CELL, UnrstIndex, check_head
from geoshade.io.stores.grid_sources import GridSource

_BLOCK = 1000
_BE = {"REAL": ">f4", "INTE": ">i4", "LOGI": ">i4", "DOUB": ">f8"}


# --------------------------------------------------------------------------------------------
# reading pieces of big records
# --------------------------------------------------------------------------------------------
def read_values(rec: Record, q0: int, q1: int) -> np.ndarray:
    """Values ``[q0, q1)`` of a record, native byte order, reading only the blocks that hold
    them (an unformatted record: blocks of 1000 values between 4-byte markers).

    Raises
    ------
    RecordError
        A block marker that does not match its block's size (one line naming the keyword).

    Examples
    --------
    >>> import os, tempfile, resfo
    >>> f = os.path.join(tempfile.mkdtemp(), "A.INIT")
    >>> resfo.write(f, [("PORO    ", np.arange(2500, dtype=np.float32))])
    >>> rec = next(iter(scan(f)))
    >>> read_values(rec, 998, 1003).tolist(), read_values(rec, 2498, 2500).tolist()
    ([998.0, 999.0, 1000.0, 1001.0, 1002.0], [2498.0, 2499.0])
    """
    q0, q1 = int(q0), int(min(q1, rec.length))
    if rec.formatted or rec.type not in _BE:
        return np.asarray(rec.read())[q0:q1]
    dt = np.dtype(_BE[rec.type])
    if q1 <= q0:
        return np.zeros(0, dt.newbyteorder("="))
    size = item_bytes(rec.type) or 4
    nb = _BLOCK * size + 8
    start = rec.end - data_bytes(rec.length, rec.type)
    nblocks = -(-rec.length // _BLOCK)
    last_n = rec.length - (nblocks - 1) * _BLOCK
    b0, b1 = q0 // _BLOCK, (q1 - 1) // _BLOCK + 1
    full = b1 - b0 - (1 if b1 == nblocks and last_n != _BLOCK else 0)
    count = full * nb + ((last_n * size + 8) if full < b1 - b0 else 0)
    raw = np.fromfile(rec.path, np.uint8, count=count, offset=start + b0 * nb)
    if raw.size != count:
        raise RecordError(f"{rec.path}: {rec.keyword}: the file ends inside its data "
                          "(truncated)", rec.start, rec.keyword, truncated=True)
    parts, bad = [], False
    if full:
        blk = raw[:full * nb].view(np.dtype([("m0", ">i4"), ("d", dt, (_BLOCK,)),
                                             ("m1", ">i4")]))
        bad |= bool(np.any(blk["m0"] != _BLOCK * size) or np.any(blk["m1"] != _BLOCK * size))
        parts.append(blk["d"].reshape(-1))
    if full < b1 - b0:
        tail = raw[full * nb:]
        m0, m1 = (int.from_bytes(bytes(b), "big", signed=True) for b in (tail[:4], tail[-4:]))
        bad |= m0 != last_n * size or m1 != last_n * size
        parts.append(tail[4:-4].view(dt))
    if bad:
        raise RecordError(f"{rec.path}: {rec.keyword}: damaged record at byte {rec.start} (a "
                          "block marker does not match its block's size)", rec.start,
                          rec.keyword)
    vals = parts[0] if len(parts) == 1 else np.concatenate(parts)
    out = vals[q0 - b0 * _BLOCK:q1 - b0 * _BLOCK]
    return out.astype(dt.newbyteorder("="))


class _Dims:
    """The little of a grid that :class:`~geoshade.io.grids.ecl_restart.UnrstIndex` needs."""

    def __init__(self, dims, nactive: int, name: str):
        self.dims, self.nactive, self.name = tuple(dims), int(nactive), name
        self.ncells = int(np.prod(self.dims))


def _to_cells(vals: np.ndarray, act: np.ndarray, dims, dtype) -> np.ndarray:
    """An active-cell (or all-cell) piece -> ``dims`` F-order, NaN / 0 in inactive cells."""
    dt = np.dtype(dtype)
    if vals.size == int(np.prod(dims)):
        return vals.astype(dt, copy=False).reshape(dims, order="F")
    out = np.full(int(np.prod(dims)), np.nan if dt.kind == "f" else 0, dt)
    out[act.reshape(-1, order="F") != 0] = vals
    return out.reshape(dims, order="F")


def _cell_dtype(type_: str):
    return {"REAL": np.float32, "DOUB": np.float64}.get(type_, np.int32)


class EclSource(GridSource):
    """An ECLIPSE/OPM case (EGRID + INIT + restarts), read in pieces at record offsets."""

    def __init__(self, path):
        files = case_files(path)
        self.files = files
        g = files.grid
        recs: dict[str, Record] = {}
        for rec in scan(g):
            if rec.keyword == "ENDGRID":
                break
            recs.setdefault(rec.keyword, rec)
        if "GRIDHEAD" not in recs:
            raise InputError(f"{g}: GRIDHEAD: not found; expected an EGRID file")
        head = recs["GRIDHEAD"].read("i")
        if head.size < 4 or int(head[0]) != 1 or min(int(v) for v in head[1:4]) < 1:
            raise InputError(f"{g}: GRIDHEAD: expected a corner-point grid (type 1) with "
                             f"positive NX NY NZ, got {head[:4].tolist()}")
        nx, ny, nz = (int(v) for v in head[1:4])
        n = nx * ny * nz
        for kw, want in (("COORD", 6 * (nx + 1) * (ny + 1)), ("ZCORN", 8 * n),
                         ("ACTNUM", n)):
            if kw not in recs:
                if kw == "ACTNUM":
                    continue
                raise InputError(f"{g}: {kw}: not found; expected {want} values")
            if recs[kw].length != want:
                raise InputError(f"{g}: {kw}: expected {want} values for GRIDHEAD "
                                 f"{nx}×{ny}×{nz}, got {recs[kw].length}")
        self.recs, self.dims, self.name = recs, (nx, ny, nz), str(g)

        def word(kw: str) -> str:
            v = recs[kw].read("S") if kw in recs else []
            return bytes(v[0]).decode(errors="replace").strip() if len(v) else ""

        self.units, self.mapunits = word("GRIDUNIT"), word("MAPUNITS")
        self.mapaxes = recs["MAPAXES"].read("f").astype(float) if "MAPAXES" in recs else None
        self.faults = []
        # active cells: counted in pieces (the INIT/UNRST checks need the number)
        nact = n
        if "ACTNUM" in recs:
            nact, step = 0, 1 << 24
            for q in range(0, n, step):
                nact += int(np.count_nonzero(read_values(recs["ACTNUM"], q, q + step)))
        self.nactive = nact
        small = _Dims(self.dims, nact, self.name)
        self.init_recs: dict[str, Record] = {}
        if files.init is None:
            raise InputError(f"{path}: no INIT file beside the EGRID; a case needs EGRID + INIT")
        irecs = list(scan(files.init))
        heads = [r for r in irecs if r.keyword == "INTEHEAD"]
        if not heads:
            raise InputError(f"{files.init}: INTEHEAD: not found; expected an INIT file")
        check_head(files.init, heads[0].read("i"), small)  # type: ignore[arg-type]
        for rec in irecs:
            if (rec.keyword not in NOT_CELL and rec.length in (n, nact) and rec.length
                    and rec.type in ("REAL", "DOUB", "INTE")):
                self.init_recs.setdefault(rec.keyword, rec)
        self.properties = {k: _cell_dtype(r.type) for k, r in self.init_recs.items()}
        self.index = None
        self.step_keywords, self.step_dates, self.step_seqnum = {}, [], []
        if files.restart is not None:
            self.index = UnrstIndex(files.restart, small)  # type: ignore[arg-type]
            kws = [kw for kw in self.index.keywords
                   if all(kw in r for r in self.index.records)]
            self.step_keywords = {kw: _cell_dtype(self.index.records[0][kw].type)
                                  for kw in kws}
            self.step_dates = list(self.index.dates)
            self.step_seqnum = list(self.index.seqnum)
        used = [g, files.init, *([] if files.restart is None else
                                 [files.restart] if isinstance(files.restart, Path)
                                 else files.restart)]
        h = hashlib.sha1()
        for f in used:
            st = Path(f).stat()
            h.update(f"{Path(f).name}|{st.st_size}|{st.st_mtime_ns}\n".encode())
        self.fingerprint = h.hexdigest()
        self.meta = {"format": "EGRID", "mapunits": self.mapunits,
                     "restart": files.restart_meta()}

    def coord(self) -> np.ndarray:
        nx, ny, _ = self.dims
        c = read_values(self.recs["COORD"], 0, 6 * (nx + 1) * (ny + 1)).astype(np.float64)
        return c.reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2)

    def zcorn(self, k0: int, k1: int) -> np.ndarray:
        nx, ny, _ = self.dims
        per = 8 * nx * ny
        v = read_values(self.recs["ZCORN"], k0 * per, k1 * per).astype(np.float32, copy=False)
        return v.reshape((2 * nx, 2 * ny, 2 * (k1 - k0)), order="F")

    def actnum(self, k0: int, k1: int) -> np.ndarray:
        nx, ny, _ = self.dims
        if "ACTNUM" not in self.recs:
            return np.ones((nx, ny, k1 - k0), np.uint8, order="F")
        per = nx * ny
        v = read_values(self.recs["ACTNUM"], k0 * per, k1 * per) != 0
        return v.astype(np.uint8).reshape((nx, ny, k1 - k0), order="F")

    def _piece(self, rec: Record, k0, k1, act, a0, dtype) -> np.ndarray:
        nx, ny, _ = self.dims
        dims = (nx, ny, k1 - k0)
        if rec.length == self.nactive:  # active cells only (all cells when all are active)
            vals = read_values(rec, a0, a0 + int(np.count_nonzero(act)))
        else:
            vals = read_values(rec, k0 * nx * ny, k1 * nx * ny)
        return _to_cells(vals, act, dims, dtype)

    def prop(self, name, k0, k1, act, a0) -> np.ndarray:
        return self._piece(self.init_recs[name], k0, k1, act, a0, self.properties[name])

    def step(self, t, kw, k0, k1, act, a0) -> np.ndarray:
        assert self.index is not None
        return self._piece(self.index.records[t][kw], k0, k1, act, a0, self.step_keywords[kw])


__all__ = ["EclSource", "read_values"]
