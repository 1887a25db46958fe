"""The ray caster's empty-space skipping map, built from the packed voxel bit map.

One texel per 8³ brick of the box, three 32-bit words (an RGB32UI texture, 12 bytes per 512
voxels, 0.023 byte per voxel):

==========  ==========================================================================
word        meaning
==========  ==========================================================================
0, 1        64-bit mask of the brick's 4×4×4 blocks of 2³ voxels: bit ``x2 + 4·y2 + 16·z2``
            (``x2, y2, z2`` in 0..3, the block inside the brick) is 1 if the block holds a
            selected voxel; word 0 holds ``z2`` 0-1, word 1 ``z2`` 2-3
2           Chebyshev distance, in bricks, to the nearest brick that holds a selected voxel
            (0: this brick holds one), at most :data:`DISTANCE_CAP`
==========  ==========================================================================

A ray in voxel ``v`` leaves, in one step, the largest empty aligned cube around ``v`` the map
proves empty: the ``(2k-1)``-brick cube around an empty brick at distance ``k``, an empty 4³
half-brick (8 bits of the mask), an empty 2³ block (1 bit), else the voxel itself. The ray
caster's shader (``render/visuals/raycast/raycast.frag``) reads it; ``docs/NOTES.md`` says why.
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.voxels.layout import (
    SKIP_BRICK,
    SKIP_WORDS,
    skip_map_bytes,
    skip_shape,
    words_per_row,
)
from geoshade.errors import InputError

#: largest brick distance stored (a ray jumps at most 2·cap - 1 bricks at once)
DISTANCE_CAP = 16

__all__ = [
    "DISTANCE_CAP",
    "SKIP_BRICK",
    "SKIP_WORDS",
    "block_masks",
    "brick_distance",
    "skip_map",
    "skip_map_bytes",
    "skip_shape",
]


def _compact_even_bits(c: np.ndarray) -> np.ndarray:
    """Bits 0, 2, 4, … 30 of each uint32 -> bits 0..15 (in place on a fresh array)."""
    c &= np.uint32(0x55555555)
    c |= c >> np.uint32(1)
    c &= np.uint32(0x33333333)
    c |= c >> np.uint32(2)
    c &= np.uint32(0x0F0F0F0F)
    c |= c >> np.uint32(4)
    c &= np.uint32(0x00FF00FF)
    c |= c >> np.uint32(8)
    c &= np.uint32(0x0000FFFF)
    return c


def block_masks(words, nx: int) -> np.ndarray:
    """The 64-bit 2³-block masks of every 8³ brick, ``(nbz, nby, nbx, 2) uint32``.

    Parameters
    ----------
    words : (nz, ny, ceil(nx/32)) uint32
        The packed voxel bit map (:func:`geoshade.compute.voxels.bitmaps.pack_bits`).
    nx : int
        Voxels along x.

    Examples
    --------
    >>> from geoshade.compute.voxels.bitmaps import pack_bits
    >>> sel = np.zeros((9, 8, 17), bool); sel[8, 0, 16] = True; sel[3, 5, 2] = True  # bit 1+8+16
    >>> m = block_masks(pack_bits(sel), 17)
    >>> m.shape, hex(int(m[0, 0, 0, 0])), hex(int(m[0, 0, 0, 1])), int(m[1, 0, 2, 0])
    ((2, 1, 3, 2), '0x2000000', '0x0', 1)
    """
    w = np.asarray(words, dtype=np.uint32)
    if w.ndim != 3 or w.shape[-1] != words_per_row(nx):
        raise InputError(f"words: expected (nz, ny, {words_per_row(nx)}) uint32, got {w.shape}")
    nz, ny, nw = w.shape
    nbz, nby, nbx = skip_shape((nx, ny, nz))
    if (nz, ny) != (nbz * 8, nby * 8):
        padded = np.zeros((nbz * 8, nby * 8, nw), np.uint32)
        padded[:nz, :ny] = w
        w = padded
    w2 = w[0::2] | w[1::2]                      # pairs of slices
    w2 = w2[:, 0::2] | w2[:, 1::2]              # pairs of rows: (4·nbz, 4·nby, nw)
    c = _compact_even_bits(w2 | (w2 >> np.uint32(1)))   # pairs along x: bit x2 of the word
    # 4 nibbles per word (4 bricks of 8 voxels), one per brick: bits x2 = 0..3
    nib = (c[..., None] >> (np.uint32(4) * np.arange(4, dtype=np.uint32))) & np.uint32(0xF)
    nib = nib.reshape(4 * nbz, 4 * nby, 4 * nw)[..., :nbx].reshape(nbz, 4, nby, 4, nbx)
    out = np.zeros((nbz, nby, nbx, 2), np.uint32)
    for z2 in range(4):
        for y2 in range(4):
            out[..., z2 // 2] |= nib[:, z2, :, y2, :] << np.uint32(4 * y2 + 16 * (z2 % 2))
    return out


def brick_distance(occupied, cap: int = DISTANCE_CAP) -> np.ndarray:
    """Chebyshev distance in bricks to the nearest occupied brick, capped at ``cap``.

    Parameters
    ----------
    occupied : (nbz, nby, nbx) bool
        Bricks that hold a selected voxel (distance 0).
    cap : int
        Largest value stored; bricks farther away (or every brick when none is occupied) get
        ``cap``.

    Returns
    -------
    (nbz, nby, nbx) uint32

    Examples
    --------
    >>> occ = np.zeros((1, 1, 6), bool); occ[0, 0, 1] = True
    >>> brick_distance(occ, cap=3)[0, 0].tolist()
    [1, 0, 1, 2, 3, 3]
    """
    occ = np.asarray(occupied, bool)
    if occ.ndim != 3:
        raise InputError(f"occupied: expected a 3D (nbz, nby, nbx) mask, got shape {occ.shape}")
    if int(cap) < 1:
        raise InputError(f"cap: expected a positive integer, got {cap!r}")
    dist = np.full(occ.shape, int(cap), np.uint32)
    dist[occ] = 0
    reached = occ.copy()
    if not reached.any():
        return dist
    for k in range(1, int(cap)):
        if reached.all():
            break
        grown = reached.copy()
        for ax in range(3):  # dilate by one brick along each axis: the 3×3×3 neighbourhood
            lo = [slice(None)] * 3
            hi = [slice(None)] * 3
            lo[ax], hi[ax] = slice(1, None), slice(None, -1)
            step = grown.copy()
            step[tuple(lo)] |= grown[tuple(hi)]
            step[tuple(hi)] |= grown[tuple(lo)]
            grown = step
        dist[grown & ~reached] = k
        reached = grown
    return dist


def skip_map(words, nx: int, cap: int = DISTANCE_CAP) -> np.ndarray:
    """The ray caster's skip map ``(nbz, nby, nbx, 3) uint32``: block masks + brick distance.

    Examples
    --------
    >>> from geoshade.compute.voxels.bitmaps import pack_bits
    >>> sel = np.zeros((8, 8, 24), bool); sel[0, 0, 0] = True
    >>> skip_map(pack_bits(sel), 24)[0, 0].tolist()
    [[1, 0, 0], [0, 0, 1], [0, 0, 2]]
    """
    masks = block_masks(words, nx)
    out = np.empty((*masks.shape[:3], SKIP_WORDS), np.uint32)
    out[..., :2] = masks
    out[..., 2] = brick_distance((masks != 0).any(axis=-1), cap)
    return out
