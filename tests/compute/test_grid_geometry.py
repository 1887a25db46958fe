"""Grid geometry: centres, pillar points, node depths, conformity, 16-bit ZCORN packing."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade.compute.grid.geometry as gg
from geoshade.compute.grid.geometry import (
    cell_centres,
    is_conforming,
    node_depths,
    pillar_points,
    zcorn_dequantise,
    zcorn_quantise,
)
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.models import CornerPointGrid


def test_cell_centres_equal_corner_means(monkeypatch):
    g = synthetic_grid(7, 5, 6, seed=2)
    ref = g.corners().mean(axis=3)
    monkeypatch.setattr(gg, "SLAB_CELLS", 40)  # several slabs
    c = cell_centres(g)
    assert np.allclose(c, ref, rtol=0, atol=1e-9)
    cells = np.array([[0, 0, 0], [6, 4, 5], [3, 2, 1]])
    assert np.allclose(cell_centres(g, cells), ref[cells[:, 0], cells[:, 1], cells[:, 2]])
    assert cell_centres(g, dtype=np.float32).dtype == np.float32
    with pytest.raises(InputError, match="outside the grid"):
        cell_centres(g, [[7, 0, 0]])


def test_pillar_points():
    coord = np.array([[[0, 0, 100, 10, 20, 200], [5, 5, 100, 5, 5, 100]]], float)  # (1, 2, 6)
    p = pillar_points(coord, np.array([[150.0, 130.0]]))
    assert p.tolist() == [[[5.0, 10.0, 150.0], [5.0, 5.0, 130.0]]]  # flat pillar keeps x, y
    p = pillar_points(coord, np.array([[[100.0, 200.0], [100.0, 100.0]]]))
    assert p.shape == (1, 2, 2, 3) and p[0, 0, 1].tolist() == [10, 20, 200]
    with pytest.raises(InputError):
        pillar_points(coord, np.zeros((2, 2)))


def test_node_depths_and_conformity():
    g = synthetic_grid(5, 4, 3, faults=False, inactive_fraction=0)
    nd = node_depths(g.zcorn)
    assert nd.shape == (6, 5, 4)
    assert np.allclose(nd[1:, 1:, 1:], g.zcorn[1::2, 1::2, 1::2])
    assert is_conforming(g)
    z = np.array(g.zcorn)
    z[3, 2, 2] += 0.5  # one corner moved: faces no longer match
    bad = CornerPointGrid(g.coord, z)
    assert not is_conforming(bad) and is_conforming(bad, tol=0.6)
    assert not is_conforming(synthetic_grid(5, 4, 3))  # faults with throw


@pytest.mark.parametrize("mode", ["global", "pillar"])
@pytest.mark.parametrize("bits", [16, 12, 8])
def test_zcorn_quantise_error_bound(mode, bits, monkeypatch):
    g = synthetic_grid(9, 7, 5, seed=4)
    monkeypatch.setattr(gg, "SLAB_CELLS", 50)
    codes, z0, scale, err = zcorn_quantise(g.zcorn, bits=bits, mode=mode)
    assert codes.dtype == np.uint16 and codes.shape == g.zcorn.shape
    assert codes.flags.f_contiguous and int(codes.max()) <= (1 << bits) - 1
    back = zcorn_dequantise(codes, z0, scale)
    real = float(np.abs(back.astype(np.float64) - g.zcorn).max())
    assert real == pytest.approx(err, abs=1e-3)  # the float32 result rounds by < 1e-3
    assert err <= float(np.max(scale)) / 2 + 1e-9
    if mode == "global":
        span = float(g.zcorn.max() - g.zcorn.min())
        assert float(scale) == pytest.approx(span / ((1 << bits) - 1))
    else:
        assert np.shape(z0) == np.shape(scale) == (10, 8)


def test_pillar_mode_beats_global_and_bad_args():
    g = synthetic_grid(12, 10, 20, seed=1)
    e_global = zcorn_quantise(g.zcorn)[3]
    e_pillar = zcorn_quantise(g.zcorn, mode="pillar")[3]
    assert e_pillar < e_global
    with pytest.raises(InputError, match=r"bits must be an integer 1\.\.16"):
        zcorn_quantise(g.zcorn, bits=17)
    with pytest.raises(InputError, match="mode must be"):
        zcorn_quantise(g.zcorn, mode="x")
