"""Face-cell gathers grouped by chunk once (compute.grid.chunks.CellGroups, grid.lazy.values_at):
the values equal numpy's fancy indexing, a switch reuses the grouping, a new cell list drops it."""

from __future__ import annotations

import gc

import dask.array as da
import numpy as np
import pytest

from geoshade.compute.grid import chunks as grid_chunks
from geoshade.compute.grid.chunks import CellGroups, gather_cells
from geoshade.grid import lazy


@pytest.fixture
def arrays():
    rng = np.random.default_rng(3)
    dims = (13, 9, 7)
    a = np.asfortranarray(rng.normal(size=dims).astype(np.float32))
    b = np.asfortranarray(rng.integers(0, 100, dims).astype(np.int32))
    return dims, a, b


@pytest.mark.parametrize("chunks", [(4, 3, 2), (13, 9, 7), (5, 9, 3), (1, 1, 1)])
def test_groups_gather_equals_fancy_indexing(arrays, chunks):
    dims, a, b = arrays
    rng = np.random.default_rng(1)
    numbers = np.unique(rng.integers(0, a.size, 200))
    for arr in (a, b):
        d = da.from_array(arr, chunks=chunks)
        g = CellGroups(numbers, dims, d.chunks)
        want = arr.ravel(order="F")[numbers]
        np.testing.assert_array_equal(g.gather(d), want)
        np.testing.assert_array_equal(gather_cells(d, None, groups=g), want)
        # unsorted and repeated cells too
        shuffled = rng.permutation(np.concatenate([numbers, numbers[:7]]))
        g2 = CellGroups(shuffled, dims, d.chunks)
        np.testing.assert_array_equal(g2.gather(d), arr.ravel(order="F")[shuffled])
    assert g.nbytes >= 8 * numbers.size and g.order.dtype == np.int32


def test_empty_and_wrong_chunks(arrays):
    dims, a, _ = arrays
    d = da.from_array(a, chunks=(4, 3, 2))
    assert CellGroups(np.zeros(0, np.int64), dims, d.chunks).gather(d).size == 0
    g = CellGroups(np.arange(5), dims, d.chunks)
    with pytest.raises(ValueError, match="chunks"):
        g.gather(da.from_array(a, chunks=(5, 5, 5)))


def test_values_at_groups_once_per_cell_list(arrays, monkeypatch):
    dims, a, b = arrays
    made = []
    real = CellGroups.__init__

    def counted(self, *args, **kw):
        made.append(1)
        real(self, *args, **kw)

    monkeypatch.setattr(CellGroups, "__init__", counted)
    numbers = np.arange(0, a.size, 5)
    da_a, da_b = da.from_array(a, chunks=(4, 3, 2)), da.from_array(b, chunks=(4, 3, 2))
    for arr, ref in ((da_a, a), (da_b, b), (da_a, a)):  # switches: one grouping
        np.testing.assert_array_equal(lazy.values_at(arr, numbers, dims),
                                      ref.ravel(order="F")[numbers])
    assert len(made) == 1
    # other chunks: grouped again; a new list (new faces): grouped again
    np.testing.assert_array_equal(lazy.values_at(da.from_array(a, chunks=(5, 5, 5)), numbers,
                                                 dims), a.ravel(order="F")[numbers])
    assert len(made) == 2
    other = numbers[::2].copy()
    np.testing.assert_array_equal(lazy.values_at(da_a, other, dims),
                                  a.ravel(order="F")[other])
    assert len(made) == 3
    oid = id(other)
    assert oid in lazy._GROUPS and id(numbers) in lazy._GROUPS  # one grouping per live list
    del other
    gc.collect()
    assert oid not in lazy._GROUPS and id(numbers) in lazy._GROUPS  # it goes with its list
    assert grid_chunks.CellGroups is CellGroups


@pytest.mark.parametrize("chunks", [(4, 3, 2), (13, 9, 3), (5, 9, 7)])
def test_long_lists_are_gathered_a_layer_at_a_time_and_not_kept(arrays, monkeypatch, chunks):
    """A list over KEEP_GROUPS cells (a 1e9 filter's) is grouped one k-layer of chunks at a
    time, not kept: the same values, in order or not, with empty layers between."""
    dims, a, b = arrays
    monkeypatch.setattr(lazy, "KEEP_GROUPS", 10)
    sizes = []
    real = CellGroups.__init__

    def counted(self, numbers, *args, **kw):
        sizes.append(np.asarray(numbers).size)
        real(self, numbers, *args, **kw)

    monkeypatch.setattr(CellGroups, "__init__", counted)
    nxy = dims[0] * dims[1]
    numbers = np.concatenate([np.arange(0, nxy, 3), np.arange(5 * nxy, a.size, 2)])  # a gap
    for arr in (a, b):
        d = da.from_array(arr, chunks=chunks)
        np.testing.assert_array_equal(lazy.values_at(d, numbers, dims),
                                      arr.ravel(order="F")[numbers])
        assert id(numbers) not in lazy._GROUPS
    layers = len(da.from_array(a, chunks=chunks).chunks[2])
    assert len(sizes) <= 2 * layers and sum(sizes) == 2 * numbers.size
    assert (max(sizes) < numbers.size) is (layers > 1)
    sizes.clear()
    shuffled = np.random.default_rng(2).permutation(numbers)   # not ascending: grouped whole
    np.testing.assert_array_equal(lazy.values_at(da.from_array(a, chunks=chunks), shuffled,
                                                 dims), a.ravel(order="F")[shuffled])
    assert sizes == [shuffled.size]


def test_colour_indices_in_batches_are_the_whole_ones(monkeypatch):
    """Colour indices are made a batch of values at a time (bounded float64 temporaries for a
    1e9 filter's cells): the same bytes, log, categories and gaps alike."""
    from geoshade.grid import cells
    from geoshade.styles.categories import CodeStyle
    from geoshade.styles.options import ColorStyle

    rng = np.random.default_rng(5)
    v = rng.lognormal(2, 1.5, 1001).astype(np.float32)
    v[::17] = np.nan
    v[::23] = -1
    codes = rng.integers(0, 6, 1001).astype(np.float32)
    cases = [(ColorStyle(), 0.5, 40.0, True, v), (ColorStyle(log=True), 1.0, 100.0, True, v),
             (ColorStyle(), 0.5, 40.0, False, v),
             (CodeStyle((3.0,)), 0, 5, True, codes)]
    whole = [cells.colour_indices(*c) for c in cases]
    monkeypatch.setattr(cells, "COLOUR_BATCH", 100)
    for c, want in zip(cases, whole, strict=True):
        np.testing.assert_array_equal(cells.colour_indices(*c), want)
