"""Picking's ray casting (geoshade.compute.pick) against brute-force numpy oracles, no GL.

The oracles are written here from scratch: points sampled densely along the ray for the cell
walk, a linear solve for the triangle test, :func:`marching_cubes` over the whole field for the
isosurface of a few cells, and every triangle of every shown cell for a corner-point grid.
"""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.mesh.marching_cubes import OUTSIDE, marching_cubes, prepare_values
from geoshade.compute.pick import (
    Ray,
    cell_corners,
    cell_isosurface,
    column_boxes,
    grid_ray_hit,
    quad_triangles,
    ray_boxes,
    ray_cells,
    ray_triangles,
    unproject,
)

# --- an independent face table: the quads of a hexahedron split along the diagonal that joins
# the face's corner nearest (0,0,0) (minus faces) or (1,1,1) (plus faces) to its opposite corner
# (corner c = a + 2b + 4c' along i, j, k) -- what the renderer's FACE_CORNERS says in words


def _oracle_quads() -> np.ndarray:
    """(6, 4): corners (A, B, C, D) of each face 0..5 = I+ J+ K+ I- J- K-, counter-clockwise seen
    from outside the cell in index space, A at (1,1,1) (plus faces) or (0,0,0) (minus)."""
    out = np.zeros((6, 4), np.int64)
    for f in range(6):
        axis, side = f % 3, int(f < 3)
        on = [c for c in range(8) if (c >> axis) & 1 == side]
        a = 7 if side else 0
        opposite = next(c for c in on if bin(c ^ a).count("1") == 2)
        b, d = (c for c in on if c not in (a, opposite))
        p = {c: np.array([c & 1, c >> 1 & 1, c >> 2 & 1], float) for c in on}
        outward = np.zeros(3)
        outward[axis] = 1 if side else -1
        if np.cross(p[opposite] - p[a], p[d] - p[b]) @ outward < 0:
            b, d = d, b
        out[f] = (a, b, opposite, d)
    return out


ORACLE_QUADS = _oracle_quads()
#: (6, 2, 3): the two triangles ABC and ACD of each face
ORACLE_TRIANGLES = ORACLE_QUADS[:, [[0, 1, 2], [0, 2, 3]]]


def oracle_ray_triangle(o, d, tri) -> np.ndarray:
    """t of the ray against (n, 3, 3) triangles by solving o + t d = A + u (B-A) + v (C-A)
    (inf where missed or outside 0 <= t <= 1)."""
    tri = np.asarray(tri, float).reshape(-1, 3, 3)
    a = tri[:, 0]
    m = np.stack([tri[:, 1] - a, tri[:, 2] - a, np.broadcast_to(-np.asarray(d, float), a.shape)],
                 axis=2)
    det = np.linalg.det(m)
    ok = np.abs(det) > 1e-12 * np.abs(m).max(axis=(1, 2), initial=0) ** 3
    sol = np.full((len(tri), 3), np.nan)
    if ok.any():
        sol[ok] = np.linalg.solve(m[ok], (np.asarray(o, float) - a)[ok][..., None])[..., 0]
    u, v, t = sol.T
    with np.errstate(invalid="ignore"):
        hit = ok & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t >= 0) & (t <= 1)
    return np.where(hit, t, np.inf)


def oracle_faces(grid, shown, hide_faults=False):
    """(cells (n, 3), face (n,), triangles (n, 2, 3, 3)) drawn: the plain-loop reference of the
    visible faces, without the fault faces against a shown cell when they are hidden."""
    from geoshade.compute.grid.faces import brute_force_visible_faces

    fs = brute_force_visible_faces(grid, shown)
    keep = ~(fs.fault & fs.neighbour_shown) if hide_faults else np.ones(len(fs.face), bool)
    cells, face = fs.cells[keep].astype(np.int64), fs.face[keep].astype(np.int64)
    corners = grid.corners()[cells[:, 0], cells[:, 1], cells[:, 2]]  # (n, 8, 3)
    tri = corners[np.arange(len(face))[:, None, None], ORACLE_TRIANGLES[face]]
    return cells, face, tri


def oracle_grid_hit(grid, faces, o, d, keep=None) -> np.ndarray:
    """t of the ray for each cell (nx, ny, nz): both triangles of every drawn face (``faces``
    from :func:`oracle_faces`, only those ``keep`` says; inf where missed or nothing drawn)."""
    cells, _, tri = faces
    if keep is not None:
        cells, tri = cells[keep], tri[keep]
    t_face = oracle_ray_triangle(o, d, tri).reshape(-1, 2).min(axis=1)
    t = np.full(grid.dims, np.inf)
    np.minimum.at(t, (cells[:, 0], cells[:, 1], cells[:, 2]), t_face)
    return t


# --- the cell walk --------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(6))
def test_ray_cells_are_the_cells_a_dense_sampling_visits(seed):
    rng = np.random.default_rng(seed)
    shape = np.array([5, 4, 6])
    o = rng.uniform(-3, 9, 3)
    target = rng.uniform(0.5, shape - 0.5)
    if seed == 0:
        o[2] = target[2]  # parallel to a slab
    d = target - o
    ray = Ray(o, d * 2.0, 0.0, 1.0)
    cells, t_in, t_out = ray_cells(ray, shape)
    assert np.all(np.diff(t_in) > 0) and np.allclose(t_in[1:], t_out[:-1])
    mid = ray.at(0.5 * (t_in + t_out))
    assert np.array_equal(np.floor(mid).astype(int), cells)  # each piece lies in its cell
    t = np.linspace(0, 1, 200001)
    p = ray.at(t)
    inside = np.all((p >= 0) & (p < shape), axis=1)
    seen = np.floor(p[inside]).astype(int)
    keep = np.concatenate([[True], np.any(seen[1:] != seen[:-1], axis=1)])
    want = [tuple(c) for c in seen[keep]]
    got = [tuple(c) for c in cells]
    # a corner grazed between two samples may be missed by the sampling, never invented by it
    assert set(want) <= set(got) and [c for c in got if c in set(want)] == want
    assert {tuple(c) for c in cells[t_out - t_in > 1e-4]} <= set(want)


def test_ray_cells_of_a_vertical_ray_and_a_miss():
    cells, t_in, _ = ray_cells(Ray(np.array([1.5, 2.5, 9.0]), np.array([0, 0, -12.0])),
                               (3, 4, 5))
    assert cells.tolist() == [[1, 2, k] for k in (4, 3, 2, 1, 0)]
    assert t_in[0] == pytest.approx(4 / 12)
    assert ray_cells(Ray(np.array([9.0, 9, 9]), np.array([1.0, 0, 0])), (3, 4, 5))[0].size == 0


def test_ray_boxes_parallel_and_clipped():
    ray = Ray(np.array([0.5, 0.5, -1.0]), np.array([0.0, 0.0, 1.0]), 0.0, 1.5)
    t_in, t_out = ray_boxes(ray, np.array([[0, 0, 0], [1, 1, 0], [2, 0, 0]]),
                            np.array([[1, 1, 1], [2, 2, 1], [3, 1, 1]]))
    assert t_in[0] == 1.0 and t_out[0] == 1.5  # clipped at t1
    assert t_in[1] > t_out[1] and t_in[2] > t_out[2]


# --- triangles -------------------------------------------------------------------------------
def test_ray_triangles_equal_a_linear_solve():
    rng = np.random.default_rng(3)
    tri = rng.uniform(-1, 1, (300, 3, 3))
    for _ in range(5):
        o = rng.uniform(-3, 3, 3)
        d = rng.uniform(-1, 1, 3) * 6 - o
        ray = Ray(o, d)
        t, u, v = ray_triangles(ray, tri)
        want = oracle_ray_triangle(o, d, tri)
        assert np.array_equal(np.isfinite(t), np.isfinite(want))
        assert np.allclose(t[np.isfinite(t)], want[np.isfinite(want)])
        hit = np.isfinite(t)
        p = (1 - u - v)[hit, None] * tri[hit, 0] + u[hit, None] * tri[hit, 1] \
            + v[hit, None] * tri[hit, 2]
        assert np.allclose(p, o + t[hit, None] * d)


def test_a_ray_through_a_shared_edge_hits_both_triangles():
    sq = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    tri = quad_triangles(sq, [[0, 1, 2, 3]])[0]
    t, _, _ = ray_triangles(Ray(np.array([0.5, 0.5, 1.0]), np.array([0, 0, -2.0])), tri)
    assert t.tolist() == [0.5, 0.5]


def test_unproject_spans_near_to_far():
    from geoshade.render.camera import Camera

    cam = Camera.framed(np.array([[0, 0, 0], [4, 3, 2.0]]), view="iso", aspect=4 / 3)
    vp = cam.projection_matrix() @ cam.view_matrix()
    r = unproject(np.linalg.inv(vp), 0.1, -0.2)
    for t, z in ((0.0, -1.0), (1.0, 1.0), (0.5, None)):
        c = vp @ np.array([*r.at(t), 1.0])
        assert np.allclose(c[:2] / c[3], [0.1, -0.2])
        if z is not None:
            assert c[2] / c[3] == pytest.approx(z)


# --- marching cubes of a few cells ---------------------------------------------------------------
def test_cell_isosurface_equals_marching_cubes():
    rng = np.random.default_rng(0)
    vals = rng.random((5, 6, 7)).astype(np.float32)
    vals[2, 3, 4] = np.nan
    pv = prepare_values(vals)
    pos = rng.uniform(-0.2, 0.2, (5, 6, 7, 3)) + np.stack(
        np.meshgrid(np.arange(7), np.arange(6), np.arange(5), indexing="ij"), -1
    ).transpose(2, 1, 0, 3)
    ref = marching_cubes(pv, 0.45, positions=pos, caps=True)  # cell_isosurface closes: caps
    nz, ny, nx = vals.shape
    z, y, x = np.meshgrid(np.arange(nz - 1), np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    cells = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)  # the reference's cell order
    from geoshade.compute.mesh.marching_cubes import CORNERS

    node = cells[:, None] + CORNERS[None]
    v = pv.values[node[..., 2], node[..., 1], node[..., 0]]
    p = pos[node[..., 2], node[..., 1], node[..., 0]]
    xprop = p[..., 0]  # a quantity equal to x: interpolated like the positions
    tri, owner, props = cell_isosurface(v, 0.45, p, xprop)
    assert owner.tolist() == ref.cells.tolist()
    assert np.allclose(tri, ref.triangles, atol=1e-6)
    assert np.allclose(props, tri[..., 0])
    assert bool((v == OUTSIDE).any())


# --- corner-point grids ------------------------------------------------------------------------
def _random_ray(rng, grid):
    b = grid.bounds()
    span = b[1] - b[0]
    target = b[0] + rng.uniform(0.1, 0.9, 3) * span
    direction = rng.normal(size=3)
    direction[2] *= 0.3
    direction /= np.linalg.norm(direction)
    origin = target - direction * 2 * np.linalg.norm(span)
    return Ray(origin, direction * 4 * np.linalg.norm(span))


@pytest.mark.parametrize("seed", range(4))
def test_grid_ray_hit_is_the_brute_force_nearest_cell(seed):
    from geoshade.render.visuals.grid.layout import FACE_CORNER_TABLE

    g = synthetic_grid(7, 6, 4, faults=True, seed=seed)
    rng = np.random.default_rng(seed)
    shown = g.active & (rng.random(g.dims) > 0.3)
    depth = g.bounds()[:, 2]
    hits = 0
    hide = bool(seed % 2)
    faces = oracle_faces(g, shown, hide)
    for _ in range(12):
        ray = _random_ray(rng, g)
        got = grid_ray_hit(g.coord, g.zcorn, shown, ray, FACE_CORNER_TABLE, depth,
                           hide_faults=hide, chunk_cells=8)
        t = oracle_grid_hit(g, faces, ray.origin, ray.direction)
        if not np.isfinite(t).any():
            assert got is None
            continue
        hits += 1
        assert got is not None
        assert got.t == pytest.approx(t.min(), abs=1e-9)
        assert t[got.cell] <= t.min() + 1e-9  # the picked cell is hit first (ties allowed)
        assert np.allclose(got.point, ray.at(got.t))
    assert hits >= 4


def test_grid_ray_hit_skips_hidden_cells_and_sees_only_drawn_faces():
    from geoshade.render.visuals.grid.layout import FACE_CORNER_TABLE

    g = synthetic_grid(5, 4, 3, faults=False, inactive_fraction=0, seed=1)
    depth = g.bounds()[:, 2]
    c = cell_corners(g.coord, g.zcorn, [[2, 1, 0]])[0]
    top = c[[0, 1, 2, 3]].mean(axis=0)
    ray = Ray(top - np.array([0, 0, 50.0]), np.array([0, 0, 1000.0]))  # straight down
    shown = g.active.copy()
    hit = grid_ray_hit(g.coord, g.zcorn, shown, ray, FACE_CORNER_TABLE, depth)
    assert hit.cell == (2, 1, 0) and hit.face == 5  # K- (the top)
    shown[2, 1, 0] = False
    assert grid_ray_hit(g.coord, g.zcorn, shown, ray, FACE_CORNER_TABLE, depth).cell == (2, 1, 1)
    # a ray that starts inside the cells meets the faces drawn, not the faces between cells
    inside = Ray(ray.at(0.05) + np.array([0, 0, c[4, 2] - c[0, 2]]) * 1.5, ray.direction)
    hit = grid_ray_hit(g.coord, g.zcorn, g.active, inside, FACE_CORNER_TABLE, depth)
    assert hit.cell == (2, 1, 2) and hit.face == 2  # the bottom of the grid, seen from inside
    shown[:] = False
    assert grid_ray_hit(g.coord, g.zcorn, shown, ray, FACE_CORNER_TABLE, depth) is None


def test_drawn_faces_are_the_visible_faces():
    from geoshade.compute.grid.faces import visible_faces
    from geoshade.compute.pick import drawn_faces

    g = synthetic_grid(6, 5, 4, faults=True, seed=3)
    shown = g.active & (np.random.default_rng(1).random(g.dims) > 0.25)
    fs = visible_faces(g, shown)
    want = np.zeros((*g.dims, 6), bool)
    want[fs.cells[:, 0], fs.cells[:, 1], fs.cells[:, 2], fs.face] = True
    cells = np.argwhere(shown)
    got = drawn_faces(g.zcorn, shown, cells)
    assert np.array_equal(got, want[shown]) and got.any()
    hidden = drawn_faces(g.zcorn, shown, cells, hide_faults=True)
    keep = ~(fs.fault & fs.neighbour_shown)
    want[:] = False
    want[fs.cells[keep, 0], fs.cells[keep, 1], fs.cells[keep, 2], fs.face[keep]] = True
    assert np.array_equal(hidden, want[shown]) and (got & ~hidden).any()


def test_column_boxes_hold_their_cells():
    g = synthetic_grid(6, 5, 3, seed=2)
    lo, hi = column_boxes(g.coord, g.bounds()[:, 2])
    corners = g.corners()
    assert np.all(corners.min(axis=(2, 3)) >= lo - 1e-9)
    assert np.all(corners.max(axis=(2, 3)) <= hi + 1e-9)
    assert np.allclose(cell_corners(g.coord, g.zcorn, [[3, 2, 1]])[0], corners[3, 2, 1])
