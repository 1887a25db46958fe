"""The numba kernels for large grids against the numpy paths (exact: same faces, same order)."""

import numpy as np
import pytest

import geoshade.compute.grid.faces as gf
from geoshade.compute.grid import kernels as grid_kernels
from geoshade.compute.grid.cell_values import summarise
from geoshade.compute.grid.faces import brute_force_visible_faces, visible_faces
from geoshade.compute.grid.geometry import zcorn_quantise, zcorn_quantiser
from geoshade.compute.grid.synthetic import synthetic_grid

FIELDS = ("cells", "face", "fault", "fault_id", "neighbour_shown")


def _same(a, b) -> bool:
    return all(np.array_equal(getattr(a, n), getattr(b, n)) for n in FIELDS)


@pytest.mark.parametrize("dims", [(1, 1, 1), (6, 5, 4), (23, 17, 9)])
@pytest.mark.parametrize("tol", [0.0, 0.5])
def test_kernel_faces_equal_numpy_faces(dims, tol):
    g = synthetic_grid(*dims, seed=4)
    rng = np.random.default_rng(1)
    for shown in (None, g.active & (rng.random(g.dims) < 0.6)):
        a = visible_faces(g, shown, tol, kernels=False)
        b = visible_faces(g, shown, tol, kernels=True)
        assert _same(a, b)
        assert len(b) > 0


def test_kernel_faces_across_many_slabs_equal_numpy(monkeypatch):
    """Slab borders inside the grid (a k pair cut by a slab) give the same faces."""
    g = synthetic_grid(20, 12, 11, seed=5)
    monkeypatch.setattr(gf, "SLAB_CELLS", 20 * 12 * 2)  # 2 layers a slab
    shown = g.active & (np.arange(11) % 4 != 2)[None, None, :]
    assert _same(visible_faces(g, shown, kernels=False), visible_faces(g, shown, kernels=True))


def test_kernel_faces_equal_numpy_with_nan_corners_and_the_brute_force_without():
    g = synthetic_grid(7, 6, 5, seed=6)
    a = visible_faces(g, kernels=True).sorted()
    b = brute_force_visible_faces(g).sorted()
    assert np.array_equal(a.cells, b.cells) and np.array_equal(a.face, b.face)
    assert np.array_equal(a.fault, b.fault)
    z = g.zcorn.copy()
    z[3, 4, 5] = np.nan  # a NaN corner never matches (readers refuse such grids; models may not)
    g.zcorn = z
    assert _same(visible_faces(g, kernels=False), visible_faces(g, kernels=True))


def test_active_depth_range_equals_the_model_method():
    g = synthetic_grid(15, 9, 6, seed=2)
    z = g.zcorn.copy()
    z[0, 0, 0], z[5, 5, 5] = np.nan, 1e30  # unusable values are left out by both
    g.zcorn = z
    assert grid_kernels.active_depth_range(g.zcorn, g.active, 1e10) == g.active_depth_range()
    none = np.zeros(g.dims, np.uint8)
    assert grid_kernels.active_depth_range(g.zcorn, none, 1e10) is None


@pytest.mark.parametrize("kernel", [False, True])
def test_summary_equals_numpy_over_active_cells(monkeypatch, kernel):
    import geoshade.compute.grid.cell_values as cv

    monkeypatch.setattr(cv, "SLAB_CELLS", 50)  # many slabs
    monkeypatch.setattr(cv, "KERNEL_CELLS", 1 if kernel else 1 << 40)
    rng = np.random.default_rng(3)
    v = np.asfortranarray(rng.normal(0.5, 1.0, (9, 8, 7)))
    v[1, 2, 3], v[4, 4, 4] = np.nan, np.inf
    act = rng.random(v.shape) < 0.8
    s = summarise(v, act)
    a = v[act]
    fin = a[np.isfinite(a)]
    pos = fin[fin > 0]
    assert (s.lo, s.hi) == (fin.min(), fin.max())
    assert (s.pos_lo, s.pos_hi) == (pos.min(), pos.max())
    assert s.nonfinite == a.size - fin.size and s.nonpositive == fin.size - pos.size
    assert s.count == a.size
    assert s.gaps(log=True) == s.nonfinite + s.nonpositive


def test_face_corner_quantisation_gives_zcorn_quantise_codes():
    """Approach 3 with faces quantises only the drawn corners, with the same codes."""
    from geoshade.render.visuals.grid import prepare

    g = synthetic_grid(12, 10, 5, seed=1)
    fs = visible_faces(g)
    codes, z0, scale, _ = zcorn_quantise(g.zcorn, bits=16)
    assert (z0, scale) == zcorn_quantiser(float(g.zcorn.min()), float(g.zcorn.max()), 16)
    full, _ = prepare.face_records(fs.cells, fs.face, g.dims, codes.ravel(order="F"))
    lazy, err = prepare.face_records(fs.cells, fs.face, g.dims, g.zcorn.ravel(order="F"),
                                     quantise=(z0, scale))
    assert np.array_equal(full, lazy)
    assert 0 < err <= scale / 2 + 1e-9


def test_summary_takes_actnum_as_given_and_dask_arrays():
    """ACTNUM 0/1 (uint8) is a mask, never indices; a dask property is summarised chunk by
    chunk to the same numbers."""
    da = pytest.importorskip("dask.array")
    rng = np.random.default_rng(5)
    v = np.asfortranarray(rng.normal(0.2, 1.0, (9, 8, 7)))
    actnum = (rng.random(v.shape) < 0.7).astype(np.uint8)
    ref = summarise(v, actnum.astype(bool))
    assert summarise(v, actnum) == ref
    lazy = summarise(da.from_array(v, chunks=(4, 3, 5)), da.from_array(actnum, chunks=(4, 3, 5)))
    assert (lazy.lo, lazy.hi, lazy.pos_lo, lazy.pos_hi) == (ref.lo, ref.hi, ref.pos_lo,
                                                            ref.pos_hi)
    assert (lazy.nonfinite, lazy.nonpositive, lazy.count) == (ref.nonfinite, ref.nonpositive,
                                                              ref.count)

