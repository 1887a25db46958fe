"""The depth compositor and the bookkeeping of parts on workers, on arrays (no GL)."""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import numpy as np
import pytest

from geoshade.compute.composite import (
    FAR,
    Tile,
    assign,
    composite,
    footprint,
    front_to_back,
    reassign,
    spatial_order,
)
from geoshade.compute.voxels.bricks import plan_bricks
from geoshade.models.volume import Box

W, H = 24, 16


def _sequential(parts, background):
    """The oracle: one process drawing the parts in rank order into one target, with the depth
    test GL_LESS (a later fragment of equal depth loses) and the cleared depth 1.0."""
    color = np.empty((H, W, 4), np.uint8)
    color[:] = background
    depth = np.full((H, W), 1.0, np.float32)
    for c, d in parts:  # in rank order
        win = d < depth
        depth[win] = d[win]
        color[win] = c[win]
    return color, depth


def _random_parts(rng, n):
    """Parts with depths on a coarse grid (many exact ties) and holes (depth 1.0: not drawn)."""
    out = []
    for _ in range(n):
        d = (rng.integers(1, 6, (H, W)) / 8).astype(np.float32)
        d[rng.random((H, W)) < 0.3] = FAR
        c = rng.integers(0, 256, (H, W, 4), dtype=np.uint8)
        out.append((c, d))
    return out


def _tiles_of(parts, assignment):
    """One tile per worker, its parts merged in rank order (as render_tile does)."""
    tiles = []
    for parts_of_worker in assignment:
        t = Tile.empty((0, 0, W, H), len(parts))
        for rank in sorted(parts_of_worker):
            c, d = parts[rank]
            t.merge(c, d, rank, (0, 0, W, H))
        tiles.append(t)
    return tiles


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_composite_equals_one_process_depth_test_on_ties(seed):
    rng = np.random.default_rng(seed)
    parts = _random_parts(rng, 7)
    bg = (12, 34, 56, 255)
    want_c, want_d = _sequential(parts, bg)
    ties = sum(int(np.sum((a[1] == b[1]) & (a[1] < 1)))
               for a, b in itertools.combinations(parts, 2))
    assert ties > 100  # the case under test: many pixels where parts meet at equal depth
    for assignment in ([[0, 1, 2, 3, 4, 5, 6]], [[0, 2, 4, 6], [1, 3, 5]],
                       [[6], [0, 5], [1, 2, 3, 4]]):
        tiles = _tiles_of(parts, assignment)
        for order in (tiles, tiles[::-1]):  # tiles arrive in any order
            c, d, _ = composite(order, (W, H), bg, n_parts=len(parts))
            np.testing.assert_array_equal(c, want_c)
            np.testing.assert_array_equal(d, want_d)


def test_equal_depth_lower_rank_wins_and_holes_never_win():
    a = Tile.empty((0, 0, 3, 1), 4)
    b = Tile.empty((0, 0, 3, 1), 4)
    a.depth[:] = (0.5, 0.5, FAR)
    a.rank[:] = 3
    a.color[:] = 100
    b.depth[:] = (0.5, FAR, FAR)   # pixel 1: a hole of a lower rank must not win over a's 0.5
    b.rank[:] = 1
    b.color[:] = 200
    for tiles in ([a, b], [b, a]):
        c, d, r = composite(tiles, (3, 1), background=(7, 7, 7, 7))
        assert c[0, :, 0].tolist() == [200, 100, 7]
        assert r[0, :2].tolist() == [1, 3]
        assert d[0].tolist() == [0.5, 0.5, 1.0]


def test_tiles_smaller_than_the_picture_land_where_they_belong():
    t = Tile.empty((5, 3, 2, 2), 2)
    t.depth[:] = 0.25
    t.rank[:] = 0
    t.color[:] = 9
    c, d, _ = composite([t], (W, H), (0, 0, 0, 0))
    assert np.argwhere(d < 1).tolist() == [[3, 5], [3, 6], [4, 5], [4, 6]]
    assert (c[d < 1] == 9).all() and (c[d == 1] == 0).all()
    with pytest.raises(ValueError, match="outside"):
        composite([Tile.empty((W - 1, 0, 2, 1))], (W, H))


def test_footprint_contains_every_projected_point_of_the_box():
    from geoshade.render.camera import Camera

    rng = np.random.default_rng(4)
    lo, hi = np.array([3.0, -2.0, 1.0]), np.array([7.0, 5.0, 4.0])
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    for az in (0, 35, 120, 250):
        cam = Camera.framed(np.array([[0, -5, 0], [10, 10, 8.0]]), "iso", azimuth=az,
                            elevation=30).with_aspect(W / H)
        pmv = cam.projection_matrix() @ cam.view_matrix()
        x0, y0, w, h = footprint(corners, pmv, (W, H), pad=0)
        pts = lo + rng.random((2000, 3)) * (hi - lo)
        p = np.c_[pts, np.ones(len(pts))] @ pmv.T
        px = (p[:, 0] / p[:, 3] + 1) / 2 * W
        py = (1 - p[:, 1] / p[:, 3]) / 2 * H
        on = (px >= 0) & (px < W) & (py >= 0) & (py < H)
        assert on.any()
        assert (px[on] >= x0).all() and (px[on] <= x0 + w).all()
        assert (py[on] >= y0).all() and (py[on] <= y0 + h).all()
    # a corner behind the eye: the whole picture (the projection says nothing there)
    eye_inside = np.eye(4)
    eye_inside[3] = (0, 0, -1, 0)   # w = -z: points at z > 0 are behind the eye
    assert footprint(np.array([[0, 0, -1.0], [0, 0, 1.0]]), eye_inside, (W, H)) == (0, 0, W, H)


def test_front_to_back_is_the_bricked_visuals_drawing_order():
    from geoshade.render.camera import Camera
    from geoshade.render.visuals.bricked.visual import BrickedVisual

    box = Box((4, 0, 8), (100, 70, 60))
    bricks = plan_bricks(box, 32)
    model = np.diag([0.5, 0.5, 2.0, 1.0])
    for az in (10, 100, 200):
        cam = Camera.framed(np.array([[0, 0, 0], [50, 35, 120.0]]), "iso", azimuth=az)
        order = BrickedVisual._order(SimpleNamespace(bricks=bricks, box=box), cam, model)
        rel = np.array([np.subtract(b.offset, box.offset) for b in bricks], float)
        ranks = front_to_back(rel + np.array([b.size for b in bricks]) / 2, model, cam.eye)
        assert [int(i) for i in np.argsort(ranks)] == [int(i) for i in order]


def test_assignment_is_balanced_contiguous_and_stable():
    rng = np.random.default_rng(5)
    weights = rng.integers(1, 100, 37)
    cells = rng.integers(0, 8, (37, 3))
    order = spatial_order(cells)
    for n in (1, 2, 3, 8):
        runs = assign(weights, n, order)
        flat = [p for r in runs for p in r]
        assert sorted(flat) == list(range(37))                    # every part exactly once
        assert flat == [int(i) for i in order]                    # runs of the curve, in order
        assert all(runs), "every worker gets parts"
        loads = [int(weights[r].sum()) for r in runs]
        assert max(loads) - min(loads) <= 2 * int(weights.max())  # balanced up to a part or two
        assert assign(weights, n, order) == runs                   # the same every time


def test_reassign_gives_lost_parts_to_the_least_loaded_survivors():
    weights = np.array([5, 1, 1, 1, 3, 3])
    got = reassign([[0, 1], [2, 3], [4, 5]], [0], weights)
    assert got == [[], [2, 3, 0], [4, 5, 1]]
    assert sorted(p for r in got for p in r) == list(range(6))
    with pytest.raises(ValueError, match="no worker"):
        reassign([[0], [1]], [0, 1], weights[:2])
