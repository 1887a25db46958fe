"""The one-pass numba maps equal the numpy maps bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute import fastmaps
from geoshade.compute.bitmaps import (
    _colour_lut,
    build_selection_maps,
    color_index,
    pack_bits,
    patch_bitmap,
)
from geoshade.compute.selection import int_bounds, select


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int8", "int16"])
@pytest.mark.parametrize("shape", [(3, 5, 7), (4, 66, 131), (2, 130, 64), (1, 1, 33)])
def test_fused_maps_equal_numpy(dtype, shape):
    rng = np.random.default_rng(len(shape) + shape[2])
    info = np.iinfo(dtype)
    a = rng.integers(info.min, int(info.max) + 1, shape).astype(dtype)
    span = int(info.max) - int(info.min)
    for lo, hi, clo, chi in [(info.min + span * 0.2, info.min + span * 0.6, None, None),
                             (info.min, info.max, info.min + 3, info.max - 7),
                             (info.min + 5.5, info.min + 5.4, 0, 0)]:
        clo, chi = (lo, hi) if clo is None else (clo, chi)
        ilo, ihi = int_bounds(float(lo), float(hi), a.dtype)
        bits, patch, color, count = fastmaps.fused_maps(a, int(ilo), int(ihi),
                                                        _colour_lut(a.dtype, clo, chi))
        sel = select(a, lo, hi) if lo <= hi else np.zeros(a.shape, bool)
        np.testing.assert_array_equal(bits, pack_bits(sel))
        np.testing.assert_array_equal(patch, patch_bitmap(sel))
        np.testing.assert_array_equal(color, color_index(a, clo, chi))
        assert count == int(sel.sum())


def test_build_selection_maps_takes_either_path(monkeypatch):
    rng = np.random.default_rng(3)
    a = rng.integers(0, 4000, (20, 70, 90)).astype(np.uint16)
    monkeypatch.setattr(fastmaps, "NUMBA_MIN_VOXELS", 0)
    calls = []
    fused = fastmaps.fused_maps
    monkeypatch.setattr(fastmaps, "fused_maps", lambda *a, **k: calls.append(1) or fused(*a, **k))
    fast = build_selection_maps(a, [3, 2, 1, 80, 60, 17], 1000, 2500, slab_bytes=20_000)
    monkeypatch.setattr(fastmaps, "supported", lambda slab: False)
    slow = build_selection_maps(a, [3, 2, 1, 80, 60, 17], 1000, 2500, slab_bytes=20_000)
    for name in ("bits", "patch_bits", "bricks", "color"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name), err_msg=name)
    assert fast.count == slow.count > 0
    assert len(calls) >= 2  # several slabs went through the fused kernel
