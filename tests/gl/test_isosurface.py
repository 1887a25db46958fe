"""Tessellation marching cubes on the GPU against the CPU reference (exact counts, same mesh)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.errors import EmptySceneWarning as EmptySurfaceWarning
from geoshade.iso import IsoView, OutsideValuesWarning, export_mesh, render
from geoshade.models import CornerPointGrid, FieldSeries

pytestmark = pytest.mark.gl


def smooth_random(shape, seed, passes=4):
    a = np.random.default_rng(seed).random(shape)
    for _ in range(passes):
        for ax in range(3):
            a = (np.roll(a, 1, ax) + 2 * a + np.roll(a, -1, ax)) / 4
    return a.astype(np.float32)


def visual(ctx, values, L=16, skip=True, positions=None):
    from geoshade.render.visuals.isosurface.visual import IsoSurfaceVisual

    v = IsoSurfaceVisual(ctx, values.shape, patch_level=L, skip_patches=skip,
                         positions=positions)
    v.upload(values, mc.patch_ranges(values, L))
    return v


def sorted_capture(cap):
    """(triangles (n, 3, 3), cells, slots) of a capture, ordered like the CPU reference."""
    ids = cap["id"].reshape(-1, 3, 2)
    assert (ids == ids[:, :1]).all()  # the three vertices of a triangle carry one id
    ids = ids[:, 0]
    order = np.lexsort((ids[:, 1], ids[:, 0]))
    return cap["pos"].reshape(-1, 3, 3)[order], ids[order, 0], ids[order, 1]


def cornerpoint_grid(nx=9, ny=7, nz=5, seed=0):
    """A small corner-point grid: sloping pillars, layers of varying thickness, a few inactive
    cells."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.arange(nx + 1) * 50.0, np.arange(ny + 1) * 40.0, indexing="ij")
    coord = np.zeros((nx + 1, ny + 1, 6))
    coord[..., 0], coord[..., 1], coord[..., 2] = x, y, 2000.0
    coord[..., 3], coord[..., 4], coord[..., 5] = x + 30.0, y + 10.0, 2200.0
    top = 2000.0 + 0.05 * x[:, :, None] + 0.02 * y[:, :, None]
    thick = 4.0 + rng.random((nx + 1, ny + 1, nz))
    levels = top + np.concatenate([np.zeros((nx + 1, ny + 1, 1)), np.cumsum(thick, axis=2)],
                                  axis=2)  # (nx+1, ny+1, nz+1) depths at the pillars
    zcorn = np.empty((2 * nx, 2 * ny, 2 * nz))
    for a in (0, 1):  # corner offsets, not cells
        for b in (0, 1):
            for c in (0, 1):
                zcorn[a::2, b::2, c::2] = levels[a:nx + a, b:ny + b, c:nz + c]
    act = np.ones((nx, ny, nz), bool)
    act[2, 3, 1] = act[5, 1, 3] = False
    return CornerPointGrid(coord, zcorn, actnum=act, name="synthetic")


# --- counts ---------------------------------------------------------------------------------------
@pytest.mark.parametrize(("shape", "L"), [
    ((9, 20, 21), 8),    # 20 cells = 2·9 + 2 and 19 = 2·9 + 1: patches with l = 1 (OpenGL
    ((7, 21, 20), 8),    # rounds an inner level of 1 up to 2; the paper's floor double-counts)
    ((12, 33, 30), 16),
    ((6, 140, 200), 64),  # 4×3 patches × 5 slices = 60 patch-quads: 4 instances on llvmpipe
])
@pytest.mark.parametrize("skip", [True, False])
def test_gpu_triangle_count_equals_cpu(ctx, shape, L, skip):
    v = smooth_random(shape, sum(shape))
    level = float(np.median(v))
    vis = visual(ctx, v, L, skip)
    try:
        assert vis.count(level) == mc.triangle_count(v, level) > 0
    finally:
        vis.release()


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_every_slice_axis_marches_the_same_cells(ctx, axis):
    """Patch slices stacked along x, y or z: the same triangles, only their order differs."""
    from geoshade.render.visuals.isosurface.visual import IsoSurfaceVisual

    v = smooth_random((11, 13, 17), 9)
    level = float(np.median(v))
    vis = IsoSurfaceVisual(ctx, v.shape, patch_level=4, slice_axis=axis)
    try:
        vis.upload(v, mc.patch_ranges(v, 4, axis))
        tri, cells, slots = sorted_capture(vis.capture(level))
    finally:
        vis.release()
    ref = mc.marching_cubes(v, level)
    assert np.array_equal(cells, ref.cells) and np.array_equal(slots, ref.slots)
    assert np.allclose(tri, ref.triangles, atol=1e-5)


def test_field_larger_than_one_tessellation_batch(ctx):
    """More patches than one instance may carry (llvmpipe re-uses the first 65,536 tessellated
    vertices of a draw): a re-used batch would repeat the first slices' triangles."""
    from geoshade.render import layout
    from geoshade.render.context import is_software

    v = np.zeros((8, 140, 200), np.float32)
    z = np.arange(8, dtype=np.float32)[:, None, None]
    v += z + 0.01 * np.arange(200, dtype=np.float32)  # one tilted layer per slice level
    vis = visual(ctx, v, L=64, skip=False)
    try:
        assert vis.n_patches > vis.ppi
        if is_software(ctx):
            assert vis.ppi * 65**2 <= layout.TESS_VERTEX_LIMIT
        for level in (1.5, 5.5):  # the surface lies in an early / a late batch
            assert vis.count(level) == mc.triangle_count(v, level) > 0
    finally:
        vis.release()


def test_level_exactly_on_grid_values(ctx):
    """Integer values, integer level: nodes equal to S* are not below it on the GPU either;
    vertices land exactly on nodes (degenerate triangles included in the count)."""
    v = np.random.default_rng(11).integers(0, 4, (9, 10, 11)).astype(np.float32)
    vis = visual(ctx, v, L=4)
    try:
        tri, cells, _slots = sorted_capture(vis.capture(2.0))
    finally:
        vis.release()
    ref = mc.marching_cubes(v, 2.0)
    assert len(tri) == ref.count and np.array_equal(cells, ref.cells)
    assert np.array_equal(tri, ref.triangles)  # t = 0 or 1 exactly, others equal to float32
    z = np.mgrid[0:6, 0:5, 0:7][0].astype(np.float32)
    vis = visual(ctx, z, L=4)
    try:
        tri = vis.capture(3.0)["pos"].reshape(-1, 3, 3)
    finally:
        vis.release()
    assert len(tri) == 2 * 4 * 6 and (tri[..., 2] == 3.0).all()
    assert mc.surface_area(tri) == pytest.approx(4 * 6)


def test_gpu_bytes_are_exact(ctx):
    v = smooth_random((10, 12, 14), 1)
    vis = visual(ctx, v, L=8)
    try:
        q_p, m_p, n_p = 9, 2, 2
        want = 10 * 12 * 14 * 4 + q_p * m_p * n_p * 8 + 256 * 16 + 1024 + 4 + 4
        assert vis.gpu_bytes == want
        vis.upload(v, mc.patch_ranges(v, 8), slot=1)
        assert vis.gpu_bytes == want + 10 * 12 * 14 * 4 + q_p * m_p * n_p * 8
    finally:
        vis.release()


# --- the captured mesh ------------------------------------------------------------------------
def test_capture_equals_cpu_reference(ctx):
    v = smooth_random((14, 18, 22), 7)
    v[4:6, 5:9, 3:4] = np.nan
    pv = mc.prepare_values(v)
    level = float(np.median(v[np.isfinite(v)]))
    vis = visual(ctx, pv.values, L=8)
    try:
        tri, cells, slots = sorted_capture(vis.capture(level))
    finally:
        vis.release()
    ref = mc.marching_cubes(pv, level)
    assert np.array_equal(cells, ref.cells) and np.array_equal(slots, ref.slots)
    assert np.allclose(tri, ref.triangles, rtol=0, atol=1e-5)


def test_sphere_mesh_equals_what_was_drawn(ctx, tmp_path):
    n, c, R = 26, np.array([12.3, 12.8, 12.6]), 9.0
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    d = -np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2).astype(np.float32)
    f = FieldSeries(d, spacing=(0.5, 0.5, 0.5), origin=(1.0, 2.0, 3.0))
    _, st = render(f, -R, size=(64, 64), frames=1, mesh=tmp_path / "s.ply", ctx=ctx)
    m = export_mesh(f, -R, ctx=ctx)
    assert m.n_faces == st["triangles"] == st["mesh_faces"] == mc.triangle_count(d, -R)
    ref = mc.marching_cubes(d, -R)
    world = ref.triangles.astype(np.float64) * 0.5 + np.array([1.0, 2.0, 3.0])
    key = lambda t: t[np.lexsort(t.reshape(len(t), -1).T[::-1])]  # noqa: E731
    mine = m.triangles()
    # same triangles, as sets (order within the soup differs): sort by centroid then compare
    a = mine[np.lexsort(np.round(mine.mean(axis=1), 5).T)]
    b = world[np.lexsort(np.round(world.mean(axis=1), 5).T)]
    assert np.allclose(key(a), key(b), atol=1e-5)
    # area of a sphere of radius R·spacing; normals point outwards (towards lower values)
    assert m.area() == pytest.approx(4 * np.pi * (R * 0.5) ** 2, rel=5e-3)
    centre = c * 0.5 + np.array([1.0, 2.0, 3.0])
    radial = m.vertices - centre
    radial /= np.linalg.norm(radial, axis=1, keepdims=True)
    assert (np.einsum("ij,ij->i", m.normals, radial) > 0.98).all()
    assert (tmp_path / "s.ply").stat().st_size > 0


def test_cornerpoint_vertices_through_cell_centres(ctx):
    g = cornerpoint_grid()
    nx, ny, nz = g.dims
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    sw = (0.2 + 0.08 * i + 0.03 * j - 0.02 * k).astype(np.float32)  # water from the east
    f = FieldSeries([sw.T, (sw + 0.1).T], grid=g, name="SWAT")
    from geoshade.iso.api import geometry

    _, pos = geometry(f)
    level = 0.55
    with IsoView(f, level, step=0, size=(64, 48), ctx=ctx, prefetch=False) as view:
        cap = view.visual.capture(level)
        _, st = view.draw(frames=1)
        mesh = view.mesh()
    pv = mc.prepare_values(f.step(0), f.active)
    ref = mc.marching_cubes(pv, level, positions=pos)
    tri, cells, _ = sorted_capture(cap)
    assert st["triangles"] == ref.count == len(tri) == mesh.n_faces > 0
    assert np.array_equal(cells, ref.cells)
    assert np.allclose(tri, ref.triangles, atol=1e-3)  # metres, float32 near the origin
    # world: x, y as the grid's, z = -depth, inside the grid's box
    b = g.bounds()
    w = mesh.vertices
    assert (w[:, 0] >= b[0, 0]).all() and (w[:, 0] <= b[1, 0]).all()
    assert (-w[:, 2] >= b[0, 2]).all() and (-w[:, 2] <= b[1, 2]).all()
    assert np.isfinite(mesh.normals).all()


# --- what the user sees -------------------------------------------------------------------------
def coverage(img):
    return np.any(img[..., :3] != 255, axis=-1)


def test_skipping_and_patch_size_draw_the_same_picture(ctx):
    f = displacement_field((40, 28, 24), steps=3, seed=2)
    pics = {}
    for L, skip in ((64, False), (64, True), (8, True)):
        img, st = render(f, 0.5, size=(96, 72), frames=1, patch_level=L, skip_patches=skip,
                         slice_axis="z", ctx=ctx)
        pics[(L, skip)] = (img, st)
    (a, sa), (b, sb), (c, sc) = pics.values()
    assert sa["triangles"] == sb["triangles"] == sc["triangles"] > 0
    assert np.array_equal(a, b)  # the skipped patches emit nothing: same draw order, same image
    assert np.array_equal(coverage(a), coverage(c))
    assert sb["cells_marched"] <= sa["cells_marched"] == sa["cells"]
    assert sc["cells_marched"] < sb["cells_marched"]
    img, sd = render(f, 0.5, size=(96, 72), frames=1, ctx=ctx)  # the defaults: auto axis
    assert sd["slice_axis"] == "x"  # the front faces the flow direction
    assert sd["triangles"] == sa["triangles"] and sd["cells_marched"] < sc["cells_marched"]
    assert np.array_equal(coverage(a), coverage(img))


def test_level_outside_the_values_draws_nothing(ctx):
    f = displacement_field((24, 16, 16), steps=2)
    with pytest.warns(EmptySurfaceWarning, match=r"level 1.5 is outside the values \[0.1, 0.8"):
        img, st = render(f, 1.5, size=(32, 32), frames=1, ctx=ctx)
    assert st["triangles"] == 0 and (img[..., :3] == 255).all() and "warning" in st
    with pytest.warns(EmptySurfaceWarning, match="equals the smallest value"):
        render(f, float(f.step(1).min()), size=(32, 32), frames=1, ctx=ctx)


def test_nan_cells_are_outside_and_counted(ctx):
    v = smooth_random((12, 14, 16), 3)
    v[2:4, 2:5, 2:6] = np.nan
    v[8, 8, 8] = np.inf
    f = FieldSeries(v, name="SWAT")
    level = float(np.nanmedian(v[np.isfinite(v)]))
    with pytest.warns(OutsideValuesWarning, match=r"25 nodes are NaN or infinite"):
        _, st = render(f, level, size=(32, 32), frames=1, ctx=ctx)
    assert st["nonfinite"] == 25
    assert st["triangles"] == mc.triangle_count(mc.prepare_values(v).values, level)


def test_color_by_property_changes_only_colours(ctx):
    f = displacement_field((30, 20, 20), steps=2, seed=1)
    plain, s1 = render(f, 0.5, size=(80, 60), frames=1, transparent=True, ctx=ctx)
    coloured, s2 = render(f, 0.5, size=(80, 60), frames=1, color_by="PRESSURE",
                          colormap="gray", transparent=True, ctx=ctx)
    assert np.array_equal(plain[..., 3] > 0, coloured[..., 3] > 0)
    assert s1["triangles"] == s2["triangles"] and s2["color_by"] == "PRESSURE"
    px = coloured[coloured[..., 3] > 0][:, :3].astype(int)
    assert (np.abs(px[:, 0] - px[:, 1]) <= 1).all()  # a grey palette, lit
    assert not np.array_equal(plain, coloured)
    with pytest.raises(Exception, match="color_by: unknown name 'SGAS'; it has PRESSURE"):
        render(f, 0.5, size=(8, 8), color_by="SGAS", ctx=ctx)


def test_step_switching_uploads_ahead_and_stays_exact(ctx):
    f = displacement_field((36, 24, 20), steps=5, seed=5)
    seen = []
    with IsoView(f, 0.5, step=0, size=(48, 32), ctx=ctx) as view:
        bytes0 = None
        for k in (0, 1, 2, 3, 4, 1):
            if k or seen:
                view.wait_prefetch()  # the user looked long enough: read, uploaded, marched
                view.update(step=k)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", EmptySurfaceWarning)
                _, st = view.draw(frames=1)
            seen.append((k, st["prefetched"], st["premarched"]))
            assert st["step"] == k
            assert st["triangles"] == mc.triangle_count(f.step(k), 0.5)
            fields = sum(n for name, n in view.visual.cache.breakdown().items()
                         if not name.startswith("mesh"))
            if k == 2:
                bytes0 = fields
            elif bytes0 is not None:
                assert fields == bytes0  # two slots, nothing re-allocated
    # stepping forward swaps to the step prepared while the previous one was shown, and its
    # surface was marched then too (the switch's frame draws captured triangles)
    assert [p for k, p, _ in seen[1:5]] == [True, True, True, True]
    assert [m for k, _, m in seen[2:5]] == [True, True, True]
    assert seen[5] == (1, False, False)


@pytest.mark.data
def test_reek_gpu_equals_cpu_while_the_front_moves(ctx, shared_data):
    """The OPM run: SWAT = 0.5 on the GPU through the cell centres, step 1 then step 36 (read
    ahead), equals the CPU reference; the surface changes between the steps."""
    from geoshade.io import load_field
    from geoshade.iso.api import geometry

    f = load_field(shared_data / "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID",
                   color_by="PRESSURE")
    _, pos = geometry(f)
    counts = {}
    with IsoView(f, 0.5, step=1, color_by="PRESSURE", size=(64, 48), ctx=ctx) as view:
        for k in (1, 36):
            if k != 1:
                view.update(step=k)
            _, st = view.draw(frames=1)
            pv = mc.prepare_values(f.step(k), f.active)
            ref = mc.marching_cubes(pv, 0.5, positions=pos)
            assert st["triangles"] == ref.count
            tri, cells, _ = sorted_capture(view.visual.capture(0.5))
            assert np.array_equal(cells, ref.cells)
            assert np.allclose(tri, ref.triangles, atol=0.05)  # metres, float32 over ~12 km
            counts[k] = st["triangles"]
        mesh = view.mesh()
    assert counts[1] != counts[36]
    assert mesh.n_faces == counts[36] and np.isfinite(mesh.values).all()
    assert 100 < float(np.median(mesh.values)) < 1000  # bar


def test_set_color_by_and_level_redo_only_what_changed(ctx):
    f = displacement_field((30, 20, 20), steps=3, seed=1)
    with IsoView(f, 0.5, step=1, size=(80, 60), ctx=ctx) as view:
        plain, s1 = view.draw(transparent=True)
        view.update(color_by="PRESSURE", color_range=(200, 300))
        coloured, s2 = view.draw(transparent=True)
        assert s2["color_by"] == "PRESSURE" and s2["gpu_bytes"] > s1["gpu_bytes"]
        assert np.array_equal(plain[..., 3] > 0, coloured[..., 3] > 0)
        assert not np.array_equal(plain, coloured)
        view.update(step=2)  # the step ahead is prepared again, with the property
        _, s3 = view.draw()
        assert s3["color_by"] == "PRESSURE" and s3["step"] == 2
        view.update(color_by=None)
        view.draw(transparent=True)
        view.update(level=0.3)
        _, s4 = view.draw()
        assert s4["triangles"] == mc.triangle_count(f.step(2), 0.3) != s3["triangles"]
        with pytest.raises(Exception, match="color_by: unknown name 'X'"):
            view.update(color_by="X")


def test_mesh_cache_redraws_the_captured_surface_exactly(ctx):
    """Frames 1 (march, count), 2 (march and capture) and 3+ (the captured triangles) draw the
    picture the paper's every-frame marching draws, through step, level and colour changes."""
    f = displacement_field((40, 30, 24), steps=3, seed=7)
    cam = None
    with IsoView(f, 0.5, step=0, size=(96, 72), prefetch=False, ctx=ctx) as view:
        vis = view.visual
        assert vis.mesh_cache

        def both():
            vis.mesh_cache = True
            cached = [view.draw(camera=cam, frames=1) for _ in range(3)]
            vis.mesh_cache = False
            ref, rst = view.draw(camera=cam, frames=1)
            vis.mesh_cache = True
            for img, st in cached:
                assert st["triangles"] == rst["triangles"] > 0
                diff = np.abs(img.astype(int) - ref.astype(int)).max(axis=-1)
                assert (diff > 1).mean() <= 1e-3
            return ref

        a = both()
        assert vis._mesh_keys[vis.front] is not None
        assert f"mesh{vis.front}" in vis.cache.breakdown()
        view.update(step=2)
        assert vis._mesh_keys[vis.front] is None  # a new step marches again (no prefetch)
        b = both()
        view.update(level=0.3)
        c = both()
        view.update(color_by="PRESSURE")
        d = both()
        assert not np.array_equal(a, b) and not np.array_equal(b, c)
        assert not np.array_equal(c, d)
        cam = view.camera(view="top", ortho=True)  # a new camera re-draws the same mesh
        key = vis._mesh_keys[vis.front]
        both()
        assert vis._mesh_keys[vis.front] == key


def test_premarched_step_draws_the_surface_of_a_fresh_march(ctx):
    """The step prepared ahead is marched while the previous one is shown (no drawing): the
    switch's frame draws those captured triangles, the same surface a fresh march draws."""
    f = displacement_field((40, 30, 24), steps=3, seed=7)
    with IsoView(f, 0.5, step=0, size=(96, 72), ctx=ctx) as view:
        view.draw(frames=2)
        view.wait_prefetch()
        back = 1 - view.visual.front
        assert view.visual.has_mesh(back, 0.5)      # step 1 marched ahead, into the back slot
        view.update(step=1)
        img, st = view.draw(frames=1)
        assert st["prefetched"] and st["premarched"]
        assert st["triangles"] == mc.triangle_count(f.step(1), 0.5)
        # on the last step, the step left behind in the back slot is not marched again at a
        # new level (only the next step is marched ahead)
        view.wait_prefetch()
        view.update(step=2)
        view.draw(frames=1)
        left = 1 - view.visual.front
        view.update(level=0.4)
        view.draw(frames=1)
        view.wait_prefetch()
        assert not view.visual.has_mesh(left, 0.4) and view.visual.has_mesh(left, 0.5)
        view.update(level=0.5)
        view.update(step=1)
    with IsoView(f, 0.5, step=1, size=(96, 72), mesh_cache=False, prefetch=False,
                 ctx=ctx) as fresh:
        ref, rst = fresh.draw(frames=1)
    assert rst["triangles"] == st["triangles"]
    diff = np.abs(img.astype(int) - ref.astype(int)).max(axis=-1)
    assert (diff > 1).mean() <= 1e-3     # as the mesh cache's own test: mesh.vert vs the march
