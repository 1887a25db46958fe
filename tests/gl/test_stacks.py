"""The stack ray caster: five layouts, one picture; exact oracles for the geologist's tools."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.stacks import (
    LAYOUTS,
    place_boreholes,
    stacks_to_voxels,
    synthetic_layers,
    voxels_to_stacks,
)
from geoshade.errors import GPUMemoryError, InputError
from geoshade.models.stacks import EMPTY, BoreholeLogs

pytestmark = pytest.mark.gl
SIZE = (96, 72)


@pytest.fixture(scope="module")
def api(ctx):
    import geoshade.stacks as st

    return st


@pytest.fixture(scope="module")
def model():
    """A small layered model with translucent-free colours, caves and two borehole columns."""
    m = synthetic_layers(14, 11, 24, max_intervals=6, mean_intervals=4.5, seed=11,
                         spacing=(10.0, 10.0, 1.0))
    v = stacks_to_voxels(m)
    v[8:10, 3:6, 4:8] = EMPTY                     # a cave
    m = voxels_to_stacks(v, empty=EMPTY, spacing=m.spacing, legend=m.legend)
    logs = BoreholeLogs(["a", "a", "b"], [25.0, 25.0, 115.0], [35.0, 35.0, 85.0],
                        top=[26.0, 20.0, 18.0], bottom=[20.0, 8.0, 2.0], code=[6, 2, 3])
    return place_boreholes(m, logs, strict=True)


def view_of(api, model, **kw):
    kw.setdefault("size", SIZE)
    return api.StacksView(model, **kw)


def draw(view, cam=None, **kw):
    img, stats = view.draw(cam, **kw)
    return img, stats


def pixel_xy(view, cam) -> np.ndarray:
    """(h, w, 2) index-space (x, y) of each pixel centre (row 0 at the top), ortho camera."""
    w, h = view.size
    i, j = np.meshgrid(np.arange(w), np.arange(h))
    ndc = np.stack([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2, np.zeros_like(i, float),
                    np.ones_like(i, float)], axis=-1)
    inv = np.linalg.inv(view.model_matrix()) @ np.linalg.inv(
        cam.projection_matrix() @ cam.view_matrix())
    p = ndc @ inv.T
    return p[..., :2] / p[..., 3:]


def top_oracle(model, visible_alpha, logs_only=False):
    """(ny, nx, 4) colour of each column's highest drawn interval (alpha 0: nothing)."""
    v = stacks_to_voxels(model)                                   # (nz, ny, nx) codes
    idx = model.legend.index_of(np.where(v == EMPTY, EMPTY, v))   # palette index, 0 = empty
    shown = (idx > 0) & (visible_alpha[np.maximum(idx - 1, 0)] > 0)
    if logs_only:
        nz = v.shape[0]
        lv = np.arange(nz)[:, None, None] + 0.5
        base = model.log_base.reshape(model.shape[1], model.shape[0])
        shown &= model.borehole.reshape(base.shape)[None] & (lv >= base[None])
    top = np.where(shown.any(0), v.shape[0] - 1 - np.argmax(shown[::-1], axis=0), -1)
    yy, xx = np.indices(top.shape)
    pal = idx[np.maximum(top, 0), yy, xx]
    out = np.zeros((*top.shape, 4), np.uint8)
    out[top >= 0] = model.legend.rgba[pal[top >= 0] - 1]
    return out


def clear_pixels(xy, shape):
    """Pixels whose centre is inside the grid and not within 0.02 of a column boundary."""
    nx, ny = shape
    frac = np.abs(xy - np.round(xy))
    inside = (xy[..., 0] > 0) & (xy[..., 0] < nx) & (xy[..., 1] > 0) & (xy[..., 1] < ny)
    return inside & (frac > 0.02).all(axis=-1)


# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("walk", "drape"), [("exact", False), ("paper", False),
                                           ("exact", True), ("paper", True)])
def test_the_five_layouts_draw_the_same_picture(api, model, walk, drape, tmp_path):
    view = view_of(api, model, walk=walk, exaggeration=2.0)
    try:
        if drape:  # the top faces take the image (layouts 2-4 pad columns with fillers)
            from PIL import Image

            rgb = np.random.default_rng(3).integers(0, 256, (8, 16, 4)).astype(np.uint8)
            rgb[..., 3] = 255
            Image.fromarray(rgb).save(tmp_path / "drape.png")
            view.update(drape=tmp_path / "drape.png", drape_mix=1.0)
        cam = view.camera(azimuth=35, elevation=30)
        images = {}
        for layout in LAYOUTS:
            view.update(layout=layout)
            images[layout], st = draw(view, cam)
            assert st["method"] == layout and st["layout_bytes"] > 0
    finally:
        view.release()
    ref = images["textures"]
    assert (ref[..., :3] != 255).any(axis=-1).mean() > 0.2
    for layout, img in images.items():
        assert np.array_equal(img, ref), f"{layout} differs from textures ({walk} walk)"


def test_exact_walk_equals_the_dense_3d_texture_ray_caster(api, model):
    view = view_of(api, model, exaggeration=2.0, lighting=False, smooth=0)
    try:
        out = {}
        for layout in ("ssbo", "dense"):
            view.update(layout=layout)
            out[layout] = [draw(view, view.camera(azimuth=a, elevation=e))[0]
                           for a, e in ((30, 40), (210, -25))]
    finally:
        view.release()
    for a, b in zip(out["ssbo"], out["dense"], strict=True):
        bad = np.abs(a.astype(int) - b).max(axis=-1) > 2
        assert bad.mean() <= 0.002, f"{bad.sum()} pixels differ"


def test_top_view_shows_each_columns_top_material(api, model):
    view = view_of(api, model, lighting=False, smooth=0)
    try:
        cam = view.camera(view="top", ortho=True)
        img, st = draw(view, cam, transparent=True)
    finally:
        view.release()
    assert st["columns"] == model.ncols and st["intervals"] == model.nintervals
    xy = pixel_xy(view, cam)
    ok = clear_pixels(xy, model.shape)
    col = np.floor(xy).astype(int)
    expect = top_oracle(model, np.ones(len(model.legend)))[col[..., 1].clip(0, 10),
                                                           col[..., 0].clip(0, 13)]
    assert ok.mean() > 0.5
    assert np.array_equal(img[ok], expect[ok])


def test_the_papers_sampling_walk_is_close_to_the_exact_walk(api, model):
    view = view_of(api, model, lighting=False, smooth=0)
    try:
        out = {}
        for walk in ("exact", "paper"):
            view.update(walk=walk)
            out[walk] = [draw(view, cam)[0] for cam in (
                view.camera(view="top", ortho=True), view.camera(azimuth=30, elevation=30))]
    finally:
        view.release()
    assert np.array_equal(out["exact"][0], out["paper"][0])     # vertical rays: no step error
    bad = np.abs(out["exact"][1].astype(int) - out["paper"][1]).max(axis=-1) > 2
    assert 0 < bad.mean() <= 0.05                                # Nyquist steps: small misses


@pytest.mark.parametrize("walk_from", ["top", "bottom"])
def test_walking_stacks_from_the_top_or_bottom_changes_nothing(api, model, walk_from):
    a = view_of(api, model)
    b = view_of(api, model, walk_from=walk_from)
    try:
        cam = a.camera(azimuth=120, elevation=20)
        assert np.array_equal(draw(a, cam)[0], draw(b, cam)[0])
    finally:
        a.release()
        b.release()


def test_a_hidden_material_disappears_and_only_it(api, model):
    view = view_of(api, model, lighting=False, smooth=0, layout="textures")
    try:
        cam = view.camera(azimuth=60, elevation=35)
        before, _ = draw(view, cam)
        code = 6                                    # the top layer: it covers most of the top
        colour = model.legend.rgba[model.legend.index_of(np.array([code]))[0] - 1][:3]
        is_m = (before[..., :3] == colour).all(axis=-1)
        assert is_m.mean() > 0.05
        view.update(opacity=None, hide=[code])
        after, st = draw(view, cam)
    finally:
        view.release()
    assert st["hidden"] == [code]
    assert not (after[..., :3] == colour).all(axis=-1).any()
    assert np.array_equal(after[~is_m], before[~is_m])
    assert (after[is_m] != before[is_m]).any(axis=-1).mean() > 0.9  # what lay below shows


def test_attenuated_material_blends_and_unknown_codes_are_refused(api, model):
    view = view_of(api, model, lighting=False, smooth=0)
    try:
        cam = view.camera(view="top", ortho=True)
        opaque, _ = draw(view, cam)
        view.update(opacity={6: 0.3})
        faint, _ = draw(view, cam)
        with pytest.raises(InputError, match="unknown material code 99"):
            view.update(opacity=None, hide=[99])
        with pytest.raises(InputError, match=r"expected a number 0\.\.1"):
            view.update(opacity={6: 2})
    finally:
        view.release()
    colour = model.legend.rgba[model.legend.index_of(np.array([6]))[0] - 1][:3]
    was = (opaque[..., :3] == colour).all(axis=-1)
    assert was.any() and not (faint[was][:, :3] == colour).all(axis=-1).any()


@pytest.mark.parametrize("plane", [(1.0, 0.0, 0.0, 62.0), (0.0, -1.0, 0.0, -47.0)])
def test_a_vertical_section_removes_exactly_the_half_space(api, model, plane):
    view = view_of(api, model, lighting=False, smooth=0)
    try:
        cam = view.camera(view="top", ortho=True)
        full, _ = draw(view, cam, transparent=True)
        view.update(plane=tuple(-np.asarray(plane)))  # keeps n·p <= d
        cut, st = draw(view, cam, transparent=True)
    finally:
        view.release()
    assert st["section"] is not None
    xy = pixel_xy(view, cam)
    world = xy * np.array(model.spacing[:2]) + np.array(model.origin[:2])
    side = world @ np.array(plane[:2]) - plane[3]
    removed, kept = side > 0.05, side < -0.05
    assert removed.mean() > 0.2 and kept.mean() > 0.2
    assert (cut[removed][:, 3] == 0).all()
    assert np.array_equal(cut[kept], full[kept])


def test_an_oblique_section_keeps_hits_inside_the_half_space(api, model):
    view = view_of(api, model, lighting=False, smooth=0)
    plane = np.array([0.3, 0.2, 1.0, 55.0])        # world: n·p <= d is kept
    try:
        cam = view.camera(azimuth=40, elevation=50)
        full, _ = draw(view, cam, transparent=True)
        _, d_full = view.visual.read_gbuffer()
        view.update(plane=tuple(-plane))  # keeps n·p <= d
        cut, _ = draw(view, cam, transparent=True)
        _, d_cut = view.visual.read_gbuffer()
    finally:
        view.release()
    w, h = view.size
    j, i = np.indices((h, w))

    def world(depth):
        ndc = np.stack([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2, depth * 2 - 1,
                        np.ones_like(depth)], axis=-1)
        inv = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix())
        p = ndc @ inv.T
        p = p[..., :3] / p[..., 3:]
        return p / np.array([1.0, 1.0, view.exaggeration])

    s_cut = world(d_cut) @ plane[:3] - plane[3]
    s_full = world(d_full) @ plane[:3] - plane[3]
    hit_cut, hit_full = d_cut < 1, d_full < 1
    assert (s_cut[hit_cut] <= 0.05).all()                       # nothing beyond the plane
    kept = hit_full & (s_full < -0.05)
    assert kept.mean() > 0.1
    assert np.array_equal(cut[kept], full[kept])                 # the rest is untouched
    assert (hit_full & (s_full > 0.05)).mean() > 0.1


def test_a_plane_that_misses_the_model_is_refused(api, model):
    view = view_of(api, model)
    try:
        with pytest.raises(InputError, match="misses the model"):
            view.update(plane=(1.0, 0.0, 0.0, 1e6))
        with pytest.raises(InputError, match="misses the model"):
            view.update(plane="0,0,-1,100")
        with pytest.raises(InputError, match="must not be zero"):
            view.update(plane=(0, 0, 0, 1))
    finally:
        view.release()


@pytest.mark.parametrize("layout", ["textures", "l-supertexels", "dense"])
def test_borehole_mode_draws_only_the_logs(api, model, layout):
    view = view_of(api, model, lighting=False, smooth=0, layout=layout)
    try:
        cam = view.camera(view="top", ortho=True)
        view.update(boreholes=True)
        img, st = draw(view, cam, transparent=True)
    finally:
        view.release()
    assert st["borehole_columns"] == 2 and st["boreholes_only"]
    xy = pixel_xy(view, cam)
    ok = clear_pixels(xy, model.shape)
    col = np.floor(xy).astype(int)
    expect = top_oracle(model, np.ones(len(model.legend)), logs_only=True)[
        col[..., 1].clip(0, 10), col[..., 0].clip(0, 13)]
    assert (expect[ok][:, 3] > 0).sum() > 20
    assert np.array_equal(img[ok], expect[ok])


def test_drape_covers_the_top_surface_only(api, model, tmp_path):
    from PIL import Image

    img = np.zeros((8, 16, 4), np.uint8)
    img[..., 3] = 255
    img[:, :8, 0] = 255                     # west half red
    img[:, 8:, 2] = 255                     # east half blue
    path = tmp_path / "ortho.png"
    Image.fromarray(img).save(path)
    view = view_of(api, model, lighting=False, smooth=0)
    try:
        cam = view.camera(view="top", ortho=True)
        view.update(drape=path, drape_mix=1.0)
        top, st = draw(view, cam, transparent=True)
        side, _ = draw(view, view.camera(view="front", ortho=True), transparent=True)
    finally:
        view.release()
    assert st["drape"]
    xy = pixel_xy(view, cam)
    ok = clear_pixels(xy, model.shape) & (top[..., 3] == 255)
    west = ok & (xy[..., 0] < 6.5)        # away from the bilinear blend at x = 7
    east = ok & (xy[..., 0] > 7.5)
    assert (top[west][:, :3] == [255, 0, 0]).all() and (top[east][:, :3] == [0, 0, 255]).all()
    pure = ((side[..., :3] == [255, 0, 0]).all(-1) | (side[..., :3] == [0, 0, 255]).all(-1))
    assert pure.mean() < 0.01               # the sides keep the material colours


def test_exaggeration_stretches_the_box_not_the_top_view(api, model):
    a, b = view_of(api, model, exaggeration=1.0), view_of(api, model, exaggeration=5.0)
    try:
        ba, bb = a.bounds(), b.bounds()
        assert np.allclose(bb[:, :2], ba[:, :2])
        assert np.isclose(bb[1, 2] - bb[0, 2], 5 * (ba[1, 2] - ba[0, 2]))
        ia = draw(a, a.camera(view="top", ortho=True))[0]
        ib = draw(b, b.camera(view="top", ortho=True))[0]
        assert np.array_equal(ia[..., 3] > 0, ib[..., 3] > 0)
        with pytest.raises(InputError, match="exaggeration"):
            b.set_exaggeration(0)
    finally:
        a.release()
        b.release()


def test_stats_and_gpu_bytes(api, model):
    img, st = api.render(model, layout="r-supertexels", size=SIZE, frames=2, legend=True)
    for key in ("width", "height", "method", "frame_ms", "gpu_bytes", "columns", "intervals",
                "max_intervals", "mrays_per_s"):
        assert key in st
    assert (st["width"], st["height"]) == SIZE and img.shape == (SIZE[1], SIZE[0], 4)
    assert st["gpu_bytes"] >= st["layout_bytes"] + 8 * SIZE[0] * SIZE[1]
    assert st["mrays_per_s"] == pytest.approx(SIZE[0] * SIZE[1] / st["frame_ms"] / 1000,
                                              rel=1e-2)


def test_a_layout_beyond_a_texture_limit_is_a_clear_error(ctx, model, monkeypatch):
    from geoshade.compute.stacks import gpu_intervals
    from geoshade.render.visuals.stacks.visual import StacksVisual

    monkeypatch.setattr(StacksVisual, "limits", lambda self: {
        "max_texture_size": 32, "max_3d_texture_size": 8, "max_ssbo_bytes": 1 << 20})
    pal = np.zeros((len(model.legend) + 1, 4), np.uint8)
    g = gpu_intervals(model)
    for layout, what in (("l-supertexels", "limit of 32"), ("texture3d", "limit of 8"),
                         ("r-supertexels", "limit of 32")):
        with pytest.raises(GPUMemoryError, match=what):
            StacksVisual(ctx, g, pal, layout=layout)
    StacksVisual(ctx, g, pal, layout="ssbo").release()


def test_every_stack_program_compiles(ctx, model):
    from geoshade.compute.stacks import gpu_intervals
    from geoshade.render.visuals.stacks.visual import LAYOUT_IDS, StacksVisual

    pal = np.zeros((len(model.legend) + 1, 4), np.uint8)
    g = gpu_intervals(model)
    for layout in LAYOUT_IDS:
        for walk in ("exact", "paper"):
            StacksVisual(ctx, g, pal, layout=layout, walk=walk).release()
