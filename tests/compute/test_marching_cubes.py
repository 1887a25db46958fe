"""The CPU marching-cubes reference: its table, its surfaces, scikit-image as an oracle."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.compute.mesh.displacement import displacement_field


def smooth_random(shape, seed, passes=6):
    """A smooth random field (box blur of noise), float32."""
    a = np.random.default_rng(seed).random(shape)
    for _ in range(passes):
        for ax in range(3):
            a = (np.roll(a, 1, ax) + 2 * a + np.roll(a, -1, ax)) / 4
    return a.astype(np.float32)


def sphere_field(n, centre, radius):
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64)
    d = np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2)
    return (-d).astype(np.float32), -float(radius)  # inside (>= level) = the ball


# --- the table ---------------------------------------------------------------------------------
def test_table_uses_exactly_the_crossed_edges():
    T, count = mc.case_table(), mc.triangle_counts()
    for K in range(256):  # 256 cases, not cells
        below = [(K >> p) & 1 for p in range(8)]
        crossed = {e for e in range(12) if below[mc.EDGES[e, 0]] != below[mc.EDGES[e, 1]]}
        row = T[K]
        n = int(count[K])
        assert set(row[: 3 * n].tolist()) == crossed
        assert (row[3 * n :] == -1).all()
        tri = row[: 3 * n].reshape(-1, 3)
        assert all(len(set(t)) == 3 for t in tri.tolist())  # no repeated edge in a triangle
    assert count[0] == count[255] == 0
    assert count.max() == mc.MAX_TRIANGLES == 5


def test_no_triangle_lies_in_a_face_of_the_cube():
    """Fan starts are chosen so that no triangle has its 3 vertices on one face (a fin)."""
    faces = []
    for axis in range(3):
        for side in (0, 1):
            corners = {p for p in range(8) if mc.CORNERS[p, axis] == side}
            faces.append({e for e in range(12) if set(mc.EDGES[e].tolist()) <= corners})
    for K in range(256):
        tri = mc.case_table()[K][: 3 * mc.triangle_counts()[K]].reshape(-1, 3)
        for t in tri.tolist():
            assert not any(set(t) <= f for f in faces), (K, t)


def test_edges_run_from_lower_to_upper_corner():
    a, b = mc.CORNERS[mc.EDGES[:, 0]], mc.CORNERS[mc.EDGES[:, 1]]
    d = b - a
    assert (d.sum(axis=1) == 1).all() and (d >= 0).all()
    assert (np.argmax(d, axis=1) == np.repeat([0, 1, 2], 4)).all()


def test_triangles_face_the_side_below_the_level():
    """For every case, each triangle's normal (right hand) points from the above end of its
    three edges towards the below end."""
    mid = (mc.CORNERS[mc.EDGES[:, 0]] + mc.CORNERS[mc.EDGES[:, 1]]) / 2
    for K in range(1, 255):
        below = np.array([(K >> p) & 1 for p in range(8)], bool)
        tri = mc.case_table()[K][: 3 * mc.triangle_counts()[K]].reshape(-1, 3)
        for e in tri:  # at most 5 triangles per case
            p = mid[e]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            a, b = mc.CORNERS[mc.EDGES[e, 0]], mc.CORNERS[mc.EDGES[e, 1]]
            towards_below = np.where(below[mc.EDGES[e, 0]][:, None], a - b, b - a)
            assert (towards_below @ n).sum() > 0, K


def test_complementary_ambiguity_rule_is_per_face():
    """Only cases with a face whose diagonal corners agree are ambiguous."""
    amb = mc.ambiguous_cases()
    assert not amb[[0, 1, 3, 7, 15, 255]].any()
    assert amb[1 | 8]  # corners 0 and 3 (diagonal on the z = 0 face)
    assert amb.sum() == 120


# --- surfaces of known area ----------------------------------------------------------------------
def test_plane_exact_area_and_position():
    z, y, x = np.mgrid[0:12, 0:10, 0:9].astype(np.float32)
    f = z - 0.3 * x - 0.2 * y  # level 2: the plane z = 2 + 0.3x + 0.2y stays inside the box
    r = mc.marching_cubes(f, 2.0)
    want = 8 * 9 * np.sqrt(1 + 0.3**2 + 0.2**2)
    assert mc.surface_area(r.triangles) == pytest.approx(want, rel=1e-5)
    p = r.triangles.reshape(-1, 3)
    assert np.abs(p[:, 2] - 2 - 0.3 * p[:, 0] - 0.2 * p[:, 1]).max() < 1e-5


def test_sphere_area_within_half_a_percent():
    """Radius 12 nodes: vertices lie on the sphere up to the interpolation error of the distance
    along an edge (< 1/(2R) node), and the flat triangles (edges ~1 node) cut each cap short by
    a relative (edge/R)²/8 ~ 0.1 %: together well under 0.5 %."""
    f, level = sphere_field(32, (15.3, 16.1, 15.7), 12.0)
    r = mc.marching_cubes(f, level)
    area = mc.surface_area(r.triangles)
    assert area == pytest.approx(4 * np.pi * 12.0**2, rel=5e-3)
    # closed surface: every edge is shared by exactly two triangles
    key = np.round(r.triangles.reshape(-1, 3).astype(np.float64), 5)
    _, inv = np.unique(key, axis=0, return_inverse=True)
    t = inv.reshape(-1, 3)
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert (counts == 2).all()


def test_level_exactly_on_grid_values():
    """Integer field, integer level: nodes equal to S* are not below it; every vertex is on a
    node or between nodes, nothing is NaN, and the plane z = 3 is made once."""
    z = np.mgrid[0:7, 0:5, 0:6][0].astype(np.float32)
    r = mc.marching_cubes(z, 3.0)
    assert np.isfinite(r.triangles).all()
    assert np.allclose(r.triangles[..., 2], 3.0)
    assert mc.surface_area(r.triangles) == pytest.approx(5 * 4)
    v = np.random.default_rng(3).integers(0, 4, (9, 8, 7)).astype(np.float32)
    r = mc.marching_cubes(v, 2.0)
    assert np.isfinite(r.triangles).all()
    assert r.count == mc.triangle_count(v, 2.0)
    # a vertex on an edge with an end exactly at S* lies on that node
    p = r.triangles.reshape(-1, 3)
    on_node = np.all(p == np.round(p), axis=1)
    assert on_node.any()
    node_vals = v[tuple(np.round(p[on_node]).astype(int)[:, ::-1].T)]
    assert (node_vals == 2.0).all()


def test_outside_nodes_close_the_surface_at_midpoints_with_caps():
    v = np.ones((4, 4, 4), np.float32)
    v[1:3, 1:3, 1:3] = 5.0
    v[2, 2, 2] = np.nan
    act = np.ones(v.shape, bool)
    act[1, 1, 1] = False
    pv = mc.prepare_values(v, act)
    assert (pv.nonfinite, pv.inactive) == (1, 1)
    assert (pv.vmin, pv.vmax) == (1.0, 5.0)
    r = mc.marching_cubes(pv, 3.0, caps=True)
    assert np.isfinite(r.triangles).all()
    p = r.triangles.reshape(-1, 3)
    # a vertex next to an outside node sits halfway
    near = np.all(np.abs(p - 1.5) <= 0.5 + 1e-6, axis=1) | np.all(np.abs(p - 2.5) <= 0.5, axis=1)
    assert near.any()
    assert mc.classify(pv.values, 3.0, caps=True)[1, 1, 1] & 1  # the inactive node is below
    # open (the default): the 8 cells around each outside node make nothing
    assert mc.classify(pv.values, 3.0)[1, 1, 1] == 0
    assert 0 < mc.marching_cubes(pv, 3.0).count < r.count


def test_classify_is_the_papers_case_number():
    rng = np.random.default_rng(1)
    v = rng.random((3, 4, 5)).astype(np.float32)
    K = mc.classify(v, 0.5)
    want = np.zeros((2, 3, 4), int)
    for p, (cx, cy, cz) in enumerate(mc.CORNERS):
        want += (v[cz : cz + 2, cy : cy + 3, cx : cx + 4] < 0.5) << p
    assert np.array_equal(K, want)


# --- scikit-image as the oracle ---------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1])
def test_counts_and_area_against_scikit_image(seed):
    measure = pytest.importorskip("skimage.measure")
    v = smooth_random((30, 34, 38), seed)
    level = float(np.median(v)) + 1e-4
    r = mc.marching_cubes(v, level)
    verts, faces, _, _ = measure.marching_cubes(v, level, method="lorensen")
    amb = mc.ambiguous_cell_count(v, level)
    assert amb > 0
    # the tables may differ only in cells with an ambiguous face (by at most 4 triangles each)
    assert abs(r.count - len(faces)) <= 4 * amb
    assert mc.surface_area(r.triangles) == pytest.approx(
        measure.mesh_surface_area(verts, faces), rel=5e-3)


def test_equal_to_scikit_image_without_ambiguous_cells():
    measure = pytest.importorskip("skimage.measure")
    f, level = sphere_field(28, (13.4, 14.2, 13.9), 9.5)
    assert mc.ambiguous_cell_count(f, level) == 0
    r = mc.marching_cubes(f, level)
    verts, faces, _, _ = measure.marching_cubes(f, level, method="lorensen")
    assert r.count == len(faces)
    # the same vertex set (skimage works in (z, y, x) index order)
    ours = np.unique(np.round(r.triangles.reshape(-1, 3).astype(np.float64), 4), axis=0)
    theirs = np.unique(np.round(verts[:, ::-1].astype(np.float64), 4), axis=0)
    assert ours.shape == theirs.shape
    assert np.abs(ours - theirs).max() < 1e-3
    assert mc.surface_area(r.triangles) == pytest.approx(
        measure.mesh_surface_area(verts, faces), rel=1e-4)


# --- patch ranges -------------------------------------------------------------------------------
@pytest.mark.parametrize(("L", "slab_bytes"), [(1, 1 << 30), (4, 1 << 30), (8, 1 << 30),
                                               (4, 64)])
def test_patch_ranges_match_brute_force(L, slab_bytes, monkeypatch):
    monkeypatch.setattr(mc, "RANGES_SLAB_BYTES", slab_bytes)  # 64: one slice per slab
    v = smooth_random((5, 21, 19), 4, passes=1)
    r = mc.patch_ranges(v, L)
    D = L + 1
    n_p, m_p, q_p = mc.patch_grid(v.shape, L)
    assert r.shape == (q_p, m_p, n_p, 2)
    for k in range(q_p):  # a few dozen patches
        for i in range(m_p):
            for j in range(n_p):
                block = v[k : k + 2, D * i : D * i + D + 1, D * j : D * j + D + 1]
                assert r[k, i, j, 0] == block.min() and r[k, i, j, 1] == block.max()
    # slices along x: the same ranges as the transposed array's along z
    rx = mc.patch_ranges(v, L, axis="x")
    assert np.array_equal(rx, mc.patch_ranges(np.ascontiguousarray(v.transpose(2, 0, 1)), L))


def test_live_patch_cells_cover_every_crossed_cell():
    v = smooth_random((9, 40, 37), 5)
    level = float(np.median(v))
    K = mc.classify(v, level)
    crossed = int(((K != 0) & (K != 255)).sum())
    live = mc.cells_in_live_patches(v, level, 8)
    assert crossed <= live <= K.size
    assert mc.cells_in_live_patches(v, float(v.max()) + 1, 8) == 0


# --- the synthetic displacement ------------------------------------------------------------------
def test_displacement_is_deterministic_and_fingers_grow():
    a = displacement_field((40, 24, 20), steps=5, seed=3)
    b = displacement_field((40, 24, 20), steps=5, seed=3)
    c = displacement_field((40, 24, 20), steps=5, seed=4)
    assert np.array_equal(a.step(4), b.step(4))
    assert not np.array_equal(a.step(4), c.step(4))
    water = [int((a.step(k) >= 0.5).sum()) for k in range(5)]
    assert water == sorted(water) and water[0] < water[-1]
    # the front grows rougher: its area per cross-section increases
    areas = [mc.surface_area(mc.marching_cubes(a.step(k), 0.5).triangles) for k in (0, 4)]
    assert areas[1] > 1.3 * areas[0]
    s = a.step(2)
    assert s.dtype == np.float32 and 0.09 < s.min() and s.max() <= 0.85 + 1e-6
    p = a.property_step("PRESSURE", 2)
    assert p.shape == s.shape and p.min() >= 200 - 1e-3 and p.max() <= 300 + 1e-3
