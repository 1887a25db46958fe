"""The ray caster's skip map against brute-force numpy."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from geoshade.compute.voxels.bitmaps import gpu_bytes_breakdown, pack_bits
from geoshade.compute.voxels.skipmap import (
    DISTANCE_CAP,
    block_masks,
    brick_distance,
    skip_map,
    skip_map_bytes,
    skip_shape,
)
from geoshade.errors import InputError


def masks_brute(sel: np.ndarray) -> np.ndarray:
    """64-bit masks of 2³ blocks per 8³ brick, one loop per block (uint64)."""
    nbz, nby, nbx = skip_shape(sel.shape[::-1])
    out = np.zeros((nbz, nby, nbx), np.uint64)
    for bz, by, bx, z2, y2, x2 in itertools.product(range(nbz), range(nby), range(nbx),
                                                     range(4), range(4), range(4)):
        z, y, x = 8 * bz + 2 * z2, 8 * by + 2 * y2, 8 * bx + 2 * x2
        if sel[z:z + 2, y:y + 2, x:x + 2].any():
            out[bz, by, bx] |= np.uint64(1) << np.uint64(x2 + 4 * y2 + 16 * z2)
    return out


def distance_brute(occ: np.ndarray, cap: int) -> np.ndarray:
    idx = np.argwhere(occ)
    out = np.full(occ.shape, cap, np.uint32)
    if len(idx) == 0:
        return out
    for p in itertools.product(*(range(n) for n in occ.shape)):
        out[p] = min(cap, int(np.abs(idx - np.array(p)).max(axis=1).min()))
    return out


@pytest.mark.parametrize("shape", [(8, 8, 8), (9, 13, 70), (17, 3, 33), (16, 24, 64), (1, 1, 1)])
@pytest.mark.parametrize("density", [0.0, 0.003, 0.05, 1.0])
def test_block_masks_equal_brute_force(shape, density):
    rng = np.random.default_rng(sum(shape))
    sel = rng.random(shape) < density
    got = block_masks(pack_bits(sel), shape[2])
    assert got.dtype == np.uint32 and got.shape == (*skip_shape(shape[::-1]), 2)
    joined = got[..., 0].astype(np.uint64) | (got[..., 1].astype(np.uint64) << np.uint64(32))
    np.testing.assert_array_equal(joined, masks_brute(sel))


@pytest.mark.parametrize("cap", [1, 3, DISTANCE_CAP])
def test_brick_distance_is_chebyshev(cap):
    rng = np.random.default_rng(cap)
    for shape, p in [((5, 7, 9), 0.02), ((3, 4, 20), 0.05), ((6, 6, 6), 0.0), ((2, 2, 2), 1.0)]:
        occ = rng.random(shape) < p
        np.testing.assert_array_equal(brick_distance(occ, cap), distance_brute(occ, cap))


def test_skip_map_words_and_bytes():
    sel = np.zeros((20, 30, 50), bool)
    sel[3, 4, 5] = sel[19, 29, 49] = True
    m = skip_map(pack_bits(sel), 50)
    assert m.shape == (3, 4, 7, 3) and m.dtype == np.uint32
    occ = (m[..., :2] != 0).any(axis=-1)
    assert occ.sum() == 2 and occ[0, 0, 0] and occ[2, 3, 6]
    np.testing.assert_array_equal(m[..., 2], distance_brute(occ, DISTANCE_CAP))
    assert skip_map_bytes((50, 30, 20)) == m.nbytes
    assert gpu_bytes_breakdown((50, 30, 20), "raycast")["bricks"] == m.nbytes


def test_bad_input_is_one_clear_line():
    with pytest.raises(InputError, match=r"words: expected \(nz, ny, 2\) uint32"):
        block_masks(np.zeros((4, 4, 1), np.uint32), 40)
    with pytest.raises(InputError, match="occupied: expected a 3D"):
        brick_distance(np.zeros((4, 4), bool))
    with pytest.raises(InputError, match="cap: expected a positive integer"):
        brick_distance(np.zeros((2, 2, 2), bool), cap=0)
