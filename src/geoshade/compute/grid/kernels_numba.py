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


@numba.njit(cache=True, nogil=True)
def drawing_rows(cells, face, step, ny, rows, counts):  # pragma: no cover - compiled
    """Each face's *row* of the drawing order (k-slab, face code, k, j; the faces of a row are
    ordered by i) into ``rows`` (size 0: not kept), each row's faces counted into ``counts``
    (size 0: not counted); True when the faces are in drawing order already (rows
    non-decreasing, i increasing inside a row).  See
    :func:`geoshade.compute.grid.faces._face_set_in_drawing_order`."""
    ok = True
    keep, count = rows.size > 0, counts.size > 0
    prev_r, prev_i = -1, -1
    for t in range(face.size):
        k = np.int64(cells[t, 2])
        r = ((k // step * 6 + face[t]) * step + k % step) * ny + cells[t, 1]
        if keep:
            rows[t] = r
        if count:
            counts[r] += 1
        i = np.int64(cells[t, 0])
        if r < prev_r or (r == prev_r and i <= prev_i):
            ok = False
        prev_r, prev_i = r, i
    return ok


@numba.njit(cache=True, nogil=True)
def place_faces(cells, face, fault, nbs, corners, step, ny, cursor, out_cells, out_face,
                out_fault, out_nbs, out_corners):  # pragma: no cover - compiled
    """One part's faces placed in drawing order: each face's row (see :func:`drawing_rows`)
    takes the next place of that row (``cursor``, advanced in place), the columns copied
    there (``corners``: (0, 4) when there are none)."""
    with_c = corners.shape[0] > 0
    for t in range(face.size):
        k = np.int64(cells[t, 2])
        r = ((k // step * 6 + face[t]) * step + k % step) * ny + cells[t, 1]
        p = cursor[r]
        cursor[r] = p + 1
        out_cells[p, 0] = cells[t, 0]
        out_cells[p, 1] = cells[t, 1]
        out_cells[p, 2] = cells[t, 2]
        out_face[p] = face[t]
        out_fault[p] = fault[t]
        out_nbs[p] = nbs[t]
        if with_c:
            for q in range(4):
                out_corners[p, q] = corners[t, q]


@numba.njit(cache=True, nogil=True)
def in_drawing_order(cells, face, step, ny):  # pragma: no cover - compiled
    """True when the faces are in drawing order (see :func:`drawing_rows`), with no output."""
    prev_r, prev_i = -1, -1
    for t in range(face.size):
        k = np.int64(cells[t, 2])
        r = ((k // step * 6 + face[t]) * step + k % step) * ny + cells[t, 1]
        i = np.int64(cells[t, 0])
        if r < prev_r or (r == prev_r and i <= prev_i):
            return False
        prev_r, prev_i = r, i
    return True


@numba.njit(cache=True, nogil=True)
def color_codes(v, lo, span, out):  # pragma: no cover - compiled
    """``round((v - lo) / span * 255)`` clipped to 0..255, NaN and -inf 0, +inf 255 (0 for all
    when ``span <= 0``), as ``geoshade.render.visuals.grid.prepare.color_index`` computes it."""
    for q in range(v.size):
        x = np.float64(v[q])
        if span > 0:
            t = (x - lo) / span
        else:
            t = 0.0
        if np.isnan(t):
            t = 0.0
        elif np.isinf(t):
            t = 1.0 if t > 0 else 0.0
        y = np.rint(t * 255.0)
        out[q] = 0 if y < 0 else (255 if y > 255 else np.uint8(y))


@numba.njit(cache=True, nogil=True)
def face_words(numbers, face, corners, low_bits, face_bits, z0, scale, z_offset, out, out_f
               ):  # pragma: no cover - compiled
    """Approach 3 face records (``render/visuals/grid/prepare.face_records``, the same bits):
    word 0 = (cell number's low bits) << face_bits | face; then, with ``scale > 0``, the four
    corners' 16-bit codes ``rint((z - z0) / scale)`` clipped to 0..65535, two a word (returns
    the largest |decoded - z|), else the four ``float32(z - z_offset)`` (written through
    ``out_f``, the same memory as float32)."""
    mask = (np.int64(1) << low_bits) - 1
    err = 0.0
    for t in range(face.size):
        out[t, 0] = (np.uint32(numbers[t] & mask) << np.uint32(face_bits)) | np.uint32(face[t])
        if scale > 0:
            codes = np.empty(4, np.uint32)
            for q in range(4):
                x = np.float64(corners[t, q])
                v = np.rint((x - z0) / scale)
                if v < 0.0:
                    v = 0.0
                elif v > 65535.0:
                    v = 65535.0
                codes[q] = np.uint32(v)
                d = abs(v * scale + z0 - x)
                if d > err:
                    err = d
            out[t, 1] = codes[0] | (codes[1] << np.uint32(16))
            out[t, 2] = codes[2] | (codes[3] << np.uint32(16))
        else:
            for q in range(4):
                out_f[t, 1 + q] = np.float32(np.float64(corners[t, q]) - z_offset)
    return err


@numba.njit(cache=True, nogil=True)
def cell_numbers(cells, nx, ny, out):  # pragma: no cover - compiled
    """``i + nx (j + ny k)`` of each row of ``cells`` into ``out`` (int64)."""
    for t in range(cells.shape[0]):
        out[t] = np.int64(cells[t, 0]) + nx * (np.int64(cells[t, 1]) + ny * np.int64(cells[t, 2]))


@numba.njit(cache=True, nogil=True)
def shown_chunk_faces(pad, ex, bad, z, abc, offs, o0, o1, o2, step):  # pragma: no cover
    """The visible faces of one chunk's shown cells, in drawing-row order (k-slab, face code,
    k, j, i), and their corner depths from the chunk's ZCORN block ``z`` (C order,
    ``(2a, 2b, 2c)``; size 0: none): ``(cells, face, fault, nbs, corners)`` (corners
    ``(0, 4)`` without ``z``).

    ``pad``/``ex``: ``(a+2, b+2, c+2)`` uint8, shown / existing cells with the face
    neighbours' facing layers as halo; ``bad``: ``(a, b, c, 6)`` uint8, the index's mismatch
    flag of each face; ``abc``: (6, 4, 3) corner offsets; ``offs``: (6, 3) the cell across;
    ``(o0, o1, o2)``: the chunk's first cell; ``step``: layers per k-slab.  One pass over the
    cells in memory order gathers the faces with their rows; a counting sort of the faces (not
    the cells) by row places them (stable: a row's faces stay in i order)."""
    a, b, c = pad.shape[0] - 2, pad.shape[1] - 2, pad.shape[2] - 2
    with_z = z.size > 0
    sl0 = o2 // step
    nsl = (o2 + c - 1) // step - sl0 + 1
    nrows = nsl * 6 * step * b
    nshown = 0
    for li in range(a):
        for lj in range(b):
            for lk in range(c):
                if pad[li + 1, lj + 1, lk + 1] != 0:
                    nshown += 1
    loc = np.empty(6 * nshown, np.int32)      # li, lj, lk packed: (li * b + lj) * c + lk
    fr = np.empty(6 * nshown, np.uint8)       # face code | fault << 3 | neighbour shown << 4
    rows = np.empty(6 * nshown, np.int32)
    counts = np.zeros(nrows + 1, np.int64)
    n = 0
    for li in range(a):
        for lj in range(b):
            for lk in range(c):
                if pad[li + 1, lj + 1, lk + 1] == 0:
                    continue
                k = o2 + lk
                for f in range(6):
                    e = ex[li + 1 + offs[f, 0], lj + 1 + offs[f, 1], lk + 1 + offs[f, 2]] != 0
                    nb = pad[li + 1 + offs[f, 0], lj + 1 + offs[f, 1], lk + 1 + offs[f, 2]] != 0
                    bd = bad[li, lj, lk, f] != 0
                    if e and nb and not bd:
                        continue
                    r = (((k // step - sl0) * 6 + f) * step + k % step) * b + lj
                    loc[n] = (li * b + lj) * c + lk
                    fr[n] = f | ((1 if (bd and e) else 0) << 3) | ((1 if (nb and e) else 0) << 4)
                    rows[n] = r
                    counts[r + 1] += 1
                    n += 1
    for r in range(nrows):
        counts[r + 1] += counts[r]
    cells = np.empty((n, 3), np.int32)
    face = np.empty(n, np.uint8)
    fault = np.empty(n, np.bool_)
    nbs = np.empty(n, np.bool_)
    corners = np.empty((n if with_z else 0, 4), np.float32)
    for t in range(n):
        p = counts[rows[t]]
        counts[rows[t]] = p + 1
        q = loc[t]
        lk = q % c
        lj = q // c % b
        li = q // (b * c)
        f = fr[t] & 7
        cells[p, 0] = li + o0
        cells[p, 1] = lj + o1
        cells[p, 2] = lk + o2
        face[p] = f
        fault[p] = (fr[t] >> 3) & 1
        nbs[p] = (fr[t] >> 4) & 1
        if with_z:
            for w in range(4):
                corners[p, w] = z[2 * li + abc[f, w, 0], 2 * lj + abc[f, w, 1],
                                  2 * lk + abc[f, w, 2]]
    return cells, face, fault, nbs, corners
