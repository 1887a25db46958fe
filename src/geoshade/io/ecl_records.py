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
:class:`RecordError` line naming the file and the keyword.  The format comes from the content:
a formatted (text) file is read through resfo's formatted reader, except under a binary name
(``.EGRID``, ``.INIT``, ``.UNRST``), where it is refused.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import resfo

from geoshade.errors import InputError
from geoshade.io.grid_checks import check_memory
from geoshade.io.paths import check_file

#: bytes of one value of each type (C0nn: nn)
ITEM_BYTES = {"INTE": 4, "REAL": 4, "LOGI": 4, "DOUB": 8, "CHAR": 8, "MESS": 0}
#: suffixes of the binary files that geoshade reads
BINARY_SUFFIXES = (".egrid", ".init", ".unrst")
#: what resfo (and numpy under it) raise on a damaged file
_READ_ERRORS = (resfo.ResfoParsingError, ValueError, IndexError, OverflowError, EOFError)
_HEADER = 24


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
    "INTE", ...), ``start`` and ``end`` byte offsets (unformatted files; formatted: 0) and, for
    formatted files, the array resfo already parsed."""

    path: Path
    keyword: str
    length: int
    type: str
    start: int
    end: int
    _array: Any = field(default=None, repr=False)

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
        if self._array is not None:
            return np.asarray(self._array)
        check_memory(self.path, f"{self.keyword} ({self.length} values)",
                     self.length * max(item_bytes(self.type) or 1, 1))
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.start)
                entry = next(resfo.lazy_read(fh, resfo.Format.UNFORMATTED))
                arr = entry.read_array()
        except _READ_ERRORS as err:
            raise RecordError(f"{self.path}: {self.keyword}: damaged record at byte "
                              f"{self.start} ({_short(err)})", self.start,
                              self.keyword) from None
        if not isinstance(arr, np.ndarray) or arr.size != self.length:
            raise RecordError(f"{self.path}: {self.keyword}: damaged record at byte "
                              f"{self.start} (read {getattr(arr, 'size', 0)} of {self.length} "
                              "values)", self.start, self.keyword)
        return arr


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
        if path.suffix.lower() in BINARY_SUFFIXES:
            name = path.suffix.lstrip(".").upper()
            raise RecordError(f"{path}: a formatted (text) ECLIPSE file under the binary name "
                              f".{name}; expected the unformatted (binary) file a simulator "
                              f"writes (a formatted one is named .F{name})")
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


def scan(path) -> Iterator[Record]:
    """Every record of an ECLIPSE file, its header checked (see the module text); raises
    :class:`RecordError` at the first damaged or truncated record, after yielding the good ones
    before it (a reader that keeps what came before, such as the UNRST index, can)."""
    p = Path(path)
    if file_format(p) == "formatted":
        yield from _scan_formatted(p)
        return
    size = p.stat().st_size
    prev, pos = "", 0
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


_FORMATTED_HEADER = re.compile(r"'([^']{1,8})'\s+-?\d+\s+'[A-Z0-9]{4}'")


def _scan_formatted(p: Path) -> Iterator[Record]:
    prev, n = "", 0
    try:
        for e in resfo.lazy_read(str(p), resfo.Format.FORMATTED):
            keyword = e.read_keyword().strip()
            raw_type = e.read_type()
            type_ = (raw_type.decode(errors="replace") if isinstance(raw_type, bytes)
                     else str(raw_type))
            length = int(e.read_length())
            if length < 0 or item_bytes(type_) is None:
                raise RecordError(f"{p}: {keyword}: bad header (count {length}, type "
                                  f"{type_!r}); a damaged file", 0, keyword, prev)
            yield Record(p, keyword, length, type_, 0, 0, e.read_array())
            prev, n = keyword, n + 1
    except RecordError:
        raise
    except _READ_ERRORS as err:  # resfo parses a whole record before naming it: find its name
        with open(p, encoding="ascii", errors="replace") as fh:
            text = fh.read(256 << 20)  # enough for any formatted file resfo's parser can take
        names = [m.group(1).strip() for m in _FORMATTED_HEADER.finditer(text)]
        keyword = names[n] if n < len(names) else ""
        what = f"{keyword}: " if keyword else ""
        after = f" after {prev}" if prev else ""
        raise RecordError(f"{p}: {what}damaged formatted record{after} ({_short(err)})", 0,
                          keyword, prev) from None
