"""GRDECL files and ``.DATA`` decks streamed into a grid store: k-slabs parsed from checkpoints.

:class:`GrdeclSource` is the grid source (:class:`~geoshade.io.stores.grid_store.GridSource`) of a
text
grid.  It reads the file (and its INCLUDEs) **once** with the keyword machinery of the in-memory
reader (:class:`~geoshade.io.grids.grdecl.GridBuilder`, or
:class:`~geoshade.io.grids.deck.DeckBuilder` for
a deck), but every big numeric array (COORD, ZCORN, ACTNUM, each cell property) is parsed into a
small scratch buffer instead of a whole array: the values are checked (count, bad tokens,
overrunning ``N*`` repeats, non-finite depths: the in-memory reader's one-line errors) and a
**checkpoint** is kept every :data:`CHECKPOINT_VALUES` values or so — the byte offset, the number
of values before it and the scanner's state (a repeat still running, inside a comment).  So a
damaged file fails before any store is written, and afterwards the values ``[q0, q1)`` of an
array are parsed from the nearest checkpoint at or before ``q0``, reading the file in pieces of
:data:`READ_BYTES`.  ZCORN is stored in Fortran order of ``(2nx, 2ny, 2nz)``, so a k-slab of
cells is one run of values (as ACTNUM and the properties are).

The numbers go through the numba scanner of the in-memory reader
(:mod:`geoshade.io.grids.grdecl_scan`) into arrays of the same dtypes (COORD float64, ZCORN float32,
ACTNUM uint8, properties float32, int32 for ``*NUM``): the store equals the one written from
the in-memory read, bit for bit.  Memory: a slab, one read piece, the checkpoints.

A property read inside a ``BOX`` and the edit keywords (EQUALS, MULTIPLY, ADD, COPY, MINVALUE,
MAXVALUE, on properties and ACTNUM) are kept as operations on the array (:class:`Cells`) and
applied to each slab in file order, element by element as the in-memory reader applies them to
the whole array.  Block-centred geometry (DX/DY/DZ/TOPS, DXV..., DEPTHZ, or an edit of them)
raises :class:`NeedsMemory` during the scan: the caller reads the file in memory.  The
inverted-cell warning of the in-memory reader is not given (it needs ACTNUM with ZCORN).
"""

from __future__ import annotations

import hashlib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids import grdecl_scan
from geoshade.io.grids.block_centred import CELL_KEYWORDS
from geoshade.io.grids.block_centred import KEYWORDS as BLOCK_KEYWORDS
from geoshade.io.grids.deck import DeckBuilder
from geoshade.io.grids.grdecl import (
    _BIG,
    GridBuilder,
    _box_text,
    _kernels,
    _Source,
    scan_error,
)
from geoshade.io.grids.grdecl import UNIT_SYSTEMS as _UNIT_SYSTEMS
from geoshade.io.grids.grdecl_edit import _DEFAULTS as _EDIT_DEFAULTS
from geoshade.io.grids.grdecl_edit import EDIT_KEYWORDS
from geoshade.io.grids.includes import missing_error
from geoshade.models import Fault
from geoshade.models.grid import _PILLAR_PARTS, MAX_COORDINATE, _all_usable, _usable

__all__ = ["CHECKPOINT_VALUES", "READ_BYTES", "SKIP_VALUES", "Cells", "GrdeclSource",
           "NeedsMemory", "Span", "read_span"]

#: values parsed per scanner call of the checking pass (one checkpoint each, at most)
CHECKPOINT_VALUES = 1 << 20
#: bytes read from the file at a time when a slab is parsed
READ_BYTES = 16 << 20
#: values parsed per call while skipping from a checkpoint to the first value wanted
SKIP_VALUES = 1 << 16
#: test hook: called with (keyword, q0, q1) each time a span's values are parsed
_on_read = None

_NEED, _FULL, _SLASH, _BAD, _OVERRUN, _EOF = (grdecl_scan.NEED, grdecl_scan.FULL,
                                              grdecl_scan.SLASH, grdecl_scan.BAD,
                                              grdecl_scan.OVERRUN, grdecl_scan.EOF)


class NeedsMemory(Exception):  # noqa: N818 - a signal to the caller, not an error
    """The file uses what a stream cannot represent; the message says what (read it in
    memory instead)."""


@dataclass
class Span:
    """Where one numeric array lies in a file, with checkpoints to parse any part of it.

    ``offsets``, ``index``, ``reps``, ``repv``, ``comment`` (one entry per checkpoint): byte
    offset, values before it, repeats of ``repv`` still to come, inside a ``--`` comment.
    ``end`` is the byte after the terminating ``/``; ``bad`` the first (index, value) that is
    not a finite coordinate (COORD, ZCORN) or None; ``stamp`` the file's (size, mtime) after
    the scan (a read refuses a file that no longer has it).
    """

    path: Path
    keyword: str
    count: int
    dtype: np.dtype
    offsets: np.ndarray
    index: np.ndarray
    reps: np.ndarray
    repv: np.ndarray
    comment: np.ndarray
    end: int
    bad: tuple[int, float] | None = None
    stamp: tuple[int, int] | None = None


def _stamp(path: Path) -> tuple[int, int]:
    st = path.stat()
    return st.st_size, st.st_mtime_ns


class _TrackedSource(_Source):
    """The in-memory reader's byte stream, also knowing the file offset of ``buf[0]``."""

    def __init__(self, path, read):
        super().__init__(path, read)
        self.base = 0

    def fill(self) -> bool:
        shift = self.pos
        ok = super().fill()
        if ok:
            self.base += shift
        return ok


def _scan_values(src: _TrackedSource, kw: str, expected: int, dtype, what: str,
                 strict: bool, check_usable: bool = False) -> tuple[int, Span | None]:
    """Parse a numeric record as :meth:`geoshade.io.grids.grdecl._Source.values` does (same counts,
    statuses and errors), into a scratch buffer, keeping checkpoints: (count or -1, Span)."""
    scan = _kernels()["scan"]
    dt = np.dtype(dtype)
    whole = int(dt.kind in "iu")
    scratch = np.empty(CHECKPOINT_VALUES, np.float64)
    st, stv, total = np.zeros(2, np.int64), np.zeros(1, np.float64), 0
    cps: list[tuple] = []
    bad = None
    src.skip_line = False
    while True:
        cps.append((src.base + src.pos, total, int(st[0]), float(stv[0]), int(st[1])))
        inside = total < expected
        limit = expected - total if total <= expected else _BIG
        dest = scratch[:min(CHECKPOINT_VALUES, expected - total)] if inside else scratch
        status, pos, n = scan(src.arr, src.pos, len(src.buf), src.eof, dest, 0, limit, st,
                              stv, whole if inside else 0)
        n = int(n)
        if check_usable and bad is None and inside and n:
            vals = dest[:min(n, expected - total)].astype(dt)
            if not _all_usable(vals):
                q = int(np.flatnonzero(~_usable(vals))[0])
                bad = (total + q, float(vals[q]))
        src.pos = int(pos)
        total += n
        if status == _SLASH:
            src.skip_line = True
            break
        if status in (_NEED, _EOF):
            if not src.fill():
                raise InputError(f"{src.path}: {kw}: no '/' terminator before the end of the "
                                 f"file; expected {expected} values {what}, got {total}")
        elif status in (_BAD, _OVERRUN):
            if not strict:
                return -1, None
            raise scan_error(src, kw, status, whole, total, expected, what)
    if strict and total != expected:
        raise InputError(f"{src.path}: {kw}: expected {expected} values {what}, got {total}")
    if total != expected:
        return total, None
    cols = list(zip(*cps, strict=True))
    span = Span(Path(src.path), kw, expected, dt, np.array(cols[0], np.int64),
                np.array(cols[1], np.int64), np.array(cols[2], np.int64),
                np.array(cols[3], np.float64), np.array(cols[4], np.int64),
                src.base + src.pos, bad)
    return total, span


def read_span(span: Span, q0: int, q1: int) -> np.ndarray:
    """Values ``[q0, q1)`` of a scanned array (its dtype), parsed from the nearest checkpoint.

    Raises
    ------
    InputError
        The file no longer holds what the scan saw (changed during the ingest): one line.
    """
    q0, q1 = int(q0), int(min(q1, span.count))
    out = np.empty(max(0, q1 - q0), span.dtype)
    if q1 <= q0:
        return out
    if _on_read is not None:
        _on_read(span.keyword, q0, q1)
    scan = _kernels()["scan"]
    c = int(np.searchsorted(span.index, q0, side="right")) - 1
    total = int(span.index[c])
    st = np.array([span.reps[c], span.comment[c]], np.int64)
    stv = np.array([span.repv[c]], np.float64)
    whole = int(span.dtype.kind in "iu")
    scratch = np.empty(min(SKIP_VALUES, max(1, q0 - total)), np.float64)
    changed = InputError(f"{span.path}: {span.keyword}: the file changed while it was being "
                         "ingested (its values are not where the scan found them); run the "
                         "ingest again")
    if span.stamp is not None and _stamp(span.path) != span.stamp:
        raise changed
    with open(span.path, "rb") as fh:
        at = int(span.offsets[c])
        fh.seek(at)
        buf, pos, eof, got = b"", 0, False, 0
        arr = np.zeros(0, np.uint8)
        need = True
        while got < out.size:
            if need:
                data = fh.read(max(0, min(READ_BYTES, span.end - at - len(buf))))
                if not data and eof:
                    raise changed
                buf, at, pos = buf[pos:] + data, at + pos, 0
                eof = not data or at + len(buf) >= span.end
                arr = np.frombuffer(buf, np.uint8)
                need = False
            skip = q0 - total
            if skip > 0:
                status, pos, n = scan(arr, pos, len(buf), eof, scratch[:skip], 0,
                                      span.count - total, st, stv, 0)
            else:
                status, pos, n = scan(arr, pos, len(buf), eof, out, got, span.count - total,
                                      st, stv, whole)
                got += int(n)
            total += int(n)
            if got >= out.size:  # the scanner may have seen the '/' or the end already
                break
            if status == _NEED:
                need = True
            elif status != _FULL:
                raise changed
    return out


@dataclass
class Cells:
    """A cell array as the edits leave it, evaluated slab by slab (:meth:`slab`).

    ``base``: a :class:`Span` of all cells, or a fill value; ``ops`` in file order, each
    ``(kind, box, arg)`` with ``box`` three slices (i, j, k): ``put`` the values of a property
    read inside a BOX (a Span over the box, Fortran order), ``EQUALS`` / ``MULTIPLY`` / ``ADD``
    / ``MINVALUE`` / ``MAXVALUE`` a number, ``COPY`` another array as it was then (a Cells).
    """

    dtype: np.dtype
    base: Span | float
    ops: list

    def snapshot(self) -> Cells:
        return Cells(self.dtype, self.base, list(self.ops))

    def slab(self, dims, k0: int, k1: int) -> np.ndarray:
        """Layers ``[k0, k1)``: (nx, ny, k1 - k0), Fortran order, the edits applied as the
        in-memory reader applies them to the whole array (element by element)."""
        nx, ny, _ = dims
        if isinstance(self.base, Span):
            a = read_span(self.base, k0 * nx * ny, k1 * nx * ny).astype(self.dtype, copy=False)
            a = a.reshape((nx, ny, k1 - k0), order="F")
        else:
            a = np.full((nx, ny, k1 - k0), self.base, self.dtype, order="F")
        for kind, box, arg in self.ops:
            ka, kb = max(box[2].start, k0), min(box[2].stop, k1)
            if ka >= kb:
                continue
            sub = (box[0], box[1], slice(ka - k0, kb - k0))
            if kind == "put":
                bi, bj = box[0].stop - box[0].start, box[1].stop - box[1].start
                q0 = (ka - box[2].start) * bi * bj
                vals = read_span(arg, q0, q0 + (kb - ka) * bi * bj)
                a[sub] = vals.reshape((bi, bj, kb - ka), order="F")
            elif kind == "EQUALS":
                a[sub] = arg
            elif kind == "COPY":
                a[sub] = arg.slab(dims, k0, k1)[sub]
            else:
                op = {"MULTIPLY": np.multiply, "ADD": np.add, "MINVALUE": np.maximum,
                      "MAXVALUE": np.minimum}[kind]
                a[sub] = op(a[sub], arg).astype(a.dtype)
        return a


class _StreamScan:
    """Mixin over a grid builder: big arrays are scanned into :class:`Span` s, not read; the
    edit keywords are kept as operations on them (:class:`Cells`)."""

    spans: dict
    cells: dict
    act: Cells | None

    #: :meth:`GridBuilder.parse` reads through a byte stream that knows its file offsets
    source_class = _TrackedSource

    def _stream_handlers(self) -> None:
        self.spans, self.cells, self.act, self.all_spans = {}, {}, None, []
        for kw in BLOCK_KEYWORDS:
            self.handlers[kw] = self._in_memory
        for kw in EDIT_KEYWORDS:
            self.handlers[kw] = self._edit_ops

    def _in_memory(self, kw, src):
        raise NeedsMemory(f"{src.path}: {kw} (block-centred geometry) is applied in memory")

    def _array(self, kw, src, count, dtype, what, check=False):
        self._nobox(kw, src)
        _, span = _scan_values(src, kw, count, dtype, what, True, check)
        self.spans[kw] = span
        self.all_spans.append(span)
        return span

    def _coord(self, kw, src):
        nx, ny, _ = self.need_dims(kw, src)
        self._array(kw, src, 6 * (nx + 1) * (ny + 1), np.float64, "(6·(nx+1)·(ny+1))", True)

    def _zcorn(self, kw, src):
        nx, ny, nz = self.need_dims(kw, src)
        self._array(kw, src, 8 * nx * ny * nz, np.float32, "(2·nx·2·ny·2·nz)", True)

    def _actnum(self, kw, src):
        nx, ny, nz = self.need_dims(kw, src)
        span = self._array(kw, src, nx * ny * nz, np.uint8, "(nx·ny·nz)")
        self.act = Cells(np.dtype(np.uint8), span, [])

    def property(self, kw: str, src, strict: bool) -> bool:
        """:meth:`GridBuilder.property`: all cells, or the values of the current BOX."""
        nx, ny, nz = self.dims
        box = self.box or (slice(0, nx), slice(0, ny), slice(0, nz))
        count = int(np.prod([b.stop - b.start for b in box]))
        is_int = kw.endswith("NUM")
        dt = np.dtype(np.int32 if is_int else np.float32)
        what = "(nx·ny·nz)" if self.box is None else f"(BOX {_box_text(box)})"
        got, span = _scan_values(src, kw, count, dt, what, strict)
        if got != count:
            _ = got == -1 and src.skip_record()
            return False
        self.all_spans.append(span)
        if self.box is None:
            self.cells[kw] = Cells(dt, span, [])
        else:
            if kw not in self.cells:
                self.cells[kw] = Cells(dt, 0 if is_int else np.nan, [])
            self.cells[kw].ops.append(("put", self.box, span))
        self.skipped.pop(kw, None)
        return True

    # -- the edit keywords (geoshade.io.grids.grdecl_edit), kept as operations ---------------------
    def _cells_get(self, name: str) -> Cells | None:
        return self.act if name == "ACTNUM" else self.cells.get(name)

    def _cells_target(self, name: str, is_int: bool) -> Cells:
        if name == "ACTNUM":
            if self.act is None:
                self.act = Cells(np.dtype(np.uint8), 1, [])
            return self.act
        if name not in self.cells:
            self.cells[name] = Cells(np.dtype(np.int32), 0, []) if is_int else \
                Cells(np.dtype(np.float32), _EDIT_DEFAULTS.get(name, np.nan), [])
        return self.cells[name]

    def _edit_ops(self, kw, src):
        """:meth:`geoshade.io.grids.grdecl_edit.EditKeywords._edit`, recording instead of
        applying."""
        for name, dst, value, box in self._edit_records(kw, src):
            if name in CELL_KEYWORDS or (kw == "COPY" and dst in CELL_KEYWORDS):
                raise NeedsMemory(f"{src.path}: {kw} {name} (block-centred geometry) is "
                                  "applied in memory")
            if kw == "EQUALS":
                self._cells_target(name, name.endswith("NUM")).ops.append((kw, box, value))
                continue
            arr = self._cells_get(name)
            if arr is None:
                warnings.warn(f"{src.path}: {kw} {name}: {name} is not defined before; "
                              "record skipped", stacklevel=2)
                continue
            if kw == "COPY":
                target = self._cells_target(dst, arr.dtype.kind in "iu")
                target.ops.append((kw, box, arr.snapshot()))
                continue
            arr.ops.append((kw, box, value))


class _GridScan(_StreamScan, GridBuilder):
    def __init__(self, path, progress=None):
        GridBuilder.__init__(self, path, progress)
        self._stream_handlers()


def _deck_scan(path, progress=None):

    class _DeckScan(_StreamScan, DeckBuilder):
        def __init__(self, p, prog=None):
            DeckBuilder.__init__(self, p, prog)
            self._stream_handlers()

    return _DeckScan(path, progress)


class GrdeclSource:
    """A GRDECL file or ``.DATA`` deck as a grid source: scanned once, then parsed slab by slab
    (see the module text).  It follows the protocol of
    :class:`geoshade.io.stores.grid_store.GridSource` (not imported: grid_store imports this
    module).

    Parameters
    ----------
    path : str or Path
        The GRDECL file (or deck, ``deck=True``); INCLUDEs are followed as the in-memory reader
        follows them.
    progress : callable(done, total), optional
        Bytes scanned of all files found so far.
    deck : bool, optional
        Read it as a deck (sections, PATHS, wells); default: by the ``.DATA`` suffix.

    Raises
    ------
    InputError
        What the in-memory reader refuses, in its words (one line naming file and keyword).
    NeedsMemory
        Block-centred geometry: read it in memory.

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "box.grdecl")
    >>> _ = open(f, "w").write("SPECGRID\\n1 1 2 1 F /\\nCOORD 0 0 0 0 0 1 1 0 0 1 0 1 0 1 "
    ...                        "0 0 1 1 1 1 0 1 1 1 /\\nZCORN 4*0 8*1 4*2 /\\nPORO 0.1 0.2 /\\n")
    >>> src = GrdeclSource(f)
    >>> src.dims, src.zcorn(1, 2)[0, 0].tolist(), src.prop("PORO", 1, 2, None, 0).tolist()
    ((1, 1, 2), [1.0, 2.0], [[[0.20000000298023224]]])
    """

    def __init__(self, path, progress=None, deck: bool | None = None):
        p = Path(path)
        if not p.is_file():
            raise InputError(f"{path}: no such file")
        if deck is None:
            deck = p.suffix.lower() == ".data"
        b = _deck_scan(p, progress) if deck else _GridScan(p, progress)
        b.parse_all()
        b.warn_skipped()
        if deck:
            b.unit_system = b.unit_system or "METRIC"
        self._finish(b, p, deck)

    def _finish(self, b, path: Path, deck: bool) -> None:
        """The in-memory reader's checks and metadata (GridBuilder.finish), without arrays."""
        if b.missing:
            raise missing_error(path, b.missing)
        if b.dims is None:
            raise InputError(f"{path}: no SPECGRID or DIMENS keyword; a corner-point grid needs "
                             "SPECGRID, COORD and ZCORN")
        absent = [k for k in ("COORD", "ZCORN") if k not in b.spans]
        if absent:
            raise InputError(f"{path}: no {' or '.join(absent)} keyword; a corner-point grid "
                             "needs SPECGRID, COORD and ZCORN (or DX, DY, DZ and TOPS); "
                             "--skip-missing shows the cells in IJK index space")
        faults = [Fault(name, np.concatenate(parts)) for name, parts in b.faults.items()]
        nx, ny, nz = self.dims = tuple(int(v) for v in b.dims)
        for f in faults:
            if (bad := (f.faces[:, :3] >= (nx, ny, nz)).any(axis=1)).any():
                cell = tuple(int(v) + 1 for v in f.faces[bad][0, :3])
                raise InputError(f"{path}: FAULTS {f.name}: cell {cell} is outside the grid "
                                 f"{b.dims}")
        w = f"{path}: "
        if (bad := b.spans["COORD"].bad) is not None:
            q, v = bad
            pil, part = divmod(q, 6)
            j, i = divmod(pil, nx + 1)
            raise InputError(f"{w}COORD: value {v:g} at index {q} (pillar i={i + 1} j={j + 1}, "
                             f"{_PILLAR_PARTS[part]}) is not a finite coordinate (expected "
                             f"|v| <= {MAX_COORDINATE:g})")
        if (bad := b.spans["ZCORN"].bad) is not None:
            q, v = bad
            a, bb, cc = np.unravel_index(q, (2 * nx, 2 * ny, 2 * nz), order="F")
            raise InputError(f"{w}ZCORN: value {v:g} at index {q} (cell i={a // 2 + 1} "
                             f"j={bb // 2 + 1} k={cc // 2 + 1}) is not a finite depth "
                             f"(expected |z| <= {MAX_COORDINATE:g})")
        if deck:
            _check_wells(b, path)
        self.name = str(path)
        self.spans, self.cells, self.act = b.spans, b.cells, b.act
        for span in b.all_spans:  # a file changed after this is refused when read
            span.stamp = _stamp(span.path)
        self.units = b.units or _UNIT_SYSTEMS.get(b.unit_system, "")
        self.mapaxes = None if b.mapaxes is None else np.asarray(b.mapaxes, float).ravel()
        self.faults = faults
        self.properties = {k: c.dtype for k, c in b.cells.items()}
        self.step_keywords, self.step_dates, self.step_seqnum = {}, [], []
        self.files = [Path(f) for f in b.meta["files"]]
        h = hashlib.sha1()
        for f in self.files:
            st = f.stat()
            h.update(f"{f.resolve()}|{st.st_size}|{st.st_mtime_ns}\n".encode())
        self.fingerprint = h.hexdigest()
        self.meta = {"format": str(b.meta.get("format", "")),
                     "mapunits": str(b.meta.get("mapunits", ""))}

    # -- slabs -----------------------------------------------------------------------------
    def coord(self) -> np.ndarray:
        nx, ny, _ = self.dims
        flat = read_span(self.spans["COORD"], 0, 6 * (nx + 1) * (ny + 1))
        return flat.reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2)

    def zcorn(self, k0: int, k1: int) -> np.ndarray:
        nx, ny, _ = self.dims
        per = 8 * nx * ny
        v = read_span(self.spans["ZCORN"], k0 * per, k1 * per)
        return v.reshape((2 * nx, 2 * ny, 2 * (k1 - k0)), order="F")

    def actnum(self, k0: int, k1: int) -> np.ndarray:
        nx, ny, _ = self.dims
        if self.act is None:
            return np.ones((nx, ny, k1 - k0), np.uint8, order="F")
        return (self.act.slab(self.dims, k0, k1) != 0).astype(np.uint8)

    def prop(self, name, k0, k1, act, a0) -> np.ndarray:
        return self.cells[name].slab(self.dims, k0, k1)

    def step(self, t, kw, k0, k1, act, a0) -> np.ndarray:  # pragma: no cover - none in GRDECL
        raise KeyError(kw)


def _check_wells(b, path: Path) -> None:
    """The well-cell check of :meth:`geoshade.io.grids.deck.DeckBuilder.wells` (wells are not
    stored)."""
    nx, ny, nz = b.dims
    for name, (hi, hj) in b.heads.items():
        cells = np.array(list(b.completions.get(name, {})), np.int64).reshape(-1, 3)
        bad = (cells < 0).any(axis=1) | (cells >= (nx, ny, nz)).any(axis=1)
        if not (0 <= hi < nx and 0 <= hj < ny) or bad.any():
            where = tuple(int(v) + 1 for v in (cells[bad][0] if bad.any() else (hi, hj)))
            raise InputError(f"{path}: well {name}: cell {where} is outside the grid "
                             f"{tuple(b.dims)}")
