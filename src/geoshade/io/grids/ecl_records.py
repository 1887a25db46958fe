"""The records of ECLIPSE/OPM output files (EGRID, INIT, UNRST), checked before use.

A binary (unformatted) file is a chain of records: a 24-byte header (Fortran markers 16,
keyword, element count, type) and the data in blocks of 1000 values (105 for strings), each
between two markers.  resfo's lazy reader trusts the header's count: a wrong one makes it seek to
the wrong place (the next header is then garbage) or past the end of the file, where it stops
as at a clean end and every array after it is silently gone; a negative count seeks backwards.
So the chain is walked here, header by header (:func:`scan`), and every header is checked before
its array is used:

- the markers are 16, the keyword is text, the type is one of ECLIPSE's;
- the count is not negative and its data fit in the bytes left in the file;
- the last record ends exactly at the end of the file (so no count can drop arrays unseen).

Arrays are then read through resfo at their offsets (:meth:`Record.read`), after a check of the
memory they need; whatever resfo raises (a damaged block marker inside the data) becomes one
:class:`RecordError` line naming the file and the keyword.

The format comes from the content.  A formatted (text) file (``.FEGRID .FINIT .FUNRST``,
``.F0001``) is indexed the same way, without parsing its values: the record headers
(``'SWAT    '  35817 'REAL'``) are found line by line in blocks of :data:`FORMATTED_BLOCK` bytes
and the values between two headers are counted (whitespace-separated tokens; quoted strings for
``CHAR``), so a formatted restart is never read whole either and a record is parsed only when it
is used, from its byte offset.  resfo's formatted reader parses character by character (10 s
for Reek's 5.7 MB FEGRID, ~2 min for its UNRST); this one splits tokens with numpy (~0.1 s) and
is tested equal to resfo's, record by record.  The checks: each header's count equals the values
that follow it, no quote inside numbers (a damaged header), the file ends with a line end (else
its last value may be cut).  A formatted file under a binary name (``.EGRID .INIT .UNRST
.X0001``) is refused, as resfo would read it as binary.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import resfo

from geoshade.errors import InputError
from geoshade.io.grids.grid_checks import check_memory
from geoshade.io.paths import check_file

#: bytes of one value of each type (C0nn: nn)
ITEM_BYTES = {"INTE": 4, "REAL": 4, "LOGI": 4, "DOUB": 8, "CHAR": 8, "MESS": 0}
#: suffixes of the binary files that geoshade reads (and ``.X0001`` ... non-unified restarts)
BINARY_SUFFIXES = (".egrid", ".init", ".unrst")
#: a non-unified restart file: ``X`` binary, ``F`` formatted, then the report number
RESTART_SUFFIX = re.compile(r"\.([XxFf])(\d{4})")
#: bytes of a formatted file looked at (headers found, values counted or parsed) at a time
FORMATTED_BLOCK = 8 << 20
#: what resfo (and numpy under it) raise on a damaged file
_READ_ERRORS = (resfo.ResfoParsingError, ValueError, IndexError, OverflowError, EOFError)
_HEADER = 24
#: numeric types read straight from a memory map (big-endian in the file)
_FAST_TYPES = {"INTE": ">i4", "REAL": ">f4", "DOUB": ">f8"}
#: values per block of a numeric record
_BLOCK = 1000
#: blocks read at a time (~4 MB of REAL values)
READ_BLOCKS = 1024


class RecordError(InputError):
    """A damaged or truncated record: one line naming the file and the keyword.

    ``offset`` is the byte where the bad record starts, ``keyword`` the record's keyword (""
    where its header is unreadable), ``after`` the keyword of the good record before it,
    ``truncated`` whether the file ends inside it.
    """

    def __init__(self, message: str, offset: int = 0, keyword: str = "", after: str = "",
                 truncated: bool = False):
        super().__init__(message)
        self.offset, self.keyword, self.after, self.truncated = offset, keyword, after, truncated


@dataclass
class Record:
    """One record of an ECLIPSE file: ``keyword``, element ``length``, ``type`` ("REAL",
    "INTE", ...), ``start`` and ``end`` byte offsets of the whole record; for a formatted file
    ``data`` is the byte offset of its values (after the header line) and ``formatted`` True."""

    path: Path
    keyword: str
    length: int
    type: str
    start: int
    end: int
    data: int = field(default=0, repr=False)
    formatted: bool = False

    def read(self, kinds: str | None = None) -> np.ndarray:
        """The record's array (big-endian as in the file for unformatted ones).

        ``kinds``: the numpy kinds it must have (``"i"``, ``"f"``, ``"fi"``, ``"S"``...): else
        one line naming the keyword and the type found.
        """
        if kinds is not None:
            want = {"i": ("INTE",), "f": ("REAL", "DOUB"), "S": ("CHAR",)}
            ok = {t for k in kinds for t in want.get(k, ())}
            if self.type not in ok and not (("S" in kinds) and self.type.startswith("C0")):
                raise RecordError(f"{self.path}: {self.keyword}: values of type {self.type}; "
                                  f"expected {' or '.join(sorted(ok))}", self.start,
                                  self.keyword)
        check_memory(self.path, f"{self.keyword} ({self.length} values)",
                     self.length * max(item_bytes(self.type) or 1, 1))
        if self.formatted:
            return _read_formatted(self)
        if self.type in _FAST_TYPES and self.length:
            return self._read_blocks()
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.start)
                entry = next(resfo.lazy_read(fh, resfo.Format.UNFORMATTED))
                arr = entry.read_array()
        except _READ_ERRORS as err:
            raise RecordError(f"{self.path}: {self.keyword}: damaged record at byte "
                              f"{self.start} ({_short(err)})", self.start,
                              self.keyword) from None
        return self._checked(arr)

    def _read_blocks(self) -> np.ndarray:
        out = np.empty(self.length, np.dtype(_FAST_TYPES[self.type]).newbyteorder("="))
        _read_blocks_into(self, out)
        return out

    def read_range(self, first: int, count: int) -> np.ndarray:
        """Values ``first .. first + count`` of a numeric record (native byte order), reading
        only their blocks: a slab of a 1e8-cell array without the rest of it."""
        if not 0 <= first <= first + count <= self.length:
            raise ValueError(f"{self.keyword}: values {first}..{first + count} outside "
                             f"0..{self.length}")
        if self.formatted or self.type not in _FAST_TYPES:
            return self.read()[first:first + count]
        out = np.empty(count, np.dtype(_FAST_TYPES[self.type]).newbyteorder("="))
        if count:
            _read_blocks_into(self, out, first)
        return out

    def _checked(self, arr) -> np.ndarray:
        if not isinstance(arr, np.ndarray) or arr.size != self.length:
            raise RecordError(f"{self.path}: {self.keyword}: damaged record at byte "
                              f"{self.start} (read {getattr(arr, 'size', 0)} of {self.length} "
                              "values)", self.start, self.keyword)
        return arr


def _read_blocks_into(rec: Record, out: np.ndarray, first: int = 0) -> None:
    """Values ``first .. first + out.size`` of the unformatted numeric record ``rec`` into
    ``out`` (native byte order): the blocks are read :data:`READ_BLOCKS` at a time into one
    reused buffer, their markers checked with numpy and the values byte-swapped in one pass
    (resfo reads block by block in Python: ~40 s for a 1e8-cell ZCORN; a memory map would add
    the file's pages to the process's resident memory)."""
    big = np.dtype(_FAST_TYPES[rec.type])
    size, n = big.itemsize, out.size
    nblocks = -(-rec.length // _BLOCK)
    full = _BLOCK * size + 8
    block_t = np.dtype([("m0", ">i4"), ("d", big, (_BLOCK,)), ("m1", ">i4")])
    base = rec.start + _HEADER
    b_end = -(-(first + n) // _BLOCK)
    buf = np.empty(min(READ_BLOCKS, b_end) * full, np.uint8)
    with open(rec.path, "rb") as fh:
        b = first // _BLOCK
        while b < b_end:  # groups of blocks, not values
            nb = min(READ_BLOCKS, b_end - b)
            last = b + nb == nblocks and rec.length % _BLOCK
            nwhole = nb - 1 if last else nb
            nbytes = nwhole * full + ((8 + (rec.length % _BLOCK) * size) if last else 0)
            fh.seek(base + b * full)
            got = fh.readinto(memoryview(buf)[:nbytes])
            if got != nbytes:
                raise RecordError(f"{rec.path}: {rec.keyword}: the file ends inside the "
                                  "record (truncated)", rec.start, rec.keyword, truncated=True)
            vals = [(buf[:nwhole * full].view(block_t), _BLOCK * size)] if nwhole else []
            if last:
                nl = rec.length % _BLOCK
                tail = buf[nwhole * full:nbytes]
                m = np.frombuffer(tail[:4].tobytes() + tail[-4:].tobytes(), ">i4")
                vals.append((np.array([(m[0], m[1])], [("m0", ">i4"), ("m1", ">i4")]),
                             nl * size))
            for q, (blk, want) in enumerate(vals):
                bad = (blk["m0"] != want) | (blk["m1"] != want)
                if bad.any():
                    k = b + (nwhole if q else int(np.argmax(bad)))
                    raise RecordError(f"{rec.path}: {rec.keyword}: damaged record at byte "
                                      f"{rec.start} (the marker of block {k} is not its "
                                      "block's size)", rec.start, rec.keyword)
            # the values of blocks [b, b + nb) that fall in [first, first + n)
            v0, v1 = max(first, b * _BLOCK), min(first + n, (b + nb) * _BLOCK)
            w0 = b * _BLOCK  # value index of the group's first value
            if nwhole:
                d = vals[0][0]["d"]
                wend = min(v1, w0 + nwhole * _BLOCK)  # values of this group's whole blocks
                i0, i1 = -(-(v0 - w0) // _BLOCK), (wend - w0) // _BLOCK
                pieces = [(v0, wend)]
                if i1 > i0:  # whole blocks straight into a 2-D view of ``out``
                    out[w0 + i0 * _BLOCK - first:w0 + i1 * _BLOCK - first].reshape(
                        -1, _BLOCK)[:] = d[i0:i1]
                    pieces = [(v0, w0 + i0 * _BLOCK), (w0 + i1 * _BLOCK, wend)]
                for a, z in pieces:  # at most two partial blocks each
                    if z > a:
                        ba, bz = (a - w0) // _BLOCK, -(-(z - w0) // _BLOCK)
                        out[a - first:z - first] = d[ba:bz].reshape(-1)[
                            a - w0 - ba * _BLOCK:z - w0 - ba * _BLOCK]
            if last and v1 > w0 + nwhole * _BLOCK:
                t0 = w0 + nwhole * _BLOCK
                tail = buf[nwhole * full + 4:nwhole * full + 4 + (rec.length % _BLOCK) * size]
                a = max(v0, t0)
                out[a - first:v1 - first] = tail.view(big)[a - t0:v1 - t0]
            b += nb


def item_bytes(type_: str) -> int | None:
    """Bytes of one value of an ECLIPSE type, None for an unknown type."""
    if len(type_) == 4 and type_.startswith("C0") and type_[2:].isdigit():
        return int(type_[2:])
    return ITEM_BYTES.get(type_)


def data_bytes(length: int, type_: str) -> int:
    """Bytes of a record's data blocks: the values plus 8 marker bytes per block."""
    size = item_bytes(type_) or 0
    if length == 0 or size == 0:
        return 0
    block = 105 if type_.startswith("C") else 1000
    return length * size + 8 * -(-length // block)


def _short(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    first = (text[0] if text else type(err).__name__)[:120]
    m = re.match(r"Unexpected size of record (-?\d+)", first)
    return f"a block marker reads {m.group(1)}, not its block's size" if m else first


def file_format(path: Path) -> str:
    """``"unformatted"`` or ``"formatted"`` from the file's first bytes; one line for an empty
    file, a text file under a binary name, or anything else (a FIFO or a folder under an
    ECLIPSE name is refused before it is opened)."""
    check_file(path, "an ECLIPSE file")
    with open(path, "rb") as fh:
        head = fh.read(256)
    if not head:
        raise RecordError(f"{path}: the file is empty; expected an ECLIPSE "
                          f"{path.suffix.lstrip('.').upper() or 'output'} file", 0,
                          truncated=True)
    if len(head) >= 4 and int.from_bytes(head[:4], "big", signed=True) == 16:
        return "unformatted"
    text = head.lstrip()
    if text[:1] == b"'" and all(32 <= c < 127 or c in (9, 10, 13) for c in head):
        name = path.suffix.lstrip(".").upper()
        restart = RESTART_SUFFIX.fullmatch(path.suffix)
        if path.suffix.lower() in BINARY_SUFFIXES or (restart and restart[1] in "Xx"):
            formatted = f"F{restart[2]}" if restart else f"F{name}"
            raise RecordError(f"{path}: a formatted (text) ECLIPSE file under the binary name "
                              f".{name}; expected the unformatted (binary) file a simulator "
                              f"writes (a formatted one is named .{formatted})")
        return "formatted"
    marker = int.from_bytes(head[:4].ljust(4, b"\0"), "big", signed=True)
    raise RecordError(f"{path}: not an ECLIPSE output file (the first record marker is "
                      f"{marker}, expected 16)")


def _header(fh, path: Path, pos: int, size: int, prev: str) -> tuple[str, int, str, int]:
    """(keyword, length, type, data start) of the record at ``pos``; checked."""
    after = f" after {prev}" if prev else ""
    raw = fh.read(_HEADER)
    if len(raw) < _HEADER:
        partial = raw[4:12] if len(raw) >= 12 and all(32 <= c < 127 for c in raw[4:12]) else b""
        raise RecordError(f"{path}: the file ends inside the header of the record at byte {pos}"
                          f"{after} (truncated)", pos, partial.decode().strip(), prev,
                          truncated=True)
    m1, m2 = (int.from_bytes(raw[a:a + 4], "big", signed=True) for a in (0, 20))
    kw_raw, type_raw = raw[4:12], raw[16:20]
    if m1 != 16 or m2 != 16 or not all(32 <= c < 127 for c in kw_raw + type_raw):
        why = (f"record marker {m1}, expected 16" if m1 != 16 else
               f"end marker {m2}, expected 16" if m2 != 16 else
               f"keyword {bytes(kw_raw)!r} or type {bytes(type_raw)!r} is not text")
        raise RecordError(f"{path}: damaged record header at byte {pos}{after} ({why}); a "
                          f"wrong element count in {prev or 'the header'} or a damaged file",
                          pos, "", prev)
    keyword, type_ = kw_raw.decode().strip(), type_raw.decode()
    length = int.from_bytes(raw[12:16], "big", signed=True)
    data = pos + _HEADER
    if type_ == "X231":  # more than 2**31 values: a second header carries the rest
        raw2 = fh.read(_HEADER)
        if len(raw2) < _HEADER:
            raise RecordError(f"{path}: {keyword}: the file ends inside its header (truncated)",
                              pos, keyword, prev, truncated=True)
        type_ = raw2[16:20].decode(errors="replace")
        length = -length * 2**31 + int.from_bytes(raw2[12:16], "big", signed=True)
        data += _HEADER
    if item_bytes(type_) is None:
        raise RecordError(f"{path}: {keyword}: unknown value type {type_!r} in the header at "
                          f"byte {pos}; a damaged file", pos, keyword, prev)
    if length < 0:
        raise RecordError(f"{path}: {keyword}: negative element count {length} in the header "
                          f"at byte {pos}; a damaged file", pos, keyword, prev)
    if length and not item_bytes(type_):
        raise RecordError(f"{path}: {keyword}: a {type_} record with {length} values in the "
                          f"header at byte {pos} (it holds none); a damaged file", pos, keyword,
                          prev)
    return keyword, length, type_, data


def scan(path, start: int = 0, prev: str = "") -> Iterator[Record]:
    """Every record of an ECLIPSE file, its header checked (see the module text); raises
    :class:`RecordError` at the first damaged or truncated record, after yielding the good ones
    before it (a reader that keeps what came before, such as the UNRST index, can).

    ``start``: the byte offset of a record header of a binary file to walk from (``prev``: the
    keyword before it, for messages); a formatted file is always walked from its start."""
    p = Path(path)
    if file_format(p) == "formatted":
        yield from _scan_formatted(p)
        return
    size = p.stat().st_size
    pos = start
    with open(p, "rb") as fh:
        while pos < size:
            fh.seek(pos)
            keyword, length, type_, data = _header(fh, p, pos, size, prev)
            end = data + data_bytes(length, type_)
            if end > size:
                raise RecordError(
                    f"{p}: {keyword}: the header at byte {pos} announces {length} values "
                    f"({end - data} bytes) but only {size - data} bytes follow it "
                    "(truncated, or a wrong element count)", pos, keyword, prev,
                    truncated=True)
            yield Record(p, keyword, length, type_, pos, end)
            prev, pos = keyword, end



# --- formatted files ---------------------------------------------------------------------------
#: a record header on a line of its own: 'KEYWORD'  count  'TYPE'
_FMT_HEADER = re.compile(rb"[ \t]*'([^'\r\n]{1,8})'[ \t]+(-?\d{1,12})[ \t]+'([A-Z0-9]{4})'")
#: bytes kept back at the end of a block so that a header cut by the block is read whole
_FMT_TAIL = 4096
#: 1 for the bytes that separate values (space, tab, line ends, form feed, vertical tab)
_SPACE = np.zeros(256, bool)
_SPACE[[9, 10, 11, 12, 13, 32]] = True
_NUMERIC = {"INTE": np.int32, "REAL": np.float32, "DOUB": np.float64}


class _Open:
    """A formatted record whose values are being counted."""

    def __init__(self, keyword: str, length: int, type_: str, start: int, data: int):
        self.keyword, self.length, self.type, self.start, self.data = (keyword, length, type_,
                                                                       start, data)
        self.count = 0  # values (tokens; for strings: quotes, two a value)
        self.quote = -1  # byte of the first quote among numbers (a damaged header), or -1
        self.space = True  # the byte before the next block is a separator

    def add(self, buf: bytes, a: int, b: int, base: int) -> None:
        """Count the values in ``buf[a:b]`` (file offset ``base + a``)."""
        if b <= a or self.quote >= 0:
            return
        if self.type.startswith("C"):
            self.count += buf.count(b"'", a, b)
            return
        q = buf.find(b"'", a, b)
        if q >= 0:
            self.quote, b = base + q, q
        if b <= a:
            return
        sp = _SPACE[np.frombuffer(buf, np.uint8, b - a, a)]
        self.count += int(np.count_nonzero(sp[:-1] & ~sp[1:])) + int(self.space and not sp[0])
        self.space = bool(sp[-1])

    def values(self) -> int:
        return self.count // 2 if self.type.startswith("C") else self.count


def _close(p: Path, rec: _Open, end: int, prev: str, last: bool, whole: bool) -> Record:
    """The finished record, or a :class:`RecordError` naming what is wrong with it."""
    n, kw = rec.values(), rec.keyword
    damaged = f"{p}: {kw}: damaged formatted record at byte {rec.start}"
    if rec.type.startswith("C") and rec.count % 2:
        raise RecordError(f"{damaged} (a quote without its pair"
                          f"{'; the file ends inside a string' if last else ''})", rec.start,
                          kw, prev, truncated=last)
    if n != rec.length:
        if last and n < rec.length and rec.quote < 0:
            raise RecordError(f"{damaged} (the file ends after {n} of its {rec.length} values; "
                              "truncated)", rec.start, kw, prev, truncated=True)
        raise RecordError(f"{damaged} ({n} values where its header announces {rec.length}"
                          f"{'; then a quote, a damaged header' if rec.quote >= 0 else ''})",
                          rec.start, kw, prev, truncated=last)
    if last and not whole and rec.length:
        raise RecordError(f"{damaged} (the file ends inside a value, without a line end; "
                          "truncated)", rec.start, kw, prev, truncated=True)
    return Record(p, kw, rec.length, rec.type, rec.start, end, rec.data, True)


def _headers(buf: bytes, limit: int) -> Iterator[re.Match]:
    """The record headers starting before ``limit``, each at the start of a line.  Numbers hold
    no quote, so the search jumps from quote to quote (``bytes.find``) instead of trying every
    line of the values."""
    q = buf.find(b"'", 0, limit)
    while q >= 0:
        line = buf.rfind(b"\n", 0, q) + 1
        m = _FMT_HEADER.match(buf, line)
        if m is not None and m.start(1) == q + 1:
            yield m
            q = buf.find(b"'", m.end(), limit)
        else:
            q = buf.find(b"'", q + 1, limit)


def _scan_formatted(p: Path) -> Iterator[Record]:
    """The records of a formatted file: headers found, values counted, nothing parsed."""
    size = p.stat().st_size
    with open(p, "rb") as fh:
        fh.seek(size - 1)
        whole = _SPACE[fh.read(1)[0]]  # a text file ends with a line end
        fh.seek(0)
        buf, base, prev = b"", 0, ""
        cur: _Open | None = None
        while True:
            chunk = fh.read(FORMATTED_BLOCK)
            buf += chunk
            eof = not chunk
            limit = len(buf) if eof else max(0, len(buf) - _FMT_TAIL)
            pos = 0
            for m in _headers(buf, limit):
                if cur is None:
                    if buf[:m.start()].strip():
                        raise RecordError(f"{p}: damaged record header at byte 0 (text before "
                                          "the first header); not a formatted ECLIPSE file", 0)
                else:
                    cur.add(buf, pos, m.start(), base)
                    if cur.quote >= 0 and cur.values() == cur.length:
                        yield _close(p, cur, cur.quote, prev, False, True)
                        raise RecordError(f"{p}: damaged record header at byte {cur.quote} "
                                          f"after {cur.keyword}", cur.quote, "", cur.keyword)
                    yield _close(p, cur, base + m.start(), prev, False, True)
                    prev = cur.keyword
                kw, length, type_ = (m[1].decode().strip(), int(m[2]), m[3].decode())
                if length < 0 or item_bytes(type_) is None or (length and not item_bytes(type_)):
                    raise RecordError(f"{p}: {kw}: bad header at byte {base + m.start()} (count "
                                      f"{length}, type {type_!r}); a damaged file",
                                      base + m.start(), kw, prev)
                cur = _Open(kw, length, type_, base + m.start(), base + m.end())
                pos = m.end()
            cut = max(pos, limit)
            if cur is None:
                if buf[:cut].strip():
                    raise RecordError(f"{p}: damaged record header at byte 0; not a formatted "
                                      "ECLIPSE file (no record header found)", 0)
            else:
                cur.add(buf, pos, cut, base)
            buf, base = buf[cut:], base + cut
            if eof:
                break
    if cur is None:
        raise RecordError(f"{p}: no record header found; expected a formatted ECLIPSE file", 0)
    if cur.quote >= 0 and cur.values() == cur.length:
        yield _close(p, cur, cur.quote, prev, False, True)
        raise RecordError(f"{p}: the file ends inside the header of the record at byte "
                          f"{cur.quote} after {cur.keyword} (truncated)", cur.quote, "",
                          cur.keyword, truncated=True)
    yield _close(p, cur, size, prev, True, bool(whole))


def _tokens(fh, start: int, end: int) -> Iterator[bytes]:
    """The text of ``[start, end)`` in pieces of about :data:`FORMATTED_BLOCK` bytes, each
    ending at a separator (no value is cut in two)."""
    fh.seek(start)
    pos, rest = start, b""
    while pos < end:
        raw = rest + fh.read(min(FORMATTED_BLOCK, end - pos))
        pos = fh.tell()
        if pos >= end:
            yield raw
            return
        cut = max(raw.rfind(c) for c in (b" ", b"\n", b"\r", b"\t"))
        if cut < 0:
            rest = raw
            continue
        yield raw[:cut]
        rest = raw[cut:]


def _read_formatted(rec: Record) -> np.ndarray:
    """The values of a formatted record, parsed block by block into one array (the dtypes of
    resfo's unformatted reader: int32, float32, float64, bool, ``S`` strings)."""
    kw, n = rec.keyword, rec.length
    where = f"{rec.path}: {kw}: damaged formatted record at byte {rec.start}"
    if rec.type == "MESS":
        return np.zeros(0, np.int32)
    try:
        with open(rec.path, "rb") as fh:
            if rec.type.startswith("C"):
                fh.seek(rec.data)
                words = re.findall(rb"'([^']*)'", fh.read(rec.end - rec.data))
                out = np.array(words, dtype=f"S{max([len(w) for w in words] or [1])}")
            else:
                dt = _NUMERIC.get(rec.type, np.bool_)
                out = np.empty(n, dt)
                done = 0
                for text in _tokens(fh, rec.data, rec.end):
                    if rec.type == "DOUB":
                        text = text.replace(b"D", b"E").replace(b"d", b"e")
                    toks = text.split()
                    if done + len(toks) > n:
                        raise ValueError(f"more than the {n} values its header announces")
                    if not toks:
                        continue
                    arr = np.array(toks)
                    if dt is np.bool_:
                        t, f = arr == b"T", arr == b"F"
                        if not (t | f).all():
                            bad = arr[~(t | f)][0].decode(errors="replace")
                            raise ValueError(f"{bad!r} is not a logical value (T or F)")
                        out[done:done + len(toks)] = t
                    else:
                        out[done:done + len(toks)] = arr.astype(dt)
                    done += len(toks)
                if done != n:
                    raise ValueError(f"{done} of its {n} values")
    except _READ_ERRORS as err:
        raise RecordError(f"{where} ({_short(err)})", rec.start, kw) from None
    if out.size != n:
        raise RecordError(f"{where} (read {out.size} of {n} values)", rec.start, kw)
    return out
