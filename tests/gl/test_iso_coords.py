"""The isosurface of a field on uneven nodes (a netCDF file's own coordinates, issue 31 item 2):
the GPU's surface, its mesh and its picks against the CPU marching cubes placed at the same
nodes, and against the field's analytic values."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.compute.mesh.marching_cubes import marching_cubes, prepare_values
from geoshade.models import FieldSeries
from tests.gl.test_pick import (
    SIZE,
    check_iso,
    key_map,
    pick_map,
    pixels_to_check,
    silhouette_agrees,
)

pytestmark = pytest.mark.gl

#: uneven layer centres of a survey's model stored top-down (2 m at the top, 200 m at depth)
DEPTHS = np.array([1.0, 4.0, 11.0, 28.0, 70.0, 175.0, 350.0])


def _linear_field():
    """v = depth + 0.1 x on x 0..900, y 0..700, z = -depth: the surface v = L is a plane."""
    x, y, z = np.arange(0, 1000, 100.0), np.arange(0, 800, 100.0), -DEPTHS[::-1]
    zz, _, xx = np.meshgrid(z, y, x, indexing="ij")
    return FieldSeries((-zz + 0.1 * xx).astype(np.float32), coords=(x, y, z), name="kh")


def test_mesh_lies_on_the_analytic_surface(ctx):
    f = _linear_field()
    assert f.is_rectilinear
    with geoshade.view(f, level=100.0, size=(160, 120), ctx=ctx) as v:
        _, st = v.draw()
        m = v.mesh()
    assert st["nodes"] == "rectilinear" and m.n_faces == st["triangles"] > 0
    x, z = m.vertices[:, 0], m.vertices[:, 2]
    np.testing.assert_allclose(-z + 0.1 * x, 100.0, atol=1e-3)   # exact on every vertex


def test_gpu_triangles_equal_the_cpu_reference_at_the_nodes(ctx):
    base = displacement_field((20, 12, 7), steps=2, seed=2)
    coords = (np.arange(20) * 5.0, np.arange(12) * 5.0, -DEPTHS[::-1])
    f = FieldSeries(base.values, coords=coords, name="S")
    with geoshade.view(f, level=0.5, step=1, size=(160, 120), ctx=ctx) as v:
        v.draw()
        gpu = v.mesh()
    ref = marching_cubes(prepare_values(f.step(1), f.active), 0.5, f.node_positions())
    assert gpu.n_faces == len(ref.triangles)
    a = np.unique(np.round(gpu.triangles().reshape(-1, 3), 3), axis=0)
    b = np.unique(np.round(np.asarray(ref.triangles, float).reshape(-1, 3), 3), axis=0)
    np.testing.assert_allclose(a, b, atol=2e-3)


def test_pick_is_the_first_point_of_the_surface(ctx):
    base = displacement_field((24, 16, 7), steps=2, seed=0)
    coords = (np.arange(24) * 4.0, np.arange(16) * 4.0, -DEPTHS[::-1] / 4)
    f = FieldSeries(base.values, coords=coords, name="S")
    exag = 2.0
    with geoshade.view(f, level=0.5, step=1, size=SIZE, exaggeration=exag, ctx=ctx) as v:
        img, _ = v.draw(count=False)
        tri = marching_cubes(prepare_values(f.step(1), f.active), 0.5,
                             f.node_positions()).triangles
        world = np.asarray(tri, float) * np.array([1.0, 1.0, exag])
        picks = pick_map(v)
        keys = key_map(picks, lambda p: p.index[0] + 100 * p.index[1] + 10000 * p.index[2])
        pixels, _ = pixels_to_check(keys, step=3)
        for x, y in pixels[::2]:
            check_iso(v, world, x, y, picks[y, x], exag)
        assert silhouette_agrees(img, picks) == 0


def test_framing_follows_the_uneven_bounds(ctx):
    f = _linear_field()
    with geoshade.view(f, level=100.0, size=(160, 120), exaggeration=3, ctx=ctx) as v:
        b = v.bounds()
    assert b.tolist() == [[0.0, 0.0, -350.0 * 3], [900.0, 700.0, -1.0 * 3]]
