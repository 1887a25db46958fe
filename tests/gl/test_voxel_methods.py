"""The four voxel methods draw the same picture; GPU counts equal numpy counts."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.bitmaps import build_selection_maps, gpu_bytes_estimate
from geoshade.compute.voxels.visibility import visible_mask
from geoshade.core import CoreView, model_matrix
from geoshade.errors import EmptySceneWarning as EmptySelectionWarning
from geoshade.errors import GPUMemoryError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.render.camera import Camera
from geoshade.render.target import Offscreen
from geoshade.render.visuals.voxels.visual import VoxelVisual

RASTER = ("trefoil", "gs", "cubes")


def random_volume(shape_zyx, fraction, seed=0) -> VoxelVolume:
    """uint8 values: selected voxels (range 100..255) have random values, i.e. random colours."""
    rng = np.random.default_rng(seed)
    sel = rng.random(shape_zyx) < fraction
    data = np.where(sel, rng.integers(100, 256, shape_zyx), rng.integers(0, 100, shape_zyx))
    return VoxelVolume(data.astype(np.uint8), name="random")


def random_palette(seed=1):
    rng = np.random.default_rng(seed)
    pal = rng.integers(0, 256, (256, 4), dtype=np.uint8)
    pal[:, 3] = 255
    return pal


def draw(ctx, view: CoreView, camera, method):
    view.update(method=method)
    return view.draw(camera, transparent=True, frames=1)


def mismatch(a, b, tol=3):
    """Fraction of pixels whose RGBA differ by more than ``tol``."""
    d = np.abs(a.astype(int) - b.astype(int)).max(axis=-1)
    return float((d > tol).mean())


@pytest.mark.parametrize("mode", ["eye", "paper"])
def test_eight_trefoil_variants(ctx, shading, mode):
    """One voxel seen from the eight octants shows exactly its three camera-facing faces."""
    data = np.zeros((3, 3, 3), np.uint8)
    data[1, 1, 1] = 200
    maps = build_selection_maps(data, Box((0, 0, 0), (3, 3, 3)), 100, 255, 0, 255)
    pal = np.full((256, 4), 200, np.uint8)
    bounds = np.array([[0, 0, 0], [3, 3, 3]], float)
    target = Offscreen(ctx, (96, 96))
    tref = VoxelVisual(ctx, maps, pal, method="trefoil", trefoil_mode=mode)
    cube = VoxelVisual(ctx, maps, pal, method="cubes", cull=False)
    variants = set()
    try:
        for az in (45, 135, 225, 315):
            for el in (35, -35):
                cam = Camera.framed(bounds, azimuth=az, elevation=el, ortho=(mode == "paper"))
                target.clear((0, 0, 0, 0))
                counts = tref.draw(cam, np.eye(4), shading, count=True)
                img = target.read()
                target.clear((0, 0, 0, 0))
                cube.draw(cam, np.eye(4), shading)
                ref = target.read()
                assert counts == {"voxels_drawn": 1, "triangles": 6}
                opaque = img[..., 3] > 0
                shades = {tuple(p) for p in img[opaque][:, :3]}
                assert len(shades) == 3, (az, el, len(shades))
                assert np.array_equal(img, ref), (az, el)
                b = tuple(int(v >= 1.5) for v in cam.eye)
                variants.add(b[0] + 2 * b[1] + 4 * b[2])
    finally:
        tref.release()
        cube.release()
        target.release()
    assert variants == set(range(8))


def inside_camera() -> Camera:
    """An eye inside the 28×26×24 box, looking across it."""
    return Camera(target=np.array([20.0, 18.0, 16.0]), distance=4.0, azimuth=200,
                  elevation=20, fovy=60, aspect=160 / 120, radius=30.0)


@pytest.fixture(scope="module")
def agree_view(ctx):
    vol = random_volume((24, 26, 28), 0.35, seed=3)
    # the eye sits in an empty voxel (inside a selected one every method sees only that voxel)
    x, y, z = np.floor(inside_camera().eye).astype(int)
    vol.data[z, y, x] = 0
    v = CoreView(vol, select=(100, 255), size=(160, 120), palette=random_palette(), ctx=ctx,
                 method="cubes")
    yield v
    v.release()


@pytest.mark.parametrize("where", ["iso", "inside"])
def test_methods_draw_the_same_picture(ctx, agree_view, where):
    v = agree_view
    cam = v.camera(view="iso")
    if where == "inside":
        cam = inside_camera()
        assert np.all(cam.eye > 0) and np.all(cam.eye < [28, 26, 24])
    ref, _ = draw(ctx, v, cam, "cubes")
    assert (ref[..., 3] > 0).mean() > 0.2
    for method in ("trefoil", "gs"):
        img, _ = draw(ctx, v, cam, method)
        assert mismatch(img, ref) <= 1e-3, method
    img, _ = draw(ctx, v, cam, "raycast")
    assert mismatch(img, ref) <= 5e-3, "raycast"


@pytest.mark.parametrize("cull", [True, False])
def test_voxels_drawn_equals_numpy_over_many_batches(ctx, shading, cull):
    """130×140×12 box: 2×3×12 patches = 72 patch-quads, 5 instances on llvmpipe (> 65,536
    tessellated vertices per draw): a re-used batch would change the count."""
    vol = random_volume((12, 140, 130), 0.4, seed=5)
    sel = vol.data >= 100
    for method in ("trefoil", "gs"):
        v = CoreView(vol, select=(100, 255), size=(64, 64), ctx=ctx, method=method, cull=cull)
        try:
            cam = v.camera(view="iso")
            _, stats = v.draw(cam, frames=1)
            eye = (np.linalg.inv(model_matrix(vol, v.box)) @ np.append(cam.eye, 1))[:3]
            want = int(visible_mask(sel, eye_ijk=eye).sum()) if cull else int(sel.sum())
            assert stats["voxels_drawn"] == want, method
            assert stats["triangles"] == 6 * want
            assert stats["voxels_selected"] == int(sel.sum())
        finally:
            v.release()


@pytest.mark.parametrize("width", [65, 66, 67, 131])
def test_no_voxel_drawn_twice_when_a_patch_has_level_one(ctx, width):
    """A last patch one or two voxels wide gets inner level 1, which OpenGL treats as 2."""
    vol = random_volume((3, 20, width), 0.6, seed=width)
    v = CoreView(vol, select=(100, 255), size=(32, 32), ctx=ctx, method="trefoil", cull=False)
    try:
        _, stats = v.draw(frames=1)
        assert stats["voxels_drawn"] == int((vol.data >= 100).sum())
    finally:
        v.release()


def test_paper_trefoil_mode_counts(ctx):
    vol = random_volume((20, 30, 40), 0.5, seed=6)
    sel = vol.data >= 100
    v = CoreView(vol, select=(100, 255), size=(64, 64), ctx=ctx, method="trefoil",
                 trefoil_mode="paper")
    try:
        cam = v.camera(view="iso", ortho=True)
        _, stats = v.draw(cam, frames=1)
        signs = tuple(bool(s) for s in (cam.direction >= 0))
        assert stats["voxels_drawn"] == int(visible_mask(sel, view_signs=signs).sum())
    finally:
        v.release()


@pytest.mark.parametrize("method", ["trefoil", "raycast"])
def test_top_ortho_coverage_and_range_alignment(ctx, method):
    """--view top --ortho --transparent: opaque exactly where the column has a selected voxel;
    two ranges give pixel-aligned pictures."""
    vol = random_volume((9, 17, 23), 0.03, seed=8)
    w, h = 23 * 6, 17 * 6
    v = CoreView(vol, select=(100, 255), size=(w, h), ctx=ctx, method=method)
    try:
        cam = v.camera(view="top", ortho=True)
        img, _ = v.draw(cam, transparent=True, frames=1)
        # world x, y of each pixel centre through the inverse of proj·view
        vp = np.linalg.inv(cam.projection_matrix() @ cam.view_matrix())
        px, py = np.meshgrid((np.arange(w) + 0.5) / w * 2 - 1, 1 - (np.arange(h) + 0.5) / h * 2)
        pts = np.stack([px, py, np.zeros_like(px), np.ones_like(px)], -1) @ vp.T
        x, y = pts[..., 0] / pts[..., 3], pts[..., 1] / pts[..., 3]
        inside = (x > 0) & (x < 23) & (y > 0) & (y < 17)
        edge = (np.abs(x - np.round(x)) < 0.01) | (np.abs(y - np.round(y)) < 0.01)
        cols = (vol.data >= 100).any(axis=0)
        want = np.zeros((h, w), bool)
        xi, yi = np.clip(x.astype(int), 0, 22), np.clip(y.astype(int), 0, 16)
        want[inside] = cols[yi[inside], xi[inside]]
        ok = ~edge
        assert np.array_equal((img[..., 3] > 0)[ok], want[ok])
        # a narrower range: a subset of the columns, on the same pixels
        v.update(select=(200, 255))
        cam2 = v.camera(view="top", ortho=True)
        assert np.allclose(cam2.projection_matrix() @ cam2.view_matrix(),
                           cam.projection_matrix() @ cam.view_matrix())
        img2, _ = v.draw(cam2, transparent=True, frames=1)
        assert not np.any((img2[..., 3] > 0) & (img[..., 3] == 0))
    finally:
        v.release()


@pytest.mark.parametrize("method", ["trefoil", "gs", "cubes", "raycast"])
def test_gpu_bytes_exact(ctx, method):
    vol = random_volume((20, 33, 70), 0.3, seed=9)
    v = CoreView(vol, select=(100, 255), size=(32, 32), ctx=ctx, method=method, cull=False)
    try:
        _, stats = v.draw(frames=1, count=False)
        want = gpu_bytes_estimate((70, 33, 20), method, int((vol.data >= 100).sum()))
        assert stats["gpu_bytes"] == want
        if method in ("trefoil", "raycast"):  # ≤ 1.2 B/voxel (small boxes pay row/brick padding)
            assert stats["gpu_bytes"] <= 1.25 * vol.data.size + 1024
            assert gpu_bytes_estimate((512, 512, 512), method) <= 1.2 * 512**3
    finally:
        v.release()


def test_empty_selection_renders_empty_scene(ctx):
    vol = random_volume((8, 8, 8), 0.0)
    v = CoreView(vol, select=(100, 255), size=(40, 30), ctx=ctx, method="trefoil")
    try:
        with pytest.warns(EmptySelectionWarning, match="empty selection"):
            img, stats = v.draw(transparent=True, frames=1)
        assert stats["voxels_selected"] == 0 and stats["voxels_drawn"] == 0
        assert not img[..., 3].any()
    finally:
        v.release()


def test_box_too_big_for_gpu_says_what_fits(ctx):
    vol = random_volume((40, 40, 40), 0.5)
    with pytest.raises(GPUMemoryError, match=r"a box of up to \d+³ voxels fits"):
        CoreView(vol, select=(100, 255), ctx=ctx, method="trefoil", gpu_memory=20_000)


def test_prepare_on_a_thread_then_apply(ctx):
    """The CPU half runs on a worker thread; applying it equals set_range."""
    from concurrent.futures import ThreadPoolExecutor

    vol = random_volume((16, 18, 20), 0.4, seed=11)
    a = CoreView(vol, select=(100, 255), size=(48, 40), ctx=ctx, method="raycast")
    b = CoreView(vol, select=(100, 255), size=(48, 40), ctx=ctx, method="raycast")
    try:
        with ThreadPoolExecutor(1) as pool:
            prep = pool.submit(a.prepare_selection, (150, 255), [2, 2, 2, 14, 12, 10]).result()
        a.apply_selection(prep)
        b.update(box=[2, 2, 2, 14, 12, 10])
        b.update(select=(150, 255))
        img_a, st_a = a.draw(frames=1)
        img_b, st_b = b.draw(frames=1)
        assert st_a["voxels_selected"] == st_b["voxels_selected"] == int(
            (vol.data[2:12, 2:14, 2:16] >= 150).sum())
        assert np.array_equal(img_a, img_b)
    finally:
        a.release()
        b.release()
