"""Terrain from a DEM, drawn as terrain: the smooth top's heights and normals equal a numpy
oracle (bilinear heights between column centres, bilinear central-difference gradients), the
shading correlates with matplotlib's hillshade of the DEM where the flat tops do not; and the
stats say ``drape`` only when the picture shows the drape."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio", reason="the geo extra (rasterio) is not installed")
from affine import Affine  # noqa: E402

from geoshade.models.stacks import Legend  # noqa: E402
from geoshade.stacks.terrain import from_surfaces  # noqa: E402

SIZE = (200, 160)
DX = 20.0
EXAG = 4.0


def hills(nx=40, ny=30) -> np.ndarray:
    """(ny, nx) heights, row 0 **south** (the model's order), smooth."""
    y, x = np.mgrid[0:ny, 0:nx].astype(np.float64)
    return 30 + 12 * np.exp(-((x - 13) ** 2 + (y - 11) ** 2) / 70) \
        + 7 * np.sin(x / 6.0) * np.cos(y / 8.0) + 0.2 * y


def white(model):
    """The model in white, coloured by material (not by elevation): the shading alone."""
    lg = model.legend
    rgba = np.full_like(lg.rgba, 255)
    return dataclasses.replace(model, legend=Legend(lg.codes, lg.names, rgba),
                               meta={**model.meta, "color_by": "material"})


@pytest.fixture(scope="module")
def terrain():
    return white(from_surfaces([hills()], spacing=(DX, DX), origin=(1000.0, 2000.0)))


def pixel_index_xy(view, cam):
    w, h = view.size
    i, j = np.meshgrid(np.arange(w), np.arange(h))
    ndc = np.stack([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2, np.zeros_like(i, float),
                    np.ones_like(i, float)], axis=-1)
    inv = np.linalg.inv(view.model_matrix()) @ np.linalg.inv(
        cam.projection_matrix() @ cam.view_matrix())
    p = ndc @ inv.T
    return p[..., :2] / p[..., 3:]


def bilinear(field, xy):
    """``field`` ((ny, nx, ...) at column centres) at index-space points xy, edges clamped."""
    ny, nx = field.shape[:2]
    q = xy - 0.5
    i0 = np.floor(q).astype(int)
    f = q - i0
    ix0, iy0 = np.clip(i0[..., 0], 0, nx - 1), np.clip(i0[..., 1], 0, ny - 1)
    ix1, iy1 = np.clip(i0[..., 0] + 1, 0, nx - 1), np.clip(i0[..., 1] + 1, 0, ny - 1)
    fx, fy = f[..., 0], f[..., 1]
    if field.ndim == 3:
        fx, fy = fx[..., None], fy[..., None]
    return ((1 - fy) * ((1 - fx) * field[iy0, ix0] + fx * field[iy0, ix1])
            + fy * ((1 - fx) * field[iy1, ix0] + fx * field[iy1, ix1]))


def gpu_tops(model) -> np.ndarray:
    """The column tops (levels) as the fp16 layouts hold them, (ny, nx)."""
    nx, ny = model.shape
    return model.column_tops().astype(np.float16).astype(np.float64).reshape(ny, nx)


def render_top(model, **kw):
    import geoshade.stacks as st

    view = st.StacksView(model, size=SIZE, exaggeration=EXAG, smooth=0, annotations=False, **kw)
    try:
        cam = view.camera(view="top", ortho=True)
        img, stats = view.draw(cam, frames=1, transparent=True)
        _, depth = view.visual.read_gbuffer()
        xy = pixel_index_xy(view, cam)
        m = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix() @ view.model_matrix())
    finally:
        view.release()
    w, h = SIZE
    i, j = np.meshgrid(np.arange(w), np.arange(h))
    ndc = np.stack([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2, depth * 2 - 1,
                    np.ones_like(depth)], axis=-1)
    p = ndc @ m.T
    z = p[..., 2] / p[..., 3]                                    # index space: levels
    return img, stats, xy, z, cam


def shading_oracle(model, xy, cam):
    """255 × the Lambert light of the interpolated gradient normal at each pixel."""
    from geoshade.styles.shading import shading_uniforms

    t = gpu_tops(model)
    gy, gx = np.gradient(t)                                      # levels per column
    g = bilinear(np.stack([gx, gy], axis=-1), xy)
    dx, dy, dz = model.spacing
    n = np.stack([-g[..., 0] / dx, -g[..., 1] / dy,
                  np.full(g.shape[:2], 1.0 / (dz * EXAG))], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    nv = n @ cam.view_matrix()[:3, :3].T
    sh = shading_uniforms()
    light = np.asarray(sh["light_dir"]) / np.linalg.norm(sh["light_dir"])
    amb, dif = sh["material"][:2]
    return 255 * np.clip(amb + dif * np.clip(nv @ light, 0, None), 0, 1)


def inside(xy, shape, margin=0.0):
    nx, ny = shape
    return ((xy[..., 0] > margin) & (xy[..., 0] < nx - margin) & (xy[..., 1] > margin)
            & (xy[..., 1] < ny - margin))


def test_smooth_top_heights_are_the_bilinear_dem(ctx, terrain):
    img, stats, xy, z, _ = render_top(terrain, lighting=False)
    assert stats["top"] == "smooth"                  # a model from a DEM: smooth by default
    ok = inside(xy, terrain.shape, 0.01) & (img[..., 3] == 255)
    assert ok.mean() > 0.5
    expect = bilinear(gpu_tops(terrain), xy)
    err = np.abs(z - expect)[ok]
    assert err.max() < 0.02, err.max()               # levels (1 level = 1 m; relief 30 m)


def test_smooth_top_normals_are_the_dem_gradient_normals(ctx, terrain):
    img, _, xy, _, cam = render_top(terrain)
    ok = inside(xy, terrain.shape, 0.01) & (img[..., 3] == 255)
    expect = shading_oracle(terrain, xy, cam)
    diff = np.abs(img[..., 0].astype(float) - expect)[ok]
    assert diff.max() <= 2.0, diff.max()             # fp16 normals, 8-bit colours


def _cell_means(img, xy, shape):
    nx, ny = shape
    ok = inside(xy, shape, 0.0) & (img[..., 3] == 255)
    col = np.floor(xy[ok]).astype(int)
    idx = np.clip(col[:, 1], 0, ny - 1) * nx + np.clip(col[:, 0], 0, nx - 1)
    s = np.bincount(idx, img[..., 0][ok].astype(float), nx * ny)
    n = np.bincount(idx, minlength=nx * ny)
    return (s / np.maximum(n, 1)).reshape(ny, nx), n.reshape(ny, nx) > 0


def test_terrain_looks_like_the_hillshade_and_flat_tops_do_not(ctx, terrain, tmp_path):
    from matplotlib.colors import LightSource

    from geoshade.styles.shading import shading_uniforms

    smooth, _, xy, _, cam = render_top(terrain)
    flat, st_flat, _, _, _ = render_top(terrain, top="flat")
    assert st_flat["top"] == "flat"
    # the renderer's light in world coordinates -> matplotlib's azimuth and altitude
    lw = cam.view_matrix()[:3, :3].T @ np.asarray(shading_uniforms()["light_dir"])
    lw /= np.linalg.norm(lw)
    az = 90 - np.degrees(np.arctan2(lw[1], lw[0]))
    alt = np.degrees(np.arcsin(lw[2]))
    heights = gpu_tops(terrain) * terrain.spacing[2]
    hs = LightSource(azdeg=az, altdeg=alt).hillshade(heights[::-1], vert_exag=EXAG, dx=DX,
                                                     dy=DX)[::-1]
    a, seen = _cell_means(smooth, xy, terrain.shape)
    b, _ = _cell_means(flat, xy, terrain.shape)
    inner = seen.copy()
    inner[[0, -1]] = False
    inner[:, [0, -1]] = False
    r_smooth = np.corrcoef(a[inner], hs[inner])[0, 1]
    r_flat = np.corrcoef(b[inner], hs[inner])[0, 1]
    assert r_smooth > 0.999, r_smooth                # measured 0.99989 (flat: 0.964)
    assert r_flat < 0.98, r_flat
    # stair steps: the flat tops jump at column boundaries, the smooth top does not
    jump = np.abs(np.diff(smooth[..., 0].astype(float), axis=1))
    jump_flat = np.abs(np.diff(flat[..., 0].astype(float), axis=1))
    both = (smooth[..., 3] == 255)[:, 1:] & (smooth[..., 3] == 255)[:, :-1]
    assert np.percentile(jump[both], 99) <= 3 < np.percentile(jump_flat[both], 99)


def test_hybrid_normals_of_the_smooth_depth_are_kept_as_an_option(ctx, terrain):
    img, _, xy, _, cam = render_top(terrain, top_normals=False)
    ok = inside(xy, terrain.shape, 0.01) & (img[..., 3] == 255)
    expect = shading_oracle(terrain, xy, cam)
    r = np.corrcoef(img[..., 0][ok].astype(float), expect[ok])[0, 1]
    assert 0.5 < r < 0.999                            # the paper's quantised normals: close


# --- drapes ------------------------------------------------------------------------------------
def write_ortho(path, model, x_from=0.0, x_to=1.0):
    """An RGB GeoTIFF of half-column pixels over the part [x_from, x_to] of the model's width,
    west half red, east half blue."""
    nx, ny = model.shape
    x0, y0 = model.origin[:2]
    c0, c1 = round(x_from * nx * 2), round(x_to * nx * 2)
    img = np.zeros((3, ny * 2, nx * 2), np.uint8)
    img[0, :, :nx] = 255
    img[2, :, nx:] = 255
    img = img[:, :, c0:c1]
    with rasterio.open(path, "w", driver="GTiff", width=img.shape[2], height=img.shape[1],
                       count=3, dtype="uint8", crs="EPSG:28992",
                       transform=Affine(DX / 2, 0, x0 + c0 * DX / 2, 0, -DX / 2,
                                        y0 + ny * DX)) as dst:
        dst.write(img)
    return path


@pytest.fixture(scope="module")
def layered():
    top = hills()
    return dataclasses.replace(
        from_surfaces([top, top - 4.0], base=float(top.min()) - 10.0, spacing=(DX, DX),
                      origin=(1000.0, 2000.0)), crs="EPSG:28992")


def test_drape_stats_count_the_pixels_that_show_it(ctx, layered, tmp_path):
    full = write_ortho(tmp_path / "full.tif", layered)
    img, st, xy, _, _ = render_top(layered, drape=full, lighting=False)
    covered = img[..., 3] == 255
    assert st["drape"] and st["drape_pixels"] == covered.sum() and st["drape_covered"] == 1.0
    nx = layered.shape[0]
    west = covered & (xy[..., 0] < nx / 2 - 0.5)
    east = covered & (xy[..., 0] > nx / 2 + 0.5)
    assert (img[west][:, :3] == [255, 0, 0]).all() and (img[east][:, :3] == [0, 0, 255]).all()

    part = write_ortho(tmp_path / "east.tif", layered, 0.6, 1.0)
    with pytest.warns(UserWarning, match=r"covers 40\.0 %"):
        img, st, xy, _, _ = render_top(layered, drape=part, lighting=False)
    covered = img[..., 3] == 255
    surely_in = covered & (xy[..., 0] > 0.6 * nx + 0.5)
    maybe_in = covered & (xy[..., 0] > 0.6 * nx - 0.5)
    assert surely_in.sum() <= st["drape_pixels"] <= maybe_in.sum()
    assert st["drape_covered"] == pytest.approx(0.4)
    # the top unit hidden, the drape at 0, or the model seen from below: no drape shows
    for kw in ({"hide": [1]}, {"drape_mix": 0.0}):
        img, st, *_ = render_top(layered, drape=full, lighting=False, **kw)
        assert (img[..., 3] == 255).any()
        assert st["drape"] is False and st["drape_pixels"] == 0, kw
    import geoshade.stacks as st_api

    with st_api.StacksView(layered, size=SIZE, drape=full, annotations=False) as view:
        img, st = view.draw(view.camera(view="bottom"), frames=1)
        assert (img[..., :3] != img[0, 0, :3]).any(axis=-1).any()
        assert st["drape"] is False


def test_flat_top_keeps_the_paper_picture(ctx):
    """A voxel model (not from a DEM) keeps its flat tops unless asked: the five layouts and the
    old pictures are unchanged."""
    import geoshade.stacks as st
    from geoshade.compute.stacks import synthetic_layers

    m = synthetic_layers(12, 10, 16, seed=1)
    a, sa = st.render(m, size=(64, 48), frames=1, annotations=False)
    b, sb = st.render(m, size=(64, 48), frames=1, annotations=False, top="flat")
    c, sc = st.render(m, size=(64, 48), frames=1, annotations=False, top="smooth")
    assert sa["top"] == sb["top"] == "flat" and sc["top"] == "smooth"
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_pick_meets_the_smooth_top_where_the_picture_shows_it(ctx, terrain):
    import geoshade.stacks as st

    with st.StacksView(terrain, size=SIZE, exaggeration=EXAG, annotations=False) as view:
        for name in ("top", "iso"):
            cam = view.camera(view=name, ortho=name == "top")
            view.draw(cam, frames=1)
            _, depth = view.visual.read_gbuffer()
            inv = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix())
            w, h = SIZE
            hits = 0
            for px, py in ((100, 80), (85, 70), (115, 90), (90, 95), (110, 65)):
                d = depth[py, px]
                if d >= 1.0:
                    continue
                ndc = np.array([(px + 0.5) / w * 2 - 1, 1 - (py + 0.5) / h * 2, 2 * d - 1, 1])
                p = inv @ ndc
                p = p[:3] / p[3]                                    # display world
                pk = view.pick(px, py, camera=cam)
                assert pk is not None, (name, px, py)
                z = p[2] / EXAG                                      # model z
                assert abs(pk.world[2] - z) < 0.05, (name, px, py, pk.world, z)
                assert np.allclose(pk.world[:2], p[:2], atol=0.05 * DX)
                hits += 1
            assert hits == 5
