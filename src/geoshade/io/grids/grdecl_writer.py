"""GRDECL writer: any :class:`~geoshade.models.CornerPointGrid` as ECLIPSE GRDECL text.

:func:`write_grdecl` streams block by block (:data:`WRITE_BLOCK` values formatted at a time by a
numba kernel), with ``N*value`` compression, each float written with the fewest digits that read
back (by :mod:`geoshade.io.grids.grdecl`'s arithmetic) to the same value (float32 for ZCORN and
properties, float64 for COORD), to a temporary file renamed into place (atomic).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import publish
from geoshade.models import CornerPointGrid, Fault
from geoshade.progress import Counter, Progress

#: values formatted per block
WRITE_BLOCK = 1 << 20
_POW10 = np.array([float(10**i) for i in range(23)])


def _ndigits(m):
    nd = 1
    while m >= 10:
        m //= 10
        nd += 1
    return nd


def _put_digits(m, nd, out, end):
    """Write the last ``nd`` decimal digits of ``m`` (zero-padded) into ``out[end - nd:end]``."""
    for z in range(nd):
        out[end - 1 - z] = 48 + m % 10
        m //= 10


def _put_int(m, out, p):
    nd = _ndigits(m)
    _put_digits(m, nd, out, p + nd)
    return p + nd


def _put_float(v, f32, out, p):
    """The fewest digits that read back (by geoshade.io.grids.grdecl's arithmetic) to ``v``."""
    if v != v or v == 0.0:
        out[p] = 48
        return p + 1
    if v < 0:
        out[p] = 45
        p += 1
        v = -v
    e = int(np.floor(np.log10(v)))
    m = 0
    q = 0
    for nd in range(1, 18):
        q = e - nd + 1
        if q <= 0:
            s = v * _POW10[-q] if -q <= 22 else v * 10.0 ** (-q)
        else:
            s = v / _POW10[q] if q <= 22 else v / 10.0 ** q
        m = int(np.floor(s + 0.5))
        if q >= 0:
            r = m * _POW10[q] if q <= 22 else m * 10.0 ** q
        else:  # the reader's own arithmetic (correctly rounded below 2**53)
            r = m / _POW10[-q] if -q <= 22 else m / 10.0 ** (-q)
        if (np.float32(r) == np.float32(v)) if f32 else (r == v):
            break
    nd = _ndigits(m)
    if 0 <= q <= 6:  # ddd000
        p = _put_int(m, out, p)
        for _ in range(q):
            out[p] = 48
            p += 1
        return p
    if q < 0 and -q - nd <= 6:
        if nd > -q:  # ddd.ddd
            scale = 10 ** (-q)
            p = _put_int(m // scale, out, p)
            out[p] = 46
            _put_digits(m % scale, -q, out, p + 1 - q)
            return p + 1 - q
        out[p] = 48  # 0.000ddd
        out[p + 1] = 46
        _put_digits(m, -q, out, p + 2 - q)
        return p + 2 - q
    p = _put_int(m, out, p)  # dddE-q
    out[p] = 69
    p += 1
    if q < 0:
        out[p] = 45
        p += 1
        q = -q
    return _put_int(q, out, p)


def _fmt(vals, f32, is_int, out, col):
    """Format ``vals`` as GRDECL tokens with N* runs into ``out``: (bytes, column)."""
    p = 0
    n = vals.shape[0]
    i = 0
    while i < n:
        v = vals[i]
        j = i + 1
        while j < n and (vals[j] == v or (vals[j] != vals[j] and v != v)):
            j += 1
        start = p
        if j - i > 1:
            p = _put_int(j - i, out, p)
            out[p] = 42
            p += 1
        if is_int:
            if v < 0:
                out[p] = 45
                p += 1
            p = _put_int(int(abs(v)), out, p)
        else:
            p = _put_float(v, f32, out, p)
        col += p - start
        if col >= 72:
            out[p] = 10
            col = 0
        else:
            out[p] = 32
            col += 1
        p += 1
        i = j
    return p, col


def _fmt_kernel():
    """The jitted formatter (numba imported and compiled on first use, cached on disk)."""
    from numba import njit

    g = globals()
    for name in ("_ndigits", "_put_digits", "_put_int", "_put_float"):
        g[name] = njit(cache=True, nogil=True)(g[name])
    return njit(cache=True, nogil=True)(_fmt)


_FMT: list = []


def _write_array(fh, name: str, flat: np.ndarray, f32: bool, is_int: bool,
                 counter: Counter) -> None:
    if not _FMT:
        _FMT.append(_fmt_kernel())
    fmt = _FMT[0]
    fh.write(f"{name}\n".encode())
    col = 0
    out = np.empty(48 * WRITE_BLOCK + 64, np.uint8)
    for s in range(0, flat.size, WRITE_BLOCK):  # blocks of a million values
        block = np.ascontiguousarray(flat[s:s + WRITE_BLOCK], dtype=np.float64)
        nbytes, col = fmt(block, f32, is_int, out, col)
        fh.write(out[:nbytes].tobytes())
        counter.add(block.size)
    fh.write(b"\n/\n\n" if col else b"/\n\n")


def _fault_records(f: Fault) -> list[str]:
    """FAULTS records with runs along k merged (vectorised)."""
    faces = f.faces[np.lexsort((f.faces[:, 2], f.faces[:, 1], f.faces[:, 0], f.faces[:, 3]))]
    if not len(faces):
        return []
    same = np.all(faces[1:, [0, 1, 3]] == faces[:-1, [0, 1, 3]], axis=1) \
        & (faces[1:, 2] == faces[:-1, 2] + 1)
    starts = np.flatnonzero(np.concatenate([[True], ~same]))
    ends = np.concatenate([starts[1:], [len(faces)]]) - 1
    names = np.array(["X", "Y", "Z", "X-", "Y-", "Z-"])
    a, b = faces[starts], faces[ends]
    return [f"'{f.name}' {i + 1} {i + 1} {j + 1} {j + 1} {k1 + 1} {k2 + 1} {fc} /"
            for i, j, k1, k2, fc in zip(a[:, 0], a[:, 1], a[:, 2], b[:, 2], names[a[:, 3]],
                                        strict=True)]


def write_grdecl(grid: CornerPointGrid, path, progress: Progress | None = None) -> Path:
    """Write a grid as GRDECL text (streaming, ``N*value`` runs, atomic).

    Keywords: SPECGRID, MAPAXES, GRIDUNIT, COORD, ZCORN, ACTNUM, FAULTS and every static
    property (``*NUM`` and integer arrays as integers).  Report steps are not written (GRDECL
    has none).  NaN values are written as 0.

    Parameters
    ----------
    grid : CornerPointGrid
    path : str or Path
        Output file; written to a temporary file in the same folder, then renamed.
    progress : callable, optional
        ``progress(values_written, values_total)`` after each block (see
        :mod:`geoshade.progress`); None: no reports.

    Returns
    -------
    Path

    Examples
    --------
    >>> import os, tempfile
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> zc = np.zeros((2, 2, 2), np.float32); zc[..., 1] = 1
    >>> g = CornerPointGrid(coord, zc, properties={"PORO": np.full((1, 1, 1), 0.25, np.float32)})
    >>> f = write_grdecl(g, os.path.join(tempfile.mkdtemp(), "g.grdecl"))
    >>> for record in open(f).read().strip().split("\\n\\n"):  # keywords, blank-line apart
    ...     print(" ".join(record.split()))
    -- written by geoshade: SPECGRID 1 1 1 1 F /
    COORD 5*0 2*1 2*0 1 0 1 0 1 2*0 4*1 0 3*1 /
    ZCORN 4*0 4*1 /
    ACTNUM 1 /
    PORO 0.25 /
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{path}: output folder {folder} does not exist")
    nx, ny, nz = grid.dims
    arrays = [("COORD", np.asarray(grid.coord).transpose(1, 0, 2).reshape(-1), False, False),
              ("ZCORN", np.asarray(grid.zcorn).reshape(-1, order="F"), True, False),
              ("ACTNUM", np.asarray(grid.actnum).reshape(-1, order="F"), False, True)]
    for name, arr in grid.properties.items():
        a = np.asarray(arr)
        is_int = a.dtype.kind in "iub"
        arrays.append((name, a.reshape(-1, order="F"), a.dtype != np.float64, is_int))
    counter = Counter(progress, sum(a[1].size for a in arrays))
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb", buffering=1 << 20) as fh:
            fh.write(f"-- written by geoshade: {grid.name}\nSPECGRID\n{nx} {ny} {nz} 1 F /\n\n"
                     .encode())
            if grid.mapaxes is not None:
                fh.write(("MAPAXES\n" + " ".join(repr(float(v)) for v in grid.mapaxes)
                          + " /\n\n").encode())
            if grid.units:
                fh.write(f"GRIDUNIT\n'{grid.units}' ' ' /\n\n".encode())
            for name, flat, f32, is_int in arrays:
                _write_array(fh, name, flat, f32, is_int, counter)
            if grid.faults:
                lines = [r for f in grid.faults for r in _fault_records(f)]
                fh.write(("FAULTS\n" + "\n".join(lines) + "\n/\n").encode())
        publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
