"""Open isosurfaces at inactive cells on the GPU (issue 14): the tessellation marching cubes emit
nothing in a cell with an inactive, NaN or infinite corner (``caps=False``, the default), exactly
the CPU reference and an independent numpy count; ``caps=True`` closes the surface as before."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.iso import IsoView, render
from geoshade.models import FieldSeries
from tests.compute.test_marching_cubes_open import REEK, sphere_with_holes, whole_cell_count
from tests.gl.test_isosurface import cornerpoint_grid, sorted_capture

pytestmark = [pytest.mark.gl,
              pytest.mark.filterwarnings("ignore::geoshade.iso.api.OutsideValuesWarning")]


def holed_field(steps=2):
    v, active, level = sphere_with_holes()
    return FieldSeries([v, v + 0.75][:steps], active=active, name="S"), level


@pytest.mark.parametrize(("L", "skip", "axis"), [(4, True, "z"), (8, True, "x"),
                                                 (64, False, "z")])
@pytest.mark.parametrize("caps", [False, True])
def test_gpu_count_and_triangles_equal_cpu(ctx, L, skip, axis, caps):
    from geoshade.render.visuals.isosurface.visual import IsoSurfaceVisual

    v, active, level = sphere_with_holes()
    pv = mc.prepare_values(v, active)
    vis = IsoSurfaceVisual(ctx, v.shape, patch_level=L, skip_patches=skip, slice_axis=axis,
                           caps=caps)
    try:
        vis.upload(pv.values, mc.patch_ranges(pv.values, L, axis, caps))
        n = vis.count(level)
        tri, cells, slots = sorted_capture(vis.capture(level))
    finally:
        vis.release()
    ref = mc.marching_cubes(pv, level, caps=caps)
    assert n == ref.count == len(tri) > 0
    assert np.array_equal(cells, ref.cells) and np.array_equal(slots, ref.slots)
    assert np.allclose(tri, ref.triangles, atol=1e-5)
    if not caps:
        assert n == whole_cell_count(v, active, level)[0]
    else:
        assert n > whole_cell_count(v, active, level)[0]


def test_view_is_open_by_default_and_caps_close_it(ctx):
    f, level = holed_field()
    pv = mc.prepare_values(f.step(1), f.active)
    opened = mc.triangle_count(pv, level)
    closed = mc.triangle_count(pv, level, caps=True)
    assert 0 < opened < closed
    img_o, so = render(f, level, size=(96, 72), frames=1, ctx=ctx)
    img_c, sc = render(f, level, size=(96, 72), frames=1, caps=True, ctx=ctx)
    assert (so["caps"], sc["caps"]) == (False, True)
    assert (so["triangles"], sc["triangles"]) == (opened, closed)
    assert so["cells_marched"] <= sc["cells_marched"]
    # the same camera: the closed picture covers the open one and more (the caps)
    cov_o = np.any(img_o[..., :3] != 255, axis=-1)
    cov_c = np.any(img_c[..., :3] != 255, axis=-1)
    assert cov_c.sum() > cov_o.sum()
    # switching caps on a live view re-prepares both slots
    with IsoView(f, level, step=0, size=(48, 36), ctx=ctx) as view:
        _, s0 = view.draw(frames=1)
        view.update(caps=True)
        _, s1 = view.draw(frames=1)
        view.update(step=1)
        _, s2 = view.draw(frames=1)
        view.update(caps=False)
        _, s3 = view.draw(frames=1)
    p0 = mc.prepare_values(f.step(0), f.active)
    assert s0["triangles"] == mc.triangle_count(p0, level)
    assert s1["triangles"] == mc.triangle_count(p0, level, caps=True)
    assert (s2["triangles"], s3["triangles"]) == (closed, opened)


def test_cornerpoint_inactive_cells_leave_the_surface_open(ctx):
    g = cornerpoint_grid()
    nx, ny, nz = g.dims
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    sw = (0.2 + 0.08 * i + 0.03 * j - 0.02 * k).astype(np.float32)
    f = FieldSeries([sw.T], grid=g, name="SWAT")
    from geoshade.iso.api import geometry

    _, pos = geometry(f)
    pv = mc.prepare_values(f.step(0), f.active)
    for caps in (False, True):
        with IsoView(f, 0.55, size=(64, 48), ctx=ctx, caps=caps) as view:
            cap = view.visual.capture(0.55)
            _, st = view.draw(frames=1)
            mesh = view.mesh()
        ref = mc.marching_cubes(pv, 0.55, positions=pos, caps=caps)
        tri, cells, _ = sorted_capture(cap)
        assert st["triangles"] == ref.count == mesh.n_faces > 0
        assert np.array_equal(cells, ref.cells)
        assert np.allclose(tri, ref.triangles, atol=1e-3)
        if not caps:
            assert ref.count == whole_cell_count(f.step(0), f.active, 0.55)[0]
            assert not mc.open_cells(pv).ravel()[cells].any()


def test_pick_sees_the_caps_only_when_they_are_drawn(ctx):
    """A plane x = 5.5 and an inactive block where the values are above the level: the caps
    draw a box around the block; its pixels pick nothing on the open surface."""
    x = np.mgrid[0:16, 0:24, 0:28][2].astype(np.float32)
    active = np.ones(x.shape, bool)
    active[5:11, 8:15, 15:21] = False
    f = FieldSeries(x, active=active, name="S")
    pics, views = {}, {}
    for caps in (False, True):
        views[caps] = IsoView(f, 5.5, size=(96, 72), view="top", ctx=ctx, caps=caps)
        img, st = views[caps].draw(frames=1)
        assert st["triangles"] == mc.triangle_count(mc.prepare_values(x, active), 5.5, caps)
        pics[caps] = np.any(img[..., :3] != 255, axis=-1)
    try:
        only = np.argwhere(pics[True] & ~pics[False])
        assert len(only) > 100
        for y0, x0 in only[:: max(1, len(only) // 12)]:
            assert views[False].pick(int(x0), int(y0)) is None
            p = views[True].pick(int(x0), int(y0))
            assert p is not None and 14 <= p.index[0] <= 21 and 4 <= p.index[2] <= 11
    finally:
        for v in views.values():
            v.release()


@pytest.mark.data
def test_reek_open_surface_gpu_equals_cpu(ctx, shared_data):
    """The OPM run, SWAT = 0.5 through the cell centres: the GPU's open surface equals the CPU
    reference and the numpy count of whole cells at three steps; caps add triangles."""
    from geoshade.io import load_field
    from geoshade.iso.api import geometry

    f = load_field(shared_data / REEK)
    _, pos = geometry(f)
    steps = (1, f.nsteps // 2, f.nsteps - 1)
    with IsoView(f, 0.5, step=steps[0], size=(64, 48), ctx=ctx) as view:
        for k in steps:
            view.update(step=k)
            _, st = view.draw(frames=1)
            pv = mc.prepare_values(f.step(k), f.active)
            ref = mc.marching_cubes(pv, 0.5, positions=pos)
            assert st["triangles"] == ref.count == whole_cell_count(f.step(k), f.active, 0.5)[0]
            tri, cells, _ = sorted_capture(view.visual.capture(0.5))
            assert np.array_equal(cells, ref.cells)
            assert np.allclose(tri, ref.triangles, atol=0.05)  # metres, float32 over ~12 km
        view.update(caps=True)
        _, st = view.draw(frames=1)
        assert st["triangles"] == mc.triangle_count(pv, 0.5, caps=True) > ref.count


def test_a_surface_only_along_inactive_cells_is_empty_and_says_why(ctx):
    from geoshade.errors import EmptySceneWarning

    x = np.broadcast_to(np.arange(10, dtype=np.float32), (6, 7, 10)).copy()
    active = np.ones(x.shape, bool)
    active[:, :, 5:7] = False  # the level 5.5 lies between x = 5 and 6: inactive nodes
    f = FieldSeries(x, active=active, name="S")
    with pytest.warns(EmptySceneWarning, match=r"no cell whose 8 corners are active .* --caps"):
        _, st = render(f, 5.5, size=(32, 24), frames=1, ctx=ctx)
    assert st["triangles"] == 0 and "--caps" in st["warning"]
    _, st = render(f, 5.5, size=(32, 24), frames=1, caps=True, ctx=ctx)
    assert st["triangles"] == mc.triangle_count(mc.prepare_values(x, active), 5.5, True) > 0
    assert "warning" not in st
