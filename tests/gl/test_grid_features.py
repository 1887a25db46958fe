"""Filters, slices, clip plane, MAPAXES, exaggeration, faults and cell edges, pixel by pixel.

The exact oracle: each cell gets its own palette colour (index = cell number, < 256 cells),
the faces are drawn unlit, and a top orthographic view is decoded pixel by pixel into the cell
that must be on top of that column according to numpy.
"""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.errors import GeoshadeDeprecationWarning, InputError
from geoshade.grid import GridView, parse_slice, plane_from_clip
from geoshade.styles.palette import random_palette
from tests.gl.grid_support import make_grid, mismatch, reference_faces

UNLIT = {"light_dir": (0.0, 0.0, 1.0), "material": (1.0, 0.0, 0.0, 1.0)}
PAL = random_palette(3)
DECODE = {tuple(int(v) for v in rgb): i for i, rgb in enumerate(PAL[:, :3])}
SIZE = (64, 64)



def id_view(grid, ctx, **kw) -> GridView:
    view = GridView(grid, property="CELLID", color_range=(0, 255), palette=PAL, size=SIZE,
                    ctx=ctx, **kw)
    view.shading = dict(UNLIT)
    return view


def pixel_world_xy(cam, size) -> np.ndarray:
    """(h, w, 2) world x, y of the pixel centres of an orthographic view (row 0 on top)."""
    w, h = size
    inv = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix())
    px, py = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    ndc = np.stack([px / w * 2 - 1, 1 - py / h * 2, np.zeros_like(px), np.ones_like(px)], -1)
    p = ndc @ inv.T
    return p[..., :2] / p[..., 3:]


def decode(img) -> np.ndarray:
    """(h, w) cell number under each pixel (-1: transparent background or not a palette colour)."""
    keys = img[..., 0].astype(np.int64) << 16 | img[..., 1].astype(np.int64) << 8 | img[..., 2]
    table = {r << 16 | g << 8 | b: i for (r, g, b), i in DECODE.items()}
    uniq, inv = np.unique(keys, return_inverse=True)
    lut = np.array([table.get(int(k), -1) for k in uniq])
    return np.where(img[..., 3] > 0, lut[inv].reshape(img.shape[:2]), -1)


def expected_top(grid, shown, gxy, dx=10.0, dy=10.0, margin_px=1.0, px_size=1.0):
    """Cell number on top of each pixel's column per numpy, and a mask of pixels away from the
    cell boundaries (``gxy``: (h, w, 2) grid x, y of the pixels)."""
    nx, ny, _ = grid.dims
    fi, fj = gxy[..., 0] / dx, gxy[..., 1] / dy
    i, j = np.floor(fi).astype(int), np.floor(fj).astype(int)
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    dist = np.minimum(np.minimum(fi - np.floor(fi), np.ceil(fi) - fi) * dx,
                      np.minimum(fj - np.floor(fj), np.ceil(fj) - fj) * dy) / px_size
    clear = dist > margin_px
    anyk = shown.any(axis=2)
    topk = np.argmax(shown, axis=2)
    ic, jc = np.clip(i, 0, nx - 1), np.clip(j, 0, ny - 1)
    cell = ic + nx * (jc + ny * topk[ic, jc])
    want = np.where(inside & anyk[ic, jc], cell, -1)
    # pixels just outside the grid are background; keep them unless near the outline
    return want, clear | ~inside & (dist > margin_px)


def check_top_view(view, grid, mapaxes_inverse=None):
    cam = view.camera(view="top", ortho=True)
    img, st = view.draw(cam, frames=1, transparent=True)
    xy = pixel_world_xy(cam.with_aspect(1.0), SIZE)
    if mapaxes_inverse is not None:
        xy = mapaxes_inverse(xy)
    px_size = 2 * cam.half_height / SIZE[1]
    want, clear = expected_top(grid, view.shown_mask(), xy, px_size=px_size)
    got = decode(img)
    assert clear.mean() > 0.5
    bad = (got != want) & clear
    assert not bad.any(), f"{bad.sum()} pixels show the wrong cell"
    return img, st, got


def test_filter_shows_exactly_the_cells_that_satisfy_it(ctx):
    g = make_grid(8, 6, 3, dip=(0.0, 0.0), inactive=[(0, 0, 0), (5, 2, 0), (5, 2, 1)])
    view = id_view(g, ctx, filter="PORO > 0.2 and PERMX > 10")
    try:
        want = g.active & (g.properties["PORO"] > 0.2) & (g.properties["PERMX"] > 10)
        np.testing.assert_array_equal(view.shown_mask(), want)
        _, st, got = check_top_view(view, g)
        assert st["faces_drawn"] == len(reference_faces(g, want).face)
        seen = set(np.unique(got[got >= 0]).tolist())
        assert seen <= set(np.flatnonzero(want.ravel(order="F")).tolist())
        # a new filter redraws from the grid in memory (the geometry objects stay)
        coord = view.visual.cache.get("coord")
        view.update(filter="PORO <= 0.2")
        _, st2, _ = check_top_view(view, g)
        assert view.visual.cache.get("coord") is coord
        assert st2["shown_cells"] == int((g.active & (g.properties["PORO"] <= 0.2)).sum())
    finally:
        view.release()


def test_slice_and_clip_plane(ctx):
    g = make_grid(8, 6, 4, dip=(0.0, 0.0))
    view = id_view(g, ctx, slice="i=2:7,j=1:5,k=1:3")
    try:
        box = np.zeros(g.dims, bool)
        box[2:7, 1:5, 1:3] = True
        np.testing.assert_array_equal(view.shown_mask(), box)
        check_top_view(view, g)
        view.update(slice=None)
        view.update(plane=(2, 0, 0, 70))      # 2x >= 70: cell centres 35.. (i >= 3)
        want = np.zeros(g.dims, bool)
        want[3:] = True
        np.testing.assert_array_equal(view.shown_mask(), want)
        check_top_view(view, g)
        view.update(plane="-1,0,0")           # through the centre (x = 40), keep the west half
        west = np.zeros(g.dims, bool)
        west[:4] = True                    # x <= 40: cell centres 5..35
        np.testing.assert_array_equal(view.shown_mask(), west)
    finally:
        view.release()


def test_deprecated_clip_plane_keeps_the_same_cells(ctx):
    """The old clip (relative to the centre, depth down) is converted to the same plane."""
    g = make_grid(8, 6, 4, dip=(0.0, 0.0))
    new = id_view(g, ctx, plane=(1, 0, 0, 35))
    with pytest.warns(GeoshadeDeprecationWarning, match="clip_plane is deprecated: use plane"):
        old = id_view(g, ctx, clip_plane=(2, 0, 0, 5))
    try:
        np.testing.assert_array_equal(old.shown_mask(), new.shown_mask())
        with pytest.warns(GeoshadeDeprecationWarning):
            deep = id_view(g, ctx, clip_plane="0,0,1,0")   # old: depth >= centre depth
        try:
            k = np.zeros(g.dims, bool)
            k[:, :, 2:] = True  # the deeper half of 4 layers
            np.testing.assert_array_equal(deep.shown_mask(), k & g.active)
        finally:
            deep.release()
    finally:
        old.release()
        new.release()


@pytest.mark.parametrize("kind", ["rotate", "mirror"])
def test_mapaxes_is_applied(ctx, kind):
    x0, y0 = 1000.0, 2000.0
    if kind == "rotate":   # grid x -> map +y, grid y -> map -x
        mapaxes = (x0 - 1, y0, x0, y0, x0, y0 + 1)
        inverse = lambda xy: np.stack([xy[..., 1] - y0, x0 - xy[..., 0]], -1)  # noqa: E731
    else:                  # grid y -> map -y (a left-handed map)
        mapaxes = (x0, y0 - 1, x0, y0, x0 + 1, y0)
        inverse = lambda xy: np.stack([xy[..., 0] - x0, y0 - xy[..., 1]], -1)  # noqa: E731
    g = make_grid(6, 4, 2, dip=(0.0, 0.0), mapaxes=mapaxes)
    view = id_view(g, ctx, filter="PORO > 0.15")
    try:
        check_top_view(view, g, mapaxes_inverse=inverse)
        # the back-face cull stays right for a mirrored map
        img_c, _ = view.draw(view.camera(azimuth=60, elevation=30), frames=1)
        view.cull = False
        img_n, _ = view.draw(view.camera(azimuth=60, elevation=30), frames=1)
        assert mismatch(img_c, img_n, tol=1) <= 0.002
    finally:
        view.release()


def test_exaggeration_and_shallow_cells_on_top(ctx):
    g = make_grid(6, 4, 5, dx=10, dy=10, dz=4, dip=(0.0, 0.0))
    heights = []
    for exag in (1.0, 3.0):
        view = id_view(g, ctx, exaggeration=exag)
        try:
            img, st = view.draw(view.camera(view="front", ortho=True), frames=1,
                                transparent=True)
        finally:
            view.release()
        got = decode(img)
        rows = np.flatnonzero((got >= 0).any(axis=1))
        cols = np.flatnonzero((got >= 0).any(axis=0))
        heights.append((rows[-1] - rows[0] + 1) / (cols[-1] - cols[0] + 1))
        layer = g.dims[0] * g.dims[1]
        top_cells = got[rows[0] + 1][got[rows[0] + 1] >= 0]
        bottom_cells = got[rows[-1] - 1][got[rows[-1] - 1] >= 0]
        assert set((top_cells // layer).tolist()) == {0}      # shallowest layer on top
        assert set((bottom_cells // layer).tolist()) == {g.dims[2] - 1}
        assert st["exaggeration"] == exag
    assert heights[1] / heights[0] == pytest.approx(3.0, rel=0.1)


def test_faults_show_highlight_hide(ctx):
    g = make_grid(8, 4, 3, throw=6.0, fault_i=4)
    views = {m: GridView(g, property="PORO", faults=m, size=SIZE, ctx=ctx)
             for m in ("show", "highlight", "hide")}
    try:
        out = {m: v.draw(v.camera(azimuth=70, elevation=30), frames=1) for m, v in views.items()}
        fs = reference_faces(g, g.active)
        assert out["show"][1]["faces_drawn"] == out["highlight"][1]["faces_drawn"] == len(fs.face)
        n_hidden = int((fs.fault & fs.neighbour_shown).sum())
        assert n_hidden > 0
        assert out["hide"][1]["faces_drawn"] == len(fs.face) - n_hidden
        show, hl = out["show"][0], out["highlight"][0]
        diff = np.abs(show.astype(int) - hl.astype(int)).max(-1) > 3
        assert 0.005 < diff.mean() < 0.3
        # highlighted pixels are redder
        assert (hl[diff][:, 0].astype(int) - show[diff][:, 0]).mean() > 20
    finally:
        for v in views.values():
            v.release()


def _boundary_distance_px(view, cam, grid, dx=10.0, dy=10.0):
    xy = pixel_world_xy(cam.with_aspect(1.0), SIZE)
    nx, ny, _ = grid.dims
    fx = xy[..., 0] / dx
    fy = xy[..., 1] / dy
    px = 2 * cam.half_height / SIZE[1]
    dxl = np.abs(fx - np.clip(np.rint(fx), 0, nx)) * dx / px
    dyl = np.abs(fy - np.clip(np.rint(fy), 0, ny)) * dy / px
    inside = (fx > 0) & (fx < nx) & (fy > 0) & (fy < ny)
    # diagonal of the top face (corner A (i, j) to C (i+1, j+1))
    u, v = fx - np.floor(fx), fy - np.floor(fy)
    diag = np.abs(u - v) * dx / np.sqrt(2) / px
    return np.minimum(dxl, dyl), inside, diag


@pytest.mark.parametrize(("mode", "approach"), [("quad", 3), ("paper", 3), ("paper", 1),
                                                ("quad", 2)])
def test_edges_only_near_cell_boundaries_never_the_diagonal(ctx, mode, approach):
    g = make_grid(4, 3, 2, dip=(0.0, 0.0))
    view = GridView(g, property="PORO", approach=approach, size=SIZE, ctx=ctx)
    try:
        cam = view.camera(view="top", ortho=True)
        plain, _ = view.draw(cam, frames=1)
        view.update(edges=mode)
        lined, st = view.draw(cam, frames=1)
    finally:
        view.release()
    dist, inside, diag = _boundary_distance_px(view, cam, g)
    changed = np.abs(plain.astype(int) - lined.astype(int)).max(-1) > 0
    assert changed.sum() > 40
    assert (dist[changed] <= 1.5).all(), dist[changed].max()
    far = dist >= 2.0
    assert not changed[far].any()
    on_diag = inside & far & (diag < 0.7)
    assert on_diag.sum() > 20 and not changed[on_diag].any()
    assert st["edges"] == mode


def test_edges_fade_with_on_screen_cell_size(ctx):
    g = make_grid(40, 40, 1, dx=1.0, dy=1.0, dip=(0.0, 0.0))
    view = GridView(g, property="PORO", size=SIZE, ctx=ctx)
    try:
        cam = view.camera(view="top", ortho=True)
        plain, _ = view.draw(cam, frames=1)
        view.update(edges=True)
        faded, _ = view.draw(cam, frames=1)            # 1.6 px cells: below the fade
        lined, _ = view.draw(cam.zoomed(8.0), frames=1)  # 13 px cells: full lines
        view.update(edges=False)
        zoomed, _ = view.draw(cam.zoomed(8.0), frames=1)
    finally:
        view.release()
    assert np.array_equal(plain, faded)
    assert mismatch(lined, zoomed, tol=3) > 0.05


def test_bad_arguments_are_one_clear_line(ctx):
    g = make_grid(4, 3, 2, steps=2)
    with pytest.raises(InputError, match=r"unknown name 'NOPE'.*PORO"):
        GridView(g, property="NOPE", size=SIZE, ctx=ctx)
    with pytest.raises(InputError, match=r"step 5 does not exist.*2 steps"):
        GridView(g, property="SWAT", step=5, size=SIZE, ctx=ctx)
    with pytest.raises(InputError, match="NOPE"):
        GridView(g, filter="NOPE > 1", size=SIZE, ctx=ctx)
    with pytest.raises(InputError, match="faults"):
        GridView(g, faults="maybe", size=SIZE, ctx=ctx)
    with pytest.raises(InputError, match="exaggeration"):
        GridView(g, exaggeration=0, size=SIZE, ctx=ctx)
    for bad in ("i=3:1", "x=1:2", "i=1:2,i=3", "i=0:9", "k", "i=a:b"):
        with pytest.raises(InputError, match="slice"):
            parse_slice(bad, g.dims)
    for bad in ("1,2,3", "0,0,0,1", "a,b,c,d"):
        with pytest.raises(InputError, match="clip"):
            plane_from_clip(bad, g)


@pytest.mark.parametrize("ortho", [False, True])
def test_framing_shows_the_whole_grid_and_keeps_it_between_near_and_far(ctx, ortho):
    from geoshade.grid import frame_points, world_bounds

    g = make_grid(10, 6, 3, dx=100, dy=100, dz=2, mapaxes=(0, 1, 0, 0, 1, 0.5))
    view = GridView(g, property="PORO", size=(96, 64), ctx=ctx, exaggeration=4)
    try:
        for az, el in [(30, 35), (200, 10), (90, 80), (0, -40)]:
            cam = view.camera(azimuth=az, elevation=el, ortho=ortho).with_aspect(1.5)
            b = world_bounds(g, 4)
            corners = np.array([[b[i, 0], b[j, 1], b[k, 2], 1.0] for i in (0, 1)
                                for j in (0, 1) for k in (0, 1)])
            p = corners @ (cam.projection_matrix() @ cam.view_matrix()).T
            assert np.all(np.abs(p[:, 2] / p[:, 3]) < 1)          # inside near .. far
            q = np.c_[frame_points(g, 4), np.ones(8)] @ (
                cam.projection_matrix() @ cam.view_matrix()).T
            ext = np.abs(q[:, :2] / q[:, 3:]).max()
            assert 0.85 < ext <= 1.0, (az, el, ext)                # the grid fills the view
            img, _ = view.draw(cam, frames=1, transparent=True)
            alpha = img[..., 3] > 0
            assert alpha[1:-1, 1:-1].any() and not alpha[[0, -1]].all()
    finally:
        view.release()


def test_a_bad_change_leaves_the_view_as_it_was(ctx):
    g = make_grid(4, 3, 2)
    view = GridView(g, property="PORO", filter="PORO > 0.1", size=SIZE, ctx=ctx)
    try:
        img0, _ = view.draw(frames=1)
        with pytest.raises(InputError, match="NOPE"):
            view.update(filter="NOPE > 1")
        with pytest.raises(InputError, match="range"):
            view.update(property="PERMX", color_range=(5, 1))
        img1, st1 = view.draw(frames=1)
        assert np.array_equal(img0, img1)
        assert (st1["filter"], st1["property"]) == ("PORO > 0.1", "PORO")
    finally:
        view.release()


def test_faces_prepared_on_a_thread_equal_set_filter(ctx):
    """prepare_faces (CPU, worker thread) + apply_faces (GL) = set_filter/set_slice."""
    from concurrent.futures import ThreadPoolExecutor

    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.grid import GridView

    g = synthetic_grid(12, 10, 4, faults=True, seed=5)
    a = GridView(g, property="PORO", size=(48, 40), ctx=ctx)
    b = GridView(g, property="PORO", size=(48, 40), ctx=ctx)
    try:
        with ThreadPoolExecutor(1) as pool:
            prep = pool.submit(a.prepare_faces, filter="PORO > 0.2",
                               slice=(slice(2, 9), slice(None), slice(None))).result()
        assert a.options.filter is None  # nothing changes before apply
        a.apply_faces(prep)
        b.update(filter="PORO > 0.2")
        b.update(slice="i=2:9")
        img_a, st_a = a.draw(frames=1)
        img_b, st_b = b.draw(frames=1)
        assert st_a["faces_drawn"] == st_b["faces_drawn"] > 0
        assert np.array_equal(img_a, img_b)
    finally:
        a.release()
        b.release()


def test_a_new_step_does_not_recolour_a_static_property(ctx, monkeypatch):
    from tests.gl.test_views_common import model_of

    g = model_of("grid")
    with geoshade.view(g, property="PORO", step=0, size=(64, 48), ctx=ctx) as v:
        img0, _ = v.draw()
        calls = []
        monkeypatch.setattr(v.visual, "set_colors", lambda ci, cells=None: calls.append(ci))
        v.update(step=2)
        img2, st = v.draw()
        assert calls == [] and st["step"] == 2
        np.testing.assert_array_equal(img0, img2)
        v.update(property="SWAT")
        assert len(calls) == 1
