"""Deterministic synthetic corner-point grids, and a streaming GRDECL writer.

:func:`synthetic_grid` makes a small but realistic reservoir grid for tests, the demo and the
benchmarks: sloping pillars, dipping and undulating layers of varying thickness, two faults
with throw that varies along them, inactive blobs, PORO/PERMX/NTG/FIPNUM and a few report
steps of SWAT moving out from an injector.  :func:`write_grdecl` writes any
:class:`~geoshade.models.CornerPointGrid` as GRDECL text, streaming block by block, with
``N*value`` compression, each float written with the fewest digits that read back to the same
value (float32 for ZCORN and properties, float64 for COORD), atomically.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.models import CornerPointGrid, Fault

#: values formatted per block by the writer
WRITE_BLOCK = 1 << 20
_POW10 = np.array([float(10**i) for i in range(23)])


def _smooth_field(shape, rng, waves: int = 4) -> np.ndarray:
    """Sum of a few random low-frequency cosines over a (nx, ny, nz) index grid, in [-1, 1]."""
    nx, ny, nz = shape
    u = (np.arange(nx) + 0.5)[:, None, None] / nx
    v = (np.arange(ny) + 0.5)[None, :, None] / ny
    w = (np.arange(nz) + 0.5)[None, None, :] / nz
    out = np.zeros(shape, np.float32)
    for _ in range(waves):  # a few waves, not cells
        f = rng.uniform(0.5, 2.5, 3)
        ph = rng.uniform(0, 2 * np.pi, 3)
        out += (np.cos(2 * np.pi * f[0] * u + ph[0]) * np.cos(2 * np.pi * f[1] * v + ph[1])
                * np.cos(2 * np.pi * f[2] * w + ph[2])).astype(np.float32)
    return out / waves


def synthetic_grid(nx: int = 20, ny: int = 15, nz: int = 6, faults: bool = True,
                   inactive_fraction: float = 0.05, seed: int = 0,
                   steps: int = 4) -> CornerPointGrid:
    """A deterministic corner-point reservoir grid of ``nx × ny × nz`` cells.

    Parameters
    ----------
    nx, ny, nz : int
        Cells along i, j, k (k downwards).
    faults : bool
        Two faults along pillar lines (``FA`` at ``i = nx // 3`` with a throw growing along j,
        ``FB`` at ``j = 2 ny // 3``), listed in ``grid.faults`` (faces I+ and J+ of the cells
        on their low side).
    inactive_fraction : float
        Fraction of inactive cells (smooth blobs, exact to one cell).
    seed : int
        Random seed: the same arguments give the same grid.
    steps : int
        Report steps of SWAT (a front spreading from an injector at cell (0, 0)), monthly
        dates from 2000-01-01.

    Returns
    -------
    CornerPointGrid
        100 m × 100 m cells about 1600–1900 m deep, COORD float64 (mm-rounded), ZCORN
        float32, ACTNUM uint8, PORO/PERMX/NTG float32 and FIPNUM int32, MAPAXES translating
        to a map origin, units METRES.

    Examples
    --------
    >>> g = synthetic_grid(8, 6, 4, seed=1)
    >>> g.dims, g.ncells - g.nactive, sorted(g.properties), len(g.steps), len(g.faults)
    ((8, 6, 4), 10, ['FIPNUM', 'NTG', 'PERMX', 'PORO'], 4, 2)
    >>> bool((g.zcorn[:, :, 1:] >= g.zcorn[:, :, :-1]).all())  # depths grow down each pillar
    True
    """
    nx, ny, nz = int(nx), int(ny), int(nz)
    if min(nx, ny, nz) < 1:
        raise InputError(f"synthetic_grid: expected positive sizes, got {(nx, ny, nz)}")
    if not 0 <= inactive_fraction < 1:
        raise InputError(f"synthetic_grid: inactive_fraction must be in [0, 1), got "
                         f"{inactive_fraction}")
    rng = np.random.default_rng(seed)
    d = 100.0
    px = np.arange(nx + 1, dtype=np.float64)[:, None] * d
    py = np.arange(ny + 1, dtype=np.float64)[None, :] * d
    lx, ly = max(nx * d, 1.0), max(ny * d, 1.0)
    # horizons at the pillars: dipping, undulating, layers of varying thickness
    top = (1600.0 + 0.06 * px + 0.03 * py
           + 25.0 * np.sin(2 * np.pi * px / lx * 1.3) * np.cos(2 * np.pi * py / ly * 0.9))
    h = rng.uniform(6.0, 18.0, nz)
    lat = 1.0 + 0.35 * np.sin(2 * np.pi * (px / lx + 0.3 * py / ly))[..., None] \
        * np.cos(np.pi * np.arange(nz) / max(nz, 1) * 2.0)[None, None, :]
    thick = np.maximum(h[None, None, :] * lat, 0.5)
    horizons = np.concatenate([top[..., None], top[..., None] + np.cumsum(thick, axis=2)],
                              axis=2)  # (nx+1, ny+1, nz+1)
    # sloping pillars through the horizons' x, y; top and bottom points above and below them
    ztop, zbot = float(horizons.min()) - 10.0, float(horizons.max()) + 10.0
    tx = 0.06 * np.sin(2 * np.pi * py / ly) + 0.0 * px
    ty = 0.04 * np.cos(2 * np.pi * px / lx) + 0.0 * py
    zref = 0.5 * (ztop + zbot)
    coord = np.empty((nx + 1, ny + 1, 6))
    for c, z in ((0, ztop), (3, zbot)):
        coord[..., c] = px + tx * (z - zref)
        coord[..., c + 1] = py + ty * (z - zref)
        coord[..., c + 2] = z
    coord = np.round(coord, 3)
    mem = np.empty((ny + 1, nx + 1, 6))  # file order: 6 numbers per pillar, i fastest
    mem[:] = coord.transpose(1, 0, 2)
    coord = mem.transpose(1, 0, 2)
    # ZCORN: cell (i, j) corner (a, b) sits on pillar (i + a, j + b), plus the fault throws
    ia = np.arange(nx)
    jb = np.arange(ny)
    zcorn = np.empty((2 * nx, 2 * ny, 2 * nz), np.float32, order="F")
    fa, fb = max(nx // 3, 1), max(2 * ny // 3, 1)
    for a in (0, 1):
        for b in (0, 1):
            throw = np.zeros((nx, ny))
            if faults:
                pj = (jb + b) / max(ny, 1)
                pi = (ia + a) / max(nx, 1)
                throw += np.where(ia[:, None] >= fa, 8.0 + 14.0 * pj[None, :], 0.0)
                throw += np.where(jb[None, :] >= fb, -(5.0 + 6.0 * pi[:, None]), 0.0)
            for c in (0, 1):
                z = horizons[a:a + nx, b:b + ny, c:c + nz] + throw[..., None]
                zcorn[a::2, b::2, c::2] = np.round(z, 3)
    # properties
    shape = (nx, ny, nz)
    blob = _smooth_field(shape, rng, 5)
    ninact = round(inactive_fraction * nx * ny * nz)
    flat = np.ones(nx * ny * nz, np.uint8)
    if ninact:
        flat[np.argpartition(-blob.ravel(order="F"), ninact - 1)[:ninact]] = 0
    actnum = flat.reshape(shape, order="F")
    layer = rng.uniform(0.08, 0.3, nz).astype(np.float32)
    noise = rng.normal(0.0, 0.01, shape).astype(np.float32)
    poro = np.clip(layer[None, None, :] + 0.06 * _smooth_field(shape, rng) + noise, 0.01, 0.38)
    poro = np.asfortranarray(np.round(poro, 4), np.float32)
    permx = np.asfortranarray(np.round(10.0 ** (-1.0 + 13.0 * poro), 2), np.float32)
    ntg = np.asfortranarray(np.round(np.clip(0.35 + 2.0 * poro, 0.0, 1.0), 3), np.float32)
    fip = np.asfortranarray(1 + (np.arange(nz)[None, None, :] >= nz // 2) * 1
                            + np.zeros(shape, np.int32), np.int32)
    props = {"PORO": poro, "PERMX": permx, "NTG": ntg, "FIPNUM": fip}
    # SWAT steps: a front from cell (0, 0), faster in permeable layers
    cx = (ia + 0.5)[:, None, None] / nx
    cy = (jb + 0.5)[None, :, None] / ny
    r = np.sqrt(cx * cx + cy * cy).astype(np.float32)
    speed = (permx / max(float(permx.mean()), 1e-6)) ** np.float32(0.2)
    step_list, dates = [], []
    for t in range(steps):  # a few report steps, not cells
        front = np.float32(1.2 * t / max(steps - 1, 1)) * speed
        sw = 0.2 + 0.6 * 0.5 * (1.0 - np.tanh((r - front) / np.float32(0.05)))
        step_list.append({"SWAT": np.asfortranarray(np.round(sw, 4), np.float32)})
        dates.append(f"{2000 + t // 12:04d}-{t % 12 + 1:02d}-01")
    fault_list = []
    if faults:
        jj, kk = np.meshgrid(np.arange(ny), np.arange(nz), indexing="ij")
        fault_list.append(Fault("FA", np.stack([np.full(jj.size, fa - 1), jj.ravel(),
                                                kk.ravel(), np.zeros(jj.size)], 1)))
        ii, kk = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
        fault_list.append(Fault("FB", np.stack([ii.ravel(), np.full(ii.size, fb - 1),
                                                kk.ravel(), np.ones(ii.size)], 1)))
    x0, y0 = 456000.0, 5926000.0
    return CornerPointGrid(coord=coord, zcorn=zcorn, actnum=actnum,
                           mapaxes=np.array([x0, y0 + 1000.0, x0, y0, x0 + 1000.0, y0]),
                           properties=props, steps=step_list, step_dates=dates,
                           faults=fault_list, units="METRES",
                           name=f"synthetic {nx}x{ny}x{nz}",
                           meta={"format": "synthetic", "seed": seed})


# --- writer ----------------------------------------------------------------------------------
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
    """The fewest digits that read back (by geoshade.io.grdecl's arithmetic) to ``v``."""
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


def _write_array(fh, name: str, flat: np.ndarray, f32: bool, is_int: bool, bar) -> None:
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
        bar(block.size)
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


def write_grdecl(grid: CornerPointGrid, path, progress=None) -> Path:
    """Write a grid as GRDECL text (streaming, ``N*value`` runs, atomic).

    Keywords: SPECGRID, MAPAXES, GRIDUNIT, COORD, ZCORN, ACTNUM, FAULTS and every static
    property (``*NUM`` and integer arrays as integers).  Report steps are not written (GRDECL
    has none).  NaN values are written as 0.

    Parameters
    ----------
    grid : CornerPointGrid
    path : str or Path
        Output file; written to a temporary file in the same folder, then renamed.
    progress : None, False or callable
        None: a tqdm bar over values (terminal only); False: none; callable(done, total).

    Returns
    -------
    Path

    Examples
    --------
    >>> import os, tempfile
    >>> g = synthetic_grid(3, 2, 2)
    >>> f = write_grdecl(g, os.path.join(tempfile.mkdtemp(), "g.grdecl"), progress=False)
    >>> open(f).read().splitlines()[1:3]
    ['SPECGRID', '3 2 2 1 F /']
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
    total = sum(a[1].size for a in arrays)
    if progress is False:
        bar, close = (lambda n: None), (lambda: None)
    elif callable(progress):
        done = [0]

        def bar(n):
            done[0] += n
            progress(done[0], total)

        def close():
            return None
    else:
        from tqdm import tqdm

        t = tqdm(total=total, desc=path.name, unit="value", unit_scale=True, leave=False,
                 disable=None)
        bar, close = t.update, t.close
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
                _write_array(fh, name, flat, f32, is_int, bar)
            if grid.faults:
                lines = [r for f in grid.faults for r in _fault_records(f)]
                fh.write(("FAULTS\n" + "\n".join(lines) + "\n/\n").encode())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp made it private; give it a normal file's mode
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    finally:
        close()
    return path
