"""What a corner-point case declares, read from its headers alone (the ``header`` functions of the
grid rows of :mod:`geoshade.io.formats`): the grid's dimensions, the active cells where they are
cheap to count, and the cell arrays beside the geometry.

- an ECLIPSE/OPM case (any of its files): the EGRID's ``GRIDHEAD``, found by walking its record
  headers (:func:`geoshade.io.grids.ecl_records.scan`, no array read); ``ACTNUM`` is counted
  when it has at most :data:`COUNT_CELLS` values (read in pieces); the INIT's cell arrays are
  counted from their headers;
- a GRDECL file or deck: ``SPECGRID`` or ``DIMENS`` found in the first :data:`SCAN_BYTES` of
  the text (INCLUDEd files are not followed; the plan then knows nothing before reading).

>>> import tempfile, os
>>> f = os.path.join(tempfile.mkdtemp(), "g.grdecl")
>>> _ = open(f, "w").write("-- a grid\\nSPECGRID\\n 40 30 5 1 F /\\nCOORD\\n 7446*0 /\\n")
>>> h = grdecl_header(f)
>>> h.shape, h.nactive
((40, 30, 5), None)
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from geoshade.io.grids.ecl_records import RecordError, scan
from geoshade.io.paths import check_file
from geoshade.io.plan import Header

#: ACTNUM is counted (read in pieces) up to this many cells; beyond, every cell is taken active
COUNT_CELLS = 1 << 25
#: bytes of a GRDECL file or deck searched for SPECGRID / DIMENS
SCAN_BYTES = 64 << 20
_BLOCK = 8 << 20
_DIMS = re.compile(rb"(?m)^[ \t]*(SPECGRID|DIMENS)\b[^\n]*\n(?:[ \t]*(?:--[^\n]*)?\n)*"
                   rb"[ \t]*(\d+)[ \t]+(\d+)[ \t]+(\d+)")


def _egrid_of(path: Path) -> Path | None:
    if path.suffix.lower() in (".egrid", ".fegrid"):
        return path
    for suf in (".EGRID", ".egrid", ".FEGRID", ".fegrid"):
        cand = path.with_suffix(suf)
        if cand.is_file():
            return cand
    return None


def _init_of(egrid: Path) -> Path | None:
    for suf in ((".INIT", ".init") if egrid.suffix.lower() == ".egrid" else (".FINIT", ".finit")):
        cand = egrid.with_suffix(suf)
        if cand.is_file():
            return cand
    return None


def _count_active(rec) -> int:
    n = 0
    for first in range(0, rec.length, 1 << 22):
        n += int(np.count_nonzero(rec.read_range(first, min(1 << 22, rec.length - first))))
    return n


def egrid_header(path) -> Header | None:
    """An ECLIPSE/OPM case's dimensions from its EGRID's ``GRIDHEAD`` (None without an EGRID
    beside ``path``, or where the lengths of its ``COORD`` and ``ZCORN`` records do not bear
    the dimensions out), ``ACTNUM`` counted when small, the INIT's cell arrays counted."""
    p = check_file(path, "a file of an ECLIPSE/OPM case")
    egrid = _egrid_of(p)
    if egrid is None:
        return None
    dims, nactive, notes, actnum = None, None, [], None
    lengths: dict[str, int] = {}
    for rec in scan(egrid):
        if rec.keyword == "GRIDHEAD" and dims is None:
            head = rec.read("i")
            if len(head) >= 4:
                dims = tuple(int(v) for v in head[1:4])
        elif rec.keyword == "ACTNUM" and actnum is None:
            actnum = rec
        elif rec.keyword in ("COORD", "ZCORN") and rec.keyword not in lengths:
            lengths[rec.keyword] = rec.length
        elif rec.keyword in ("ENDGRID", "LGR"):
            break
    if dims is None or min(dims) < 1:
        return None
    ncells = dims[0] * dims[1] * dims[2]
    # a GRIDHEAD its own arrays do not bear out (damaged): no plan, the reader says what is wrong
    want = {"COORD": 6 * (dims[0] + 1) * (dims[1] + 1), "ZCORN": 8 * ncells}
    if any(lengths.get(k) != n for k, n in want.items()):
        return None
    if actnum is not None and actnum.length == ncells and ncells <= COUNT_CELLS:
        nactive = _count_active(actnum)
    else:
        notes.append("active cells not counted (every cell taken active)")
    arrays = 0
    init = _init_of(egrid)
    if init is not None:
        try:
            arrays = sum(1 for r in scan(init) if r.length in (ncells, nactive)
                         and r.type in ("REAL", "INTE", "DOUB"))
        except RecordError:
            arrays = 0   # the reader says what is damaged
    size = sum(os.path.getsize(f) for f in (egrid, init) if f is not None)
    return Header(str(path), "eclipse", "grid", dims, file_bytes=size, nactive=nactive,
                  arrays=arrays, notes=tuple(notes))


def grdecl_header(path) -> Header | None:
    """A GRDECL file's or deck's ``SPECGRID``/``DIMENS`` from the first :data:`SCAN_BYTES` of
    its text (None where it is not there: an INCLUDEd file holds it)."""
    p = check_file(path, "a GRDECL file or deck")
    size = os.path.getsize(p)
    tail = b""
    with open(p, "rb") as fh:
        for _ in range(0, SCAN_BYTES, _BLOCK):
            block = fh.read(_BLOCK)
            if not block:
                break
            text = tail + block
            m = _DIMS.search(text)
            if m is not None:
                dims = tuple(int(v) for v in m.group(2, 3, 4))
                if min(dims) < 1:
                    return None
                fmt = "deck" if p.suffix.lower() == ".data" else "grdecl"
                return Header(str(path), fmt, "grid", dims, file_bytes=size,
                              notes=("active cells not counted (every cell taken active)",))
            tail = text[-4096:]
    return None


__all__ = ["COUNT_CELLS", "SCAN_BYTES", "egrid_header", "grdecl_header"]
