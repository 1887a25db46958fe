"""Approach 3 with faces colours only the cells it draws: after any filter, slice or property
change the picture equals a fresh view's, and the colour range never depends on the filter."""

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView

SIZE = (160, 120)


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(18, 14, 6, seed=3, steps=2)


def _img(ctx, grid, **opts):
    with GridView(grid, size=SIZE, ctx=ctx, annotations=False, **opts) as v:
        img, st = v.draw(frames=1)
        return img, st, v.colours.range


@pytest.mark.parametrize("approach,store", [(3, "faces"), (2, "faces")])
def test_changes_recolour_the_newly_visible_cells(ctx, grid, approach, store):
    base = dict(property="PORO", approach=approach, zcorn_store=store)
    with GridView(grid, size=SIZE, ctx=ctx, annotations=False, **base) as v:
        assert v.visual.color_cells() is not None  # only drawn cells hold colours
        v.draw(frames=1)
        v.update(filter="PORO > 0.2")
        v.update(slice="i=2:15")
        v.update(property="PERMX")
        v.update(filter="PORO < 0.25")
        img, _ = v.draw(frames=1)
        rng = v.colours.range
    fresh, _, frng = _img(ctx, grid, filter="PORO < 0.25", slice="i=2:15",
                          **{**base, "property": "PERMX"})
    assert np.array_equal(img, fresh)
    assert rng == frng


def test_colour_range_is_over_all_active_cells_whatever_the_filter(ctx, grid):
    _, _, full = _img(ctx, grid, property="PORO")
    _, _, filtered = _img(ctx, grid, property="PORO", filter="PORO > 0.25")
    poro = grid.properties["PORO"][grid.active]
    assert full == filtered == (float(poro.min()), float(poro.max()))


def test_subset_colours_draw_what_per_cell_colours_draw(ctx, grid):
    """Approach 3: per-face colour bytes of the drawn cells (faces) and the per-cell colour
    texture (grid, every cell) give the same picture."""
    a, _, _ = _img(ctx, grid, property="SWAT", step=1, approach=3, zcorn_store="faces",
                   zcorn_bits=32)
    b, _, _ = _img(ctx, grid, property="SWAT", step=1, approach=3, zcorn_store="grid",
                   zcorn_bits=32)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("faults", ["show", "highlight"])
def test_grids_beyond_29_bit_cell_numbers_draw_in_ranges(ctx, grid, monkeypatch, faults):
    """Approach 3 with faces numbers cells with 29 bits and draws larger grids (up to 2^32
    cells) in ranges with a ``cell_base`` each: shrunk to 2^6-cell ranges here, the picture
    is the same."""
    from geoshade.render.visuals.grid import layout

    opts = dict(property="PORO", faults=faults, edges="quad")
    plain, _, _ = _img(ctx, grid, **opts)
    monkeypatch.setattr(layout, "A3F_BUCKET_BITS", 6)
    with GridView(grid, size=SIZE, ctx=ctx, annotations=False, **opts) as v:
        ranged, _ = v.draw(frames=1)
        assert len(v.visual.ranges) > grid.ncells // 64  # many ranges were drawn
    assert np.array_equal(plain, ranged)
