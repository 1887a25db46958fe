"""One pass over a slab for the bit map, patch map, colour index map and count (numba).

:func:`geoshade.compute.bitmaps.build_selection_maps` makes the maps of Section 4 with numpy, one
array operation per map: the selection mask, its packing, the patch OR-reduction and the colour
lookup each read the slab again. For 8- and 16-bit integer volumes this module does all of it
in one parallel pass (z slices over the cores), which is what a new range costs the viewer. The
results are bit-identical to the numpy path (tested); other dtypes and small slabs keep numpy.
numba is imported and the kernel compiled on first use (cached on disk).
"""

from __future__ import annotations

import sys

import numpy as np

#: slabs smaller than this take the numpy path until numba is loaded (start-up ~0.5 s)
NUMBA_MIN_VOXELS = 4_000_000

_KERNEL: dict[str, object] = {}


def _fused(slab, ilo, ihi, lut, offset, L, bits, patch, color, counts):  # pragma: no cover
    """numba kernel: see :func:`fused_maps` (runs compiled; plain Python only in tests)."""
    nz, ny, nx = slab.shape
    nw = bits.shape[2]
    for z in _prange(nz):
        cnt = 0
        for y in range(ny):
            jp = y // L
            for wi in range(nw):
                x0 = wi * 32
                n = min(32, nx - x0)
                word = np.uint32(0)
                for k in range(n):
                    v = np.int64(slab[z, y, x0 + k])
                    color[z, y, x0 + k] = lut[v - offset]
                    if ilo <= v <= ihi:
                        word |= np.uint32(1) << np.uint32(k)
                bits[z, y, wi] = word
                if word != 0:
                    c = word
                    while c:  # popcount
                        c &= c - np.uint32(1)
                        cnt += 1
                    i0 = x0 // L
                    b = (i0 + 1) * L - x0  # first bit of the word in patch i0 + 1
                    if b >= 32:
                        patch[z, jp, i0] = True
                    else:
                        if word & ((np.uint32(1) << np.uint32(b)) - np.uint32(1)):
                            patch[z, jp, i0] = True
                        if word >> np.uint32(b):
                            patch[z, jp, i0 + 1] = True
        counts[z] = cnt


def _prange(n):  # replaced by numba.prange in the compiled kernel
    return range(n)


def _kernel():
    if "fused" not in _KERNEL:
        import numba

        g = _fused.__globals__
        g["_prange"] = numba.prange
        _KERNEL["fused"] = numba.njit(parallel=True, cache=True, nogil=True)(_fused)
    return _KERNEL["fused"]


def supported(slab: np.ndarray) -> bool:
    """Whether :func:`fused_maps` takes this slab (8/16-bit integers, large enough or numba up)."""
    a = slab
    if a.ndim != 3 or a.dtype.kind not in "ui" or a.dtype.itemsize > 2:
        return False
    return a.size >= NUMBA_MIN_VOXELS or "numba" in sys.modules


def fused_maps(slab: np.ndarray, ilo: int, ihi: int, lut: np.ndarray, l: int = 64):
    """Bit map words, patch mask, colour indices and count of one ``(nz, ny, nx)`` slab.

    Parameters
    ----------
    slab : (nz, ny, nx) uint8/uint16/int8/int16 array
    ilo, ihi : int
        Inclusive integer selection bounds (``ilo > ihi``: nothing selected).
    lut : uint8 array
        Colour index of every value of the dtype, from its minimum up.
    l : int
        Patch-quad subdivision (a patch covers ``l + 1`` voxels in x and y).

    Returns
    -------
    bits (nz, ny, ceil(nx/32)) uint32, patch (nz, ceil(ny/(l+1)), ceil(nx/(l+1))) bool,
    color (nz, ny, nx) uint8, count int
    """
    a = np.ascontiguousarray(slab)
    nz, ny, nx = a.shape
    L = int(l) + 1
    bits = np.empty((nz, ny, -(-nx // 32)), np.uint32)
    patch = np.zeros((nz, -(-ny // L), -(-nx // L)), np.bool_)
    color = np.empty((nz, ny, nx), np.uint8)
    counts = np.zeros(nz, np.int64)
    offset = int(np.iinfo(a.dtype).min)
    _kernel()(a, np.int64(ilo), np.int64(ihi), np.ascontiguousarray(lut, np.uint8),
              np.int64(offset), np.int64(L), bits, patch, color, counts)
    return bits, patch, color, int(counts.sum())
