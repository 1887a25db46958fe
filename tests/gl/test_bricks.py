"""Bricked rendering of boxes beyond the GPU's limits: same picture as unbricked, streamed,
GPU bytes, overviews from a pyramid."""

from __future__ import annotations

import dask.array as da
import numpy as np
import pytest

from geoshade.compute.voxels.bitmaps import gpu_bytes_estimate
from geoshade.compute.voxels.bricks import largest_box, plan_bricks
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core import CoreView, overview_level, render_overview
from geoshade.core import backends as core_backends
from geoshade.core import view as core_view
from geoshade.models import Box, VoxelVolume
from geoshade.render.visuals.bricked import visual as bricked_visual

SIZE = (120, 90)
RANGE = (0, 18000)


@pytest.fixture(scope="module")
def volumes():
    vol = synthetic_core(48, seed=3)
    lazy = VoxelVolume(da.from_array(vol.data, chunks=(16, 16, 16)), spacing=vol.spacing)
    return vol, lazy


def test_plan_covers_the_box_exactly():
    box = Box((5, 7, 3), (100, 41, 70))
    cover = np.zeros((80, 50, 110), np.int32)
    bs = plan_bricks(box, 32)
    for b in bs:
        assert max(b.size) <= 32
        cover[b.slices()] += 1
    inside = np.zeros_like(cover)
    inside[box.slices()] = 1
    assert np.array_equal(cover, inside)  # every voxel of the box in exactly one brick
    assert all((b.offset[0] - 5) % 32 == 0 and (b.offset[2] - 3) % 8 == 0 for b in bs)


def _pair(ctx, volumes, method, view, **kw):
    vol, lazy = volumes
    v0 = CoreView(vol, select=RANGE, size=SIZE, ctx=ctx, method=method, bricks=False)
    v1 = CoreView(lazy, select=RANGE, size=SIZE, ctx=ctx, method=method, **kw)
    try:
        cam = v0.camera(view=view)
        img0, s0 = v0.draw(cam, frames=1, transparent=True)
        img1, s1 = v1.draw(cam, frames=1, transparent=True)
    finally:
        v0.release()
        v1.release()
    return img0, s0, img1, s1


def _differ(img0, img1) -> float:
    return float(np.mean(np.any(img0 != img1, axis=-1)))


@pytest.mark.parametrize(("method", "view"), [("trefoil", "iso"), ("trefoil", "front"),
                                              ("raycast", "iso"), ("raycast", "top")])
def test_bricks_draw_the_unbricked_picture(ctx, volumes, method, view):
    img0, s0, img1, s1 = _pair(ctx, volumes, method, view, bricks=20)
    assert s1["bricks"] == 27 and s1["brick_mode"] == "resident"
    assert s1["voxels_selected"] == s0["voxels_selected"]
    assert (img1[..., 3] > 0).mean() > 0.2
    if method == "raycast":
        # the bricks build the whole box's rays and walk its voxels: the same picture
        assert np.array_equal(img0, img1)
        return
    # rasterised bricks are transformed in their own frame, so a pixel whose edge lies within
    # float rounding of a voxel edge may go to the neighbouring face: a few pixels at most
    assert _differ(img0, img1) < 2e-3
    if view == "iso":
        assert np.array_equal(img0, img1)


def test_one_brick_is_exactly_the_unbricked_picture(ctx, volumes):
    vol, lazy = volumes
    v0 = CoreView(vol, select=RANGE, size=SIZE, ctx=ctx, method="raycast", bricks=False)
    v1 = CoreView(lazy, select=RANGE, size=SIZE, ctx=ctx, method="raycast", scheduler="threads")
    try:
        img0, s0 = v0.draw(frames=1)
        img1, s1 = v1.draw(frames=1)
        assert "bricks" not in s1 and s1["gpu_bytes"] == s0["gpu_bytes"]
        assert np.array_equal(img0, img1)
    finally:
        v0.release()
        v1.release()


def test_streamed_bricks_bound_gpu_memory(ctx, volumes):
    """A GPU budget smaller than the box: one brick at a time, same picture."""
    vol, _lazy = volumes
    whole = gpu_bytes_estimate(vol.shape_xyz, "raycast")
    img0, _s0, img1, s1 = _pair(ctx, volumes, "raycast", "iso", bricks=24,
                               gpu_memory=whole // 2)
    assert s1["brick_mode"] == "streamed" and s1["bricks"] == 8
    assert s1["gpu_bytes"] <= gpu_bytes_estimate((24, 24, 24), "raycast") < whole // 2
    assert np.array_equal(img0, img1)


def test_auto_bricks_above_the_texture_limit(ctx, volumes, monkeypatch):
    """A box wider than the (simulated) 3D-texture limit is bricked without being asked."""
    for module in (bricked_visual, core_view, core_backends):   # where it is imported
        monkeypatch.setattr(module, "tex_limit", lambda ctx: 32)
    vol, lazy = volumes
    v = CoreView(lazy, select=RANGE, size=SIZE, ctx=ctx, method="raycast")
    try:
        img, st = v.draw(frames=1, transparent=True)
        assert st["bricks"] == 8 and st["brick_side"] == 32
        assert st["largest_box"]["tex_limit"] == 32 and st["largest_box"]["unbricked"] <= 32
        ref = int(((vol.data >= RANGE[0]) & (vol.data <= RANGE[1])).sum())
        assert st["voxels_selected"] == ref
        v.update(select=(0, 9000))  # a new range rebuilds the bricks' maps
        img2, st2 = v.draw(frames=1, transparent=True)
        assert st2["voxels_selected"] == int((vol.data <= 9000).sum())
        assert (img[..., 3] > 0).sum() > (img2[..., 3] > 0).sum() > 0
    finally:
        v.release()


def test_largest_box_report():
    budget = 8 * 2**30
    r = largest_box("raycast", budget, 2048)
    d = r["unbricked"]  # the largest cube the formula fits in the budget
    assert gpu_bytes_estimate((d, d, d), "raycast") <= budget
    assert gpu_bytes_estimate((d + 1, d + 1, d + 1), "raycast") > budget
    assert (d, r["resident_bricks"], r["tex_limit"]) == (1954, 1955, 2048)
    assert largest_box("raycast", None, 2048)["resident_bricks"] is None


def test_overview_then_full_resolution_box(ctx, tmp_path):
    from geoshade.io.stores.ingest import ingest, read_level

    vol = synthetic_core(40, seed=5)
    vol.data.tofile(tmp_path / "c.raw")
    rep = ingest(tmp_path / "c.raw", tmp_path / "c.zarr", chunks=(16, 16, 16), levels=3,
                 shape=(40, 40, 40), dtype="uint16")
    img, st = render_overview(rep.path, select=RANGE, size=(80, 60), ctx=ctx, frames=1)
    assert st["level"] == 0 and st["level_shape_xyz"] == [40, 40, 40]
    img, st = render_overview(rep.path, select=RANGE, level=2, size=(80, 60), ctx=ctx, frames=1)
    assert st["level_shape_xyz"] == [10, 10, 10] and (img[..., 3] > 0).any()
    assert overview_level(rep.path, max_voxels=20**3) == 1
    full = read_level(rep.path, 0)
    assert np.array_equal(full.bounds(), read_level(rep.path, 2).bounds())  # same world box
    img, st = __import__("geoshade").core.render(full, select=RANGE, box=[8, 8, 8, 16, 16, 16],
                                                 size=(80, 60), ctx=ctx, frames=1)
    sub = vol.data[8:24, 8:24, 8:24]
    assert st["voxels_selected"] == int(((sub >= 0) & (sub <= 18000)).sum())


def test_auto_bricks_when_the_box_exceeds_the_gpu_budget(ctx):
    a = np.random.default_rng(2).integers(0, 256, (104, 104, 104)).astype(np.uint8)
    vol = VoxelVolume(da.from_array(a, chunks=(52, 104, 104)))
    need = gpu_bytes_estimate((104, 104, 104), "raycast")
    v = CoreView(vol, select=(0, 20), size=(48, 36), ctx=ctx, method="raycast",
                 gpu_memory=need - 10_000)
    try:
        _, st = v.draw(frames=1, count=False)
        assert st["bricks"] == 8 and st["brick_side"] == 64 and st["brick_mode"] == "streamed"
        assert st["gpu_bytes"] <= gpu_bytes_estimate((64, 64, 64), "raycast") < need
        assert st["voxels_selected"] == int((a <= 20).sum())
    finally:
        v.release()


def test_eye_inside_the_box_draws_the_voxels_before_the_far_plane(ctx):
    """With the eye inside the box the whole box's far corners lie beyond the far plane: the
    ray caster's proxy must not be clipped there (its pixels would get no ray), so the whole
    box, its bricks and the rasterised cubes agree on which pixels show a voxel."""
    from geoshade.render.camera import Camera

    vol = synthetic_core(64, porosity=0.3, seed=2)
    c = np.asarray(vol.shape_xyz, float) / 2 + 0.3
    cam = Camera(target=c, distance=4.0, azimuth=30.0, elevation=20.0, fovy=60.0,
                 radius=float(np.linalg.norm(vol.shape_xyz)) / 2)
    imgs = {}
    for method, bricks in (("raycast", False), ("raycast", 32), ("cubes", False)):
        with CoreView(vol, select=(0, 12000), size=(128, 128), ctx=ctx, method=method,
                      bricks=bricks) as v:
            imgs[method, bricks] = v.draw(cam, frames=1, count=False)[0]
    whole, bricked, cubes = imgs["raycast", False], imgs["raycast", 32], imgs["cubes", False]
    np.testing.assert_array_equal(whole, bricked)
    bg = whole[0, 0]
    assert (bricked != bg).any(-1).mean() > 0.5
    # the cubes are the reference picture of the voxels: the same pixels show a voxel (their
    # shading differs at a few voxel edges, not coverage)
    covered = (whole != bg).any(-1)
    assert np.mean(covered != (cubes != bg).any(-1)) < 2e-3


def test_silhouette_pixels_get_their_rays(ctx):
    """A pixel whose centre lies within the rasteriser's subpixel snapping of the box's outline
    got no proxy fragment, hence no ray, though its ray touches a voxel on the box's face (its
    bricks, with other triangles, drew it): the proxy is one voxel wider than the box. Whole box
    and bricks now cover the same pixels (cameras where they differed before)."""
    vol = synthetic_core(96, porosity=0.3, seed=1)
    sel = tuple(vol.meta["pore_range"])
    cover = {}
    for bricks in (False, 32):
        with CoreView(vol, select=sel, size=(512, 384), ctx=ctx, method="raycast",
                      bricks=bricks) as v:
            for az, el in ((0.0, 10.0), (21.0, 10.0), (42.0, 40.0)):
                v.draw(v.camera("iso", azimuth=az, elevation=el), frames=1, count=False)
                depth = np.frombuffer(v.target.depth.read(), np.float32)
                cover[bricks, az] = depth < 1.0
    for az in (0.0, 21.0, 42.0):
        assert cover[False, az].mean() > 0.2
        np.testing.assert_array_equal(cover[False, az], cover[32, az])
