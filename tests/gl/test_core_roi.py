"""A core drawn inside an ROI: the picture equals the picture of a volume whose voxels outside the
ROI hold a value the selection does not take (an exact oracle built here with numpy), in one
texture, in bricks and from a dask volume; picks never land outside."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.models import VoxelVolume
from tests.compute.test_roi import core_in_air, cylinder_mask

SIZE = (96, 72)


def _render(vol, ctx, **options):
    return geoshade.core.render(vol, ctx=ctx, size=SIZE, frames=1, annotations=False, **options)


@pytest.mark.parametrize("method", ["raycast", "cubes"])
def test_roi_picture_equals_the_masked_volume(ctx, method):
    vol, (cx, cy, r) = core_in_air(40, seed=11, air=200)  # bright air: selected without an ROI
    a = np.asarray(vol.data)
    inside = cylinder_mask(a.shape, cx, cy, r)
    masked = VoxelVolume(np.where(inside, a, 0).astype(a.dtype), vol.spacing, unit=vol.unit)
    sel = (20, 255)
    img, st = _render(vol, ctx, select=sel, roi=f"cylinder:{cx},{cy},{r}", method=method,
                      color_range=sel)
    # the masked volume as it is (sample="none": its zeros outside are not taken as air)
    ref, st_ref = _render(masked, ctx, select=sel, method=method, color_range=sel,
                          sample="none")
    assert st["voxels_selected"] == st_ref["voxels_selected"] == int(
        (np.broadcast_to(inside, a.shape) & (a >= 20)).sum())
    assert np.array_equal(img, ref)
    # in bricks: the masked volume's bricked picture (rasterised methods drawn in bricks may
    # differ from one texture in single pixels at brick faces, with or without an ROI)
    bricked, stb = _render(vol, ctx, select=sel, roi=f"cylinder:{cx},{cy},{r}", method=method,
                           color_range=sel, bricks=16)
    ref_b, _ = _render(masked, ctx, select=sel, method=method, color_range=sel, bricks=16,
                       sample="none")
    assert stb["bricks"] > 1 and np.array_equal(bricked, ref_b)
    if method == "raycast":
        assert np.array_equal(bricked, img)
    # from a dask volume: the same picture
    da = pytest.importorskip("dask.array")
    lazy = VoxelVolume(da.from_array(a, chunks=(16, 16, 16)), vol.spacing, unit=vol.unit)
    img_lazy, _ = _render(lazy, ctx, select=sel, roi=f"cylinder:{cx},{cy},{r}", method=method,
                          color_range=sel)
    assert np.array_equal(img_lazy, img)


def test_whole_dtype_selection_inside_a_mask(ctx):
    rng = np.random.default_rng(5)
    a = rng.integers(0, 256, (24, 20, 28), dtype=np.uint8)
    m = np.zeros(a.shape, np.uint8)
    m[4:20, 3:17, 5:25] = 1
    img, st = _render(VoxelVolume(a), ctx, select=(0, 255), mask=VoxelVolume(m))
    assert st["voxels_selected"] == int(m.sum()) and st["roi"]["kind"] == "mask"
    img_b, st_b = _render(VoxelVolume(a), ctx, select=(0, 255), mask=VoxelVolume(m), bricks=16)
    assert st_b["voxels_selected"] == int(m.sum()) and np.array_equal(img, img_b)


def test_pick_skips_voxels_outside_the_roi(ctx):
    vol, (cx, cy, r) = core_in_air(32, seed=12, air=200)
    with geoshade.core.CoreView(vol, ctx=ctx, select=(150, 255), size=SIZE,
                                roi=f"cylinder:{cx},{cy},{r}", annotations=False) as view:
        view.draw()
        roi = view.options.roi
        h, w = SIZE[1], SIZE[0]
        hits = 0
        for y in range(0, h, 4):
            for x in range(0, w, 4):
                p = view.pick(x, y)
                if p is None:
                    continue
                hits += 1
                i, j, _k = p.index
                assert roi.contains(np.array([i]), np.array([j]), np.array([0]))[0]
                assert 150 <= p.value <= 255
        assert hits > 10
