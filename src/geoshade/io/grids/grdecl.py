"""ECLIPSE GRDECL text grids (SPECGRID, COORD, ZCORN, ACTNUM, MAPAXES, FAULTS, properties).

The file is read as a **stream** of byte chunks (:data:`CHUNK_BYTES`), never whole.  Keywords and
short records are tokenised with regular expressions; long numeric arrays go through a numba
scanner (:func:`_scan`: numbers and ``N*value`` repeats parsed from the bytes, a token cut by a
chunk boundary carried over) into an array preallocated from the size SPECGRID implies.  Small
arrays wholly in the buffer take a numpy path (no numba start-up); any doubt sends them to the
scanner, which owns the error messages.  ``--`` comments, ``/`` terminators (the rest of the line
is a comment), quotes, ``N*`` defaults, ``D`` exponents, nested ``INCLUDE`` (relative to the
including file) and ``BOX`` are handled.  Any keyword with ``nx·ny·nz`` numbers is a cell
property; others are skipped with a warning naming file and keyword.  EQUALS, MULTIPLY, ADD,
COPY, MINVALUE and MAXVALUE edit cell arrays (:mod:`geoshade.io.grids.grdecl_edit`);
:mod:`geoshade.io.grids.deck` adds sections, PATHS and wells.

Block-centred geometry (``DX/DY/DZ/TOPS``, ``DXV/DYV/DZV/DEPTHZ``) becomes COORD and ZCORN as
OPM makes them (:mod:`geoshade.io.grids.block_centred`).  METRIC/FIELD/LAB/PVT-M set
``meta["unit_system"]`` and the length unit.  A missing INCLUDE does not stop the reading:
every one is listed (:mod:`geoshade.io.grids.includes`), as an error, or with ``skip_missing`` as
one
warning, and a grid whose geometry is missing then gets unit cells in IJK index space.

Layout (:class:`~geoshade.models.CornerPointGrid`): ZCORN, ACTNUM and properties are the flat
file arrays ``reshape(shape, order="F")``; COORD ``(nx+1, ny+1, 6)`` is indexed ``[i, j, c]``
with the file's memory order (6 numbers per pillar, i fastest; ``coord.transpose(1, 0, 2)`` is
C-contiguous).  dtypes: COORD float64, ZCORN float32, ACTNUM uint8, properties float32 (int32
for ``*NUM``).
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids import grdecl_scan
from geoshade.io.grids.block_centred import KEYWORDS as BLOCK_KEYWORDS
from geoshade.io.grids.block_centred import BlockCentredKeywords, index_space_geometry
from geoshade.io.grids.grdecl_edit import EDIT_KEYWORDS, EditKeywords
from geoshade.io.grids.grid_checks import check_grid_size, check_memory, warn_inverted
from geoshade.io.grids.includes import count_open, missing_error, missing_text, resolve_include
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid, Fault
from geoshade.progress import Counter

#: bytes read from the file at a time
CHUNK_BYTES = 16 << 20
#: values parsed per call of the numba scanner
SCRATCH_VALUES = 1 << 20
#: until numba is loaded, arrays up to this many values wholly in the buffer are parsed with
#: numpy (saves numba's start-up, ~0.5 s, on small grids)
SMALL_VALUES = 1 << 21

#: statuses of the scanner (:mod:`geoshade.io.grids.grdecl_scan`)
_NEED, _FULL, _SLASH, _BAD, _OVERRUN, _EOF = (getattr(grdecl_scan, n) for n in (
    "NEED", "FULL", "SLASH", "BAD", "OVERRUN", "EOF"))
_BIG = 1 << 62

#: keywords that take no data (section names, switches); they are neither used nor warned about
NO_DATA = frozenset(
    "RUNSPEC GRID EDIT PROPS REGIONS SOLUTION SUMMARY SCHEDULE END ENDBOX ECHO NOECHO OIL WATER "
    "GAS DISGAS VAPOIL INIT UNIFIN UNIFOUT UNIFSAVE NOINSPEC NORSSPEC "
    "NOSIM FMTIN FMTOUT NEWTRAN OLDTRAN NONNC SKIPREST ALL MSUMLINS MSUMNEWT SEPARATE RPTONLY "
    "RUNSUM EXCEL FORMFEED NOWARN WARN NOGGF ENDFIN ENDSKIP SKIP SKIP100 SKIP300 SAVE".split()
)
#: keywords whose (single) record holds words, so it must not be mistaken for keywords
_WORD_RECORDS = frozenset("GDORIENT MAPUNITS GRIDUNIT SCALECRS GRIDOPTS EQLOPTS RPTRST RPTSOL "
                          "RPTSCHED RPTPROPS RPTGRID RPTRUNSP RPTREGS NSTACK".split())
#: keywords followed by one line of free text without a terminator
_FREE_TEXT = frozenset({"TITLE"})
#: unit systems (RUNSPEC) -> the length unit of their grid (``grid.units``)
UNIT_SYSTEMS = {"METRIC": "METRES", "FIELD": "FEET", "LAB": "CM", "PVT-M": "METRES"}
#: cell properties whose value count must equal the cell count (else an error, not a skip)
KNOWN_PROPERTIES = frozenset(
    "PORO PERMX PERMY PERMZ NTG SWATINIT SWL SWCR SWU SGL SGCR SGU SOWCR SOGCR KRW KRO KRG "
    "MULTX MULTY MULTZ MULTX- MULTY- MULTZ- MULTPV PORV PRESSURE SWAT SGAS SOIL RS RV TEMPI "
    "FIPNUM EQLNUM SATNUM PVTNUM MULTNUM ROCKNUM IMBNUM FLUXNUM OPERNUM ENDNUM".split()
)
_SKIPREC_RE = re.compile(rb"'[^']*'|--[^\n]*|/|'")
_KEYWORD_RE = re.compile(r"[A-Z][A-Z0-9_]{0,7}[+-]?")
_SKIP_RE = re.compile(rb"(?:[ \t\r\n]+|--[^\n]*\n)*")
_TOK_RE = re.compile(rb"'([^']*)'|(/)|([^\s/']+)")
_FACES = {"X": 0, "I": 0, "Y": 1, "J": 1, "Z": 2, "K": 2,
          "X-": 3, "I-": 3, "Y-": 4, "J-": 4, "Z-": 5, "K-": 5}


# --- numba kernels (geoshade.io.grids.grdecl_scan; compiled on first use, cached on disk) ---------
_KERNELS: dict = {}


def _kernels():
    """The jitted scanner; numba is imported only when a large array needs it."""
    if not _KERNELS:
        _KERNELS.update(grdecl_scan.kernels())
    return _KERNELS



# --- byte stream -----------------------------------------------------------------------------
def scan_error(src, keyword: str, status: int, whole: bool, total: int, expected: int,
               what: str) -> InputError:
    """The one line for a value the scanner stopped at (``status``) in ``src`` at its position:
    not a 32-bit integer, not a number, or a repeat that overruns the values expected."""
    m = _TOK_RE.match(src.buf, src.pos)
    tok = m.group(0).decode(errors="replace") if m else src.buf[src.pos:][:20]
    if status == _BAD and whole and _is_number(tok):
        return InputError(f"{src.path}: {keyword}: value {tok!r} at value {total + 1} is not an "
                          f"integer of 32 bits; expected {expected} integers {what}")
    if status == _BAD:
        return InputError(f"{src.path}: {keyword}: non-numeric token {tok!r} at value "
                          f"{total + 1}; expected {expected} numbers {what}")
    return InputError(f"{src.path}: {keyword}: repeat {tok!r} at value {total + 1} overruns the "
                      f"{expected} values {what}")


#: the UTF-8 byte-order mark some editors write at the start of a file
BOM = b"\xef\xbb\xbf"


class _Source:
    """One open file read in chunks; ``buf[pos:]`` is what is left to read."""

    def __init__(self, path: Path, read: Callable[[int], object]):
        # an INCLUDE naming a FIFO or a folder is refused before it is opened (no hang)
        self.path, self.fh, self.read = path, open(check_file(path, "a GRDECL file"), "rb"), read
        self.buf, self.arr, self.pos = b"", np.zeros(0, np.uint8), 0
        self.eof, self.bol0, self.skip_line = False, True, False

    def close(self) -> None:
        self.fh.close()

    def fill(self) -> bool:
        """Append the next chunk to what is left; False at the end of the file."""
        if self.eof:
            return False
        first = self.fh.tell() == 0
        data = self.fh.read(CHUNK_BYTES)
        if first and data.startswith(BOM):   # a UTF-8 byte-order mark: blanks (offsets kept)
            data = b" " * len(BOM) + data[len(BOM):]
        if self.pos > 0:
            self.bol0 = self.buf[self.pos - 1] == 10
        rest = self.buf[self.pos:]
        self.buf, self.pos = (rest + data if rest else data), 0
        self.arr = np.frombuffer(self.buf, np.uint8)
        self.eof = not data
        self.read(len(data))
        return True

    def token(self):
        """Next token: (kind, text, at_line_start, start).

        kind: ``"w"`` bare word starting with a letter, ``"v"`` other bare token (numbers,
        ``N*x``), ``"q"`` quoted string (text without quotes), ``"/"``, or ``""`` at the end.
        """
        while True:
            buf = self.buf
            if self.skip_line:
                nl = buf.find(b"\n", self.pos)
                if nl < 0:
                    self.pos = len(buf)
                    if not self.fill():
                        return "", "", True, self.pos
                    continue
                self.pos, self.skip_line = nl + 1, False
            p = _SKIP_RE.match(buf, self.pos).end()
            n = len(buf)
            if p >= n or buf.startswith(b"--", p) or (p == n - 1 and buf[p] == 45):
                if not self.eof:
                    self.pos = p
                    self.fill()
                    continue
                if p >= n or buf.startswith(b"--", p):
                    self.pos = n
                    return "", "", True, n
            m = _TOK_RE.match(buf, p)
            if m is None or (m.end() >= n and not self.eof):
                if not self.eof:
                    self.pos = p
                    self.fill()
                    continue
                raise InputError(f"{self.path}: unterminated quoted string "
                                 f"{buf[p:p + 40].decode(errors='replace')!r}")
            self.pos = m.end()
            q = p - 1
            while q >= 0 and buf[q] in (32, 9, 13):
                q -= 1
            bol = buf[q] == 10 if q >= 0 else self.bol0
            if m.group(1) is not None:
                return "q", m.group(1).decode(errors="replace"), bol, p
            if m.group(2) is not None:
                self.skip_line = True
                return "/", "/", bol, p
            text = m.group(3).decode(errors="replace")
            return ("w" if text[0].isalpha() else "v"), text, bol, p

    def skip_lines(self, count: int) -> None:
        """Skip the rest of the current line and ``count - 1`` more lines."""
        self.skip_line = False
        while count > 0:
            nl = self.buf.find(b"\n", self.pos)
            if nl < 0:
                self.pos = len(self.buf)
                if not self.fill():
                    return
                continue
            self.pos = nl + 1
            count -= 1

    def peek(self):
        tok = self.token()
        if tok[0]:
            self.pos, self.skip_line = tok[3], False
        return tok

    def record(self, keyword: str) -> list:
        """The tokens up to the next ``/`` (``N*`` expands to N None, ``N*x`` to N times x)."""
        out: list = []
        while True:
            kind, text, _, _ = self.token()
            if kind == "/":
                return out
            if kind == "":
                raise InputError(f"{self.path}: {keyword}: no '/' terminator before the end "
                                 "of the file")
            cnt, _, val = text.partition("*")
            if kind == "v" and cnt.isdigit() and 0 < int(cnt) < 1_000_000 and "*" in text:
                out.extend([val or None] * int(cnt))
                continue
            out.append(text)
            if len(out) > 1_000_000:
                raise InputError(f"{self.path}: {keyword}: record has more than 1e6 items; "
                                 "missing '/'?")

    def skip_record(self) -> bool:
        """Skip past the next ``/`` outside quotes and comments; False if the file ended."""
        self.skip_line = False
        while True:
            keep = max(self.pos, len(self.buf) - 1)  # a lone '-' may start a comment
            for m in _SKIPREC_RE.finditer(self.buf, self.pos):
                t = m.group(0)
                if t == b"/":
                    self.pos, self.skip_line = m.end(), True
                    return True
                if (t == b"'" or m.end() == len(self.buf)) and not self.eof:
                    keep = m.start()  # a quote or comment that goes on in the next chunk
                    break
            self.pos = keep
            if not self.fill():
                return False

    def _values_small(self, expected: int, out: np.ndarray, strict: bool) -> int | None:
        """numpy path for a record wholly in the buffer: the count as :meth:`values` gives it,
        or None (stream untouched) to leave the record to the scanner and its exact errors.
        """
        buf, pos, seen = self.buf, self.pos, set()
        end = -1
        for m in _SKIPREC_RE.finditer(buf, pos, min(len(buf), pos + 32 * expected + 4096)):
            if m.group(0) == b"/":
                end = m.start()
                break
            seen.add(m.group(0)[:1])
        if end < 0 or (b"'" in seen and strict):
            return None
        if b"'" in seen:
            return -1
        seg = buf[pos:end] if b"-" not in seen else re.sub(rb"--[^\n]*", b" ", buf[pos:end])
        if b"_" in seg:  # float() reads 1_0 as 10, the scanner does not: let it decide
            return None
        toks = np.array(seg.split(), dtype=bytes)
        try:
            star = np.char.find(toks, b"*") >= 0 if b"*" in seg else np.zeros(toks.size, bool)
            counts, vals = np.ones(toks.size, np.int64), np.empty(toks.size)
            vals[~star] = toks[~star].astype(np.float64)
            if star.any():
                parts = np.char.partition(toks[star], b"*")  # (n, 3): count, "*", value
                counts[star], vals[star] = parts[:, 0].astype(np.int64), parts[:, 2].astype(float)
            total = int(counts.sum())
            if counts.min(initial=1) < 1 or total > 1 << 40:
                raise ValueError
            if out.dtype.kind in "iu" and not np.all(np.abs(vals) < 2**31):  # NaN too
                raise ValueError  # the scanner names the value
        except (ValueError, OverflowError):
            return None if strict else -1
        if total != expected:
            if strict:
                return None
            if total > expected and expected not in np.cumsum(counts):
                return -1   # a repeat runs past the values asked for: as the scanner says
            if total < expected:  # as the scanner leaves it: the values read, then the rest
                out[:total] = np.repeat(vals, counts)
        else:
            out[:] = np.repeat(vals, counts)
        self.pos, self.skip_line = end + 1, True
        return total

    def values(self, keyword: str, expected: int, out: np.ndarray | None, what: str,
               strict: bool = True):
        """Parse a numeric record into ``out`` (``expected`` values up to ``/``): the count.

        ``strict``: a wrong count, a non-numeric token or an overrunning repeat raises; else
        -1 is returned for the last two, leaving the stream at the offending token.
        """
        if not _KERNELS and expected <= SMALL_VALUES and out is not None:
            got = self._values_small(expected, out, strict)
            if got is not None:
                return got
        scan = _kernels()["scan"]
        scratch = np.empty(SCRATCH_VALUES, np.float64)  # for values beyond ``out``
        st, stv, total = np.zeros(2, np.int64), np.zeros(1, np.float64), 0
        whole = int(out is not None and out.dtype.kind in "iu")
        self.skip_line = False
        while True:
            limit = expected - total if total <= expected else _BIG
            dest, base = (out, total) if out is not None and total < expected else (scratch, 0)
            status, pos, n = scan(self.arr, self.pos, len(self.buf), self.eof, dest, base,
                                  limit, st, stv, whole if dest is out else 0)
            self.pos = int(pos)
            total += int(n)
            if status == _SLASH:
                self.skip_line = True
                break
            elif status in (_NEED, _EOF):
                if not self.fill():
                    raise InputError(f"{self.path}: {keyword}: no '/' terminator before the end "
                                     f"of the file; expected {expected} values {what}, "
                                     f"got {total}")
            elif status in (_BAD, _OVERRUN):
                if not strict:
                    return -1
                raise scan_error(self, keyword, status, whole, total, expected, what)
        if strict and total != expected:
            raise InputError(f"{self.path}: {keyword}: expected {expected} values {what}, "
                             f"got {total}")
        return total


def _is_number(tok: str) -> bool:
    """``tok`` (or the value of an ``N*value`` repeat) reads as a float."""
    try:
        float(tok.rpartition("*")[2].replace("D", "E").replace("d", "e"))
    except ValueError:
        return False
    return True


# --- keyword handling ------------------------------------------------------------------------
class GridBuilder(BlockCentredKeywords, EditKeywords):
    """Collects the keywords of a GRDECL file and its INCLUDEs; :meth:`finish` makes the grid.

    Subclasses (the deck reader) add handlers to :attr:`handlers` (keyword -> method).
    ``skip_missing``: INCLUDEs that are not found are listed (:attr:`missing`) and the rest is
    read; without it :meth:`finish` refuses them all in one line.
    """

    #: the byte stream a file is read through (a streamed ingest's keeps file offsets)
    source_class: type = _Source

    def __init__(self, path: Path, progress=None, skip_missing: bool = False):
        self.root = Path(path)
        self.skip_missing = bool(skip_missing)
        #: INCLUDEs not found: (name as written, including file)
        self.missing: list[tuple[str, Path]] = []
        #: INCLUDE opens so far, per file (:func:`~geoshade.io.grids.includes.count_open`)
        self.opened: dict[str, int] = {}
        #: block-centred geometry keywords read (see :mod:`geoshade.io.grids.block_centred`)
        self.block: dict[str, np.ndarray] = {}
        self.unit_system = ""
        self.dims: tuple[int, int, int] | None = None
        self.coord = self.zcorn = self.actnum = self.mapaxes = None
        self.props: dict[str, np.ndarray] = {}
        self.faults: dict[str, list] = {}
        self.meta: dict = {"format": "GRDECL", "source": str(self.root), "files": []}
        self.units, self.box, self.skipped, self.aliases, self.stack = "", None, {}, {}, []
        #: bytes read of all files found so far (an INCLUDE adds its size)
        self.progress = Counter(progress, self.root.stat().st_size)
        self.handlers: dict[str, Callable] = {
            "SPECGRID": self._specgrid, "DIMENS": self._specgrid, "COORD": self._coord,
            "ZCORN": self._zcorn, "ACTNUM": self._actnum, "MAPAXES": self._mapaxes,
            "MAPUNITS": self._words, "GRIDUNIT": self._words, "GDORIENT": self._words,
            "FAULTS": self._faults, "INCLUDE": self._include, "BOX": self._boxkw,
            "ENDBOX": self._endbox,
            **dict.fromkeys(("DX", "DY", "DZ", "TOPS"), self._block_cells),
            **dict.fromkeys(("DXV", "DYV", "DZV", "DEPTHZ"), self._block_vector),
            **dict.fromkeys(UNIT_SYSTEMS, self._unit_system),
            **dict.fromkeys(EDIT_KEYWORDS, self._edit),
        }

    # -- driving --------------------------------------------------------------------------
    def parse(self, path: Path) -> None:
        """Read one file (recursively its INCLUDEs) into the builder."""
        if len(self.stack) > 32:
            raise InputError(f"{path}: INCLUDE nested more than 32 deep (a loop?)")
        self.stack.append(path)
        self.meta["files"].append(str(path))
        src = self.source_class(path, self.progress.add)
        try:
            while True:
                kind, text, _, _ = src.token()
                if kind == "":
                    break
                if kind != "w" or not _KEYWORD_RE.fullmatch(text.upper()):
                    if kind != "/":  # records of a multi-record keyword being skipped
                        src.skip_record()
                    continue
                self.keyword(text.upper(), src)
        finally:
            src.close()
            self.stack.pop()

    def keyword(self, kw: str, src: _Source) -> None:
        handler = self.handlers.get(kw)
        if handler is not None:
            handler(kw, src)
        elif kw in NO_DATA:
            pass
        elif kw in _FREE_TEXT:
            src.skip_lines(2)
        elif kw in _WORD_RECORDS:
            self.skip(kw, src)
            src.skip_record()
        else:
            self.unknown(kw, src)

    def skip(self, kw: str, src: _Source) -> None:
        """Note a keyword that is not used (warned about in :meth:`finish`)."""
        self.skipped.setdefault(kw, str(src.path))

    def unknown(self, kw: str, src: _Source) -> None:
        """A keyword without a handler: a cell property if it holds nx·ny·nz numbers."""
        kind, text, bol, _ = src.peek()
        if kind == "" or (kind == "w" and bol and _KEYWORD_RE.fullmatch(text.upper())):
            return self.skip(kw, src)
        if kind == "v" and self.dims is not None and kw not in BLOCK_KEYWORDS:
            if self.property(kw, src, strict=kw in KNOWN_PROPERTIES):
                return
        else:
            src.skip_record()
        self.skip(kw, src)

    # -- helpers --------------------------------------------------------------------------
    def need_dims(self, kw: str, src: _Source) -> tuple[int, int, int]:
        if self.dims is None:
            raise InputError(f"{src.path}: {kw} comes before SPECGRID/DIMENS: the grid size "
                             "is unknown")
        return self.dims

    def property(self, kw: str, src: _Source, strict: bool) -> bool:
        """Read a cell property (in the current BOX); False (stream past it) if it is not one."""
        nx, ny, nz = self.dims
        box = self.box or (slice(0, nx), slice(0, ny), slice(0, nz))
        shape = tuple(s.stop - s.start for s in box)
        count = shape[0] * shape[1] * shape[2]
        is_int = kw.endswith("NUM")
        check_memory(src.path, f"{kw} ({count} values)", 4 * count)
        flat = np.empty(count, np.int32 if is_int else np.float32)
        what = "(nx·ny·nz)" if self.box is None else f"(BOX {_box_text(box)})"
        if (got := src.values(kw, count, flat, what, strict=strict)) != count:
            _ = got == -1 and src.skip_record()
            return False
        block = flat.reshape(shape, order="F")
        if self.box is None:
            self.props[kw] = block
        else:
            arr = self.props.get(kw)
            if arr is None:
                arr = np.zeros((nx, ny, nz), np.int32, order="F") if is_int else \
                    np.full((nx, ny, nz), np.nan, np.float32, order="F")
                self.props[kw] = arr
            arr[box] = block
        self.skipped.pop(kw, None)
        return True

    # -- handlers -------------------------------------------------------------------------
    def _specgrid(self, kw, src):
        rec = src.record(kw)
        try:
            dims = tuple(int(v) for v in rec[:3])
        except (TypeError, ValueError):
            dims = ()
        if len(dims) != 3 or min(dims) < 1:
            raise InputError(f"{src.path}: {kw}: expected 3 positive integers NX NY NZ, got "
                             f"{' '.join(str(v) for v in rec[:3])!r}")
        if kw == "SPECGRID":
            if len(rec) > 3 and rec[3] not in (None, "1"):
                raise InputError(f"{src.path}: SPECGRID: {rec[3]} reservoirs (NUMRES) are not "
                                 "supported; expected 1")
            if len(rec) > 4 and rec[4] is not None and str(rec[4]).upper().startswith("T"):
                raise InputError(f"{src.path}: SPECGRID: radial grids are not supported; "
                                 "expected F (cartesian)")
        if self.dims is not None and self.dims != dims:
            raise InputError(f"{src.path}: {kw}: {dims} differs from the grid size "
                             f"{self.dims} given before")
        check_grid_size(src.path, kw, dims)
        self.dims = dims

    def _coord(self, kw, src):
        nx, ny, _ = self.need_dims(kw, src)
        self._nobox(kw, src)
        n = 6 * (nx + 1) * (ny + 1)
        check_memory(src.path, f"{kw} ({n} values)", 8 * n)
        flat = np.empty(n, np.float64)
        src.values(kw, flat.size, flat, "(6·(nx+1)·(ny+1))")
        self.coord = flat.reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2)

    def _zcorn(self, kw, src):
        nx, ny, nz = self.need_dims(kw, src)
        self._nobox(kw, src)
        check_memory(src.path, f"{kw} ({8 * nx * ny * nz} values)", 32 * nx * ny * nz)
        flat = np.empty(8 * nx * ny * nz, np.float32)
        src.values(kw, flat.size, flat, "(2·nx·2·ny·2·nz)")
        self.zcorn = flat.reshape((2 * nx, 2 * ny, 2 * nz), order="F")

    def _actnum(self, kw, src):
        nx, ny, nz = self.need_dims(kw, src)
        self._nobox(kw, src)
        check_memory(src.path, f"{kw} ({nx * ny * nz} values)", nx * ny * nz)
        flat = np.empty(nx * ny * nz, np.uint8)
        src.values(kw, flat.size, flat, "(nx·ny·nz)")
        self.actnum = flat.reshape((nx, ny, nz), order="F")

    def _nobox(self, kw, src):
        if self.box is not None:
            raise InputError(f"{src.path}: {kw} inside a BOX is not supported; expected it for "
                             "the whole grid")

    def _mapaxes(self, kw, src):
        rec = src.record(kw)
        try:
            vals = np.array([float(str(v).replace("D", "E").replace("d", "e")) for v in rec])
        except (TypeError, ValueError):
            vals = np.zeros(0)
        if vals.size != 6:
            raise InputError(f"{src.path}: MAPAXES: expected 6 numbers X1 Y1 X0 Y0 X2 Y2, got "
                             f"{' '.join(str(v) for v in rec)!r}")
        self.mapaxes = vals

    def _words(self, kw, src):
        """MAPUNITS, GRIDUNIT (-> units), GDORIENT: kept in meta (lower-case keyword)."""
        words = [str(v).strip() for v in src.record(kw) if v is not None]
        self.meta[kw.lower()] = words[0] if kw != "GDORIENT" and words else words
        if kw == "GRIDUNIT":
            self.units = words[0] if words else ""

    def _unit_system(self, kw, src):
        """METRIC, FIELD, LAB, PVT-M (RUNSPEC): ``meta["unit_system"]`` and, unless GRIDUNIT
        says otherwise, the length unit ``grid.units``."""
        if self.unit_system and self.unit_system != kw:
            raise InputError(f"{src.path}: {kw}: the deck already chose the {self.unit_system} "
                             "unit system; expected one of METRIC, FIELD, LAB, PVT-M")
        self.unit_system = kw

    def _include(self, kw, src):
        rec = src.record(kw)
        if not rec or not rec[0]:
            raise InputError(f"{src.path}: INCLUDE: expected a file name")
        path = resolve_include(str(rec[0]), src.path, self.root, self.aliases)
        if path is None:  # listed; the rest is read so that every missing one is found
            self.missing.append((str(rec[0]).strip(), src.path))
            return
        count_open(self.opened, path, self.root)  # a budget of opens (and of one file's re-reads)
        self.progress.grow(path.stat().st_size)
        self.parse(path)

    def _faults(self, kw, src):
        while True:
            rec = src.record(kw)
            if not rec:
                return
            name = str(rec[0]).strip() if rec[0] else ""
            try:
                i1, i2, j1, j2, k1, k2 = (int(v) for v in rec[1:7])
                face = _FACES[str(rec[7]).strip().upper()]
            except (TypeError, ValueError, IndexError, KeyError):
                raise InputError(f"{src.path}: FAULTS: expected NAME IX1 IX2 IY1 IY2 IZ1 IZ2 "
                                 f"FACE (X Y Z X- Y- Z-), got {' '.join(map(str, rec))!r}"
                                 ) from None
            lim = self.dims or (_BIG,) * 3
            if not (1 <= i1 <= i2 <= lim[0] and 1 <= j1 <= j2 <= lim[1]
                    and 1 <= k1 <= k2 <= lim[2]):
                raise InputError(f"{src.path}: FAULTS {name}: box {i1}-{i2}, {j1}-{j2}, "
                                 f"{k1}-{k2} is outside the grid {self.dims or '(no size yet)'}")
            n = (i2 - i1 + 1) * (j2 - j1 + 1) * (k2 - k1 + 1)
            check_memory(src.path, f"FAULTS {name} ({n} faces)", 64 * n)
            ii, jj, kk = np.meshgrid(np.arange(i1 - 1, i2), np.arange(j1 - 1, j2),
                                     np.arange(k1 - 1, k2), indexing="ij")
            faces = np.stack([ii.ravel(order="F"), jj.ravel(order="F"), kk.ravel(order="F"),
                              np.full(ii.size, face)], axis=1)
            self.faults.setdefault(name, []).append(faces)

    def _boxkw(self, kw, src):
        self.box = self._box_from(src.record(kw), 0, kw, src, use_current=False)

    def _endbox(self, kw, src):
        self.box = None

    def _box_from(self, rec, at, kw, src, use_current=True):
        """Slices from 1-based ``I1 I2 J1 J2 K1 K2`` at ``rec[at:]`` (defaults: current box)."""
        nx, ny, nz = self.need_dims(kw, src)
        cur = (self.box if use_current else None) or (slice(0, nx), slice(0, ny), slice(0, nz))
        vals = [*rec[at:at + 6], *[None] * 6][:6]
        out = []
        for d, n in enumerate((nx, ny, nz)):
            lo, hi = vals[2 * d], vals[2 * d + 1]
            try:
                lo = cur[d].start if lo is None else int(lo) - 1
                hi = cur[d].stop if hi is None else int(hi)
            except ValueError:
                raise InputError(f"{src.path}: {kw}: expected box indices I1 I2 J1 J2 K1 K2, got "
                                 f"{' '.join(map(str, rec[at:at + 6]))!r}") from None
            if not 0 <= lo < hi <= n:
                raise InputError(f"{src.path}: {kw}: box {lo + 1}-{hi} is outside 1-{n}")
            out.append(slice(lo, hi))
        return tuple(out)

    # -- result ---------------------------------------------------------------------------
    def warn_skipped(self) -> None:
        for kw, where in self.skipped.items():
            warnings.warn(f"{where}: keyword {kw} is not used by the grid reader; skipped",
                          stacklevel=3)

    def parse_all(self) -> None:
        """Read the root file; an error after an INCLUDE went missing names the missing ones
        too (they are the likely cause)."""
        try:
            self.parse(self.root)
        except InputError as err:
            if not self.missing:
                raise
            if not self.skip_missing:
                raise missing_error(self.root, self.missing) from err
            raise InputError(f"{err} ({len(self.missing)} INCLUDE file(s) missing: "
                             f"{missing_text(self.missing)})") from err

    def geometry(self, path: Path, notes: list[str]):
        """COORD, ZCORN and what they came from: the file's corner points, block-centred
        keywords, or (``skip_missing``, none read) unit cells in IJK index space."""
        if self.block and (self.coord is not None or self.zcorn is not None):
            raise InputError(f"{path}: both COORD/ZCORN and block-centred "
                             f"{', '.join(sorted(self.block))}; expected one kind of geometry")
        gaps = self.block_gaps()
        if self.block and not gaps:
            coord, zcorn, geometry, moved = self.block_geometry(path)
            if moved > 1e-6:
                warnings.warn(f"{path}: {geometry}: cells reaching above the bottom of the cell "
                              f"above were cut at it (by up to {moved:.6g}), as OPM does",
                              stacklevel=4)
            return coord, zcorn, geometry
        absent = [k for k, v in (("COORD", self.coord), ("ZCORN", self.zcorn)) if v is None]
        if not absent:
            return self.coord, self.zcorn, "corner-point"
        what = (f"block-centred geometry without {', '.join(gaps)}; expected DX (or DXV), "
                "DY (or DYV), DZ (or DZV) and TOPS, or DXV, DYV, DZV and DEPTHZ" if gaps else
                f"no {' or '.join(absent)} keyword; a corner-point grid needs SPECGRID, "
                "COORD and ZCORN (or DX, DY, DZ and TOPS)")
        err = InputError(f"{path}: {what}; --skip-missing shows the cells in IJK index space")
        if not self.skip_missing:
            raise err
        self.meta.setdefault("strict_error", str(err))
        why = f"block-centred {', '.join(gaps)}" if gaps else " or ".join(absent)
        notes.append(f"no {why} was read, so the cells are shown in IJK index space (unit "
                     "cells: x = I, y = J, depth = K)")
        coord, zcorn = index_space_geometry(self.dims)
        return coord, zcorn, "IJK index space"

    def finish(self) -> CornerPointGrid:
        path = self.root
        notes: list[str] = []  # what skip_missing left out: one warning
        if self.missing:
            if not self.skip_missing:
                raise missing_error(path, self.missing)
            self.meta["strict_error"] = str(missing_error(path, self.missing))
            notes.append(f"{len(self.missing)} INCLUDE file(s) missing and skipped: "
                         f"{missing_text(self.missing)}")
        if self.dims is None:
            extra = (f"; {len(self.missing)} INCLUDE file(s) missing ("
                     f"{missing_text(self.missing)}): the size may be in one of them"
                     if self.missing else "")
            raise InputError(f"{path}: no SPECGRID or DIMENS keyword; a corner-point grid needs "
                             f"SPECGRID, COORD and ZCORN{extra}")
        coord, zcorn, geometry = self.geometry(path, notes)
        faults = [Fault(name, np.concatenate(parts)) for name, parts in self.faults.items()]
        nx, ny, nz = self.dims
        for f in faults:
            if (bad := (f.faces[:, :3] >= (nx, ny, nz)).any(axis=1)).any():
                cell = tuple(int(v) + 1 for v in f.faces[bad][0, :3])
                raise InputError(f"{path}: FAULTS {f.name}: cell {cell} is outside the grid "
                                 f"{self.dims}")
        meta = self.meta
        meta["geometry"] = geometry
        meta["skipped_keywords"] = list(self.skipped)
        if self.missing:
            meta["missing_includes"] = [name for name, _ in self.missing]
        if self.unit_system:
            meta["unit_system"] = self.unit_system
        units = self.units or UNIT_SYSTEMS.get(self.unit_system, "")
        mapaxes = self.mapaxes
        if geometry == "IJK index space":  # unit cells, not map positions
            meta["index_space"], units, mapaxes = True, "", None
        if notes:
            warnings.warn(f"{path}: {'; '.join(notes)}", stacklevel=3)
        grid = CornerPointGrid(coord=coord, zcorn=zcorn, actnum=self.actnum,
                               mapaxes=mapaxes, properties=self.props, faults=faults,
                               units=units, name=str(path), meta=meta)
        warn_inverted(grid, path)
        return grid


def _box_text(box) -> str:
    return ", ".join(f"{s.start + 1}-{s.stop}" for s in box)


def read_grdecl(path, progress=None, skip_missing: bool = False) -> CornerPointGrid:
    """Read an ECLIPSE GRDECL corner-point grid, streaming (the text is never held whole).

    Parameters
    ----------
    path : str or Path
        A GRDECL file (``.grdecl``, ``.grid``, ``.inc``, ...); its INCLUDEs are read too,
        relative to the including file.
    progress : callable, optional
        ``progress(bytes_read, bytes_total)`` after each chunk, over the file and its INCLUDEs
        (the total grows as INCLUDEs are found; see :mod:`geoshade.progress`).  None: no
        reports.
    skip_missing : bool
        Read what is there when INCLUDE files are missing (one warning names them); a grid
        whose geometry is missing (but not its size) gets unit cells in IJK index space
        (``meta["index_space"]``).  Default: missing INCLUDEs are an error that lists them all.

    Returns
    -------
    CornerPointGrid
        COORD float64, ZCORN float32, ACTNUM uint8 (all ones if absent), properties float32
        (int32 for ``*NUM``), FAULTS as :class:`~geoshade.models.Fault` lists, ``units`` from
        GRIDUNIT (else from METRIC/FIELD/LAB: METRES/FEET/CM), ``meta`` with ``format``,
        ``source``, ``files`` (all files read), ``geometry`` ("corner-point", "block-centred
        (DX, DY, DZ, TOPS)", ... or "IJK index space"), ``skipped_keywords``, and where given
        ``unit_system``, ``mapunits``, ``gdorient``, ``missing_includes``, ``index_space`` and
        ``strict_error`` (the line a read without ``skip_missing`` would have raised).
        Block-centred keywords (``DX/DY/DZ/TOPS``, ``DXV/DYV/DZV/DEPTHZ``, in a BOX or set by
        EQUALS too) become COORD and ZCORN as OPM makes them
        (:mod:`geoshade.io.grids.block_centred`);
        EQUALS, MULTIPLY, ADD, COPY, MINVALUE, MAXVALUE edit cell arrays.

    Raises
    ------
    InputError
        One line naming file and keyword: an array longer or shorter than SPECGRID implies, an
        overrunning ``N*`` repeat, a non-numeric token, missing INCLUDEs (all of them listed),
        arrays before SPECGRID/DIMENS, no geometry, an incomplete set of block-centred
        keywords.  Warns once per unused keyword (file, keyword).

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "box.grdecl")
    >>> _ = open(f, "w").write('''SPECGRID
    ... 1 1 1 1 F /
    ... COORD
    ... 0 0 0 0 0 1   1 0 0 1 0 1   0 1 0 0 1 1   1 1 0 1 1 1 /
    ... ZCORN 4*0 4*1 /
    ... PORO 0.25 / -- a property
    ... ''')
    >>> g = read_grdecl(f)
    >>> g.dims, g.nactive, float(g.properties["PORO"][0, 0, 0])
    ((1, 1, 1), 1, 0.25)
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    builder = GridBuilder(p, progress, skip_missing)
    builder.parse_all()
    builder.warn_skipped()
    return builder.finish()


