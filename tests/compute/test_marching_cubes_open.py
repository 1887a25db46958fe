"""Open isosurfaces at inactive cells (issue 14): a cell with an inactive, NaN or infinite corner
makes no triangles (as at the grid's outer boundary) unless ``caps``; counted against an
independent numpy count and scikit-image's lorensen marching cubes masked to whole cells."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.mesh import marching_cubes as mc

REEK = "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"


def sphere_with_holes(n=28):
    """A ball (level: its sphere, no ambiguous cells) cut by an inactive slab, a few inactive
    and NaN nodes on the sphere, and an inactive block inside the ball."""
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    v = (-np.sqrt((x - 13.4) ** 2 + (y - 14.2) ** 2 + (z - 13.9) ** 2)).astype(np.float32)
    active = np.ones(v.shape, bool)
    active[:, :, 17:20] = False  # a slab through the ball
    active[3, 14, 13] = active[24, 10, 11] = False
    active[11:15, 12:16, 9:13] = False  # inside the ball: caps draw a box around it
    v[14, 3, 12] = np.nan
    v[14, 24, 15] = np.inf
    return v, active, -9.5


def whole_cell_count(values, active, level) -> tuple[int, np.ndarray]:
    """(triangles, whole) by the test's own classification: cells whose 8 corners are active
    and finite, each with its case's triangle count; ``whole`` is (nz-1, ny-1, nx-1) bool."""
    v = np.asarray(values, np.float32)
    ok = np.asarray(active, bool) & np.isfinite(v)
    nz, ny, nx = v.shape
    K = np.zeros((nz - 1, ny - 1, nx - 1), np.int64)
    whole = np.ones(K.shape, bool)
    for p in range(8):  # the 8 corners, not cells
        cx, cy, cz = p & 1, p >> 1 & 1, p >> 2 & 1
        sl = (slice(cz, cz + nz - 1), slice(cy, cy + ny - 1), slice(cx, cx + nx - 1))
        K |= (v[sl] < np.float32(level)).astype(np.int64) << p
        whole &= ok[sl]
    return int(mc.triangle_counts().astype(np.int64)[K[whole]].sum()), whole


def skimage_masked(values, active, level, whole):
    """scikit-image's lorensen triangles over the whole cells only. Its ``mask[z, y, x]`` gates
    the cell whose *upper* corner is node (z, y, x) (checked below)."""
    measure = pytest.importorskip("skimage.measure")
    vol = np.where(np.asarray(active, bool) & np.isfinite(values), values, 0).astype(np.float32)
    mask = np.zeros(vol.shape, bool)
    mask[1:, 1:, 1:] = whole
    verts, faces, _, _ = measure.marching_cubes(vol, level, method="lorensen", mask=mask,
                                                allow_degenerate=True)
    return verts, faces


def test_scikit_image_mask_gates_the_cell_below_its_node():
    measure = pytest.importorskip("skimage.measure")
    v = np.zeros((4, 4, 4), np.float32)
    v[1, 1, 1] = 1  # the 8 cells around node (1, 1, 1) are crossed, one triangle each
    for node, want in (((1, 1, 1), 1), ((2, 2, 2), 1), ((3, 3, 3), 0), ((0, 1, 1), 0)):
        mask = np.zeros(v.shape, bool)
        mask[node] = True
        mask[3, 3, 3] = True  # cell (2, 2, 2): nothing there, keeps skimage from raising
        v2 = v.copy()
        v2[3, 3, 3] = 1  # ... but something somewhere else
        _, faces, _, _ = measure.marching_cubes(v2, 0.5, method="lorensen", mask=mask,
                                                allow_degenerate=True)
        assert len(faces) == want + 1, node


def test_open_count_equals_numpy_count_and_scikit_image_masked():
    v, active, level = sphere_with_holes()
    pv = mc.prepare_values(v, active)
    assert (pv.inactive, pv.nonfinite) == (int((~active).sum()), 2)
    n, whole = whole_cell_count(v, active, level)
    assert mc.ambiguous_cell_count(pv, level) == 0
    r = mc.marching_cubes(pv, level)
    assert r.count == mc.triangle_count(pv, level) == n > 0
    verts, faces = skimage_masked(v, active, level, whole)
    assert r.count == len(faces)  # no ambiguous cell: the tables agree exactly
    assert mc.surface_area(r.triangles) == pytest.approx(
        mc.surface_area(verts[faces][..., ::-1]), rel=1e-4)
    closed = mc.marching_cubes(pv, level, caps=True)
    assert closed.count > r.count


def test_open_surface_is_the_closed_one_without_the_cells_at_outside_nodes():
    v, active, level = sphere_with_holes()
    pv = mc.prepare_values(v, active)
    gone = mc.open_cells(pv).ravel()
    closed = mc.marching_cubes(pv, level, caps=True)
    opened = mc.marching_cubes(pv, level)
    keep = ~gone[closed.cells]
    assert np.array_equal(opened.cells, closed.cells[keep])
    assert np.array_equal(opened.slots, closed.slots[keep])
    assert np.array_equal(opened.triangles, closed.triangles[keep])
    # the closed surface is watertight; the open one has a rim where it meets outside cells
    assert boundary_edges(closed.triangles) == 0 < boundary_edges(opened.triangles)


def boundary_edges(triangles) -> int:
    key = np.round(triangles.reshape(-1, 3).astype(np.float64), 5)
    _, inv = np.unique(key, axis=0, return_inverse=True)
    t = inv.reshape(-1, 3)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int((counts == 1).sum())


@pytest.mark.parametrize("seed", [0, 1])
def test_open_counts_on_a_rough_field_within_the_ambiguity_of_the_tables(seed):
    rng = np.random.default_rng(seed)
    v = rng.random((20, 24, 26))
    for _ in range(4):  # smooth it a little
        for ax in range(3):
            v = (np.roll(v, 1, ax) + 2 * v + np.roll(v, -1, ax)) / 4
    v = v.astype(np.float32)
    active = np.ones(v.shape, bool)
    active[5:12, 3:9, :] = False
    active[rng.random(v.shape) < 0.02] = False
    level = float(np.median(v)) + 1e-4
    pv = mc.prepare_values(v, active)
    n, whole = whole_cell_count(v, active, level)
    r = mc.marching_cubes(pv, level)
    assert r.count == mc.triangle_count(pv, level) == n
    _, faces = skimage_masked(v, active, level, whole)
    amb = mc.ambiguous_cell_count(pv, level)
    assert abs(r.count - len(faces)) <= 4 * amb


def test_open_patch_ranges_leave_outside_nodes_out():
    v, active, level = sphere_with_holes()
    pv = mc.prepare_values(v, active)
    L = 4
    D = L + 1
    for caps in (False, True):
        r = mc.patch_ranges(pv.values, L, caps=caps)
        for k in range(r.shape[0]):  # a few hundred patches
            for i in range(r.shape[1]):
                for j in range(r.shape[2]):
                    block = pv.values[k: k + 2, D * i: D * i + D + 1, D * j: D * j + D + 1]
                    inside = block[block > mc.OUTSIDE_BELOW]
                    lo = block.min() if caps else (inside.min() if inside.size else np.inf)
                    assert r[k, i, j, 0] == lo and r[k, i, j, 1] == block.max()
        # every cell that makes triangles lies in a live patch
        K = mc.classify(pv, level, caps)
        crossed = int(((K != 0) & (K != 255)).sum())
        live = mc.cells_in_live_patches(pv, level, L, caps=caps)
        assert crossed <= live
    # a patch of outside nodes and nodes above the level is live only with caps
    w = np.ones((2, 6, 6), np.float32)
    w[:, :3] = mc.OUTSIDE
    assert mc.cells_in_live_patches(w, 0.5, 8) == 0
    assert mc.cells_in_live_patches(w, 0.5, 8, caps=True) == 25


def test_open_cells_and_no_outside_nodes():
    v = np.random.default_rng(0).random((5, 6, 7)).astype(np.float32)
    assert mc.open_cells(v) is None
    assert np.array_equal(mc.classify(v, 0.5), mc.classify(v, 0.5, caps=True))
    v[2, 3, 4] = mc.OUTSIDE
    gone = mc.open_cells(v)
    assert gone.sum() == 8 and gone[1:3, 2:4, 3:5].all()


@pytest.mark.data
def test_reek_open_surface_counts(shared_data):
    """The OPM run, SWAT = 0.5: the open surface has exactly the whole cells' triangles
    (numpy), scikit-image's masked lorensen within the tables' ambiguity; caps add triangles."""
    from geoshade.io import load_field

    f = load_field(shared_data / REEK)
    for k in (1, f.nsteps // 2, f.nsteps - 1):
        s = f.step(k)
        pv = mc.prepare_values(s, f.active)
        n, whole = whole_cell_count(s, f.active, 0.5)
        opened = mc.triangle_count(pv, 0.5)
        assert opened == n > 0
        _, faces = skimage_masked(s, f.active, 0.5, whole)
        assert abs(opened - len(faces)) <= 4 * mc.ambiguous_cell_count(pv, 0.5)
        assert mc.triangle_count(pv, 0.5, caps=True) > opened
