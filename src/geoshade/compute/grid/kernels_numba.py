"""The compiled kernels of :mod:`geoshade.compute.grid.kernels` (imported on first use only).

Module-level functions, so that numba's on-disk cache finds them again in a new process (kernels
defined inside a function are recompiled every time).
"""

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def depth_range(z, act, maxabs):  # pragma: no cover - compiled
    n2x, n2y, n2z = z.shape
    nz = n2z // 2
    los = np.full(nz, np.inf)
    his = np.full(nz, -np.inf)
    for k in range(nz):
        lo, hi = np.inf, -np.inf
        for c in range(2):
            for jj in range(n2y):
                for ii in range(n2x):
                    if act[ii // 2, jj // 2, k] == 0:
                        continue
                    v = z[ii, jj, 2 * k + c]
                    if not (abs(v) <= maxabs):
                        continue
                    if v < lo:
                        lo = v
                    if v > hi:
                        hi = v
        los[k], his[k] = lo, hi
    return los.min(), his.max()

@numba.njit(inline="always")
def differ(a, b, tol):  # pragma: no cover - compiled
    if tol <= 0.0:
        return a != b
    return abs(np.float64(a) - np.float64(b)) > tol

@numba.njit(inline="always")
def pair_i(z, lo, j, k, tol):  # pragma: no cover - compiled
    """Do cells (lo, j, k) and (lo + 1, j, k) not match on their shared face?"""
    for b in range(2):
        for c in range(2):
            if differ(z[2 * lo + 1, 2 * j + b, 2 * k + c], z[2 * lo + 2, 2 * j + b, 2 * k + c],
                      tol):
                return True
    return False

@numba.njit(inline="always")
def pair_j(z, i, lo, k, tol):  # pragma: no cover - compiled
    for a in range(2):
        for c in range(2):
            if differ(z[2 * i + a, 2 * lo + 1, 2 * k + c], z[2 * i + a, 2 * lo + 2, 2 * k + c],
                      tol):
                return True
    return False

@numba.njit(inline="always")
def pair_k(z, i, j, lo, tol):  # pragma: no cover - compiled
    for a in range(2):
        for b in range(2):
            if differ(z[2 * i + a, 2 * j + b, 2 * lo + 1], z[2 * i + a, 2 * j + b, 2 * lo + 2],
                      tol):
                return True
    return False

@numba.njit(cache=True, nogil=True)
def slab_faces(z, s, tol, k0, k1):  # pragma: no cover - compiled
    nx, ny, nz = s.shape
    nk = k1 - k0
    # pass 1, layer by layer: bit f of vis/bad/nbr = face f visible / not matching /
    # neighbour shown.  Each i pair and j pair is compared once (the + face of one cell
    # is the - face of the next), k pairs once per side.
    vis = np.zeros((nx, ny, nk), np.uint8)
    bad = np.zeros((nx, ny, nk), np.uint8)
    nbr = np.zeros((nx, ny, nk), np.uint8)
    counts = np.zeros((6, nk), np.int64)
    for kk in range(nk):
        k = k0 + kk
        prev_j = np.zeros(nx, np.bool_)  # pair (j-1, j) of each i
        for j in range(ny):
            prev_i = False  # pair (i-1, i)
            for i in range(nx):
                bi = i < nx - 1 and pair_i(z, i, j, k, tol)
                bj = j < ny - 1 and pair_j(z, i, j, k, tol)
                if s[i, j, k] != 0:
                    mv, mb, mn = 0, 0, 0
                    for f in range(6):
                        if f == 0:
                            ex, nb, bd = i < nx - 1, i < nx - 1 and s[i + 1, j, k] != 0, bi
                        elif f == 3:
                            ex, nb, bd = i > 0, i > 0 and s[i - 1, j, k] != 0, prev_i
                        elif f == 1:
                            ex, nb, bd = j < ny - 1, j < ny - 1 and s[i, j + 1, k] != 0, bj
                        elif f == 4:
                            ex, nb, bd = j > 0, j > 0 and s[i, j - 1, k] != 0, prev_j[i]
                        elif f == 2:
                            ex = k < nz - 1
                            nb = ex and s[i, j, k + 1] != 0
                            bd = ex and pair_k(z, i, j, k, tol)
                        else:
                            ex = k > 0
                            nb = ex and s[i, j, k - 1] != 0
                            bd = ex and pair_k(z, i, j, k - 1, tol)
                        if (not ex) or (not nb) or bd:
                            mv |= 1 << f
                            counts[f, kk] += 1
                        if bd:
                            mb |= 1 << f
                        if nb:
                            mn |= 1 << f
                    vis[i, j, kk], bad[i, j, kk], nbr[i, j, kk] = mv, mb, mn
                prev_i = bi
                prev_j[i] = bj
    start = np.zeros(6 * nk + 1, np.int64)
    for r in range(6 * nk):
        start[r + 1] = start[r] + counts[r // nk, r % nk]
    total = start[6 * nk]
    cells = np.empty((total, 3), np.int32)
    face = np.empty(total, np.uint8)
    fault = np.empty(total, np.bool_)
    nbs = np.empty(total, np.bool_)
    # pass 2: emit in the numpy path's order (face code, then k, j, i)
    for r in range(6 * nk):
        f, kk = r // nk, r % nk
        bit = np.uint8(1 << f)
        p = start[r]
        for j in range(ny):
            for i in range(nx):
                if vis[i, j, kk] & bit:
                    cells[p, 0], cells[p, 1], cells[p, 2] = i, j, k0 + kk
                    face[p] = f
                    fault[p] = (bad[i, j, kk] & bit) != 0
                    nbs[p] = (nbr[i, j, kk] & bit) != 0
                    p += 1
    return cells, face, fault, nbs


@numba.njit(cache=True, nogil=True)
def value_summary(v, act):  # pragma: no cover - compiled
    """lo, hi, pos_lo, pos_hi, nonfinite, nonpositive, count of ``v`` over ``act`` != 0."""
    lo, hi, plo, phi = np.inf, -np.inf, np.inf, -np.inf
    nonfinite, nonpositive, count = 0, 0, 0
    flat_v = v.reshape(-1)
    flat_a = act.reshape(-1)
    for q in range(flat_v.size):
        if flat_a[q] == 0:
            continue
        count += 1
        x = flat_v[q]
        if not np.isfinite(x):
            nonfinite += 1
            continue
        if x < lo:
            lo = x
        if x > hi:
            hi = x
        if x > 0:
            if x < plo:
                plo = x
            if x > phi:
                phi = x
        else:
            nonpositive += 1
    return lo, hi, plo, phi, nonfinite, nonpositive, count


@numba.njit(cache=True, nogil=True)
def chunk_keys(num, nx, ny, nz, blk_x, blk_y, blk_z, off_x, off_y, off_z, size_y, size_z,
               nby, nbz, flat, local):  # pragma: no cover - compiled
    """Per cell number ``i + nx (j + ny k)``: its chunk (C order of the chunk grid) into
    ``flat`` and its C-order offset inside the chunk into ``local`` (per-axis tables of the
    coordinate's chunk, offset and chunk size; see
    :class:`~geoshade.compute.grid.chunks.CellGroups`)."""
    for q in range(num.size):
        x = num[q]
        i = x % nx
        j = x // nx % ny
        k = x // (nx * ny) % nz
        flat[q] = (blk_x[i] * nby + blk_y[j]) * nbz + blk_z[k]
        local[q] = (off_x[i] * size_y[j] + off_y[j]) * size_z[k] + off_z[k]
