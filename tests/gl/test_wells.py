"""Well tubes (the paper's impostor from lines_adjacency) and sphere impostors: coverage and
depth, measured in pixels against the radius."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.grid import GridView
from geoshade.models.grid import WellPath
from geoshade.render.camera import Camera
from geoshade.render.target import Offscreen
from geoshade.render.visuals.wells.visual import WellsVisual, tube_buffers
from tests.gl.grid_support import make_grid

SIZE = (64, 64)



def render_wells(ctx, shading, paths, markers=(), radius=1.0, view="top", bounds=None,
                 exact=True):
    bounds = np.array([[-10, -10, -10], [10, 10, 10.0]]) if bounds is None else bounds
    cam = Camera.framed(bounds, view=view, ortho=True)
    target = Offscreen(ctx, SIZE)
    vis = WellsVisual(ctx, paths, markers, radius=radius, exact=exact)
    try:
        target.clear((0, 0, 0, 0))
        vis.draw(cam, np.eye(4), shading)
        return target.read(), cam
    finally:
        vis.release()
        target.release()


def disc_stats(mask, cam):
    """Pixel radius of a covered disc from its area, its centre, and the px per world unit."""
    area = mask.sum()
    ys, xs = np.nonzero(mask)
    px_per_unit = SIZE[1] / (2 * cam.half_height)
    return np.sqrt(area / np.pi), (xs.mean() + 0.5, ys.mean() + 0.5), px_per_unit


def test_vertical_tube_from_the_top_is_a_disc_of_the_radius(ctx, shading):
    path = np.array([[0, 0, -8.0], [0, 0, 0.0], [0, 0, 8.0]])
    img, cam = render_wells(ctx, shading, [path], radius=3.0)
    mask = img[..., 3] > 0
    r_px, (cx, cy), ppu = disc_stats(mask, cam)
    assert r_px == pytest.approx(3.0 * ppu, abs=0.6)
    assert (cx, cy) == pytest.approx((32, 32), abs=0.5)
    # every covered pixel lies within the radius, every pixel well inside it is covered
    yy, xx = np.mgrid[0:64, 0:64] + 0.5
    d = np.hypot(xx - 32, yy - 32)
    assert d[mask].max() <= 3.0 * ppu + 1.0
    assert mask[d < 3.0 * ppu - 1.0].all()


@pytest.mark.parametrize("exact", [True, False])
def test_horizontal_tube_is_a_band_two_radii_wide(ctx, shading, exact):
    path = np.array([[-8, 0, 0.0], [-2, 0, 0.0], [3, 0, 0.0], [8, 0, 0.0]])
    img, cam = render_wells(ctx, shading, [path], radius=2.0, exact=exact)
    mask = img[..., 3] > 0
    ppu = SIZE[1] / (2 * cam.half_height)
    cols = mask[:, 20:44].sum(axis=0)            # away from the rounded ends
    assert np.all(np.abs(cols - 4.0 * ppu) <= 1.0)
    # shaded as a cylinder: the light (from +y, above) leaves the -y rim darker than the middle
    profile = img[mask[:, 32], 32, :3].astype(int).sum(-1)   # rows from +y (top) to -y
    assert profile.std() > 5
    assert profile[len(profile) // 2] > profile[-1]


def test_bent_tube_has_no_gaps(ctx, shading):
    path = np.array([[-8, -6, 0.0], [0, 2, 0.0], [8, -6, 0.0]])   # a 90 degree bend
    img, cam = render_wells(ctx, shading, [path], radius=1.5)
    mask = img[..., 3] > 0
    ppu = SIZE[1] / (2 * cam.half_height)
    # sample the polyline densely: every point of the axis is covered, with its neighbourhood
    t = np.linspace(0, 1, 200)[:, None]
    pts = np.concatenate([path[0] + t * (path[1] - path[0]), path[1] + t * (path[2] - path[1])])
    px = np.clip((pts[:, 0] * ppu + 32).astype(int), 0, 63)
    py = np.clip((32 - pts[:, 1] * ppu).astype(int), 0, 63)
    assert mask[py, px].all()


def test_sphere_impostor_is_a_disc_and_writes_depth(ctx, shading):
    # a marker alone, seen from the front: a disc of the marker radius
    img, cam = render_wells(ctx, shading, [], markers=[np.array([[1.0, 0.0, 2.0]])],
                            radius=2.0, view="front")
    mask = img[..., 3] > 0
    r_px, (cx, cy), ppu = disc_stats(mask, cam)
    assert r_px == pytest.approx(2.0 * 1.8 * ppu, abs=0.6)
    assert (cx, cy) == pytest.approx((32 + 1.0 * ppu, 32 - 2.0 * ppu), abs=0.6)


def test_sphere_depth_composes_with_the_grid(ctx):
    """A marker 3 m below the top of the grid, radius 5.4 m: from the top only the cap above
    the grid shows, a disc of radius sqrt(5.4² - 3²)."""
    g = make_grid(4, 4, 2, dx=10, dy=10, dz=5, top=1000.0, dip=(0.0, 0.0))
    well = WellPath("W", np.array([[200.0, 200, 900], [200, 200, 901]]),
                    markers=np.array([[20.0, 20.0, 1003.0]]))
    view = GridView(g, size=SIZE, ctx=ctx, wells=[well], well_radius=3.0)
    view.shading = {"light_dir": (0.0, 0.0, 1.0), "material": (1.0, 0.0, 0.0, 1.0)}
    try:
        cam = view.camera(view="top", ortho=True, zoom=1.0)
        img, st = view.draw(cam, frames=1)
    finally:
        view.release()
    marker = np.all(np.abs(img[..., :3].astype(int) - [242, 140, 26]) <= 3, axis=-1)
    r_px, _, ppu = disc_stats(marker, cam)
    assert r_px == pytest.approx(np.sqrt(5.4**2 - 3**2) * ppu, abs=0.7)
    assert st["wells"] == 1 and st["gpu_bytes"] > 0


def test_tube_buffers_extrapolate_the_ends():
    v, i = tube_buffers([np.zeros((1, 3)), np.array([[0, 0, 0], [1, 0, 0.0]])])
    assert v.tolist() == [[-1, 0, 0], [0, 0, 0], [1, 0, 0], [2, 0, 0]]
    assert i.tolist() == [[0, 1, 2, 3]]
