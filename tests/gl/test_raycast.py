"""The exact voxel ray caster (``raycast`` method) against exact oracles and the cubes method."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.bitmaps import (
    SelectionMaps,
    brick_occupancy,
    gpu_bytes_breakdown,
    pack_bits,
    patch_bitmap,
    patch_grid,
)
from geoshade.render.camera import Camera
from geoshade.render.target import Offscreen

pytestmark = pytest.mark.gl

_L = np.array([0.3, 0.5, 0.81])
#: directional light in view space; Phong with specular (colour varies within a face)
SHADING = {"light_dir": tuple(_L / np.linalg.norm(_L)), "material": (0.3, 0.7, 0.25, 16.0)}
#: no specular term: every face of one orientation has one colour
FLAT = {"light_dir": SHADING["light_dir"], "material": (0.3, 0.7, 0.0, 1.0)}
TRANSPARENT = (0.0, 0.0, 0.0, 0.0)


def make_maps(sel: np.ndarray, color: np.ndarray | None = None) -> SelectionMaps:
    """SelectionMaps of a bool ``(nz, ny, nx)`` mask with the given colour indices."""
    nz, ny, nx = sel.shape
    if color is None:
        color = np.full(sel.shape, 200, np.uint8)
    return SelectionMaps(
        bits=pack_bits(sel), patch_bits=pack_bits(patch_bitmap(sel)),
        patch_shape=patch_grid(nx, ny, nz), bricks=brick_occupancy(sel),
        color=np.ascontiguousarray(color, np.uint8), count=int(sel.sum()), shape_xyz=(nx, ny, nz))


def random_palette(rng) -> np.ndarray:
    pal = rng.integers(0, 256, (256, 4)).astype(np.uint8)
    pal[:, 3] = 255
    return pal


def grey_palette() -> np.ndarray:
    pal = np.full((256, 4), 255, np.uint8)
    pal[:, :3] = np.arange(256, dtype=np.uint8)[:, None]
    return pal


def bounds(model: np.ndarray, shape_xyz) -> np.ndarray:
    """World (2, 3) bounds of the box [0, n] under ``model``."""
    n = np.asarray(shape_xyz, float)
    c = np.array([[i, j, k, 1.0] for i in (0, n[0]) for j in (0, n[1]) for k in (0, n[2])])
    w = (model @ c.T).T[:, :3]
    return np.array([w.min(axis=0), w.max(axis=0)])


def render(ctx, visuals, camera, model, size, shading=SHADING, count=False):
    """Draw ``visuals`` in order into a fresh target: (rgba, depth, stats of the first)."""
    target = Offscreen(ctx, size)
    try:
        target.clear(TRANSPARENT)
        stats = [v.draw(camera, model, shading, count=count) for v in visuals]
        ctx.finish()
        w, h = size
        depth = np.frombuffer(target.depth.read(), np.float32).reshape(h, w)[::-1].copy()
        return target.read(), depth, stats[0]
    finally:
        target.release()


def mismatch(a: np.ndarray, b: np.ndarray, tol: int = 3) -> np.ndarray:
    """(h, w) bool: coverage differs, or a colour channel differs by more than ``tol``."""
    cov = (a[..., 3] == 255) != (b[..., 3] == 255)
    col = np.abs(a[..., :3].astype(int) - b[..., :3].astype(int)).max(axis=-1) > tol
    return cov | ((a[..., 3] == 255) & col)


def pixel_index_xy(camera, model, size) -> np.ndarray:
    """(h, w, 2) index-space (x, y) of each pixel centre (row 0 at the top) of an ortho camera."""
    w, h = size
    i, j = np.meshgrid(np.arange(w), np.arange(h))
    ndc = np.stack([(i + 0.5) / w * 2 - 1, 1 - (j + 0.5) / h * 2, np.zeros_like(i, float),
                    np.ones_like(i, float)], axis=-1)
    inv = np.linalg.inv(model) @ np.linalg.inv(camera.projection_matrix() @ camera.view_matrix())
    p = ndc @ inv.T
    return p[..., :2] / p[..., 3:]


@pytest.fixture(scope="module")
def raycast_cls(ctx):
    from geoshade.render.visuals.raycast.visual import RaycastVisual

    return RaycastVisual


@pytest.fixture(scope="module")
def cubes_cls(ctx):
    from geoshade.render.visuals.voxels.visual import VoxelVisual

    return lambda c, maps, pal: VoxelVisual(c, maps, pal, method="cubes", cull=False)


# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("azimuth", [45, 135, 225, 315])
@pytest.mark.parametrize("elevation", [35, -35])
def test_one_voxel_shows_three_face_shades(ctx, raycast_cls, azimuth, elevation):
    sel = np.zeros((3, 3, 3), bool)
    sel[1, 1, 1] = True
    vis = raycast_cls(ctx, make_maps(sel), grey_palette())
    try:
        model = np.eye(4)
        cam = Camera.framed(bounds(model, (3, 3, 3)), azimuth=azimuth, elevation=elevation)
        img, _, stats = render(ctx, [vis], cam, model, (64, 64), shading=FLAT)
    finally:
        vis.release()
    assert stats == {}
    opaque = img[img[..., 3] == 255]
    assert len(opaque) > 100
    assert len(np.unique(opaque[:, :3], axis=0)) == 3


@pytest.mark.parametrize("view", ["top", "bottom"])
def test_orthographic_coverage_equals_selected_columns(ctx, raycast_cls, view):
    rng = np.random.default_rng(1)
    nx, ny, nz, k = 21, 13, 9, 4
    sel = rng.random((nz, ny, nx)) < 0.08
    model = np.array([[1.5, 0, 0, 10.0], [0, 1.5, 0, -4.0], [0, 0, 2.0, 1.0], [0, 0, 0, 1]])
    size = (nx * k, ny * k)
    cam = Camera.framed(bounds(model, (nx, ny, nz)), view, ortho=True, aspect=nx / ny)
    vis = raycast_cls(ctx, make_maps(sel), grey_palette())
    try:
        img, _, _ = render(ctx, [vis], cam, model, size)
    finally:
        vis.release()
    xy = pixel_index_xy(cam, model, size)
    inside = (xy[..., 0] > 0) & (xy[..., 0] < nx) & (xy[..., 1] > 0) & (xy[..., 1] < ny)
    col = np.clip(np.floor(xy).astype(int), 0, [nx - 1, ny - 1])
    expect = inside & sel.any(axis=0)[col[..., 1], col[..., 0]]
    frac = np.abs(xy - np.round(xy))
    clear = (frac > 0.01).all(axis=-1)
    assert clear.mean() > 0.9
    got = img[..., 3] == 255
    assert expect[clear].sum() > 100
    np.testing.assert_array_equal(got[clear], expect[clear])


def _inside_camera(shape_xyz, fovy=60.0):
    c = np.asarray(shape_xyz, float) / 2 + 0.3
    cam = Camera(target=c, distance=4.0, azimuth=30.0, elevation=20.0, fovy=fovy,
                 radius=float(np.linalg.norm(shape_xyz)) / 2)
    return cam


@pytest.mark.parametrize("where", ["iso", "inside", "mirrored", "ortho"])
def test_matches_cubes_colour_and_depth(ctx, raycast_cls, cubes_cls, where):
    rng = np.random.default_rng(2)
    n = 24
    sel = rng.random((n, n, n)) < 0.3
    color = rng.integers(0, 256, sel.shape).astype(np.uint8)
    model = np.eye(4)
    if where == "inside":
        cam = _inside_camera((n, n, n))
        ex, ey, ez = np.floor(cam.eye).astype(int)
        assert all(0 < e < n - 1 for e in (ex, ey, ez)), "the eye must be inside the box"
        sel[ez - 1:ez + 2, ey - 1:ey + 2, ex - 1:ex + 2] = False
    else:
        if where == "mirrored":
            model = np.diag([-1.0, 1.0, 1.0, 1.0])
            model[0, 3] = 5.0
        cam = Camera.framed(bounds(model, (n, n, n)), "iso", azimuth=60, elevation=25,
                            ortho=where == "ortho")
    maps, pal = make_maps(sel, color), random_palette(rng)
    ray, cube = raycast_cls(ctx, maps, pal), cubes_cls(ctx, maps, pal)
    try:
        a, da, _ = render(ctx, [ray], cam, model, (128, 128))
        b, db, _ = render(ctx, [cube], cam, model, (128, 128))
    finally:
        ray.release()
        cube.release()
    bad = mismatch(a, b)
    assert (b[..., 3] == 255).mean() > 0.3
    assert bad.mean() <= 0.005, f"{bad.sum()} of {bad.size} pixels differ"
    both = (a[..., 3] == 255) & (b[..., 3] == 255) & ~bad
    assert np.abs(da[both] - db[both]).max() <= 1e-4
    assert (da[a[..., 3] != 255] == 1.0).all()


def test_near_plane_cut_voxel_shows_its_far_faces_like_cubes(ctx, raycast_cls, cubes_cls):
    n = 12
    cam = _inside_camera((n, n, n), fovy=40.0)
    ex, ey, ez = np.floor(cam.eye).astype(int)
    sel = np.zeros((n, n, n), bool)
    sel[ez, ey, ex] = True
    maps, pal = make_maps(sel), grey_palette()
    ray, cube = raycast_cls(ctx, maps, pal), cubes_cls(ctx, maps, pal)
    try:
        a, _, stats = render(ctx, [ray], cam, np.eye(4), (64, 64), count=True)
        b, _, _ = render(ctx, [cube], cam, np.eye(4), (64, 64))
    finally:
        ray.release()
        cube.release()
    assert (a[..., 3] == 255).all()
    assert stats["voxels_drawn"] == 1
    assert mismatch(a, b).mean() <= 0.005


def test_depth_composes_with_other_geometry(ctx, raycast_cls, cubes_cls):
    rng = np.random.default_rng(3)
    n = 20
    both = rng.random((n, n, n)) < 0.25
    part = rng.random((n, n, n)) < 0.5
    color = rng.integers(0, 256, both.shape).astype(np.uint8)
    pal = random_palette(rng)
    cam = Camera.framed(bounds(np.eye(4), (n, n, n)), "iso")
    ray = raycast_cls(ctx, make_maps(both & part, color), pal)
    other = cubes_cls(ctx, make_maps(both & ~part, color), pal)
    union = cubes_cls(ctx, make_maps(both, color), pal)
    try:
        a, _, _ = render(ctx, [ray, other], cam, np.eye(4), (128, 128))
        a2, _, _ = render(ctx, [other, ray], cam, np.eye(4), (128, 128))
        b, _, _ = render(ctx, [union], cam, np.eye(4), (128, 128))
    finally:
        for v in (ray, other, union):
            v.release()
    assert mismatch(a, b).mean() <= 0.005
    assert mismatch(a2, b).mean() <= 0.005


def test_brick_skipping_does_not_change_the_picture(ctx, raycast_cls):
    rng = np.random.default_rng(4)
    n = 32
    sel = np.zeros((n, n, n), bool)
    for z, y, x in rng.integers(0, n - 4, (12, 3)):
        sel[z:z + 4, y:y + 4, x:x + 4] = rng.random((4, 4, 4)) < 0.5
    maps = make_maps(sel, rng.integers(0, 256, sel.shape).astype(np.uint8))
    assert 0 < maps.bricks.mean() < 0.7
    cam = Camera.framed(bounds(np.eye(4), (n, n, n)), "iso", azimuth=20)
    vis = raycast_cls(ctx, maps, random_palette(rng))
    try:
        a, _, sa = render(ctx, [vis], cam, np.eye(4), (128, 128), count=True)
        vis.brick_skip = False
        b, _, sb = render(ctx, [vis], cam, np.eye(4), (128, 128), count=True)
    finally:
        vis.release()
    assert (a[..., 3] == 255).sum() > 300
    assert mismatch(a, b, tol=0).mean() <= 0.001
    assert abs(sa["voxels_drawn"] - sb["voxels_drawn"]) <= 2


@pytest.mark.parametrize("where", ["iso", "back", "ortho", "inside"])
def test_skip_map_jumps_do_not_change_the_picture(ctx, raycast_cls, cubes_cls, where):
    """Sparse clusters far apart: jumps over many bricks, 4³ and 2³ blocks, and single voxels;
    the picture equals the walk with skipping off (voxel by voxel) and the cubes method."""
    from geoshade.compute.voxels.skipmap import skip_map

    rng = np.random.default_rng(11)
    n = 96
    sel = np.zeros((n, n, n), bool)
    for z, y, x in rng.integers(0, n - 6, (16, 3)):
        sel[z:z + 6, y:y + 6, x:x + 6] |= rng.random((6, 6, 6)) < 0.15
    skip = skip_map(pack_bits(sel), n)
    occupied = (skip[..., :2] != 0).any(axis=-1)
    assert skip[..., 2].max() >= 4 and 0.01 < occupied.mean() < 0.1
    if where == "inside":
        cam = _inside_camera((n, n, n))
        ex, ey, ez = np.floor(cam.eye).astype(int)
        sel[ez - 1:ez + 2, ey - 1:ey + 2, ex - 1:ex + 2] = False
    else:
        cam = Camera.framed(bounds(np.eye(4), (n, n, n)), "iso",
                            azimuth=200 if where == "back" else 35, elevation=-30 if
                            where == "back" else 25, ortho=where == "ortho")
    maps, pal = make_maps(sel, rng.integers(0, 256, sel.shape).astype(np.uint8)), \
        random_palette(rng)
    vis, cube = raycast_cls(ctx, maps, pal), cubes_cls(ctx, maps, pal)
    try:
        a, da, sa = render(ctx, [vis], cam, np.eye(4), (160, 160), count=True)
        vis.brick_skip = False
        b, db, sb = render(ctx, [vis], cam, np.eye(4), (160, 160), count=True)
        c, _, _ = render(ctx, [cube], cam, np.eye(4), (160, 160))
    finally:
        vis.release()
        cube.release()
    assert (a[..., 3] == 255).sum() > 300
    assert mismatch(a, b, tol=0).mean() <= 0.001
    np.testing.assert_allclose(da, db, atol=1e-6)
    assert abs(sa["voxels_drawn"] - sb["voxels_drawn"]) <= 2
    assert mismatch(a, c).mean() <= 0.005


def test_voxels_drawn_counts_top_voxels_of_columns(ctx, raycast_cls):
    rng = np.random.default_rng(5)
    nx, ny, nz, k = 20, 16, 12, 3
    sel = rng.random((nz, ny, nx)) < 0.05
    model = np.eye(4)
    size = (nx * k, ny * k)
    cam = Camera.framed(bounds(model, (nx, ny, nz)), "top", ortho=True, aspect=nx / ny)
    vis = raycast_cls(ctx, make_maps(sel), grey_palette())
    try:
        before = vis.gpu_bytes
        img, _, stats = render(ctx, [vis], cam, model, size, count=True)
        _, _, again = render(ctx, [vis], cam, model, size, count=True)
        _, _, none = render(ctx, [vis], cam, model, size)
        assert vis.gpu_bytes == before
    finally:
        vis.release()
    # numpy reference: the columns that hold a pixel centre and a selected voxel
    xy = pixel_index_xy(cam, model, size)
    inside = (xy[..., 0] > 0) & (xy[..., 0] < nx) & (xy[..., 1] > 0) & (xy[..., 1] < ny)
    cols = np.floor(xy[inside]).astype(int)
    hit = np.zeros((ny, nx), bool)
    hit[cols[:, 1], cols[:, 0]] = True
    assert hit.all(), "every column must hold a pixel centre"
    expect = int((hit & sel.any(axis=0)).sum())
    assert stats == {"voxels_drawn": expect, "triangles": 0}
    assert again == stats
    assert none == {}
    assert (img[..., 3] == 255).any()


def test_gpu_bytes_are_the_texture_sizes(ctx, raycast_cls):
    rng = np.random.default_rng(6)
    n = 64
    sel = rng.random((n, n, n)) < 0.4
    vis = raycast_cls(ctx, make_maps(sel), grey_palette())
    try:
        expect = gpu_bytes_breakdown((n, n, n), "raycast")
        assert vis.cache.breakdown() == {
            "palette": expect["palette"], "voxel_bits": expect["bits"],
            "color_index": expect["color"], "bricks": expect["bricks"]}
        assert vis.gpu_bytes == sum(expect.values())
        assert vis.gpu_bytes <= 1.2 * n**3
        # a new box of another size: textures replaced, program kept
        prog = vis.prog
        small = np.zeros((5, 7, 40), bool)
        small[2, 3, 33] = True
        vis.upload(make_maps(small))
        assert vis.prog is prog
        assert vis.gpu_bytes == sum(gpu_bytes_breakdown((40, 7, 5), "raycast").values())
        cam = Camera.framed(bounds(np.eye(4), (40, 7, 5)), "top", ortho=True, aspect=40 / 7)
        _, _, stats = render(ctx, [vis], cam, np.eye(4), (80, 14), count=True)
        assert stats["voxels_drawn"] == 1
    finally:
        vis.release()


def test_rejects_maps_of_the_wrong_shape(ctx, raycast_cls):
    from geoshade.errors import InputError

    sel = np.zeros((8, 8, 8), bool)
    maps = make_maps(sel)
    maps.bits = np.zeros((8, 8, 2), np.uint32)
    with pytest.raises(InputError, match=r"maps\.bits"):
        raycast_cls(ctx, maps, grey_palette())
