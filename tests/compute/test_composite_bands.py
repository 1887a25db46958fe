"""Direct-send compositing (compute.composite.bands/crop/composite_band): bands composited apart
make exactly the picture that compositing every tile at once makes (no GL, no cluster)."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.composite import FAR, Tile, bands, composite, composite_band, crop


def _random_tiles(rng, size, n_tiles, n_parts):
    w, h = size
    tiles = []
    for _ in range(n_tiles):
        x0, y0 = int(rng.integers(0, w - 1)), int(rng.integers(0, h - 1))
        tw, th = int(rng.integers(1, w - x0 + 1)), int(rng.integers(1, h - y0 + 1))
        t = Tile.empty((x0, y0, tw, th), n_parts)
        drawn = rng.random((th, tw)) < 0.7
        # few distinct depths so that ties (decided by rank) are common
        t.depth[drawn] = rng.integers(1, 6, drawn.sum()) / 8
        t.rank[drawn] = rng.integers(0, n_parts, drawn.sum())
        t.color[drawn] = rng.integers(0, 255, (drawn.sum(), 4))
        t.color[drawn, 3] = 255
        tiles.append(t)
    return tiles


@pytest.mark.parametrize("n_bands", [1, 2, 3, 4, 7, 64])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bands_composited_apart_equal_the_whole_composite(seed, n_bands):
    rng = np.random.default_rng(seed)
    size = (37, 29)
    tiles = _random_tiles(rng, size, 6, 12)
    bg = (3, 4, 5, 6)
    color, depth, _ = composite(tiles, size, bg, n_parts=12)
    cut = bands(size, n_bands)
    assert sum(b[3] for b in cut) == size[1] and all(b[2] == size[0] for b in cut)
    assert len(cut) == min(n_bands, size[1])
    out_c = np.zeros_like(color)
    out_d = np.zeros_like(depth)
    for band in cut:
        # each worker's pieces of the band, as its peers crop them
        pieces = [c for c in (crop(t, band) for t in tiles) if c is not None]
        c, d = composite_band(pieces, band, bg, n_parts=12)
        _, y0, _, bh = band
        out_c[y0:y0 + bh] = c
        out_d[y0:y0 + bh] = d
    np.testing.assert_array_equal(out_c, color)
    np.testing.assert_array_equal(out_d, depth)
    assert (depth < FAR).any() and (depth == FAR).any()


def test_crop_keeps_only_the_rect_and_copies():
    t = Tile.empty((2, 3, 4, 5), 4)
    t.depth[:] = np.arange(20, dtype=np.float32).reshape(5, 4) / 40
    c = crop(t, (0, 4, 5, 2))
    assert c.rect == (2, 4, 3, 2)
    np.testing.assert_array_equal(c.depth, t.depth[1:3, 0:3])
    c.depth[:] = 0.9
    assert t.depth.max() < 0.9            # a copy: pickling sends only the band's pixels
    assert c.nbytes == 3 * 2 * (4 + 4 + 2)
    assert crop(t, (6, 3, 1, 1)) is None and crop(t, (0, 8, 10, 1)) is None


def test_bands_never_empty():
    assert bands((10, 1), 8) == [(0, 0, 10, 1)]
    assert [b[3] for b in bands((5, 10), 3)] in ([3, 3, 4], [3, 4, 3], [4, 3, 3])
