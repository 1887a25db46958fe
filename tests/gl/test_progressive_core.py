"""A progressive CoreView (issue 26, target 4): a preview from a store's overview level first,
then the full picture, which is pixel for pixel the non-progressive View's."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.voxels.roi import Cylinder
from geoshade.core import CoreView
from geoshade.core import preview as preview_mod
from geoshade.core.preview import level_box, preview_roi, preview_volume
from geoshade.io.stores.ingest import ingest
from geoshade.models.volume import Box

SIZE = (320, 240)
SELECT = (0, 15000)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    d = tmp_path_factory.mktemp("core")
    a = np.asarray(geoshade.synthetic_core(64, porosity=0.25, seed=3).data)
    a.tofile(d / "c.raw")
    rep = ingest(d / "c.raw", d / "c.zarr", chunks=(16, 16, 16), levels=3, shape=a.shape,
                 dtype=str(a.dtype))
    return rep.path


@pytest.fixture
def small_budget(monkeypatch):
    monkeypatch.setattr(preview_mod, "PREVIEW_VOXELS", 40**3)   # 64³ needs level 1


def full_picture(vol, **kw):
    kw = {"size": SIZE, "select": SELECT, **kw}
    with CoreView(vol, **kw) as v:
        return v.draw(frames=1)


def test_preview_then_exactly_the_full_picture(ctx, store, small_budget):
    vol = geoshade.load(store)
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True,
                  annotations=True) as view:
        assert view.loading and view.drawing is None       # nothing of level 0 built yet
        pics = list(view.pictures(frames=1))
        assert not view.loading and view.preview is None
    (coarse, cs), (full, fs) = pics
    assert cs["coarse"] is True and cs["level"] == 1 and cs["coarse_ratio"] == 2
    assert "coarse" not in fs and "level" not in fs
    note = "coarse preview, level 1 (1/2 resolution) — full picture loading"
    assert cs["coarse_note"] == note
    assert note in str(cs["annotations"]["title"]) and note not in str(fs["annotations"])
    ref, rs = full_picture(vol, annotations=True)
    assert np.array_equal(full, ref)                       # ends on exactly the full picture
    assert fs["voxels_selected"] == rs["voxels_selected"]
    assert not np.array_equal(coarse, ref)


def bbox(img):
    rows, cols = np.nonzero((img[..., :3] != 255).any(-1))
    return np.array([rows.min(), rows.max(), cols.min(), cols.max()])


def test_the_preview_has_the_full_pictures_framing(ctx, store, small_budget):
    vol = geoshade.load(store)
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True) as view:
        coarse, _ = view.draw(frames=1)
    full, _ = full_picture(vol)
    # the same box in the same place: the model's extent differs by at most a coarse voxel
    assert np.abs(bbox(coarse) - bbox(full)).max() <= 4


def test_the_preview_is_the_level_drawn_over_the_full_box(ctx, store, small_budget):
    vol = geoshade.load(store)
    box = vol.resolve_box([8, 0, 4, 40, 64, 48])
    lvl, lbox = preview_volume(vol, 1, box)
    np.testing.assert_allclose(lvl.bounds(lbox), vol.bounds(box))   # scaled to the full box
    assert lbox.size == (20, 32, 24)
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, box=box, progressive=True) as view:
        _img, st = view.draw(frames=1)
        # the preview's selection is the level's own: its voxels counted there
        level1 = np.asarray(geoshade.io.stores.zarr_io.read_level(store, 1).data)
        sl = level1[lbox.offset[2]:lbox.offset[2] + lbox.size[2],
                    lbox.offset[1]:lbox.offset[1] + lbox.size[1],
                    lbox.offset[0]:lbox.offset[0] + lbox.size[0]]
        assert st["voxels_selected"] == int(((sl >= SELECT[0]) & (sl <= SELECT[1])).sum())
        assert st["color_range"] == list(SELECT)


def test_a_change_while_loading_makes_a_new_preview_and_one_refine_job(ctx, store,
                                                                       small_budget):
    vol = geoshade.load(store)
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True) as view:
        first = view.preview.view
        assert view.jobs(view="top") == []          # the camera: the same preview
        jobs = view.jobs(select=(0, 9000))
        assert [j.key for j in jobs] == [view.refine_key()] and view.loading
        assert view.preview.view is not first and first.released
        assert view.preview.view.options.select == (0.0, 9000.0)
        jobs[0].run()
        img, st = view.draw(frames=1)
    ref, _rs = full_picture(vol, select=(0, 9000), view="top")
    assert np.array_equal(img, ref) and "coarse" not in st


def test_no_preview_without_levels_or_within_budget(ctx, store):
    vol = geoshade.load(store)   # 64³ is within the default budget: the full picture at once
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True) as view:
        assert not view.loading
        assert len(list(view.pictures(frames=1))) == 1
    mem = geoshade.synthetic_core(32)
    with CoreView(mem, ctx=ctx, size=SIZE, select=SELECT, progressive=True) as view:
        assert not view.loading


def test_roi_in_level_voxels():
    box, lbox = Box((0, 0, 0), (64, 64, 64)), Box((0, 0, 0), (32, 32, 32))
    c = preview_roi(Cylinder(32.0, 30.0, 20.0), box, lbox)
    assert (c.cx, c.cy, c.r) == (16.0, 15.0, 10.0)
    assert level_box(Box((5, 6, 7), (10, 10, 10)), 1, (32, 32, 32)) == ((2, 3, 3), (8, 8, 9))


def test_release_frees_the_preview(ctx, store, small_budget):
    vol = geoshade.load(store)
    view = CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True)
    view.draw(frames=1)
    assert view.gpu_bytes > 0
    pv = view.preview.view
    view.release()
    assert pv.released and view.gpu_bytes == 0


def test_pick_while_loading_asks_the_preview(ctx, store, small_budget):
    vol = geoshade.load(store)
    with CoreView(vol, ctx=ctx, size=SIZE, select=SELECT, progressive=True) as view:
        view.draw(frames=1)
        raw = view.preview.view.pick(SIZE[0] // 2, SIZE[1] // 2)
        assert raw is not None and max(raw.index) < 32        # a voxel of level 1 (32³)
        hit = view.pick(SIZE[0] // 2, SIZE[1] // 2)           # said as the voxels it merges
        assert hit.index == tuple(2 * v for v in raw.index)
        assert hit.label == "voxels " + " ".join(f"{a}={2 * v}–{2 * v + 1}"
                                                 for a, v in zip("xyz", raw.index, strict=True))
        assert hit.extra[-1] == ("preview", "the merged value of 2×2×2 voxels (exact in the "
                                            "full picture)")
        view.refine()
        view.draw(frames=1)
        full = view.pick(SIZE[0] // 2, SIZE[1] // 2)
        assert full is not None and full.label.startswith("voxel x=") and not full.extra
